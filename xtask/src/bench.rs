//! `cargo xtask bench [--quick]`: runs the measurement examples in release mode and writes their
//! tables, with the machine and versions they were measured on, to `bench/results/<date>.md`.
//!
//! The suite (each an example that prints Markdown tables, see its own doc comment):
//! * `step_cost`: the cost of one step against its floor, one pair of triangular solves;
//! * `b3_table`: B3 through the slave for every model choice, `full` as the yardstick (issue 4);
//! * `b2_drift`: B2's angular momentum and energy drift with and without `f_nl` and frames.
//!
//! `--quick` runs fewer steps (for checking the task itself; its figures are not for reports).

use crate::{output, Result, Workspace};
use std::fmt::Write as _;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

/// One entry of the suite: title, example and its arguments (full and quick).
struct Entry {
    title: &'static str,
    example: &'static str,
    args: &'static [&'static str],
    quick_args: &'static [&'static str],
}

const SUITE: &[Entry] = &[
    Entry {
        title: "Cost of a step against one solve (B1 cantilever and variants)",
        example: "step_cost",
        args: &["2000"],
        quick_args: &["50"],
    },
    Entry {
        title: "B3: every model choice against the full nonlinear reference",
        example: "b3_table",
        args: &["0.01"],
        quick_args: &["0.01", "40 frames"],
    },
    Entry {
        title: "B2: angular momentum and energy drift of a free tumbling beam over 10 s",
        example: "b2_drift",
        args: &["1e-3"],
        quick_args: &["2e-3"],
    },
];

pub fn bench_task(workspace: &Workspace, quick: bool) -> Result<()> {
    let mut report = String::new();
    let date = utc_date();
    writeln!(report, "# Benchmarks, {date}\n").unwrap();
    writeln!(report, "{}", machine(workspace)).unwrap();
    if quick {
        writeln!(report, "**--quick run: reduced sizes, not for reports.**\n").unwrap();
    }
    for (k, entry) in SUITE.iter().enumerate() {
        println!(
            "xtask bench: [{}/{}] {} (cargo run --release --example {})",
            k + 1,
            SUITE.len(),
            entry.title,
            entry.example
        );
        let started = Instant::now();
        let args = if quick { entry.quick_args } else { entry.args };
        let table = output(
            workspace
                .cargo()
                .args([
                    "run",
                    "--quiet",
                    "--release",
                    "--example",
                    entry.example,
                    "--",
                ])
                .args(args),
        )?;
        let seconds = started.elapsed().as_secs_f64();
        println!(
            "xtask bench: [{}/{}] done in {seconds:.0} s",
            k + 1,
            SUITE.len()
        );
        writeln!(
            report,
            "## {}\n\n`cargo run --release --example {} -- {}` ({seconds:.0} s)\n\n{}\n",
            entry.title,
            entry.example,
            args.join(" "),
            table.trim_end()
        )
        .unwrap();
    }
    let dir = workspace.root.join("bench").join("results");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let name = if quick {
        format!("{date}-quick.md")
    } else {
        format!("{date}.md")
    };
    let path = dir.join(name);
    std::fs::write(&path, report).map_err(|e| format!("{}: {e}", path.display()))?;
    println!("xtask bench: wrote {}", path.display());
    Ok(())
}

/// Machine, compiler and source revision, as a Markdown list.
fn machine(workspace: &Workspace) -> String {
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
        "- machine: {cpu}, {cores} cores available (shared: medians, compare ratios within one run)\n- {}\n- source: {}\n",
        read(std::process::Command::new("rustc").arg("-V")),
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
