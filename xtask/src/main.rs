//! The project's tasks, run as `cargo xtask <task>` (alias in `.cargo/config.toml`):
//!
//! * `fmu [--body FILE] [--out FILE] [--platforms LIST] [--fmi 2|3]`: builds the release library
//!   (for each platform: this machine's and, by default, win64 cross-built with MinGW-w64) and
//!   the description binary and packages `modelDescription.xml`,
//!   `binaries/<platform>/<modelIdentifier>.<ext>` and `resources/body.json` into an FMI 2.0
//!   (default) or 3.0 `.fmu` (default: `<target>/fmu/<body name>.fmu`, `<body name>-fmi3.fmu`).
//! * `test [--python-only] [PYTEST ARGS...]`: all Rust tests (`cargo test --workspace`), the
//!   library's Rust tests cross-built for win64 and run under wine, then the default FMU
//!   (linux64 and win64; the win64 DLL's imports checked to be Windows' own), the driven cantilever's FMU (`examples/driven_cantilever.json`), the pinned
//!   Python environment (`<target>/venv`) and `pytest tests/python` with the FMUs' paths in
//!   `FLEXBODY_FMU`, `FLEXBODY_DRIVEN_FMU`, `FLEXBODY_CONROD_FMU` (`examples/conrod.json`) and
//!   `FLEXBODY_ARM_FMU` (`examples/controlled_arm.json`).
//! * `demo`: the default FMU driven by fmpy (`tests/python/demo.py`): a step load on the
//!   cantilever's tip, a table, the comparison with the Timoshenko deflection and a PNG plot.
//!
//! * `bench [--quick]`: the measurement examples in release mode, the Exudyn peers in the pinned
//!   bench venv (`<target>/bench-venv`) and the plots, written to `bench/results/<date>.md`
//!   (see `bench.rs`).
//! * `venv`: only the pinned Python environment; prints its interpreter.
//!
//! Only `std::process::Command` and the zip crate: no shell, no build scripts of our own.

mod bench;
mod fmu;
mod venv;

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

/// Errors of a task: a message for the terminal.
pub type Result<T> = std::result::Result<T, String>;

const USAGE: &str = "\
usage: cargo xtask <task>

tasks:
  fmu [--body FILE] [--out FILE] [--platforms LIST] [--fmi 2|3]
                                    build the .fmu (default body: examples/cantilever.json,
                                    default out: <target>/fmu/<body name>.fmu, or
                                    <body name>-fmi3.fmu with --fmi 3; default FMI version 2.0,
                                    default platforms: linux64,win64; win64 is cross-built with the
                                    x86_64-pc-windows-gnu target, which rustup adds, and
                                    Debian's gcc-mingw-w64-x86-64, installed when run as root)
  test [--python-only] [ARGS...]    cargo test --workspace, build the default and the driven
                                    cantilever's .fmu, set up the pinned venv (<target>/venv)
                                    and run pytest tests/python
                                    (ARGS go to pytest; --python-only skips the Rust tests)
  demo                              simulate the default cantilever with fmpy, print a table,
                                    compare with the Timoshenko deflection, plot to
                                    <target>/demo/cantilever.png
  bench [--quick]                   run the measurement examples in release mode, the Exudyn
                                    peers (pinned venv <target>/bench-venv) and the plots;
                                    report in bench/results/<date>.md
  venv                              set up the pinned venv only and print its python";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (task, rest) = match args.split_first() {
        Some((task, rest)) => (task.as_str(), rest),
        None => {
            eprintln!("{USAGE}");
            return ExitCode::FAILURE;
        }
    };
    let result = match task {
        "fmu" => fmu_task(rest),
        "test" => test_task(rest),
        "demo" => demo_task(rest),
        "venv" => venv_task(rest),
        "bench" => match rest {
            [] => Workspace::locate().and_then(|w| bench::bench_task(&w, false)),
            [q] if q == "--quick" => Workspace::locate().and_then(|w| bench::bench_task(&w, true)),
            _ => Err(format!("unexpected arguments {rest:?}\n{USAGE}")),
        },
        "-h" | "--help" | "help" => {
            println!("{USAGE}");
            Ok(())
        }
        other => Err(format!("unknown task '{other}'\n{USAGE}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("xtask {task}: error: {message}");
            ExitCode::FAILURE
        }
    }
}

/// The platforms of the `.fmu` unless `--platforms` says otherwise.
const DEFAULT_PLATFORMS: &str = "linux64,win64";

/// `cargo xtask fmu [--body FILE] [--out FILE] [--platforms LIST] [--fmi 2|3]`.
fn fmu_task(args: &[String]) -> Result<()> {
    let mut body = None;
    let mut out = None;
    let mut platforms = fmu::platforms(DEFAULT_PLATFORMS)?;
    let mut fmi = 2;
    let mut args = args.iter();
    while let Some(arg) = args.next() {
        let slot = match arg.as_str() {
            "--body" => &mut body,
            "--out" => &mut out,
            "--fmi" => {
                fmi = match args.next().map(String::as_str) {
                    Some("2") => 2,
                    Some("3") => 3,
                    _ => return Err("--fmi needs 2 or 3".into()),
                };
                continue;
            }
            "--platforms" => {
                let list = args
                    .next()
                    .ok_or("--platforms needs a list (linux64,win64)")?;
                platforms = fmu::platforms(list)?;
                continue;
            }
            other => return Err(format!("unexpected argument '{other}'\n{USAGE}")),
        };
        let value = args
            .next()
            .ok_or_else(|| format!("{arg} needs a file name"))?;
        // Relative paths are relative to where the user typed the command.
        *slot = Some(std::path::absolute(value).map_err(|e| format!("{value}: {e}"))?);
    }
    let workspace = Workspace::locate()?;
    workspace.build_fmu(body.as_deref(), out.as_deref(), &platforms, fmi)?;
    Ok(())
}

/// `cargo xtask test [--python-only] [PYTEST ARGS...]`.
fn test_task(args: &[String]) -> Result<()> {
    let python_only = args.iter().any(|a| a == "--python-only");
    // `cargo xtask test -- -k state` passes a `--` through: it only separates, pytest gets the rest.
    let pytest_args: Vec<&String> = args
        .iter()
        .filter(|a| *a != "--python-only" && *a != "--")
        .collect();
    let workspace = Workspace::locate()?;
    if !python_only {
        println!("xtask test: Rust tests (cargo test --workspace)");
        run(workspace.cargo().args(["test", "--workspace"]))?;
        windows_tests(&workspace)?;
    }
    let fmu = workspace.build_fmu(None, None, &fmu::platforms(DEFAULT_PLATFORMS)?, 2)?;
    let fmu3 = workspace.build_fmu(None, None, &fmu::platforms(DEFAULT_PLATFORMS)?, 3)?;
    let dll = fmu::build_cross_library(&workspace, fmu::WIN64)?;
    let imports = fmu::check_windows_imports(&dll)?;
    let exports = fmu::check_windows_exports(&dll, &fmu::build_release(&workspace)?.library)?;
    println!(
        "xtask test: the win64 DLL exports the {exports} fmi2, fmi3 and flexbody_ functions of the linux64 library, unmangled, and imports only Windows' own DLLs: {}",
        imports.join(", ")
    );
    // The other release builds are no-ops: only the packaging differs.
    let host = [fmu::host_platform()?];
    let driven_fmu = workspace.build_fmu(Some(&workspace.driven_body()), None, &host, 2)?;
    let conrod_fmu = workspace.build_fmu(Some(&workspace.conrod_body()), None, &host, 2)?;
    let arm_fmu = workspace.build_fmu(Some(&workspace.arm_body()), None, &host, 2)?;
    // The win64 DLL is also run under wine by fmpy's remoting server (tests/python/test_win64.py),
    // with the stand-in for wine 8.0's missing bcryptprimitives.dll beside the server.
    let wine64 = fmu::ensure_wine64()?;
    let stand_in = fmu::build_wine_stand_in(&workspace, &workspace.target_dir.join("wine"))?;
    let python = venv::ensure(&workspace)?;
    println!(
        "xtask test: Python tests (pytest tests/python) on {} and {}",
        fmu.display(),
        driven_fmu.display()
    );
    let mut pytest = Command::new(&python);
    pytest
        .current_dir(&workspace.root)
        .args(["-m", "pytest", "tests/python"])
        .args(pytest_args)
        .env("FLEXBODY_FMU", &fmu)
        .env("FLEXBODY_FMU3", &fmu3)
        .env("FLEXBODY_WINE64", &wine64)
        .env("FLEXBODY_WINE_STAND_IN", &stand_in)
        .env("FLEXBODY_DRIVEN_FMU", &driven_fmu)
        .env("FLEXBODY_CONROD_FMU", &conrod_fmu)
        .env("FLEXBODY_ARM_FMU", &arm_fmu)
        .env("MPLBACKEND", "Agg");
    run(&mut pytest)
}

/// The library's Rust tests (unit and integration: the C ABI, the slave, the physics),
/// cross-built for win64 and run under wine, with the wine-only stand-in for
/// `bcryptprimitives.dll` beside them. Their output goes to `<target>/wine/tests.log` and the
/// summary lines are printed afterwards: a wineserver left running would hold a pipe open and
/// keep the caller waiting; it is stopped at the end.
fn windows_tests(workspace: &Workspace) -> Result<()> {
    let target = fmu::WIN64.rust_target.expect("win64 is a cross target");
    fmu::ensure_windows_toolchain()?;
    let wine64 = fmu::ensure_wine64()?;
    println!(
        "xtask test: the Rust tests for win64 under wine (cargo test --target {target} --tests)"
    );
    let deps = workspace.target_dir.join(target).join("debug").join("deps");
    fmu::build_wine_stand_in(workspace, &deps)?;
    let log_path = workspace.target_dir.join("wine").join("tests.log");
    std::fs::create_dir_all(log_path.parent().unwrap())
        .map_err(|e| format!("cannot create {}: {e}", log_path.display()))?;
    let log = std::fs::File::create(&log_path)
        .map_err(|e| format!("cannot create {}: {e}", log_path.display()))?;
    // One wineserver for the whole run: started per binary, it exits a few seconds after the
    // last client, and a binary that connects while it exits fails with "wine client error:
    // recvmsg: Connection reset by peer" (seen once in 35 binaries).
    let wineserver = wine64.with_file_name("wineserver");
    if wineserver.exists() {
        let _ = Command::new(&wineserver)
            .arg("-p")
            .stdin(std::process::Stdio::null())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .status();
    }
    let mut cargo = workspace.cargo();
    cargo
        .args(["test", "--no-fail-fast", "--target", target, "--tests"])
        .env(fmu::WINDOWS_LINKER.0, fmu::WINDOWS_LINKER.1)
        .env("CARGO_TARGET_X86_64_PC_WINDOWS_GNU_RUNNER", &wine64)
        .env("WINEDEBUG", "-all")
        .stdin(std::process::Stdio::null())
        .stdout(log.try_clone().map_err(|e| e.to_string())?)
        .stderr(log);
    let result = run(&mut cargo);
    if wineserver.exists() {
        let _ = Command::new(&wineserver)
            .arg("-k")
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .status();
    }
    let text = std::fs::read_to_string(&log_path).unwrap_or_default();
    // The summary: each binary, its result, and whatever failed.
    for line in text.lines().filter(|l| {
        l.contains("Running")
            || l.starts_with("test result")
            || l.contains("FAILED")
            || l.contains("panicked")
            || l.starts_with("error")
    }) {
        println!("  {line}");
    }
    result.map_err(|e| format!("{e} (the whole output is in {})", log_path.display()))
}

/// `cargo xtask demo`.
fn demo_task(args: &[String]) -> Result<()> {
    if let Some(arg) = args.first() {
        return Err(format!("unexpected argument '{arg}'\n{USAGE}"));
    }
    let workspace = Workspace::locate()?;
    // The demo runs here: this machine's binary is all it needs.
    let fmu = workspace.build_fmu(None, None, &[fmu::host_platform()?], 2)?;
    let python = venv::ensure(&workspace)?;
    let plot = workspace.target_dir.join("demo").join("cantilever.png");
    let mut demo = Command::new(&python);
    demo.current_dir(&workspace.root)
        .arg("tests/python/demo.py")
        .arg("--fmu")
        .arg(&fmu)
        .arg("--plot")
        .arg(&plot)
        .env("MPLBACKEND", "Agg");
    run(&mut demo)
}

/// `cargo xtask venv`: for running pytest or the demo by hand.
fn venv_task(args: &[String]) -> Result<()> {
    if let Some(arg) = args.first() {
        return Err(format!("unexpected argument '{arg}'\n{USAGE}"));
    }
    let python = venv::ensure(&Workspace::locate()?)?;
    println!("{}", python.display());
    Ok(())
}

/// Where things are: the workspace root (sources) and cargo's target directory (outputs).
pub struct Workspace {
    pub root: PathBuf,
    /// Cargo's target directory: honours `CARGO_TARGET_DIR` and `build.target-dir`.
    pub target_dir: PathBuf,
    cargo: OsString,
}

impl Workspace {
    /// Finds the workspace (the parent of this crate) and asks cargo for its target directory.
    fn locate() -> Result<Workspace> {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"))
            .parent()
            .ok_or("xtask has no parent directory")?
            .to_path_buf();
        // `cargo run` tells the program which cargo started it.
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let metadata = output(Command::new(&cargo).current_dir(&root).args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
        ]))?;
        let metadata: serde_json::Value =
            serde_json::from_str(&metadata).map_err(|e| format!("cargo metadata: {e}"))?;
        let target_dir = metadata["target_directory"]
            .as_str()
            .ok_or("cargo metadata has no target_directory")?
            .into();
        Ok(Workspace {
            root,
            target_dir,
            cargo,
        })
    }

    /// A `git` command run in the workspace root.
    pub fn git(&self) -> Command {
        let mut command = Command::new("git");
        command.current_dir(&self.root);
        command
    }

    /// A `cargo` command run in the workspace root.
    pub fn cargo(&self) -> Command {
        let mut command = Command::new(&self.cargo);
        command.current_dir(&self.root);
        command
    }

    /// The default body file (also embedded in the library).
    pub fn default_body(&self) -> PathBuf {
        self.root.join("examples").join("cantilever.json")
    }

    /// The driven cantilever (root clamped to an input frame): the coupling tests' second body.
    pub fn driven_body(&self) -> PathBuf {
        self.root.join("examples").join("driven_cantilever.json")
    }

    /// The connecting rod (Gmsh tet10 mesh in resources/, motion and force interfaces on its eyes).
    pub fn conrod_body(&self) -> PathBuf {
        self.root.join("examples").join("conrod.json")
    }

    /// Kane's beam on a hinge with a rigid hub (`tests/python/controlled_arm.py`'s FMU).
    pub fn arm_body(&self) -> PathBuf {
        self.root.join("examples").join("controlled_arm.json")
    }

    /// Builds and packages the FMI `fmi` (2 or 3) FMU with the binaries of `platforms`;
    /// returns its path.
    fn build_fmu(
        &self,
        body: Option<&Path>,
        out: Option<&Path>,
        platforms: &[fmu::Platform],
        fmi: u8,
    ) -> Result<PathBuf> {
        let body = body.map_or_else(|| self.default_body(), Path::to_path_buf);
        let artifacts = fmu::build_release(self)?;
        let mut others = Vec::new();
        for &platform in platforms.iter().filter(|p| p.rust_target.is_some()) {
            others.push((platform, fmu::build_cross_library(self, platform)?));
        }
        let package = fmu::package(self, &artifacts, &others, &body, out, fmi)?;
        let size = std::fs::metadata(&package)
            .map_err(|e| format!("{}: {e}", package.display()))?
            .len();
        println!(
            "xtask fmu: wrote {} ({:.1} MiB, {size} bytes)",
            package.display(),
            size as f64 / (1024.0 * 1024.0)
        );
        Ok(package)
    }
}

/// Runs a command with inherited standard streams; an error if it fails.
pub fn run(command: &mut Command) -> Result<()> {
    let status = command
        .status()
        .map_err(|e| format!("cannot run {}: {e}", describe(command)))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("{} failed ({status})", describe(command)))
    }
}

/// Runs a command and returns its standard output (standard error goes to the terminal).
pub fn output(command: &mut Command) -> Result<String> {
    let result = command
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| format!("cannot run {}: {e}", describe(command)))?;
    if !result.status.success() {
        return Err(format!("{} failed ({})", describe(command), result.status));
    }
    String::from_utf8(result.stdout)
        .map_err(|e| format!("{}: output is not UTF-8: {e}", describe(command)))
}

/// The command line, for messages.
fn describe(command: &Command) -> String {
    std::iter::once(command.get_program())
        .chain(command.get_args())
        .map(|s| s.to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join(" ")
}
