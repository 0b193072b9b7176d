//! The floors of the house (docs/architecture.md): every module of `src/` uses only the floors
//! below it. Read from the sources: each `crate::<module>` path outside comments and unit-test
//! files names the module it uses.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The floors, bottom first; modules on one floor do not use each other.
const FLOORS: &[&[&str]] = &[
    &["error"],
    &["linalg"],
    &["element"],
    &["mesh"],
    &["fem"],
    &["body"],
    &["solver", "output"],
    &["model"],
    &["slave"],
    &["fmi2"],
    &["fmi3"],
];

fn floor_of(module: &str) -> Option<usize> {
    FLOORS.iter().position(|f| f.contains(&module))
}

/// The `.rs` files under `dir` (unit-test files excluded).
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs")
            && path.file_name().is_some_and(|n| n != "tests.rs")
        {
            out.push(path);
        }
    }
}

/// The modules named by `crate::<module>` in `text`, comments and inline test modules left out.
fn used_modules(text: &str) -> BTreeSet<String> {
    let code = text.split("#[cfg(test)]\nmod tests {").next().unwrap();
    let mut used = BTreeSet::new();
    for line in code.lines() {
        let line = line.split("//").next().unwrap();
        let mut rest = line;
        while let Some(at) = rest.find("crate::") {
            rest = &rest[at + "crate::".len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            used.insert(name);
        }
    }
    used
}

#[test]
fn every_module_uses_only_the_floors_below_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let mut violations = Vec::new();
    let mut seen = BTreeSet::new();
    for file in &files {
        let relative = file.strip_prefix(&src).unwrap();
        let first = relative.components().next().unwrap().as_os_str();
        let module = first.to_str().unwrap().trim_end_matches(".rs").to_string();
        // The crate root declares the floors; binaries use the library from outside.
        if module == "lib" || module == "bin" {
            continue;
        }
        let Some(own) = floor_of(&module) else {
            violations.push(format!(
                "{}: module {module} is on no floor",
                relative.display()
            ));
            continue;
        };
        seen.insert(module.clone());
        for used in used_modules(&std::fs::read_to_string(file).unwrap()) {
            if used == module || used == "Error" || used == "ErrorKind" {
                continue;
            }
            match floor_of(&used) {
                Some(f) if f < own => {}
                _ => violations.push(format!(
                    "{}: {module} (floor {}) uses crate::{used}",
                    relative.display(),
                    own + 1
                )),
            }
        }
    }
    assert!(violations.is_empty(), "{}", violations.join("\n"));
    // Every floor's module exists: the table describes the crate as it is.
    for module in FLOORS.iter().flat_map(|f| f.iter()) {
        assert!(seen.contains(*module), "no module {module} in src/");
    }
}
