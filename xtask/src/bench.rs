//! `cargo xtask bench [--quick]`: runs the measurement examples in release mode and writes their
//! tables, with the machine and versions they were measured on, to `bench/results/<date>.md`.
//!
//! The suite (each an example that prints Markdown tables, see its own doc comment):
//! * `step_cost`: the cost of one step against its floor, one pair of triangular solves (the
//!   reduced body with 8 modes among the bodies, to set beside the peers' CB-8);
//! * `b3_table`: B3 through the slave for every model choice, `full` as the yardstick (issue 4);
//! * `b3_step_time`: B3 as an importer drives it (stop time defined, inputs every 10 ms), the
//!   time inside `do_step` and the error against `full` of the reduced body with
//!   `model.modes = auto` beside the mesh body (issue 17), interleaved rounds, median;
//! * `b2_drift`: B2's angular momentum and energy drift with and without `f_nl` and frames;
//! * `work_precision`: run time against error on B1 and B3 for each formulation (CSV);
//! * `accuracy_table`: `model.accuracy`'s error achieved against the error requested, and its
//!   run time against the cheapest hand-chosen setting of the same error (B1, B3, the
//!   connecting rod, B2), from interleaved pairs;
//! * `soak`: 10⁶ steps of the undamped cantilever, energy drift and resident memory (issue 7);
//! * `step_scaling`: a step against one solve from 384 to ~100k DOF (CSV);
//! * the peers: `export_matrices` writes B1's mesh and matrices, `bench/peers.py` runs Exudyn's
//!   floating frame of reference on them (CB-8 modes and all nodal DOF) in the pinned bench venv
//!   (`<target>/bench-venv` from `bench/requirements.txt` + `constraints.txt`), against
//!   `work_precision`'s B1 reference trajectory (CSV);
//! * `bench/paired.py`: our reduced body (`reduced_run`) against Exudyn's CB-8 models, regular
//!   and fast module, in interleaved paired rounds (2 s and 10 s simulated, setup apart, the
//!   median of the rounds' ratios, two series that must agree), each side's error its tip's
//!   deviation from our mesh body at the same step;
//! * `bench/plot.py`: the PNGs (work–precision, step scaling) and the summary of ratios at equal
//!   error, which heads the report.
//!
//! CSVs and PNGs go beside the report as `bench/results/<date>[-quick]-<name>.{csv,png}`.
//! `--quick` runs fewer steps and sizes (for checking the task itself; its figures are not for
//! reports).

use crate::{output, venv, Result, Workspace};
use std::fmt::Write as _;
use std::path::Path;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

/// One entry of the suite: title, example and its arguments (full and quick); `csv`: the example
/// takes `--csv FILE` and writes `<date>-<csv>.csv` beside the report.
struct Entry {
    title: &'static str,
    example: &'static str,
    args: &'static [&'static str],
    quick_args: &'static [&'static str],
    csv: Option<&'static str>,
}

const SUITE: &[Entry] = &[
    Entry {
        title: "Cost of a step against one solve (B1 cantilever and variants)",
        example: "step_cost",
        args: &["2000"],
        quick_args: &["50"],
        csv: None,
    },
    Entry {
        title: "B3: every model choice against the full nonlinear reference",
        example: "b3_table",
        args: &["0.01"],
        quick_args: &["0.01", "40 frames"],
        csv: None,
    },
    Entry {
        title:
            "B3 as an importer drives it: time inside do_step, the reduced body against the mesh",
        example: "b3_step_time",
        args: &["5"],
        quick_args: &["1"],
        csv: None,
    },
    Entry {
        title: "B2: angular momentum and energy drift of a free tumbling beam over 10 s",
        example: "b2_drift",
        args: &["1e-3"],
        quick_args: &["2e-3"],
        csv: None,
    },
    Entry {
        title: "Run time against error: B1 dynamic and B3, every formulation",
        example: "work_precision",
        args: &[],
        quick_args: &["--quick"],
        csv: Some("work_precision"),
    },
    Entry {
        title: "model.accuracy: the error achieved and the cost against the cheapest hand-chosen setting",
        example: "accuracy_table",
        args: &[],
        quick_args: &["--quick"],
        csv: None,
    },
    Entry {
        title: "Soak: 10⁶ steps of the undamped cantilever (energy drift, resident memory)",
        example: "soak",
        args: &["1000000"],
        quick_args: &["2000"],
        csv: None,
    },
    Entry {
        title: "Per-step cost against the floor, 384 to ~100k DOF",
        example: "step_scaling",
        args: &[],
        quick_args: &["--quick"],
        csv: Some("step_scaling"),
    },
];

/// Steps after the examples: the matrix export, the peers, the plots.
const EXTRA_STEPS: usize = 4;

pub fn bench_task(workspace: &Workspace, quick: bool) -> Result<()> {
    let date = utc_date();
    let dir = workspace.root.join("bench").join("results");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let stem = if quick {
        format!("{date}-quick")
    } else {
        date.clone()
    };
    let file = |name: &str| dir.join(format!("{stem}-{name}"));
    let total = SUITE.len() + EXTRA_STEPS;
    let progress = |k: usize, what: &str| println!("xtask bench: [{k}/{total}] {what}");

    // The bench venv first: a broken install should fail before half an hour of measurements.
    let python = venv::ensure_env(workspace, &venv::BENCH)?;

    let root = workspace.root.display().to_string();
    let mut sections = String::new();
    for (k, entry) in SUITE.iter().enumerate() {
        progress(
            k + 1,
            &format!(
                "{} (cargo run --release --example {})",
                entry.title, entry.example
            ),
        );
        let started = Instant::now();
        let mut args: Vec<String> = if quick { entry.quick_args } else { entry.args }
            .iter()
            .map(|a| a.to_string())
            .collect();
        if let Some(name) = entry.csv {
            args.push("--csv".into());
            args.push(file(&format!("{name}.csv")).display().to_string());
        }
        let table = run_example(workspace, entry.example, &args)?;
        let seconds = started.elapsed().as_secs_f64();
        println!("xtask bench: [{}/{total}] done in {seconds:.0} s", k + 1);
        writeln!(
            sections,
            "## {}\n\n`cargo run --release --example {} -- {}` ({seconds:.0} s)\n\n{}\n",
            entry.title,
            entry.example,
            args.join(" ")
                .replace(&workspace.root.display().to_string(), "."),
            table.trim_end().replace(&root, ".")
        )
        .unwrap();
    }

    // The peers: B1's mesh and matrices for Exudyn, then bench/peers.py against our reference.
    let mut k = SUITE.len() + 1;
    progress(k, "B1's mesh and matrices for the peers (export_matrices)");
    let matrices = workspace.target_dir.join("bench").join("b1-matrices");
    let exported = run_example(
        workspace,
        "export_matrices",
        &[matrices.display().to_string()],
    )?;
    k += 1;
    progress(
        k,
        "peers: Exudyn's floating frame of reference on B1 (bench/peers.py)",
    );
    let started = Instant::now();
    let reference = file("work_precision_b1_reference.csv");
    let peers_csv = file("peers.csv");
    let mut command = std::process::Command::new(&python);
    command
        .arg(workspace.root.join("bench/peers.py"))
        .arg("--matrices")
        .arg(&matrices)
        .arg("--reference")
        .arg(&reference)
        .arg("--csv")
        .arg(&peers_csv)
        .env("PYTHONWARNINGS", "ignore::DeprecationWarning");
    if quick {
        command.arg("--quick");
    }
    let peers = output(&mut command)?;
    let seconds = started.elapsed().as_secs_f64();
    println!("xtask bench: [{k}/{total}] done in {seconds:.0} s");
    writeln!(
        sections,
        "## Peers: Exudyn on B1, our mesh and matrices\n\n{}\n`bench/peers.py{}` ({seconds:.0} s; \
         the models and their settings are described in the script's docstring)\n\n{}\n",
        exported.trim_end().replace(&root, "."),
        if quick { " --quick" } else { "" },
        peers.trim_end()
    )
    .unwrap();

    k += 1;
    progress(
        k,
        "ours against Exudyn's reduced models, interleaved paired rounds (bench/paired.py)",
    );
    let started = Instant::now();
    output(
        workspace
            .cargo()
            .args(["build", "--quiet", "--release", "--example", "reduced_run"]),
    )?;
    let ours = workspace
        .target_dir
        .join("release")
        .join("examples")
        .join(format!("reduced_run{}", std::env::consts::EXE_SUFFIX));
    let mut command = std::process::Command::new(&python);
    command
        .arg(workspace.root.join("bench/paired.py"))
        .arg("--ours")
        .arg(&ours)
        .arg("--matrices")
        .arg(&matrices)
        .env("PYTHONWARNINGS", "ignore::DeprecationWarning");
    if quick {
        command.args(["--rounds", "2", "--short", "0.2", "--long", "1"]);
    }
    let paired = output(&mut command)?;
    let seconds = started.elapsed().as_secs_f64();
    println!("xtask bench: [{k}/{total}] done in {seconds:.0} s");
    writeln!(
        sections,
        "## Ours against Exudyn's reduced models, interleaved\n\n`bench/paired.py{}` ({seconds:.0} s; \
         the method is in the script's docstring)\n\n{}\n",
        if quick {
            " --rounds 2 --short 0.2 --long 1"
        } else {
            ""
        },
        paired.trim_end()
    )
    .unwrap();

    k += 1;
    progress(k, "plots and summary (bench/plot.py)");
    let summary = output(
        std::process::Command::new(&python)
            .arg(workspace.root.join("bench/plot.py"))
            .arg("--prefix")
            .arg(dir.join(&stem))
            .arg("--work")
            .arg(file("work_precision.csv"))
            .arg("--peers")
            .arg(&peers_csv)
            .arg("--scaling")
            .arg(file("step_scaling.csv")),
    )?;

    let mut report = String::new();
    writeln!(report, "# Benchmarks, {date}\n").unwrap();
    writeln!(report, "{}", machine(workspace, &python)).unwrap();
    if quick {
        writeln!(report, "**--quick run: reduced sizes, not for reports.**\n").unwrap();
    }
    writeln!(
        report,
        "## Summary: ours against the peers\n\nThe ratio of run times that holds up on a shared machine \
         is the interleaved one (section \"Ours against Exudyn's reduced models, interleaved\" \
         below); the ratios at equal error here come from runs made apart, minutes apart, and \
         place the models on the work–precision plane only.\n\n{}\n\nData: `{stem}-*.csv` beside this file.\n",
        summary.trim_end()
    )
    .unwrap();
    report.push_str(&sections);
    let path = dir.join(format!("{stem}.md"));
    std::fs::write(&path, report).map_err(|e| format!("{}: {e}", path.display()))?;
    println!("xtask bench: wrote {}", path.display());
    Ok(())
}

/// `cargo run --quiet --release --example <example> -- <args>`, its standard output.
fn run_example(workspace: &Workspace, example: &str, args: &[String]) -> Result<String> {
    output(
        workspace
            .cargo()
            .args(["run", "--quiet", "--release", "--example", example, "--"])
            .args(args),
    )
}

/// Machine, compiler, Python and Exudyn, and the source revision, as a Markdown list.
fn machine(workspace: &Workspace, python: &Path) -> String {
    let read = |command: &mut std::process::Command| {
        output(command)
            .map(|s| s.trim().to_string())
            .unwrap_or_else(|e| format!("unknown ({e})"))
    };
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!(
        "- machine: {cpu}, {cores} cores available (shared: medians, compare ratios within one run)\n- {}\n- {}, Exudyn {} (bench venv: `bench/requirements.txt`)\n- source: {}\n",
        read(std::process::Command::new("rustc").arg("-V")),
        read(std::process::Command::new(python).arg("--version")),
        read(std::process::Command::new(python).args([
            "-W",
            "ignore",
            "-c",
            "import exudyn; print(exudyn.config.Version())"
        ])),
        read(workspace.git().args(["describe", "--always", "--dirty"]))
    )
}

/// Today's UTC date `YYYY-MM-DD` (civil from days, H. Hinnant's algorithm).
fn utc_date() -> String {
    let days = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() / 86_400) as i64;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}

#[cfg(test)]
mod tests {
    #[test]
    fn date_has_the_iso_shape() {
        let d = super::utc_date();
        assert_eq!(d.len(), 10);
        assert!(d.starts_with("20") && &d[4..5] == "-" && &d[7..8] == "-");
    }
}
