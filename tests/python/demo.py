"""`cargo xtask demo`: the default cantilever FMU (B1) under a step load, driven by fmpy.

A steel beam 1 m x 20 mm x 20 mm, clamped at the root, gets a tip force of -10 N along y
(`tip.force[2]`) at t = 0.01 s. Stiffness-proportional damping (`damping.beta` = 2 ms) lets it
settle within the second. Prints a table of the tip displacement and the root reaction, compares
the settled deflection with Timoshenko beam theory (1.19084e-3 m) and plots both to a PNG.

Usage: python demo.py --fmu FILE --plot FILE.png
"""

import argparse
import pathlib
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from fmpy import read_model_description, simulate_fmu  # noqa: E402

from flexbody_fmu import step_input  # noqa: E402

TIMOSHENKO_DEFLECTION = 1.19084e-3  # m
LOAD = 10.0  # N
T_STEP, T_END, H = 0.01, 1.0, 1e-3  # s
BETA = 2e-3  # s


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--fmu", required=True, help="the .fmu to run")
    parser.add_argument("--plot", required=True, help="where to write the PNG")
    args = parser.parse_args()

    md = read_model_description(args.fmu)
    print(f"{md.modelName}: {md.description}" if md.description else md.modelName)
    print(f"step load tip.force[2] = {-LOAD} N at t = {T_STEP} s, damping.beta = {BETA} s, "
          f"communication step {H} s, until t = {T_END} s")
    wall = time.perf_counter()
    result = simulate_fmu(
        args.fmu,
        start_time=0.0,
        stop_time=T_END,
        output_interval=H,
        start_values={"damping.beta": BETA},
        input=step_input(md, "tip.force[2]", -LOAD, T_STEP, T_END),
        output=["tip.position[2]", "root.force[2]"],
    )
    wall = time.perf_counter() - wall
    t = result["time"]
    deflection = result["tip.position[2]"] - result["tip.position[2]"][0]
    reaction = result["root.force[2]"]

    print()
    print(f"{'t (s)':>8}  {'tip displacement y (mm)':>24}  {'root force y (N)':>17}")
    for t_row in [0.0, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0]:
        k = int(np.argmin(np.abs(t - t_row)))
        print(f"{t[k]:8.3f}  {deflection[k] * 1e3 + 0.0:24.5f}  {reaction[k] + 0.0:17.4f}")

    settled = deflection[-1]
    error = (abs(settled) - TIMOSHENKO_DEFLECTION) / TIMOSHENKO_DEFLECTION
    print()
    print(f"settled tip deflection {settled:.6e} m; Timoshenko {-TIMOSHENKO_DEFLECTION:.6e} m; "
          f"error {100 * error:+.3f} %")
    print(f"settled root reaction {reaction[-1]:.5f} N (balances the {LOAD} N load: "
          f"{100 * (reaction[-1] - LOAD) / LOAD:+.3f} %)")
    print(f"{len(t) - 1} communication steps in {wall:.2f} s wall time "
          f"({1e3 * wall / max(len(t) - 1, 1):.2f} ms per step, including instantiation)")

    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
    ax1.plot(t, deflection * 1e3, label="FMU: tip.position[2] - start")
    ax1.axhline(-TIMOSHENKO_DEFLECTION * 1e3, color="k", linestyle="--", label="Timoshenko static")
    ax1.set_ylabel("tip displacement y (mm)")
    ax1.legend(loc="upper right")
    ax1.grid(True)
    ax2.plot(t, reaction, color="tab:red", label="FMU: root.force[2]")
    ax2.axhline(LOAD, color="k", linestyle="--", label="static reaction")
    ax2.set_xlabel("time (s)")
    ax2.set_ylabel("root reaction y (N)")
    ax2.legend(loc="center right")
    ax2.grid(True)
    fig.suptitle(f"flexbody {md.modelName}: {-LOAD} N step at the tip, damping.beta = {BETA} s")
    fig.tight_layout()
    plot = pathlib.Path(args.plot)
    plot.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(plot, dpi=120)
    print(f"plot: {plot.resolve()}")


if __name__ == "__main__":
    main()
