"""A flexible arm spun up by a PD controller in plain explicit coupling (issue 19, item 3).

The FMU (``examples/controlled_arm.json``): Kane's beam (L = 10 m, EI = 1.4e4 N m², rhoA = 1.2 kg/m)
on a hinge about z at its root face (``bearing``), with a rigid hub of 50 kg and J_hub = 100 kg m²
about z (a lumped body on the rigid force interface ``hub``, on the same face: the hinge holds the
rigid face's centre and locks it to the axis) that takes the motor torque ``hub.torque[3]``.

The controller is the way Simulink, Dymola or a fmpy loop couple one: every communication step
H it reads the hub's rotation and angular velocity at the communication point and sets the torque,
held over the step (zero-order hold, no iteration):

    tau = J_total * alpha_ref + Kp * (theta_ref - theta) + Kd * (omega_ref - omega)

tracking Kane's spin-up profile (to 6 rad/s in 15 s, ``kane_profile``). The gains come from the
inertias: ``J_total = J_hub + rhoA L^3 / 3`` (the hub and the beam as one rigid body about the
hinge) sets the closed loop's bandwidth, ``Kp = J_total omega_c^2``, ``Kd = 2 zeta J_total omega_c``;
what limits H is the hub: above the beam's frequencies the torque meets the hub's inertia alone, and
a sampled PD on an inertia J with zero-order hold is stable while the spectral radius of its
two-by-two step map stays below 1 (``largest_stable_step``), about ``2 J_hub / Kd`` for a small
``Kp H``. With omega_c = 2 rad/s and zeta = 1 that is H < 0.1 s. Without the hub (the torque on
the bare face, whose own inertia is almost nothing) no H works: the issue's finding.

Usage: python controlled_arm.py --fmu controlled_arm.fmu [--step 0.01] [--end 20]
"""

import argparse
import math
import time

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

# The arm (examples/controlled_arm.json).
J_HUB = 100.0  # kg m², the hub about the hinge axis
RHO_A, LENGTH = 1.2, 10.0  # kg/m, m
J_TOTAL = J_HUB + RHO_A * LENGTH**3 / 3.0  # kg m², hub and beam as one rigid body about the hinge
# Kane's spin-up.
SPIN_TIME, SPIN_RATE = 15.0, 6.0  # s, rad/s


def kane_profile(t: float) -> tuple[float, float, float]:
    """Angle (rad), rate (rad/s) and acceleration (rad/s²) of Kane's spin-up at time t."""
    ts, ws = SPIN_TIME, SPIN_RATE
    if t >= ts:
        return ws * (t - ts / 2.0), ws, 0.0
    k = 2.0 * math.pi / ts
    theta = ws / ts * (t * t / 2.0 + (math.cos(k * t) - 1.0) / k**2)
    omega = ws / ts * (t - math.sin(k * t) / k)
    alpha = ws / ts * (1.0 - math.cos(k * t))
    return theta, omega, alpha


def gains(omega_c: float = 2.0, zeta: float = 1.0) -> tuple[float, float]:
    """Kp (N m/rad) and Kd (N m s/rad) for the closed-loop frequency omega_c and damping zeta."""
    return J_TOTAL * omega_c**2, 2.0 * zeta * J_TOTAL * omega_c


def step_map_radius(inertia: float, kp: float, kd: float, h: float) -> float:
    """Spectral radius of one step of the sampled PD on a rigid inertia (zero-order hold):
    theta' = theta + h omega + h² tau / 2J, omega' = omega + h tau / J, tau = -kp theta - kd omega."""
    a, b = kd * h / inertia, kp * h * h / inertia
    m = np.array([[1.0 - b / 2.0, h - a * h / 2.0], [-b / h, 1.0 - a]])
    return float(max(abs(np.linalg.eigvals(m))))


def largest_stable_step(inertia: float, kp: float, kd: float) -> float:
    """The largest H for which the sampled PD on `inertia` is stable (bisection on the radius)."""
    lo, hi = 1e-6, 10.0
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if step_map_radius(inertia, kp, kd, mid) < 1.0:
            lo = mid
        else:
            hi = mid
    return lo


class Arm:
    """The arm FMU instantiated and initialized (fmpy's FMU2Slave)."""

    def __init__(self, unzipdir: str, model_description, name: str = "arm", parameters=None):
        self.vr = {v.name: v.valueReference for v in model_description.modelVariables}
        types = {v.name: v.type for v in model_description.modelVariables}
        self.fmu = FMU2Slave(
            guid=model_description.guid,
            unzipDirectory=unzipdir,
            modelIdentifier=model_description.coSimulation.modelIdentifier,
            instanceName=name,
        )
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        for parameter, value in (parameters or {}).items():
            if types[parameter] == "Integer":
                self.fmu.setInteger([self.vr[parameter]], [int(value)])
            elif types[parameter] == "Boolean":
                self.fmu.setBoolean([self.vr[parameter]], [bool(value)])
            else:
                self.fmu.setReal([self.vr[parameter]], [value])
        self.fmu.exitInitializationMode()
        self.rotation = [self.vr[f"hub.rotation[{i}]"] for i in range(1, 10)]
        self.tip = [self.vr[f"tip.position[{i}]"] for i in (1, 2)]
        self.rate = self.vr["hub.angularVelocity[3]"]
        self.torque = self.vr["hub.torque[3]"]

    def hub_angle_and_rate(self) -> tuple[float, float, np.ndarray]:
        """The hub's angle about z (in (-pi, pi]), its rate, and its rotation matrix."""
        r = np.array(self.fmu.getReal(self.rotation)).reshape(3, 3)
        return math.atan2(r[1, 0], r[0, 0]), self.fmu.getReal([self.rate])[0], r

    def tip_deflection(self) -> float:
        """The tip's displacement across the hub's x axis (m): the deflection in the rotating frame."""
        _, _, r = self.hub_angle_and_rate()
        tip = np.array(self.fmu.getReal(self.tip) + [0.0])
        return float((r.T @ tip)[1])

    def free(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def run(unzipdir: str, model_description, h: float, t_end: float, omega_c: float = 2.0, zeta: float = 1.0,
        parameters=None):
    """The controlled spin-up with communication step h until t_end (or until the FMU refuses a
    step), the FMU's `parameters` (name: value) set in initialization mode; returns a dict of
    arrays at the communication points: time, angle, reference, rate, reference rate, torque, tip
    deflection; 'completed' (whether t_end was reached) and 'seconds' (wall time of the loop)."""
    from fmpy.fmi1 import FMICallException

    kp, kd = gains(omega_c, zeta)
    arm = Arm(unzipdir, model_description, f"arm-{h}", parameters)
    started = time.perf_counter()
    rows = {n: [] for n in ("time", "angle", "reference", "rate", "reference_rate", "torque", "deflection")}
    completed = True
    try:
        angle, last = 0.0, 0.0
        for k in range(int(round(t_end / h))):
            t = k * h
            wrapped, rate, _ = arm.hub_angle_and_rate()
            angle += math.remainder(wrapped - last, 2.0 * math.pi)  # unwrapped
            last = wrapped
            theta_ref, omega_ref, alpha_ref = kane_profile(t)
            tau = J_TOTAL * alpha_ref + kp * (theta_ref - angle) + kd * (omega_ref - rate)
            for name, value in zip(rows, (t, angle, theta_ref, rate, omega_ref, tau, arm.tip_deflection())):
                rows[name].append(value)
            arm.fmu.setReal([arm.torque], [tau])
            try:
                arm.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            except FMICallException:
                completed = False
                break
    finally:
        seconds = time.perf_counter() - started
        arm.free()
    history = {n: np.array(v) for n, v in rows.items()}
    history["completed"] = completed
    history["seconds"] = seconds
    return history


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--fmu", required=True)
    parser.add_argument("--step", type=float, default=0.01, help="communication step H (s)")
    parser.add_argument("--end", type=float, default=20.0, help="end time (s)")
    args = parser.parse_args()
    md = read_model_description(args.fmu)
    history = run(extract(args.fmu), md, args.step, args.end)
    kp, kd = gains()
    error = np.abs(history["angle"] - history["reference"])
    print(f"Kp = {kp:.0f} N m/rad, Kd = {kd:.0f} N m s/rad; largest stable H (hub alone) "
          f"{largest_stable_step(J_HUB, kp, kd):.4f} s")
    print(f"H = {args.step} s: {'completed' if history['completed'] else 'the FMU refused a step'}; "
          f"largest tracking error {error.max():.3e} rad; tip deflection from "
          f"{history['deflection'].min():.4f} to {history['deflection'].max():.4f} m")


if __name__ == "__main__":
    main()
