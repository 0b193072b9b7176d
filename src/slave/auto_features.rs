//! `model.auto`: which of the allowed terms are in force, chosen per communication step.

use super::assembly::Model;
use super::{Dynamics, LogEvent};
use crate::body::feature_indicators::{self};
use crate::model::category;

/// `Dynamics::quiet_since` of a term whose indicator is not below its switch-off threshold (a
/// finite number: the state's byte form holds finite numbers only).
pub(super) const NOT_QUIET: f64 = f64::MAX;

/// `model.auto`: decides from the state at the communication point which allowed terms are in
/// force over the next communication step (held over its internal steps, like `K_G`), logs each
/// change once under `logEvents` with the estimate and the threshold, and puts the terms into
/// force. A term goes on when `SAFETY × estimate > target`; it goes off when that has stayed
/// below `HYSTERESIS × target` for one period `2π/ω₁` of the lowest mode (a vibrating body's
/// indicators peak twice per period: the dwell keeps a term from switching with the vibration).
/// `target` (m) is the iteration's absolute tolerance `solver.tolerance × size`. `f_nl` is kept
/// off on a body with supports (see below). No allocation unless a decision changes.
pub(super) fn choose_features(
    model: &mut Model,
    dynamics: &mut Dynamics,
    target: f64,
    accuracy: f64,
    events: &mut Vec<LogEvent>,
    scratch: &mut [f64],
) {
    if let Some(indicators) = model.indicators.as_mut() {
        let s = &dynamics.state;
        let e = indicators.estimate(&model.body, &s.position, &s.velocity, &s.acceleration);
        let dwell = indicators
            .first_frequency()
            .map_or(0.0, |w| 2.0 * std::f64::consts::PI / w);
        let mut f = dynamics.features;
        let mut decide = |active: &mut bool,
                          quiet_since: &mut f64,
                          allowed: bool,
                          estimate: Option<f64>,
                          name: &str| {
            let Some(e) = estimate.filter(|_| allowed) else {
                *active = allowed;
                *quiet_since = NOT_QUIET;
                return;
            };
            let scaled = feature_indicators::SAFETY * e;
            let next = if *active {
                if scaled >= feature_indicators::HYSTERESIS * target {
                    *quiet_since = NOT_QUIET;
                    true
                } else {
                    if *quiet_since == NOT_QUIET {
                        *quiet_since = s.time;
                    }
                    s.time - *quiet_since < dwell
                }
            } else {
                scaled > target
            };
            if next != *active {
                *active = next;
                events.push(LogEvent {
                    category: category::EVENTS,
                    message: if next {
                        format!(
                            "model.auto: at t = {} {name} switched on: estimated effect {e:.3e} m, × {} = {scaled:.3e} m > the target {target:.3e} m",
                            s.time,
                            feature_indicators::SAFETY
                        )
                    } else {
                        format!(
                            "model.auto: at t = {} {name} switched off: estimated effect {e:.3e} m, × {} = {scaled:.3e} m < {} × the target = {:.3e} m since t = {} (at least one period 2π/ω₁ = {dwell:.3e} s)",
                            s.time,
                            feature_indicators::SAFETY,
                            feature_indicators::HYSTERESIS,
                            feature_indicators::HYSTERESIS * target,
                            *quiet_since
                        )
                    },
                });
            }
        };
        let [quiet_nl, quiet_stiffening] = &mut dynamics.quiet_since;
        // On a body with supports (the ones whose f_nl has an estimate) and one co-moving frame
        // f_nl is kept off: on B3 it moved the peak 9 % away from the full reference, where
        // leaving it off stays within 1.6 % (docs/fmu.md, "Which terms a scene needs"). Only a
        // free body, whose spurious moment accumulates, gets it (always on, no estimate).
        let helps = model.allowed.nonlinear_forces && e.nonlinear_forces.is_none();
        decide(
            &mut f.nonlinear_forces,
            quiet_nl,
            helps,
            e.nonlinear_forces,
            "the nonlinear force f_nl",
        );
        decide(
            &mut f.stiffening,
            quiet_stiffening,
            model.allowed.stiffening,
            e.stiffening,
            "geometric stiffening",
        );
        dynamics.features = f;
    }
    choose_slabs(model, dynamics, accuracy, events, scratch);
    model.apply_features(dynamics.features);
}

/// The single frame's error on a body that bends far, in units of the largest deformation
/// gradient squared: B3's one-frame deviation from `full` is 1.57 % of the peak where the
/// strain watch's `‖∇ū‖` peaks at 0.061 (`4 g²` = 1.5 %).
pub(super) const BENDING_ERROR: f64 = 4.0;

/// The part of `model.accuracy` the single frame may use up before the slabs are switched on:
/// switching applies the two models' force difference (about the single frame's error) as a
/// step load, whose response is up to twice as large and stays as a free vibration; at a
/// quarter that leaves half of the accuracy to the slabs. Measured on B3 (40 slabs, 20 s):
/// switched at the accuracy 0.65 % of the peak off `full`, at a quarter 0.24 %, at a tenth
/// 0.23 % (the slabs alone 0.23 %).
pub(super) const SWITCH_AT: f64 = 0.25;

/// `model.auto`'s slabs (one co-moving frame per element layer along the body's long axis,
/// `Patches::element_layers`): switched on, once and for good, at the first communication
/// point where the single frame's error estimate `BENDING_ERROR × ‖∇ū‖²` (the strain watch's
/// gradient of the local deformation) exceeds [`SWITCH_AT`] × `model.accuracy`; logged. They are not switched off: the two models' elastic forces differ
/// by the single frame's artefact, and dropping the slabs applies that difference as a step
/// load (on B3, slabs from 4 s to 10 s ended 7.1 % off `full` against 0.57 % when kept).
/// Switching needs no state transfer (the state is nodal positions) and no factorization (the
/// constant iteration matrix holds the same `K`). If a communication step does not converge
/// with the slabs on (just switched on, or later as the body goes on bending violently),
/// `Slave::do_step` redoes it with the one frame and the slabs are not tried again (B1 under
/// 5 kN, far beyond small strain).
fn choose_slabs(
    model: &Model,
    dynamics: &mut Dynamics,
    accuracy: f64,
    events: &mut Vec<LogEvent>,
    local_deformation: &mut [f64],
) {
    let f = dynamics.features;
    if !model.allowed.frames || f.frames || f.frames_refused {
        return;
    }
    let Some((monitor, _)) = &model.strain_monitor else {
        return;
    };
    // From the state (not the last residual's scratch, which depends on what was evaluated
    // last: a rejected attempt, an output request).
    model
        .body
        .local_deformation(&dynamics.state.position, local_deformation);
    let g = monitor.largest_gradient(local_deformation);
    let estimate = BENDING_ERROR * g * g;
    if estimate > SWITCH_AT * accuracy {
        dynamics.features.frames = true;
        events.push(LogEvent {
            category: category::EVENTS,
            message: format!(
                "model.auto: at t = {} the body bends far against its co-moving frame (‖∇ū‖ ≈ {g:.3}; the single frame's error ≈ {BENDING_ERROR} ‖∇ū‖² = {estimate:.2e} > {SWITCH_AT} × model.accuracy = {accuracy:e}): {} co-moving frames (slabs, one per element layer) from now on",
                dynamics.state.time,
                model.parked_slab_count()
            ),
        });
    }
}
