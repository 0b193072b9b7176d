//! The pinned Python environments, made with `python3 -m venv` and filled from a
//! `requirements.txt` with every transitive dependency pinned by the `constraints.txt` beside it:
//! * [`TESTS`]: `<target>/venv` from `tests/python/` (the fmpy tests and the demo, CI);
//! * [`BENCH`]: `<target>/bench-venv` from `bench/` (Exudyn, scipy, matplotlib for
//!   `cargo xtask bench`; kept apart so that the test venv stays small).
//!
//! A stamp file in the venv holds the interpreter's version and both files' text; the venv is
//! reused while the stamp matches and rebuilt from scratch when it does not (or when an
//! installation was interrupted, which leaves no stamp).

use crate::{run, Result, Workspace};
use std::path::{Path, PathBuf};
use std::process::Command;

const STAMP: &str = "flexbody-requirements.stamp";

/// A pinned environment: the folder (relative to the workspace root) that holds its
/// `requirements.txt` and `constraints.txt`, and the venv's folder name under the target dir.
pub struct Env {
    pub files: &'static str,
    pub venv: &'static str,
}

/// The fmpy tests and the demo.
pub const TESTS: Env = Env {
    files: "tests/python",
    venv: "venv",
};

/// The benchmark's peers and plots.
pub const BENCH: Env = Env {
    files: "bench",
    venv: "bench-venv",
};

/// The test venv's Python interpreter (see [`ensure_env`]).
pub fn ensure(workspace: &Workspace) -> Result<PathBuf> {
    ensure_env(workspace, &TESTS)
}

/// Returns the venv's Python interpreter, creating or rebuilding the venv when needed.
/// The base interpreter is `$FLEXBODY_PYTHON`, else `python3`.
pub fn ensure_env(workspace: &Workspace, env: &Env) -> Result<PathBuf> {
    let base_python = std::env::var_os("FLEXBODY_PYTHON").unwrap_or_else(|| "python3".into());
    let requirements = workspace.root.join(env.files).join("requirements.txt");
    let constraints = workspace.root.join(env.files).join("constraints.txt");
    let version = crate::output(Command::new(&base_python).arg("--version"))?;
    let wanted = stamp_text(&version, &read(&requirements)?, &read(&constraints)?);

    let venv = workspace.target_dir.join(env.venv);
    let python = venv_python(&venv);
    let stamp = venv.join(STAMP);
    if python.exists() && std::fs::read_to_string(&stamp).ok().as_deref() == Some(wanted.as_str()) {
        println!("xtask: reusing {}", venv.display());
        return Ok(python);
    }

    println!("xtask: creating {} ({})", venv.display(), version.trim());
    if venv.exists() {
        std::fs::remove_dir_all(&venv)
            .map_err(|e| format!("cannot remove {}: {e}", venv.display()))?;
    }
    run(Command::new(&base_python).args(["-m", "venv"]).arg(&venv))?;
    run(Command::new(&python)
        .args([
            "-m",
            "pip",
            "install",
            "--disable-pip-version-check",
            "--no-input",
            "-r",
        ])
        .arg(&requirements)
        .arg("-c")
        .arg(&constraints))?;
    std::fs::write(&stamp, wanted).map_err(|e| format!("cannot write {}: {e}", stamp.display()))?;
    Ok(python)
}

/// What the venv was built from.
fn stamp_text(python_version: &str, requirements: &str, constraints: &str) -> String {
    format!(
        "{}\n--- requirements.txt\n{requirements}\n--- constraints.txt\n{constraints}",
        python_version.trim()
    )
}

fn read(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|e| format!("cannot read {}: {e}", path.display()))
}

/// The interpreter inside a venv.
fn venv_python(venv: &Path) -> PathBuf {
    if cfg!(windows) {
        venv.join("Scripts").join("python.exe")
    } else {
        venv.join("bin").join("python")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stamp_changes_with_every_input() {
        let base = stamp_text("Python 3.11.7\n", "fmpy==0.3.32\n", "numpy==2.4.6\n");
        assert_eq!(
            base,
            stamp_text("Python 3.11.7", "fmpy==0.3.32\n", "numpy==2.4.6\n")
        );
        assert_ne!(
            base,
            stamp_text("Python 3.12.1", "fmpy==0.3.32\n", "numpy==2.4.6\n")
        );
        assert_ne!(
            base,
            stamp_text("Python 3.11.7", "fmpy==0.3.31\n", "numpy==2.4.6\n")
        );
        assert_ne!(
            base,
            stamp_text("Python 3.11.7", "fmpy==0.3.32\n", "numpy==2.4.5\n")
        );
    }

    #[test]
    fn pinned_files_pin_every_line() {
        // Every requirement is `name==version`: an unpinned line would make the venv drift.
        for env in [TESTS, BENCH] {
            let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("..")
                .join(env.files);
            pinned(&dir);
            let requirements = read(&dir.join("requirements.txt")).unwrap();
            assert!(requirements.lines().any(|l| l.trim() == "fmpy==0.3.32"));
        }
    }

    fn pinned(dir: &Path) {
        for file in ["requirements.txt", "constraints.txt"] {
            let text = read(&dir.join(file)).unwrap();
            let lines: Vec<&str> = text
                .lines()
                .map(str::trim)
                .filter(|l| !l.is_empty() && !l.starts_with('#'))
                .collect();
            assert!(!lines.is_empty(), "{file} is empty");
            for line in lines {
                let (name, version) = line
                    .split_once("==")
                    .unwrap_or_else(|| panic!("{file}: '{line}' is not pinned"));
                assert!(
                    !name.is_empty() && !version.is_empty() && !version.contains(['*', ',']),
                    "{file}: '{line}'"
                );
            }
        }
    }
}
