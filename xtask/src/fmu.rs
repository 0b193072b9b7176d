//! Building and packaging the `.fmu`: a zip archive (FMI 2.0 section 2.3, FMI 3.0 section 2.5)
//! with
//!
//! ```text
//! modelDescription.xml                           from `flexbody-model-description --body FILE
//!                                                [--fmi 3]`
//! binaries/<platform>/<modelIdentifier>.<ext>    the release cdylib of each platform, renamed
//!                                                (linux64: .so, win64: .dll; FMI 3.0's folders
//!                                                are x86_64-linux and x86_64-windows)
//! resources/body.json                            the body file, byte for byte
//! resources/<mesh file>                          a Gmsh mesh the body file names ("mesh":
//!                                                { "gmsh": { "file": ... } }), at the same
//!                                                path relative to body.json
//! ```
//!
//! The shared library's name is taken from the `modelIdentifier` attribute of the generated XML,
//! so the archive cannot disagree with its own description.

use crate::{Result, Workspace};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::Command;
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

/// The package and binary names the build produces.
const LIBRARY_PACKAGE: &str = "flexbody";
const DESCRIPTION_BINARY: &str = "flexbody-model-description";

/// A folder of `binaries/`: its name in FMI 2.0 (section 2.3) and in FMI 3.0 (section 2.5.1.1,
/// `<arch>-<os>`), the library extension and the Rust target that builds it (`None`: the
/// machine's own).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Platform {
    pub folder: &'static str,
    pub fmi3_folder: &'static str,
    pub extension: &'static str,
    pub rust_target: Option<&'static str>,
}

impl Platform {
    /// The folder under `binaries/` in an FMU of FMI version `fmi` (2 or 3).
    pub fn folder_for(&self, fmi: u8) -> &'static str {
        if fmi == 3 {
            self.fmi3_folder
        } else {
            self.folder
        }
    }
}

/// 64-bit Windows, cross-built with the `x86_64-pc-windows-gnu` target and Debian's MinGW-w64
/// linker: the DLL links the C runtime statically and imports only Windows' own DLLs
/// ([`check_windows_imports`]).
pub const WIN64: Platform = Platform {
    folder: "win64",
    fmi3_folder: "x86_64-windows",
    extension: "dll",
    rust_target: Some("x86_64-pc-windows-gnu"),
};

/// The MinGW-w64 linker and tools for [`WIN64`] (Debian package `gcc-mingw-w64-x86-64`).
const MINGW_GCC: &str = "x86_64-w64-mingw32-gcc";
const MINGW_OBJDUMP: &str = "x86_64-w64-mingw32-objdump";
const MINGW_PACKAGE: &str = "gcc-mingw-w64-x86-64";

/// The platforms of a `--platforms` list (`linux64,win64`): the machine's own folder and `win64`.
pub fn platforms(list: &str) -> Result<Vec<Platform>> {
    let host = host_platform()?;
    let mut chosen = Vec::new();
    for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
        let platform = if name == host.folder {
            host
        } else if name == WIN64.folder {
            WIN64
        } else {
            return Err(format!(
                "platform '{name}': this machine builds {} and {} (macOS needs Apple's SDK, which it does not have)",
                host.folder, WIN64.folder
            ));
        };
        if !chosen.contains(&platform) {
            chosen.push(platform);
        }
    }
    if chosen.is_empty() {
        return Err("--platforms names no platform".into());
    }
    Ok(chosen)
}

/// The release cdylib of a cross `platform` (`cargo build --release -p flexbody --lib --target
/// ...`), after making sure the Rust target and its linker are there: `rustup target add` runs
/// by itself; the MinGW-w64 linker is installed with apt-get when this runs as root (CI, a fresh
/// machine), otherwise the error says what to install.
pub fn build_cross_library(workspace: &Workspace, platform: Platform) -> Result<PathBuf> {
    let target = platform
        .rust_target
        .ok_or("the machine's own platform is built by build_release")?;
    ensure_rust_target(target)?;
    ensure_mingw()?;
    println!("xtask fmu: cargo build --release -p {LIBRARY_PACKAGE} --lib --target {target}");
    let messages = crate::output(
        workspace
            .cargo()
            .args([
                "build",
                "--release",
                "-p",
                LIBRARY_PACKAGE,
                "--lib",
                "--target",
                target,
                "--message-format=json-render-diagnostics",
            ])
            .env("CARGO_TARGET_X86_64_PC_WINDOWS_GNU_LINKER", MINGW_GCC),
    )?;
    cdylib_from_messages(&messages, &format!(".{}", platform.extension))?
        .ok_or_else(|| format!("cargo reported no cdylib for {LIBRARY_PACKAGE} on {target}"))
}

/// `rustup target add target` unless `rustup target list --installed` has it.
fn ensure_rust_target(target: &str) -> Result<()> {
    let installed = crate::output(Command::new("rustup").args(["target", "list", "--installed"]))
        .map_err(|e| format!("{e} (the {target} target needs rustup)"))?;
    if installed.lines().any(|l| l.trim() == target) {
        return Ok(());
    }
    println!("xtask fmu: rustup target add {target}");
    crate::run(Command::new("rustup").args(["target", "add", target]))
}

/// The MinGW-w64 linker on PATH, installed with apt-get if missing and this runs as root.
fn ensure_mingw() -> Result<()> {
    let present = || {
        Command::new(MINGW_GCC)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if present() {
        return Ok(());
    }
    if apt_install_as_root(&[MINGW_PACKAGE], "the linker of the win64 binary")? && present() {
        return Ok(());
    }
    Err(format!(
        "the win64 binary needs the MinGW-w64 linker {MINGW_GCC}: install Debian's {MINGW_PACKAGE} (apt-get install {MINGW_PACKAGE}), or build this machine's platform only with --platforms {}",
        host_platform().map_or("linux64", |p| p.folder)
    ))
}

/// Installs Debian `packages` with apt-get when this runs as root on a Debian-like system (CI, a
/// fresh machine), saying `why`; `Ok(false)` when it cannot (the caller then says what to
/// install).
fn apt_install_as_root(packages: &[&str], why: &str) -> Result<bool> {
    let root = crate::output(Command::new("id").arg("-u")).is_ok_and(|u| u.trim() == "0");
    if !root || !Path::new("/usr/bin/apt-get").exists() {
        return Ok(false);
    }
    println!("xtask: apt-get install -y {} ({why})", packages.join(" "));
    crate::run(Command::new("apt-get").args(["update", "-qq"]))?;
    crate::run(
        Command::new("apt-get")
            .args(["install", "-y", "-qq"])
            .args(packages)
            .env("DEBIAN_FRONTEND", "noninteractive"),
    )?;
    Ok(true)
}

/// The Rust target and the MinGW-w64 linker of [`WIN64`], set up as [`build_cross_library`]
/// does (for building its tests).
pub fn ensure_windows_toolchain() -> Result<()> {
    ensure_rust_target(WIN64.rust_target.expect("win64 is a cross target"))?;
    ensure_mingw()
}

/// The environment variable that names the linker of [`WIN64`] for cargo, and its value.
pub const WINDOWS_LINKER: (&str, &str) = ("CARGO_TARGET_X86_64_PC_WINDOWS_GNU_LINKER", MINGW_GCC);

/// wine's 64-bit loader (Debian: `/usr/lib/wine/wine64`, not on PATH), installed with apt-get
/// (Debian's `wine` and `wine64`) if missing and this runs as root.
pub fn ensure_wine64() -> Result<PathBuf> {
    let find = || {
        ["/usr/lib/wine/wine64", "/usr/bin/wine64"]
            .iter()
            .map(PathBuf::from)
            .find(|p| p.exists())
    };
    if let Some(path) = find() {
        return Ok(path);
    }
    if apt_install_as_root(&["wine", "wine64"], "to run the win64 tests")? {
        if let Some(path) = find() {
            return Ok(path);
        }
    }
    Err("the win64 tests run under wine: install Debian's wine and wine64 (apt-get install wine wine64)".into())
}

/// Builds the wine-only stand-in for `bcryptprimitives.dll` (`tests/wine/`) as
/// `dir/bcryptprimitives.dll`, beside the executables that need it under wine.
pub fn build_wine_stand_in(workspace: &Workspace, dir: &Path) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let dll = dir.join("bcryptprimitives.dll");
    crate::run(
        Command::new(MINGW_GCC)
            .args(["-shared", "-O2", "-o"])
            .arg(&dll)
            .arg(
                workspace
                    .root
                    .join("tests/wine/bcryptprimitives_stand_in.c"),
            )
            .arg("-ladvapi32"),
    )?;
    Ok(dll)
}

/// Windows' own DLLs, which every Windows 10 and later has: the only imports a win64 binary of
/// the FMU may have (lower case; `api-ms-win-*` are the API sets).
const WINDOWS_SYSTEM_DLLS: &[&str] = &[
    "kernel32.dll",
    "ntdll.dll",
    "msvcrt.dll",
    "userenv.dll",
    "ws2_32.dll",
    "advapi32.dll",
    "bcrypt.dll",
    "bcryptprimitives.dll",
];

/// The DLLs a win64 `dll` imports (`x86_64-w64-mingw32-objdump -p`); an error naming any that
/// is not one of Windows' own, which an importer's machine would not have.
pub fn check_windows_imports(dll: &Path) -> Result<Vec<String>> {
    let dump = crate::output(Command::new(MINGW_OBJDUMP).arg("-p").arg(dll))?;
    let imports = imported_dlls(&dump);
    let foreign: Vec<&String> = imports
        .iter()
        .filter(|name| !is_windows_system_dll(name))
        .collect();
    if !foreign.is_empty() {
        return Err(format!(
            "{} imports {foreign:?}, which are not Windows' own DLLs: an importer's machine would not load it",
            dll.display()
        ));
    }
    Ok(imports)
}

/// Checks that a win64 `dll` exports the same `fmi2*` and `fmi3*` functions as this machine's
/// `library` (`objdump -p`'s export table against `nm -D --defined-only`); returns their number.
pub fn check_windows_exports(dll: &Path, library: &Path) -> Result<usize> {
    let dump = crate::output(Command::new(MINGW_OBJDUMP).arg("-p").arg(dll))?;
    let mut windows: Vec<String> = dump
        .lines()
        .filter_map(|l| l.trim().strip_prefix('['))
        .filter_map(|l| l.split_once(']'))
        .map(|(_, name)| name.trim().to_string())
        .filter(|name| is_fmi_function(name))
        .collect();
    let symbols = crate::output(
        Command::new("nm")
            .args(["-D", "--defined-only"])
            .arg(library),
    )?;
    let mut host: Vec<String> = symbols
        .lines()
        .filter_map(|l| l.split_whitespace().last())
        .filter(|name| is_fmi_function(name))
        .map(str::to_string)
        .collect();
    windows.sort();
    windows.dedup();
    host.sort();
    if windows != host || host.is_empty() {
        return Err(format!(
            "{} exports {windows:?}, {} exports {host:?}: the two binaries of the .fmu must export the same fmi2, fmi3 and flexbody_ functions",
            dll.display(),
            library.display()
        ));
    }
    Ok(host.len())
}

/// The functions an importer calls: FMI 2.0's, FMI 3.0's and ours (`flexbody_GetStepJacobian`).
fn is_fmi_function(name: &str) -> bool {
    name.starts_with("fmi2") || name.starts_with("fmi3") || name.starts_with("flexbody_")
}

/// The `DLL Name:` entries of an `objdump -p` listing.
fn imported_dlls(dump: &str) -> Vec<String> {
    dump.lines()
        .filter_map(|l| l.trim().strip_prefix("DLL Name:"))
        .map(|name| name.trim().to_string())
        .collect()
}

fn is_windows_system_dll(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    lower.starts_with("api-ms-win-") || WINDOWS_SYSTEM_DLLS.contains(&lower.as_str())
}

/// The release artifacts an FMU is made of.
pub struct Artifacts {
    /// The cdylib (`libflexbody.so` on Linux).
    pub library: PathBuf,
    /// The `flexbody-model-description` executable.
    pub description_binary: PathBuf,
}

/// `cargo build --release -p flexbody --lib --bins`; finds the artifacts in cargo's JSON messages
/// (so `CARGO_TARGET_DIR`, `build.target-dir` and cross targets need no guessing).
pub fn build_release(workspace: &Workspace) -> Result<Artifacts> {
    println!("xtask fmu: cargo build --release -p {LIBRARY_PACKAGE} --lib --bins");
    let messages = crate::output(workspace.cargo().args([
        "build",
        "--release",
        "-p",
        LIBRARY_PACKAGE,
        "--lib",
        "--bins",
        "--message-format=json-render-diagnostics",
    ]))?;
    artifacts_from_messages(&messages)
}

/// Picks the cdylib and the description binary out of cargo's `compiler-artifact` messages.
fn artifacts_from_messages(messages: &str) -> Result<Artifacts> {
    let mut library = None;
    let mut description_binary = None;
    for line in messages.lines().filter(|l| l.starts_with('{')) {
        let message: serde_json::Value =
            serde_json::from_str(line).map_err(|e| format!("cargo message {line}: {e}"))?;
        if message["reason"] != "compiler-artifact" {
            continue;
        }
        let target = &message["target"];
        let kinds = target["kind"].as_array().cloned().unwrap_or_default();
        let is_kind = |kind: &str| kinds.iter().any(|k| k == kind);
        if target["name"] == LIBRARY_PACKAGE && is_kind("cdylib") {
            library = library_file(&message, std::env::consts::DLL_SUFFIX);
        } else if target["name"] == DESCRIPTION_BINARY && is_kind("bin") {
            description_binary = message["executable"].as_str().map(PathBuf::from);
        }
    }
    Ok(Artifacts {
        library: library.ok_or("cargo reported no cdylib for flexbody")?,
        description_binary: description_binary
            .ok_or_else(|| format!("cargo reported no executable {DESCRIPTION_BINARY}"))?,
    })
}

/// The file ending in `suffix` among a `compiler-artifact` message's filenames.
fn library_file(message: &serde_json::Value, suffix: &str) -> Option<PathBuf> {
    message["filenames"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|f| f.as_str())
        .find(|f| f.ends_with(suffix))
        .map(PathBuf::from)
}

/// The flexbody cdylib ending in `suffix` in cargo's messages, if any.
fn cdylib_from_messages(messages: &str, suffix: &str) -> Result<Option<PathBuf>> {
    for line in messages.lines().filter(|l| l.starts_with('{')) {
        let message: serde_json::Value =
            serde_json::from_str(line).map_err(|e| format!("cargo message {line}: {e}"))?;
        let target = &message["target"];
        let cdylib = target["kind"]
            .as_array()
            .is_some_and(|kinds| kinds.iter().any(|k| k == "cdylib"));
        if message["reason"] == "compiler-artifact" && target["name"] == LIBRARY_PACKAGE && cdylib {
            return Ok(library_file(&message, suffix));
        }
    }
    Ok(None)
}

/// Generates the FMI `fmi` (2 or 3) description for `body` and writes the `.fmu` with the
/// host's library and the cross-built `others` (platform, library); returns its path (by
/// default `<target>/fmu/<body name>.fmu`, `<body name>-fmi3.fmu` for FMI 3.0: one archive holds
/// one `modelDescription.xml`, so one FMI version).
pub fn package(
    workspace: &Workspace,
    artifacts: &Artifacts,
    others: &[(Platform, PathBuf)],
    body: &Path,
    out: Option<&Path>,
    fmi: u8,
) -> Result<PathBuf> {
    let body_text = std::fs::read_to_string(body)
        .map_err(|e| format!("cannot read {}: {e}", body.display()))?;
    let xml = crate::output(
        std::process::Command::new(&artifacts.description_binary)
            .arg("--body")
            .arg(body)
            .args(["--fmi", &fmi.to_string()]),
    )?;
    let model_identifier = model_identifier(&xml)?;
    let resources = mesh_resources(&body_text, body.parent().unwrap_or(Path::new(".")))?;
    let out = match out {
        Some(path) => path.to_path_buf(),
        None => workspace.target_dir.join("fmu").join(format!(
            "{}{}.fmu",
            file_stem(&body_name(&body_text)?),
            if fmi == 3 { "-fmi3" } else { "" }
        )),
    };
    let mut libraries = vec![(host_platform()?, artifacts.library.clone())];
    libraries.extend(others.iter().cloned());
    let libraries: Vec<(&str, &str, PathBuf)> = libraries
        .into_iter()
        .map(|(p, library)| (p.folder_for(fmi), p.extension, library))
        .collect();
    write_fmu(
        &out,
        &xml,
        &model_identifier,
        &libraries,
        body_text.as_bytes(),
        &resources,
    )?;
    Ok(out)
}

/// The mesh file a body file names (`mesh.gmsh.file`), as (path inside `resources/`, bytes).
/// The path must be relative and stay inside the body file's directory, so that the FMU can
/// hold it at the same place relative to `resources/body.json` and the body file stays as it is.
fn mesh_resources(body_json: &str, body_dir: &Path) -> Result<Vec<(String, Vec<u8>)>> {
    let body: serde_json::Value =
        serde_json::from_str(body_json).map_err(|e| format!("body file: {e}"))?;
    let Some(file) = body["mesh"]["gmsh"]["file"].as_str() else {
        return Ok(Vec::new());
    };
    let relative = Path::new(file);
    let mut parts = Vec::new();
    for component in relative.components() {
        match component {
            std::path::Component::Normal(part) => parts.push(
                part.to_str()
                    .ok_or_else(|| format!("mesh file '{file}': not UTF-8"))?
                    .to_string(),
            ),
            _ => {
                return Err(format!(
                    "mesh file '{file}': must be a relative path inside the body file's                      directory (no '..', no absolute path) to be packaged into resources/"
                ))
            }
        }
    }
    if parts.is_empty() || parts.last().is_some_and(|p| p == "body.json") {
        return Err(format!("mesh file '{file}': not a usable file name"));
    }
    let path = body_dir.join(relative);
    let bytes = std::fs::read(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    Ok(vec![(format!("resources/{}", parts.join("/")), bytes)])
}

/// The FMI platform folder and library extension of the machine this xtask was built for.
pub fn host_platform() -> Result<Platform> {
    if cfg!(not(target_pointer_width = "64")) {
        return Err("only 64-bit platforms are packaged".into());
    }
    let (folder, extension) = match std::env::consts::OS {
        "linux" => ("linux64", "so"),
        "macos" => ("darwin64", "dylib"),
        "windows" => ("win64", "dll"),
        os => return Err(format!("FMI 2.0 defines no binaries folder for {os}")),
    };
    let fmi3_folder = match (std::env::consts::ARCH, std::env::consts::OS) {
        ("x86_64", "linux") => "x86_64-linux",
        ("aarch64", "linux") => "aarch64-linux",
        ("x86_64", "macos") => "x86_64-darwin",
        ("aarch64", "macos") => "aarch64-darwin",
        ("x86_64", "windows") => "x86_64-windows",
        (arch, os) => return Err(format!("no FMI 3.0 binaries folder for {arch} {os}")),
    };
    Ok(Platform {
        folder,
        fmi3_folder,
        extension,
        rust_target: None,
    })
}

/// Writes the archive next to `out` and renames it into place, so a failed run leaves no
/// half-written `.fmu`.
fn write_fmu(
    out: &Path,
    xml: &str,
    model_identifier: &str,
    libraries: &[(&str, &str, PathBuf)],
    body_json: &[u8],
    resources: &[(String, Vec<u8>)],
) -> Result<()> {
    let mut binaries = Vec::new();
    for (folder, extension, library) in libraries {
        let bytes = std::fs::read(library)
            .map_err(|e| format!("cannot read {}: {e}", library.display()))?;
        binaries.push((
            format!("binaries/{folder}/{model_identifier}.{extension}"),
            bytes,
        ));
    }
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    }
    let partial = out.with_extension("fmu.partial");
    let mut entries: Vec<(String, &[u8], u32)> =
        vec![("modelDescription.xml".into(), xml.as_bytes(), 0o644)];
    for (name, bytes) in &binaries {
        entries.push((name.clone(), bytes, 0o755));
    }
    entries.push(("resources/body.json".into(), body_json, 0o644));
    for (name, bytes) in resources {
        entries.push((name.clone(), bytes, 0o644));
    }
    let write = || -> std::io::Result<()> {
        let mut zip = ZipWriter::new(BufWriter::new(File::create(&partial)?));
        for (name, bytes, mode) in entries {
            let options = SimpleFileOptions::default()
                .compression_method(CompressionMethod::Deflated)
                .unix_permissions(mode);
            zip.start_file(name, options)?;
            zip.write_all(bytes)?;
        }
        zip.finish()?.flush()
    };
    write().map_err(|e| format!("cannot write {}: {e}", partial.display()))?;
    std::fs::rename(&partial, out).map_err(|e| {
        format!(
            "cannot move {} to {}: {e}",
            partial.display(),
            out.display()
        )
    })
}

/// The `modelIdentifier` attribute of the `<CoSimulation>` element.
fn model_identifier(xml: &str) -> Result<String> {
    let key = "modelIdentifier=\"";
    let start = xml
        .find(key)
        .ok_or("modelDescription.xml has no modelIdentifier")?
        + key.len();
    let length = xml[start..]
        .find('"')
        .ok_or("modelDescription.xml: unterminated modelIdentifier")?;
    let identifier = &xml[start..start + length];
    let valid = identifier
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && identifier
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_');
    if valid {
        Ok(identifier.to_string())
    } else {
        Err(format!(
            "modelIdentifier '{identifier}' is not a C identifier"
        ))
    }
}

/// The body file's `name`.
fn body_name(body_json: &str) -> Result<String> {
    let body: serde_json::Value =
        serde_json::from_str(body_json).map_err(|e| format!("body file: {e}"))?;
    body["name"]
        .as_str()
        .map(str::to_string)
        .ok_or_else(|| "body file has no \"name\"".into())
}

/// A file name made from a model name: characters other than letters, digits, `-`, `_` and `.`
/// become `_`.
fn file_stem(name: &str) -> String {
    let stem: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if stem.is_empty() || stem.chars().all(|c| c == '.') {
        "body".into()
    } else {
        stem
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    #[test]
    fn model_identifier_is_read_from_the_cosimulation_element() {
        let xml = r#"<fmiModelDescription fmiVersion="2.0" modelName="cantilever">
            <CoSimulation modelIdentifier="flexbody" canHandleVariableCommunicationStepSize="true"/>"#;
        assert_eq!(model_identifier(xml).unwrap(), "flexbody");
        assert!(model_identifier("<fmiModelDescription/>").is_err());
        assert!(model_identifier(r#"<CoSimulation modelIdentifier="../evil"/>"#).is_err());
    }

    #[test]
    fn file_stem_keeps_safe_characters_only() {
        assert_eq!(file_stem("cantilever"), "cantilever");
        assert_eq!(file_stem("robot arm/link 2"), "robot_arm_link_2");
        assert_eq!(file_stem(".."), "body");
        assert_eq!(file_stem(""), "body");
    }

    #[test]
    fn body_name_comes_from_the_body_file() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../examples/cantilever.json"
        ))
        .unwrap();
        assert_eq!(body_name(&text).unwrap(), "cantilever");
        assert!(body_name("{}").is_err());
    }

    #[test]
    fn artifacts_are_found_in_cargo_messages() {
        let messages = r#"
{"reason":"compiler-artifact","target":{"kind":["lib"],"name":"serde"},"filenames":["/t/release/deps/libserde.rlib"],"executable":null}
{"reason":"compiler-artifact","target":{"kind":["cdylib","rlib"],"name":"flexbody"},"filenames":["/t/release/libflexbody.so","/t/release/libflexbody.rlib"],"executable":null}
{"reason":"compiler-artifact","target":{"kind":["bin"],"name":"flexbody-model-description"},"filenames":["/t/release/flexbody-model-description"],"executable":"/t/release/flexbody-model-description"}
{"reason":"build-finished","success":true}
"#;
        let artifacts = artifacts_from_messages(messages).unwrap();
        if cfg!(target_os = "linux") {
            assert_eq!(artifacts.library, Path::new("/t/release/libflexbody.so"));
        }
        assert_eq!(
            artifacts.description_binary,
            Path::new("/t/release/flexbody-model-description")
        );
        assert!(artifacts_from_messages(r#"{"reason":"build-finished","success":true}"#).is_err());
    }

    #[test]
    fn the_mesh_file_of_a_body_goes_into_resources() {
        let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
        let conrod = std::fs::read_to_string(examples.join("conrod.json")).unwrap();
        let resources = mesh_resources(&conrod, &examples).unwrap();
        assert_eq!(resources.len(), 1);
        assert_eq!(resources[0].0, "resources/conrod/conrod.msh");
        assert!(resources[0].1.starts_with(b"$MeshFormat"));
        let beam = std::fs::read_to_string(examples.join("cantilever.json")).unwrap();
        assert!(mesh_resources(&beam, &examples).unwrap().is_empty());
        let outside = r#"{"mesh": {"gmsh": {"file": "../x.msh"}}}"#;
        assert!(mesh_resources(outside, &examples)
            .unwrap_err()
            .contains("no '..'"));
        let missing = r#"{"mesh": {"gmsh": {"file": "nowhere.msh"}}}"#;
        assert!(mesh_resources(missing, &examples)
            .unwrap_err()
            .contains("cannot read"));
    }

    #[test]
    fn imports_are_read_from_objdump_and_foreign_dlls_are_named() {
        let dump = "\tDLL Name: KERNEL32.dll\n\tvma:  Hint/Ord Member-Name\n\tDLL Name: api-ms-win-core-synch-l1-2-0.dll\n\tDLL Name: libgcc_s_seh-1.dll\n";
        let imports = imported_dlls(dump);
        assert_eq!(
            imports,
            [
                "KERNEL32.dll",
                "api-ms-win-core-synch-l1-2-0.dll",
                "libgcc_s_seh-1.dll"
            ]
        );
        let foreign: Vec<&String> = imports
            .iter()
            .filter(|n| !is_windows_system_dll(n))
            .collect();
        assert_eq!(foreign, ["libgcc_s_seh-1.dll"]);
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn platform_lists_name_this_machine_and_win64() {
        assert_eq!(
            platforms("linux64, win64,linux64").unwrap(),
            [host_platform().unwrap(), WIN64]
        );
        assert!(platforms("darwin64").unwrap_err().contains("SDK"));
        assert!(platforms("").is_err());
    }

    #[cfg(all(target_os = "linux", target_arch = "x86_64"))]
    #[test]
    fn fmi3_folders_are_arch_dash_os() {
        let host = host_platform().unwrap();
        assert_eq!(
            (host.folder_for(2), host.folder_for(3)),
            ("linux64", "x86_64-linux")
        );
        assert_eq!(
            (WIN64.folder_for(2), WIN64.folder_for(3)),
            ("win64", "x86_64-windows")
        );
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn fmu_has_the_fmi_layout() {
        let dir = std::env::temp_dir().join(format!("xtask-fmu-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let library = dir.join("libflexbody.so");
        std::fs::write(&library, b"\x7fELF not really").unwrap();
        let dll = dir.join("flexbody.dll");
        std::fs::write(&dll, b"MZ not really").unwrap();
        let out = dir.join("out").join("cantilever.fmu");
        let xml = r#"<fmiModelDescription><CoSimulation modelIdentifier="flexbody"/></fmiModelDescription>"#;
        write_fmu(
            &out,
            xml,
            "flexbody",
            &[("linux64", "so", library), ("win64", "dll", dll)],
            b"{\"name\":\"cantilever\"}",
            &[("resources/meshes/part.msh".into(), b"$MeshFormat".to_vec())],
        )
        .unwrap();
        assert!(!out.with_extension("fmu.partial").exists());

        let mut archive = zip::ZipArchive::new(File::open(&out).unwrap()).unwrap();
        let mut names: Vec<String> = archive.file_names().map(str::to_string).collect();
        names.sort();
        assert_eq!(
            names,
            [
                "binaries/linux64/flexbody.so",
                "binaries/win64/flexbody.dll",
                "modelDescription.xml",
                "resources/body.json",
                "resources/meshes/part.msh"
            ]
        );
        let mut read = |name: &str| {
            let mut entry = archive.by_name(name).unwrap();
            let mut bytes = Vec::new();
            entry.read_to_end(&mut bytes).unwrap();
            (bytes, entry.unix_mode())
        };
        assert_eq!(read("modelDescription.xml").0, xml.as_bytes());
        let (library_bytes, mode) = read("binaries/linux64/flexbody.so");
        assert_eq!(library_bytes, b"\x7fELF not really");
        assert_eq!(mode.map(|m| m & 0o777), Some(0o755));
        assert_eq!(read("binaries/win64/flexbody.dll").0, b"MZ not really");
        assert_eq!(read("resources/body.json").0, b"{\"name\":\"cantilever\"}");
        assert_eq!(read("resources/meshes/part.msh").0, b"$MeshFormat");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
