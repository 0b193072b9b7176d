"""A PD-controlled flexible arm in plain explicit coupling (issue 19, item 3): Kane's beam on a
hinge with a rigid hub (a lumped body on a rigid attachment) tracks Kane's spin-up profile; the
stable range of the communication step is the sampled PD's on the hub's inertia
(``controlled_arm.py`` derives the gains and the bound).
"""

import numpy as np
import pytest

from controlled_arm import J_HUB, J_TOTAL, gains, largest_stable_step, run

# The gains of the example (omega_c = 2 rad/s, zeta = 1) and the largest stable H they allow on
# the hub alone: 0.1 s.
KP, KD = gains()
H_LIMIT = largest_stable_step(J_HUB, KP, KD)


def test_the_bound_comes_from_the_hub_not_the_whole_arm():
    # The whole arm as one rigid body would allow any H below 0.4 s (Kd H / J_total < 2); the hub
    # alone limits it to 0.1 s; the bare face (a thousandth of the hub's inertia) to 0.1 ms.
    assert H_LIMIT == pytest.approx(0.1, rel=1e-3)
    assert largest_stable_step(J_TOTAL, KP, KD) > 3.5 * H_LIMIT
    assert largest_stable_step(J_HUB / 1000.0, KP, KD) < 1e-3 * H_LIMIT * 1.01


def test_the_arm_tracks_the_spin_up_at_ten_milliseconds(arm_unzipdir, arm_model_description):
    history = run(arm_unzipdir, arm_model_description, 0.01, 20.0)
    assert history["completed"]
    error = np.abs(history["angle"] - history["reference"])
    deflection = history["deflection"]
    t = history["time"]
    print(f"largest tracking error {error.max():.3e} rad; tip deflection peak {deflection.min():.4f} m "
          f"at {t[np.argmin(deflection)]:.2f} s; last 2 s within {np.abs(deflection[t > 18.0]).max():.2e} m")
    # The feedforward J_total alpha_ref carries the spin-up; the PD corrects what the flexible beam
    # and the sampling leave: measured 1.8e-3 rad, against 1.5 rad and more once the loop is
    # unstable (below).
    assert error.max() < 5e-3
    # The beam lags in the spin-up as B3's does on its prescribed hub (peak -0.571 m near 7 s;
    # measured -0.569 m) and straightens after it.
    assert -0.60 < deflection.min() < -0.54
    assert 5.0 < t[np.argmin(deflection)] < 9.0
    assert np.abs(deflection[t > 18.0]).max() < 0.02


def test_stable_below_the_hub_bound_and_unstable_above(arm_unzipdir, arm_model_description):
    # 0.8 x the bound: stable and tracking for the whole spin-up (measured 1.8e-3 rad).
    stable = run(arm_unzipdir, arm_model_description, 0.8 * H_LIMIT, 20.0)
    assert stable["completed"]
    assert np.abs(stable["angle"] - stable["reference"]).max() < 5e-3
    # 1.5 x the bound: the loop diverges within 6 s (measured: the hub rate is 2.8 rad/s off the
    # profile at 5.4 s and oscillates by tens of rad/s after; the FMU may refuse a step first).
    unstable = run(arm_unzipdir, arm_model_description, 1.5 * H_LIMIT, 6.0)
    rate_error = np.abs(unstable["rate"] - unstable["reference_rate"]).max()
    print(f"H = {1.5 * H_LIMIT:.3f} s: completed {unstable['completed']}, largest rate error {rate_error:.3e} rad/s")
    assert not unstable["completed"] or rate_error > 1.0

