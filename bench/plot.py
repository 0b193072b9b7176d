"""Plots and the headline summary of `cargo xtask bench` (issue 7).

    python bench/plot.py --prefix bench/results/DATE [--work W.csv] [--peers P.csv] [--scaling S.csv]

Reads the CSVs of examples/work_precision.rs (W), bench/peers.py (P) and examples/step_scaling.rs
(S), writes `PREFIX-work_precision.png` (wall time against max tip error, log-log, one line per
model; B1 with the peers, B3 beside it) and `PREFIX-step_scaling.png` (step and solve time
against DOF), and prints a Markdown summary: our wall time against each peer's at equal error
(the peer's wall time interpolated log-log in its error at ours) and steps per second at equal h.
Missing inputs are skipped.
"""

import argparse
import csv
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    if not path or not os.path.exists(path):
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def series(rows, problem):
    out = {}
    for r in rows:
        if r["problem"] == problem:
            out.setdefault(r["model"], []).append(
                (float(r["h"]), float(r["wall_s"]), float(r["max_error_m"]), float(r["steps_per_s"]), int(r["steps"]))
            )
    for v in out.values():
        v.sort()
    return out


def interpolate_wall(points, error):
    """The wall time of a (h, wall, error, ...) series at `error`, log-log, or None outside it."""
    pts = sorted((p[2], p[1]) for p in points)
    for (e0, w0), (e1, w1) in zip(pts, pts[1:]):
        if e0 <= error <= e1 and e0 > 0:
            if e1 == e0:
                return w0
            s = (math.log(error) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(w0) + s * (math.log(w1) - math.log(w0)))
    return None


def plot_work(work, peers, path):
    b1 = series(work, "B1")
    b1.update(series(peers, "B1"))
    b3 = series(work, "B3")
    panels = [("B1 dynamic (0.1 s)", b1)] + ([("B3 spin-up", b3)] if b3 else [])
    fig, axes = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 4), squeeze=False)
    for ax, (title, data) in zip(axes[0], panels):
        for model, pts in data.items():
            if model == "Exudyn full FFRF":
                continue  # a short run: its error over a few steps is not comparable
            style = "--" if model.startswith("Exudyn") else "-"
            ax.loglog([p[2] for p in pts], [p[1] for p in pts], style + "o", ms=4, label=model)
            for p in pts:
                if model.startswith("reducedStrain, f_nl off") or model == "Exudyn FFRF CB-8":
                    ax.annotate(f"{p[0]:g}", (p[2], p[1]), fontsize=6, xytext=(2, 2), textcoords="offset points")
        ax.set_xlabel("max tip error (m)")
        ax.set_ylabel("wall time (s)")
        ax.set_title(title + ", labels: h (s)", fontsize=9)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def plot_scaling(rows, path):
    dof = [int(r["free_dof"]) for r in rows]
    fig, ax = plt.subplots(figsize=(5.2, 4))
    ax.loglog(dof, [float(r["step_ms"]) for r in rows], "-o", ms=4, label="step (reducedStrain, h = 1e-4 s)")
    ax.loglog(dof, [float(r["solve_ms"]) for r in rows], "--s", ms=4, label="one solve (floor)")
    ax.set_xlabel("free DOF")
    ax.set_ylabel("time (ms, median)")
    ax.set_title("Per-step cost against one triangular solve pair", fontsize=9)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def summary(work, peers):
    ours = series(work, "B1")
    theirs = series(peers, "B1")
    if not ours or not theirs:
        return
    print("B1 dynamic, our wall time against each peer's at the same error (peer's wall time interpolated log-log in its error at ours; ratio < 1: ours faster):\n")
    print("| our model | h (s) | our error (m) | our wall (ms) | peer | peer wall at that error (ms) | ours / peer | peer error at the same h (m) | ours / peer at the same h |")
    print("|---|---|---|---|---|---|---|---|---|")
    for model, pts in ours.items():
        if model == "full":
            continue
        for peer, ppts in theirs.items():
            if peer == "Exudyn full FFRF":
                continue
            for h, wall, err, _, _ in pts:
                pw = interpolate_wall(ppts, err)
                same = [p for p in ppts if abs(p[0] - h) < 1e-12]
                if pw is None and not same:
                    continue
                at_err = f"{1e3 * pw:.1f} | {wall / pw:.2f}" if pw is not None else "outside its range |"
                at_h = f"{same[0][2]:.3e} | {wall / same[0][1]:.2f}" if same else "|"
                print(f"| {model} | {h:g} | {err:.3e} | {1e3 * wall:.1f} | {peer} | {at_err} | {at_h} |")
    print()
    print("Steps per second at equal h (B1; the full FFRF ran a shorter time, its steps/s include its setup):\n")
    models = list(ours) + list(theirs)
    hs = sorted({p[0] for pts in list(ours.values()) + list(theirs.values()) for p in pts}, reverse=True)
    print("| h (s) | " + " | ".join(models) + " |")
    print("|---" * (len(models) + 1) + "|")
    table = {**ours, **theirs}
    for h in hs:
        cells = []
        for m in models:
            v = [p[3] for p in table[m] if abs(p[0] - h) < 1e-12]
            cells.append((f"{v[0]:.0f}" if v[0] >= 10 else f"{v[0]:.2g}") if v else "")
        print(f"| {h:g} | " + " | ".join(cells) + " |")
    full = [p for p in theirs.get("Exudyn full FFRF", [])]
    base = {p[0]: p[3] for p in ours.get("reducedStrain, f_nl off", [])}
    for h, _, _, sps, _ in full:
        if h in base:
            print(f"\nAt h = {h:g} s: reducedStrain (f_nl off) {base[h]:.0f} steps/s, Exudyn's full FFRF {sps:.2f} steps/s: {base[h] / sps:.0f}x.")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--prefix", required=True)
    parser.add_argument("--work")
    parser.add_argument("--peers")
    parser.add_argument("--scaling")
    args = parser.parse_args()
    work, peers, scaling = read(args.work), read(args.peers), read(args.scaling)
    written = []
    if work or peers:
        plot_work(work, peers, args.prefix + "-work_precision.png")
        written.append(args.prefix + "-work_precision.png")
    if scaling:
        plot_scaling(scaling, args.prefix + "-step_scaling.png")
        written.append(args.prefix + "-step_scaling.png")
    summary(work, peers)
    for w in written:
        print(f"\n![{os.path.basename(w)}]({os.path.basename(w)})")


if __name__ == "__main__":
    main()
