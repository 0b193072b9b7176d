"""Our reduced body against Exudyn's floating frame of reference on B1, timed the way that holds
up on a shared machine: interleaved paired runs (issue 17).

    python bench/paired.py --ours PATH --matrices DIR [--rounds 15] [--series 2] [--h 1e-3]

Each side is a separate process that builds its model (setup, timed on its own) and then runs
B1 for a short and a long time (2 s and 10 s simulated, fixed step h), each from a fresh model:
ours is `examples/reduced_run.rs` (PATH: its release binary), the reduced body with the mode
count `model.modes = auto` chooses (4 at the default accuracy: 34 fields with the tip's
attachment fields, 102 coordinates) and with the fewest modes that are as accurate as Exudyn's
CB-8 (below), as the reduced-strain body and as the linear body (`--linear 1`, `model.linear`:
the frame held at the clamp, one linear solve per step; Exudyn's floating frame, fixed to the
ground by the clamp's joint, is linear in its modal coordinates too); the peers are
bench/peers.py's reduced models (CB-8: 8 fixed-root eigenmodes; CB-8 + tip: the tip face as a
second boundary, 14 coordinates) in Exudyn's regular module and its fast module
(`exudynCPPfast`: no range checks, vector extensions), selected per process. The cost of a step
is the difference of the two runs' stepping times over the difference of their step counts,
which cancels what a run costs once (first factorization, solver initialization).

The error of every side is measured against one yardstick: our mesh body (`--modes 0`, the full
B1 mesh, one frame) at the same step h, over the short run's communication points (every 2 ms):
the largest deviation of the tip's y from it over its largest |y|. Both schemes are
generalized-α at ρ∞ = 0.9 on the same step, so what separates the sides is their reduction.
Before the rounds, one run of CB-8 gives its deviation, and ours are run with 1, 2, … modes until
the deviation is at most that: the comparison at equal error.

A round runs every side once, in an order that rotates from round to round, so that each of our
runs has its peers' runs within seconds of it; the ratio ours/peer of a round uses those runs
only, and the figure is the median of the rounds' ratios, with their range. The whole is done
`--series` times; a ratio is a result only if the series agree (their medians are printed side
by side).
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

PEERS = [
    ("Exudyn CB-8", "cb8", False),
    ("Exudyn CB-8, fast module", "cb8", True),
    ("Exudyn CB-8 + tip, fast module", "cb8tip", True),
]


def worker(args):
    """One peer process: setup, then the short and the long run; one JSON line."""
    if args.fast:
        sys.exudynFast = True  # read by `import exudyn` (bench/peers.py imports it)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import peers

    started = time.perf_counter()
    fem, w, root, tip = peers.load_fem(args.matrices)
    make, modes = peers.build_reduced(fem, w, root, tip, args.model == "cb8tip")
    built = make()
    setup = time.perf_counter() - started
    times, tip_y, samples = [], None, None
    for end, model in ((args.short, built), (args.long, None)):
        sc, mbs, sensor = model if model is not None else make()
        s = peers.settings(args.h, end, False)
        started = time.perf_counter()
        mbs.SolveDynamic(s)
        times.append(time.perf_counter() - started)
        if tip_y is None:
            data = mbs.GetSensorStoredData(sensor)
            tip_y = float(data[-1, 2])
            # The y at t = k peers.SAMPLE, k = 1 … (the sensor also stores t = 0).
            by_sample = {round(t / peers.SAMPLE): float(y) for t, y in zip(data[:, 0], data[:, 2])}
            samples = [by_sample[k] for k in range(1, round(args.short / peers.SAMPLE) + 1)]
    module = "exudynCPPfast" if "exudyn.exudynCPPfast" in sys.modules else "exudynCPP"
    print(json.dumps({
        "setup_s": setup, "short_s": times[0], "short_steps": round(args.short / args.h),
        "long_s": times[1], "long_steps": round(args.long / args.h), "tip_y_short": tip_y,
        "tip_y_samples": samples, "modes": modes, "module": module,
    }))


def run(command):
    out = subprocess.run(command, check=True, capture_output=True, text=True,
                         env={**os.environ, "PYTHONWARNINGS": "ignore"}).stdout
    return json.loads(out.strip().splitlines()[-1])


def deviation(samples, reference):
    """The largest deviation of `samples` from `reference` over the reference's largest |y|."""
    peak = max(abs(y) for y in reference)
    return max(abs(a - b) for a, b in zip(samples, reference)) / peak


def per_step(r):
    return (r["long_s"] - r["short_s"]) / (r["long_steps"] - r["short_steps"])


def series(args, sides):
    """`args.rounds` rounds over `sides` (name, command); per round each side's result."""
    rounds = []
    for k in range(args.rounds):
        order = sides[k % len(sides):] + sides[:k % len(sides)]
        rounds.append({name: run(command) for name, command in order})
    return rounds


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--ours")
    parser.add_argument("--matrices", required=True)
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--series", type=int, default=2)
    parser.add_argument("--h", type=float, default=1e-3)
    parser.add_argument("--short", type=float, default=2.0)
    parser.add_argument("--long", type=float, default=10.0)
    parser.add_argument("--worker", action="store_true")
    parser.add_argument("--model", default="cb8")
    parser.add_argument("--fast", action="store_true")
    args = parser.parse_args()
    if args.worker:
        return worker(args)

    def timing(long):
        return ["--h", str(args.h), "--short", str(args.short), "--long", str(long)]

    def peer(model, fast, long):
        return [sys.executable, os.path.abspath(__file__), "--worker", "--matrices", args.matrices,
                "--model", model, *timing(long)] + (["--fast"] if fast else [])

    peers = [(name, peer(model, fast, args.long)) for name, model, fast in PEERS]

    # The yardstick, CB-8's error against it, and the fewest of our modes as accurate.
    short_only = timing(0)
    mesh = run([args.ours, *short_only, "--modes", "0"])["tip_y_samples"]
    # (The worker runs its long run too: as short as the short one here.)
    cb8 = deviation(run(peer(PEERS[0][1], PEERS[0][2], args.short))["tip_y_samples"], mesh)
    for modes in range(1, 33):
        ours_error = deviation(run([args.ours, *short_only, "--modes", str(modes)])["tip_y_samples"],
                               mesh)
        if ours_error <= cb8:
            break
    else:
        sys.exit(f"no mode count up to 32 is as accurate as CB-8 ({cb8:.1e}): no equal error")
    both = timing(args.long)
    ours = [
        ("ours, modes = auto", [args.ours, *both, "--modes", "auto"]),
        (f"ours, {modes} modes", [args.ours, *both, "--modes", str(modes)]),
        (f"ours, {modes} modes, linear", [args.ours, *both, "--modes", str(modes), "--linear", "1"]),
    ]
    sides = ours + peers

    print(f"B1, h = {args.h:g} s, per-step cost from {args.short:g} s and {args.long:g} s simulated; "
          f"{args.series} series of {args.rounds} interleaved rounds (sides in rotating order). "
          f"CB-8's deviation from our mesh body is {cb8:.1e} of the peak; {modes} modes are the "
          f"fewest of ours within it ({ours_error:.1e}).\n")
    results = [series(args, sides) for _ in range(args.series)]

    print("| side | module | setup (s, median) | µs per step (median) | tip y at "
          f"{args.short:g} s (m) | deviation from the mesh body over {args.short:g} s / peak |")
    print("|---|---|---|---|---|---|")
    for name, _ in sides:
        runs = [r[name] for rounds in results for r in rounds]
        print(f"| {name} | {runs[0].get('module', 'flexbody')} "
              f"| {statistics.median(r['setup_s'] for r in runs):.3f} "
              f"| {1e6 * statistics.median(per_step(r) for r in runs):.1f} "
              f"| {runs[0]['tip_y_short']:.6e} "
              f"| {deviation(runs[0]['tip_y_samples'], mesh):.1e} |")
    print()
    header = " | ".join(f"series {k + 1}: median (range)" for k in range(args.series))
    print(f"| ours / peer, per step | {header} |")
    print("|---|" + "---|" * args.series)
    for mine, _ in ours:
        for name, _ in sides[len(ours):]:
            cells = []
            for rounds in results:
                ratios = [per_step(r[mine]) / per_step(r[name]) for r in rounds]
                cells.append(f"{statistics.median(ratios):.2f} ({min(ratios):.2f}–{max(ratios):.2f})")
            print(f"| {mine} / {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
