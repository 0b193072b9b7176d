//! `model.auto`: which of the allowed terms are in force, chosen per communication step.

use super::assembly::{Features, Model};
use super::{Dynamics, LogEvent};
use crate::body::feature_indicators::{self};
use crate::body::frame::angle_between;
use crate::body::lowest_modes::MODES;
use crate::model::category;
use crate::solver::generalized_alpha::Carried;

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
    decide_linear: bool,
    events: &mut Vec<LogEvent>,
    scratch: &mut [f64],
) {
    let before = dynamics.features;
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
            let next = hysteresis(*active, scaled, target, quiet_since, s.time, dwell);
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
        let [quiet_nl, quiet_stiffening, _] = &mut dynamics.quiet_since;
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
        // The one frame's stiffening acts on its deformation `ū`: with the slabs, which turn
        // apart from that frame, it is off (on B3 the slabs with it ended 1.3e-2 of the peak
        // from `full`, without 2.1e-3; docs/fmu.md, "model.auto"); the slabs take their own
        // ([`choose_slab_stiffening`]).
        decide(
            &mut f.stiffening,
            quiet_stiffening,
            model.allowed.stiffening && !f.frames,
            e.stiffening,
            "geometric stiffening",
        );
        dynamics.features = f;
    }
    choose_slabs(model, dynamics, accuracy, events, scratch);
    if dynamics.features.frames && model.allowed.frames {
        dynamics.features.stiffening = false;
    }
    if decide_linear {
        choose_linear(model, dynamics, accuracy, events);
    }
    model.apply_features(dynamics.features);
    if dynamics.features != before {
        // Another model, another contraction: measured again.
        dynamics.state.iteration_error_ratio = f64::INFINITY;
    }
}

/// A switch of `model.auto` with hysteresis: a term that is off goes on when `value` exceeds
/// `on_above`; one that is on goes off once `value` has stayed below
/// [`feature_indicators::HYSTERESIS`] × `on_above` for `dwell` (s) since `quiet_since` (the time
/// it fell below, [`NOT_QUIET`] while it is not), which this keeps, at time `time`.
fn hysteresis(
    active: bool,
    value: f64,
    on_above: f64,
    quiet_since: &mut f64,
    time: f64,
    dwell: f64,
) -> bool {
    if !active {
        return value > on_above;
    }
    if value >= feature_indicators::HYSTERESIS * on_above {
        *quiet_since = NOT_QUIET;
        return true;
    }
    if *quiet_since == NOT_QUIET {
        *quiet_since = time;
    }
    time - *quiet_since < dwell
}

/// A reduced body's stiffening from the driving motion is in force while it changes the lowest
/// modes' stiffness by more than this times `model.accuracy`: a switch applies `f_stiff`, of
/// about that relative size, as a step load, as the slabs' and the linear body's switches do
/// ([`LINEAR_AT`]). On B3 the spin-up reaches `η ≈ Ω²/ω₁² ≈ 2.5` (docs/formulation.md, "The
/// reduced body").
pub(super) const DRIVEN_STIFFENING_AT: f64 = 0.25;

/// `model.auto`'s stiffening of a reduced body driven by a motion interface (docs/formulation.md,
/// "The reduced body": when the stiffening is taken), from its `driven` coefficients
/// ([`crate::body::stiffening::driven_inertial_coefficients`]): in force from the first
/// communication point where the relative stiffness change `η` of the lowest modes under the
/// driving motion's `K_G` ([`crate::body::lowest_modes::LowestModes::relative_stiffening`]) exceeds
/// [`DRIVEN_STIFFENING_AT`] × `model.accuracy`, out of force once `η` stayed below
/// [`feature_indicators::HYSTERESIS`] times that for one period `2π/ω₁`. Each switch is logged;
/// it needs no factorization (`K_G` stays on the right-hand side). O(12 × MODES²), no
/// allocation unless a decision changes.
pub(super) fn choose_driven_stiffening(
    model: &Model,
    dynamics: &mut Dynamics,
    accuracy: f64,
    driven: Option<&[f64; 12]>,
    events: &mut Vec<LogEvent>,
) {
    let (Some(projections), Some(modes), Some(c)) = (
        model.driven_stiffening.as_ref(),
        model.lowest_modes.as_ref(),
        driven,
    ) else {
        return;
    };
    let s = &dynamics.state;
    let mut g = [[0.0; MODES]; MODES];
    for (ck, gk) in c.iter().zip(projections) {
        for (row, row_k) in g.iter_mut().zip(gk) {
            for (x, xk) in row.iter_mut().zip(row_k) {
                *x += ck * xk;
            }
        }
    }
    let eta = modes.relative_stiffening(&g);
    let limit = DRIVEN_STIFFENING_AT * accuracy;
    let f = &mut dynamics.features;
    let quiet = &mut dynamics.quiet_since[1];
    let next = hysteresis(
        f.stiffening,
        eta,
        limit,
        quiet,
        s.time,
        modes.first_period(),
    );
    if next != f.stiffening {
        f.stiffening = next;
        events.push(LogEvent {
            category: category::EVENTS,
            message: if next {
                format!(
                    "model.auto: at t = {} the reduced body's stiffening from the driving motion switched on: it changes the lowest modes' stiffness by {eta:.3e} > {DRIVEN_STIFFENING_AT} × model.accuracy = {limit:.3e}",
                    s.time
                )
            } else {
                format!(
                    "model.auto: at t = {} the reduced body's stiffening from the driving motion switched off: it changed the lowest modes' stiffness by less than {} × {limit:.3e} since t = {} (now {eta:.3e})",
                    s.time,
                    feature_indicators::HYSTERESIS,
                    *quiet
                )
            },
        });
        *quiet = NOT_QUIET;
        // Another model's terms: the iteration's contraction is measured again.
        dynamics.state.iteration_error_ratio = f64::INFINITY;
    }
}

/// The linear body's frame is held while its rotation `θ` against the placement is at most
/// this times `model.accuracy`. The linear body differs from the reduced-strain body by about a
/// third of `θ` relative to the deformation (B1 under a tip step load: 0.34 θ at 1 N and 10 N,
/// `tests/linear_body.rs`), and a switch applies the difference of their elastic forces as a
/// step load, whose ringing the error control then resolves: a quarter, as for the slabs
/// ([`SWITCH_AT`]). Measured on B1 (10 N, `examples/accuracy_table.rs`): at `model.accuracy`
/// 1e-3, switching at the accuracy itself took 12 196 internal steps (7.6e-5 of the peak), at a
/// quarter 6 563 (1.5e-4), as many as without the linear body (6 404); at 1e-2 the body stays
/// linear either way (5.2e-3, 395 steps) (docs/formulation.md, "The linear body").
pub(super) const LINEAR_AT: f64 = 0.25;

/// The rotation `θ` (rad) of the best-fit frame of positions `x` against the linear body's
/// placement (`None` for a body that cannot be linear).
fn frame_turn(model: &Model, x: &[f64]) -> Option<f64> {
    let placement = model
        .body
        .linear
        .as_ref()
        .or(model.parked_linear.as_ref())?;
    let rotation = model.body.frame_weights.best_fit(x).rotation;
    Some(angle_between(&placement.frame.rotation, &rotation))
}

/// After a communication step taken with `model.auto`'s linear body: the frame's rotation `θ`
/// at its end if it went beyond the linear body's reach (then the step is redone with the
/// frame following, `Slave::do_step`: a load that arrived during the step was not foreseen
/// at its start).
pub(super) fn linear_reach_exceeded(model: &Model, x: &[f64], accuracy: f64) -> Option<f64> {
    if !model.allowed.linear || model.body.linear.is_none() {
        return None;
    }
    frame_turn(model, x).filter(|&theta| theta > LINEAR_AT * accuracy)
}

/// `model.auto`'s linear body (docs/formulation.md, "The linear body"), for a body held by
/// fixed supports: linear (the frame held at the placement, one linear solve per step) while
/// the rotation `θ` of its best-fit frame against the placement stays at most [`LINEAR_AT`] ×
/// `model.accuracy`; the frame follows the body from the first communication point where it
/// does not, and is held again once `θ` has stayed below [`feature_indicators::HYSTERESIS`]
/// times that for one period `2π/ω₁` of the lowest mode. Each switch is logged; it needs no
/// state transfer and no factorization (the same `K`, `M` and iteration matrix). The slabs
/// (a body that bends far) end it for good.
fn choose_linear(
    model: &Model,
    dynamics: &mut Dynamics,
    accuracy: f64,
    events: &mut Vec<LogEvent>,
) {
    if !model.allowed.linear {
        return;
    }
    let f = &mut dynamics.features;
    let s = &dynamics.state;
    let Some(theta) = frame_turn(model, &s.position) else {
        return;
    };
    let limit = LINEAR_AT * accuracy;
    let dwell = model
        .lowest_modes
        .as_ref()
        .map_or(0.0, |m| m.first_period());
    let quiet = &mut dynamics.quiet_since[2];
    let next = if f.frames {
        false
    } else if f.linear {
        theta <= limit
    } else if theta <= feature_indicators::HYSTERESIS * limit {
        if *quiet == NOT_QUIET {
            *quiet = s.time;
        }
        // (Strictly later: a step redone at the same time stays with the frame following.)
        s.time - *quiet >= dwell.max(f64::MIN_POSITIVE)
    } else {
        *quiet = NOT_QUIET;
        false
    };
    if next != f.linear {
        f.linear = next;
        *quiet = NOT_QUIET;
        if next {
            f.nonlinear_forces = false;
        }
        events.push(LogEvent {
            category: category::EVENTS,
            message: if next {
                format!(
                    "model.auto: at t = {} the body is linear again: its frame has turned {theta:.3e} rad from its placement, below {} × {LINEAR_AT} × model.accuracy = {:.3e} since t = {} (at least one period 2π/ω₁ = {dwell:.3e} s); one linear solve per step",
                    s.time,
                    feature_indicators::HYSTERESIS,
                    feature_indicators::HYSTERESIS * limit,
                    s.time - dwell.min(s.time)
                )
            } else {
                format!(
                    "model.auto: at t = {} the body's frame follows it: it has turned {theta:.3e} rad from its placement, more than {LINEAR_AT} × model.accuracy = {limit:.3e} (the linear body's error is about a third of it)",
                    s.time
                )
            },
        });
    }
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

/// Carries the state over from the one frame to `model.auto`'s slabs just switched on (before
/// the first internal step of `h` of the communication step where they came on; `old`: the
/// terms in force before it): the one frame's internal force at the state (`old_force`, scratch
/// of `3N`) against the slabs' ([`crate::solver::integrator::TimeIntegrator::carry_over_force_change`]).
/// The one frame's state balances its own linear strain of the slabs' turns `θ`, an axial
/// stretch of about `θ²/2` that the slabs do not have: put in place as it is, the slabs spring
/// back from it at the stiff modes' periods (docs/formulation.md, "The slabs' switch"). `None`
/// (the state as it is) on a body with pins, hinges or rigid sets, whose lowest modes do not
/// see the constraints, or without the lowest modes (no error control). With `events`, what it
/// did is logged there.
#[allow(clippy::too_many_arguments)]
pub(super) fn carry_over_to_slabs(
    model: &mut Model,
    dynamics: &mut Dynamics,
    h: f64,
    old: Features,
    old_force: &mut [f64],
    tolerance: f64,
    events: Option<&mut Vec<LogEvent>>,
) -> Option<Carried> {
    if model.free.is_constrained() || model.lowest_modes.is_none() {
        return None;
    }
    let slabs = dynamics.features;
    model.apply_features(Features {
        frames: false,
        ..old
    });
    model
        .forces
        .observe(&model.body, &dynamics.state, old_force);
    model.apply_features(slabs);
    let rotation = model
        .body
        .frame_weights
        .best_fit(&dynamics.state.position)
        .rotation;
    let modes = model.lowest_modes.as_ref().expect("checked above");
    let remove_lowest = |v: &mut [f64]| modes.remove_lowest(&rotation, v);
    let carried = model.integrator.carry_over_force_change(
        h,
        &model.body,
        &model.free,
        &mut dynamics.state,
        &mut model.forces,
        old_force,
        &remove_lowest,
        tolerance,
    )?;
    if let Some(events) = events {
        events.push(LogEvent {
            category: category::EVENTS,
            message: format!(
                "model.auto: at t = {} the state is carried over to the slabs: the free nodes moved by up to {:.3e} m in {} corrections (the static response to the two models' force difference above the lowest modes){}",
                dynamics.state.time,
                carried.largest,
                carried.corrections,
                if carried.last > tolerance {
                    format!(
                        "; the last, {:.3e} m, is above the iteration's tolerance {tolerance:.3e} m",
                        carried.last
                    )
                } else {
                    String::new()
                }
            ),
        });
    }
    Some(carried)
}

/// The words of the log message of the slabs' own stiffening switched on (a redone attempt
/// withdraws it).
pub(super) const SLAB_STIFFENING_ON: &str = "the slabs' own geometric stiffening switched on";

/// The slabs' own stiffening (docs/formulation.md, "Geometric stiffening within the slabs"):
/// while it is in force, refreshes each slab's `G_p` from the state at the communication step's
/// start; for `model.auto`'s slabs, where `measure` (see [`SlabStiffeningSwitch::due`]) and the state
/// is the slabs' own, measures how much their prestress changes their stiffness (the energy
/// ratio of [`Patches::update_stiffening`], kept in `Dynamics::slab_stiffening_ratio`) and
/// switches it on, once and for good, where that exceeds [`SlabStiffeningSwitch::threshold`];
/// logged. From the switch it comes in over the lowest period ([`SlabStiffeningSwitch::scale`]). No
/// allocation unless the decision changes.
///
/// The caller passes `measure` false where the state is not the slabs' own: a communication
/// step at which the slabs came on starts from the one frame's state, which the carry-over
/// then changes (measured from it, B3 at `1e-3` switched at 1.67 s on a ratio of 2.55e-4 where
/// the carried-over state read 2.4e-8).
///
/// [`Patches::update_stiffening`]: crate::body::patches::Patches::update_stiffening
pub(super) fn choose_slab_stiffening(
    model: &mut Model,
    dynamics: &mut Dynamics,
    switch: SlabStiffeningSwitch,
    events: &mut Vec<LogEvent>,
    measure: bool,
) {
    if model.body.reduction.is_some() {
        return;
    }
    let f = dynamics.features;
    let decides = measure && model.allowed.frames && f.frames && !f.slab_stiffening;
    if !(f.slab_stiffening || decides) {
        return;
    }
    let scale = switch.scale(dynamics);
    let Some(patches) = model.body.patches.as_mut().filter(|p| p.has_stiffening()) else {
        return;
    };
    let x = &dynamics.state.position;
    let Some(ratio) = patches.update_stiffening(x, decides, scale) else {
        return;
    };
    dynamics.slab_stiffening_ratio = ratio;
    if ratio > switch.threshold() {
        // It comes in over the lowest period from here (`SlabStiffeningSwitch::scale`).
        dynamics.slab_stiffening_since = Some(dynamics.state.time);
        patches.update_stiffening(x, false, 0.0);
        dynamics.features.slab_stiffening = true;
        model.apply_features(dynamics.features);
        dynamics.state.iteration_error_ratio = f64::INFINITY;
        events.push(LogEvent {
            category: category::EVENTS,
            message: format!(
                "model.auto: at t = {} {SLAB_STIFFENING_ON}, coming in over the lowest period: their prestress changes their stiffness by {ratio:.3e} > {SWITCH_AT} × model.accuracy / {:.3} = {:.3e} (the lowest mode's phase drift over the horizon; docs/formulation.md, \"Geometric stiffening within the slabs\")",
                dynamics.state.time,
                switch.drift,
                switch.threshold()
            ),
        });
    }
}

/// The rule of the slabs' own stiffening under `model.auto` (docs/formulation.md, "Geometric
/// stiffening within the slabs"): where it is switched on, when it is measured while off, and
/// how it comes in once on; all from `model.accuracy`, the horizon `H` and the lowest period
/// `T₁`.
///
/// It is switched on where it changes the slabs' stiffness by more than [`SWITCH_AT`] ×
/// `model.accuracy` / `drift`. A stiffness left out by a share `r` is a static error of about
/// `r` and shifts the lowest frequency by `r/2`, a phase that drifts by `ω₁ H r / 2` over the
/// horizon: `drift = max(1, ω₁ H / 2)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct SlabStiffeningSwitch {
    /// `model.accuracy`.
    pub accuracy: f64,
    /// `max(1, ω₁ H / 2)`, 1 without a lowest mode or horizon.
    pub drift: f64,
    /// `T₁` (s); 0 without a lowest mode.
    pub period: f64,
}

/// How often the slabs' stiffening is measured while it is off
/// ([`SlabStiffeningSwitch::due`]): at the communication steps that begin a new
/// `T₁ / SLAB_STIFFENING_CADENCE` of time, and at every communication step once the last ratio
/// is above [`SLAB_STIFFENING_NEAR`] of the switch. The measurement is a product with every
/// slab's stiffness: at every communication point it was 9 % of B3's run at
/// `model.accuracy = 1e-2`. A ratio that grows from below the near mark to above the switch
/// within `T₁/16` (its strain energy's share more than fourfold in a sixteenth of the lowest
/// period) is caught at most that late.
pub(super) const SLAB_STIFFENING_CADENCE: f64 = 16.0;

/// The part of the switch above which the slabs' stiffening is measured at every communication
/// step ([`SLAB_STIFFENING_CADENCE`]).
pub(super) const SLAB_STIFFENING_NEAR: f64 = 0.25;

impl SlabStiffeningSwitch {
    /// The rule for `accuracy` over the `horizon` (s) of a body whose lowest period is
    /// `period` (s).
    pub fn new(accuracy: f64, horizon: Option<f64>, period: Option<f64>) -> SlabStiffeningSwitch {
        let drift = horizon
            .zip(period)
            .map_or(1.0, |(h, t1)| std::f64::consts::PI * h / t1)
            .max(1.0);
        SlabStiffeningSwitch {
            accuracy,
            drift: if drift.is_finite() { drift } else { 1.0 },
            period: period
                .filter(|t1| *t1 > 0.0 && t1.is_finite())
                .unwrap_or(0.0),
        }
    }

    /// The energy ratio above which the stiffening is switched on.
    pub fn threshold(&self) -> f64 {
        SWITCH_AT * self.accuracy / self.drift
    }

    /// The share of the slabs' own stiffening in force at the state's time: it comes in
    /// linearly over `T₁` from `model.auto`'s switch (`Dynamics::slab_stiffening_since`), a load
    /// that a step would have rung the body with. 1 where it was forced on.
    pub fn scale(&self, dynamics: &Dynamics) -> f64 {
        match dynamics.slab_stiffening_since {
            Some(since) if self.period > 0.0 => {
                ((dynamics.state.time - since) / self.period).clamp(0.0, 1.0)
            }
            _ => 1.0,
        }
    }

    /// Whether the communication step `[t, t + H)` measures the slabs' stiffening
    /// ([`SLAB_STIFFENING_CADENCE`]): it begins a new `T₁/16` of time, the last ratio was near
    /// the switch, none was measured yet (0: the slabs' first step where the state could not
    /// be carried over to them), or the body has no lowest period.
    pub fn due(&self, dynamics: &Dynamics, big_h: f64) -> bool {
        let ratio = dynamics.slab_stiffening_ratio;
        let near = ratio > SLAB_STIFFENING_NEAR * self.threshold() || ratio == 0.0;
        let interval = self.period / SLAB_STIFFENING_CADENCE;
        if near || interval <= 0.0 {
            return true;
        }
        let t = dynamics.state.time;
        (t / interval).floor() < ((t + big_h) / interval).floor()
    }
}

/// `model.auto`'s slabs (one co-moving frame per element layer along the body's long axis,
/// `Patches::element_layers`): switched on, once and for good, at the first communication
/// point where the single frame's error estimate `BENDING_ERROR × ‖∇ū‖²` (the strain watch's
/// gradient of the local deformation) exceeds [`SWITCH_AT`] × `model.accuracy`; logged. They are not switched off: the two models' elastic forces differ
/// by the single frame's artefact, and dropping the slabs applies that difference as a step
/// load (on B3, slabs from 4 s to 10 s ended 7.1 % off `full` against 0.57 % when kept).
/// Switching needs no factorization (the constant iteration matrix holds the same `K`); the
/// state is carried over to the slabs ([`carry_over_to_slabs`]). If a communication step does not converge
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
                "model.auto: at t = {} the body bends far against its co-moving frame (‖∇ū‖ ≈ {g:.3}; the single frame's error ≈ {BENDING_ERROR} ‖∇ū‖² = {estimate:.2e} > {SWITCH_AT} × model.accuracy = {accuracy:e}): {} co-moving frames (slabs, one per element layer) from now on{}",
                dynamics.state.time,
                model.parked_slab_count(),
                if dynamics.features.stiffening {
                    ", without the one frame's geometric stiffening (it acts on the one frame's deformation, which the slabs replace; they take their own where model.accuracy asks for it)"
                } else {
                    ""
                }
            ),
        });
    }
}
