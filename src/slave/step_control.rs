//! `model.accuracy`: the internal step chosen by the time integration error (docs/formulation.md,
//! "Time error control").
//!
//! Every internal step of generalized-α estimates its local error `e` (m, mass-weighted RMS,
//! `generalized_alpha::IterationMatrix::local_error`). The step is accepted when
//!
//! ```text
//! e ≤ allowance(h) = max(ε D h / H,  ITERATION_NOISE × tolerance × size)
//! ```
//!
//! with `ε = model.accuracy`, `D` the deformation scale (the largest mass-weighted RMS elastic
//! displacement relative to the supports seen so far, from the lowest modes, or quasi-static
//! displacement of the accelerations, m: docs/formulation.md, "The deformation scale") and `H`
//! the horizon (s): the run, `stopTime − startTime`, when the importer defined its stop time,
//! else the period `T₁ = 2π/ω₁` of the body's lowest natural frequency (docs/formulation.md,
//! "The horizon"): the errors committed over the horizon add up to at most `ε D`. The floor is
//! above the iteration's own error: the estimate differences accelerations of converged
//! iterates, each off by up to the iteration's `tolerance × size` in position
//! (`Parameters::iteration_tolerance`), which puts a
//! noise of `(β − 1/6)/β` of that into `e` whatever `h` is; asking the time step for less would
//! refine it down the whole ladder for nothing.
//!
//! The internal step lives on a ladder of rungs `h_k = solver.stepSize / 2^k`, `k ≤`
//! [`MAX_LEVEL`] (a communication step is split into equal internal steps no longer than the
//! rung). A communication step in which some internal step exceeds its allowance is redone from
//! its start on a finer rung (the local error is third order in `h` and the allowance first
//! order: the ratio falls like `h²`); one that stayed below [`GROW_BELOW`] moves one rung up for
//! the next. Steps on a rung seen before reuse its factorization (`MATRIX_CACHE_SIZE`).
//!
//! A rung reached by refining can hold an estimate that does not fall with the step: the
//! iteration's noise (a step accepted on the contraction estimate of its first two corrections
//! carries more than `solver.tolerance × size`) or a ringing the steps do not resolve, both about
//! the same whatever `h` is, while the allowance falls like `h`. Waiting for the ratio to fall
//! below [`GROW_BELOW`] would then keep the fine rung for the rest of the run (B3 at
//! `model.accuracy` 1e-3, stepped as two half steps per input update: 22 internal steps per half
//! step from 1.67 s on, 16 times the work of whole steps). So after [`PROBE_FIRST`] communication
//! steps in a row below [`PROBE_BELOW`] on a rung, the next one is taken on the rung above (a
//! probe): if it stays within its allowance the body keeps the coarser rung, if not it is redone
//! on its own rung and the next probe waits twice as long (at most [`PROBE_LAST`] steps); a
//! refinement after a kept probe doubles the wait as well, and only a refinement from a
//! confirmed rung (the scene has become harder) resets it, which bounds the cost of probes that
//! fail to a few per cent of the steps. A step that would not be estimated (one internal step
//! after an input jump) is not taken as a probe: a probe is kept on an estimate only.
//!
//! **Growth.** A quiet step moves one rung up at once, unless the step was itself redone on a
//! finer rung. The rung it reaches is unconfirmed like a probe's: a refinement before as many
//! calm steps as the next probe waits for doubles that wait, and from then on quiet growth
//! waits too ([`Ladder::may_grow`]). Without that, an estimate that does not fall like `h²`
//! between two rungs made the body grow, fail and redo at every communication step (B3 at
//! `model.accuracy = 1e-3` in its steady spin: 1.74 × the allowance on the rung above, 0.005 ×
//! on its own, 495 communication steps redone). Such a refinement is redone on the rung the
//! step grew from ([`Ladder::redo_level`]), not as far down as the ratio would ask: that rung's
//! steps were quiet, and the ratio between the two rungs is what did not fall like `h²`.

/// The floor of the allowance in units of the iteration's tolerance `solver.tolerance × size`:
/// the estimate's noise from the iteration is below 0.4 of that (see the module documentation).
pub const ITERATION_NOISE: f64 = 10.0;

/// The iteration's tolerance follows the allowance of the internal steps where the floor would
/// pass their errors ([`ITERATION_NOISE`] × tolerance × size above the allowance), once the
/// deformation scale is established (the first period has passed, or on a body without
/// supports the scale has settled: [`ScaleSettling`]), and only for a deformation whose whole
/// budget `ε D` is at least this many of the iteration's own tolerances `tolerance × size`
/// ([`above_resolution`]): below, the deformation is at the
/// iteration's resolution and the floor stands (docs/formulation.md, "Time error control": the
/// iteration's tolerance). B2 at `ε = 1e-3`: `ε D` is 1.8e5 of them, and it follows; a nearly
/// rigid pendulum (`D` 1e-8 of its size at `ε = 1e-2`): 1, and following its allowance down to
/// round-off refined it to 4 µs for its whole swing.
pub const FOLLOW_ABOVE: f64 = 1e3;

/// Whether the budget `ε D` (`accuracy` × `scale`, m) is above the iteration's resolution,
/// [`FOLLOW_ABOVE`] × `tolerance` × `size` (m): only then does the iteration's tolerance follow
/// the allowance, and does the deformation scale's settling count ([`ScaleSettling`]).
pub fn above_resolution(accuracy: f64, scale: f64, tolerance: f64, size: f64) -> bool {
    accuracy * scale >= FOLLOW_ABOVE * tolerance * size
}

/// An estimate that refining did not reduce becomes a floor of the allowance with this margin,
/// so that the rung it came from is judged within its allowance.
pub const NOISE_MARGIN: f64 = 4.0;

/// Finest rung: `solver.stepSize / 2^MAX_LEVEL`. Ten rungs: B2 (an undamped free body over a
/// run of 3.3 `T₁`) meets `1e-4` on steps of `solver.stepSize / 2^9` (docs/benchmarks.md); with
/// eight, its steps stayed on the finest rung and it ended 6.3e-4 of its peak off.
pub const MAX_LEVEL: u32 = 10;

/// Finest rung while the deformation scale is not yet established (neither settled nor a first
/// period old: [`finest_level`]). A scale still growing from 0 at a load's onset sets an
/// allowance far below what the run's errors will be judged against, and the two finest rungs
/// bought nothing there: the connecting rod's onset at `1e-3` went down to `2^9` and took
/// 1 566 internal steps where `2^8` takes 799, for the same error (docs/benchmarks.md).
pub const EARLY_MAX_LEVEL: u32 = 8;

/// The finest rung the ladder may refine to: [`MAX_LEVEL`] once the deformation scale is
/// `established`, [`EARLY_MAX_LEVEL`] before.
pub fn finest_level(established: bool) -> u32 {
    if established {
        MAX_LEVEL
    } else {
        EARLY_MAX_LEVEL
    }
}

/// The lowest relative tolerance (× size) the iteration's tolerance follows the allowance down
/// to (docs/formulation.md, "The iteration's tolerance"). Below the round-off of a residual in
/// absolute coordinates (`TOLERANCE_FLOOR`, 1e-13) a correction can still be resolved on the
/// finest rungs, where the mass term dominates the iteration matrix: B2 at `1e-4` needs 1e-15.
pub const FOLLOWING_TOLERANCE_FLOOR: f64 = 1e-15;

/// The deformation scale has settled when it has not grown by this factor for
/// [`SETTLED_FOR`] of the lowest period (docs/formulation.md, "The iteration's tolerance").
pub const SETTLED_GROWTH: f64 = 1.1;

/// See [`SETTLED_GROWTH`]: a sixteenth of `T₁`. B2's scale reaches its level within 0.03 s
/// (`T₁` = 0.30 s) and its tolerance must follow from 0.05 s; B3's grows by 10 % in 0.1 s
/// (`T₁/16`) through its spin-up.
pub const SETTLED_FOR: f64 = 1.0 / 16.0;

/// Whether the deformation scale `D` has settled (docs/formulation.md, "The iteration's
/// tolerance"): it has not grown by [`SETTLED_GROWTH`] for [`SETTLED_FOR`] of the lowest period
/// `T₁`, counted only while `ε D` is above the iteration's resolution. Once settled it stays
/// settled, and on a body without supports (whose `D` is the RMS of its local field itself) the
/// iteration's tolerance may follow the allowance before the first period has passed: errors
/// committed then are judged against the scale of the run, not of a body still deforming.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScaleSettling {
    /// When `D` last grew by [`SETTLED_GROWTH`] (or was below the iteration's resolution), s.
    pub since: f64,
    /// `D` then (m).
    pub scale: f64,
    /// Whether it has settled.
    pub settled: bool,
}

impl ScaleSettling {
    /// At the start of a run at `time` (s).
    pub fn at(time: f64) -> ScaleSettling {
        ScaleSettling {
            since: time,
            scale: 0.0,
            settled: false,
        }
    }

    /// After a communication step that ends at `time` (s) with the scale `scale` (m), for the
    /// lowest period `first_period` (s); `resolved`: whether `ε D` is above the iteration's
    /// resolution ([`FOLLOW_ABOVE`] × tolerance × size).
    pub fn after_step(
        self,
        time: f64,
        scale: f64,
        first_period: f64,
        resolved: bool,
    ) -> ScaleSettling {
        if self.settled {
            self
        } else if !resolved || scale > SETTLED_GROWTH * self.scale {
            ScaleSettling {
                since: time,
                scale,
                settled: false,
            }
        } else if time - self.since >= SETTLED_FOR * first_period * (1.0 - 1e-9) {
            ScaleSettling {
                settled: true,
                ..self
            }
        } else {
            self
        }
    }
}

/// A communication step whose largest `e / allowance` stayed below this moves one rung up (a
/// doubled step multiplies the ratio by about 4: it lands below 1/2 of the allowance).
pub const GROW_BELOW: f64 = 0.125;

/// The order of `e / allowance` in `h` (local error `h³` against an allowance `∝ h`).
pub const RATIO_ORDER: f64 = 2.0;

/// Communication steps on a rung, each with its largest ratio below [`PROBE_BELOW`], before
/// the next is taken as a probe on the rung above (see the module documentation).
pub const PROBE_FIRST: u32 = 8;

/// The longest wait between probes (communication steps), reached by doubling [`PROBE_FIRST`]
/// after each probe that failed.
pub const PROBE_LAST: u32 = 256;

/// A communication step counts towards a probe when its largest ratio is below this: on the rung
/// above, a ratio that falls like `h²` would be below 2 (a failed probe costs one step on the
/// coarser rung), one that does not fall with `h` below 1/2.
pub const PROBE_BELOW: f64 = 0.5;

/// Communication steps in a row that nothing estimated (each one internal step that starts at
/// an input jump: docs/formulation.md, "Time error control") before the body warns, once, that
/// their time error is not controlled. A single jump (a step load) passes unremarked; inputs
/// that jump at every communication point with `solver.stepSize` at or above the communication
/// step (a driven body sampled by its importer: B3) are named within the first 10 steps.
pub const UNESTIMATED_WARN_AFTER: u32 = 10;

/// Internal steps after a motion input's jump that are not estimated when the motion is sampled
/// (the jump came within as many internal steps of the one before: a driven body whose importer
/// sets its motion at every update). Each jump is a kink of the held coordinates' prescribed
/// path; their accelerations follow it through the scheme's update formulas, whose recurrence
/// rings with the factor `−α_m / (1 − α_m)` per step (−0.72 at `ρ∞ = 0.9`), and the estimate of
/// the next steps reads that ringing, which does not fall with the step, as their error
/// (docs/formulation.md, "The steps after a motion input's jump"). After 8 steps it is 0.72⁸ =
/// 7 % of what it was. So an importer that steps twice per input update (B3 as two half steps)
/// is judged as one that steps once: neither is estimated. A jump after a calm stretch (a step
/// of the driving velocity) leaves only its first internal step unestimated, as a force
/// input's does: the body's response to it is what the estimate must follow.
pub const MOTION_RINGING_STEPS: u32 = 8;

/// Whether an internal step that `steps` internal steps follow since a sampled motion input's
/// jump (`since_jump` of them before the communication step, [`MOTION_RINGING_STEPS`] once the
/// motion is not sampled) lies within the jump's ringing, and is not estimated.
pub fn within_ringing(since_jump: u32, steps: usize) -> bool {
    u64::from(since_jump) + (steps as u64) < u64::from(MOTION_RINGING_STEPS)
}

/// Where the internal step stands on the ladder between communication steps (part of the FMU
/// state).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ladder {
    /// The rung `k` of the next communication step's internal steps, `solver.stepSize / 2^k`.
    pub level: u32,
    /// Communication steps in a row on this rung below [`PROBE_BELOW`].
    pub calm_steps: u32,
    /// How many such steps the next probe waits for ([`PROBE_FIRST`] … [`PROBE_LAST`]).
    pub probe_after: u32,
    /// Whether this rung was reached by a probe that has not yet been confirmed by as many
    /// calm steps as the next probe waits for.
    pub probed: bool,
    /// Internal steps since a motion input last jumped (saturating; [`MOTION_RINGING_STEPS`]).
    pub since_motion_jump: u32,
    /// Whether that jump came within [`MOTION_RINGING_STEPS`] of the one before (a sampled
    /// motion, whose next internal steps are not estimated).
    pub sampled_motion: bool,
}

impl Default for Ladder {
    fn default() -> Ladder {
        Ladder {
            level: 0,
            calm_steps: 0,
            probe_after: PROBE_FIRST,
            probed: false,
            since_motion_jump: MOTION_RINGING_STEPS,
            sampled_motion: false,
        }
    }
}

impl Ladder {
    /// Whether the next communication step is a probe on the rung above.
    pub fn probes(&self) -> bool {
        self.level > 0 && self.calm_steps >= self.probe_after
    }

    /// On rung `level`, probes from the start.
    pub fn on(level: u32) -> Ladder {
        Ladder {
            level,
            ..Ladder::default()
        }
    }

    /// Whether a quiet step may move a rung up: at once, unless growth or probes from here
    /// have failed, then after `probe_after − PROBE_FIRST` calm steps (8, 24, … 248).
    pub fn may_grow(&self) -> bool {
        self.calm_steps + PROBE_FIRST >= self.probe_after
    }

    /// On rung `level` after a quiet step moved it up from this ladder's rung: like a probe, the
    /// rung is not confirmed until as many calm steps as the next probe waits for.
    pub fn after_growth(self, level: u32) -> Ladder {
        Ladder {
            level,
            calm_steps: 0,
            probed: true,
            ..self
        }
    }

    /// On rung `level` after a probe from this ladder's rung was kept: the wait for the next
    /// probe stays as it was.
    pub fn after_kept_probe(self, level: u32) -> Ladder {
        Ladder {
            level,
            calm_steps: 0,
            probed: true,
            ..self
        }
    }

    /// On the finer rung `level` after a step was redone on it. If the rung it left had been
    /// reached by a probe not yet confirmed, that probe was wrong after all: the next waits twice
    /// as long (a kept probe followed by a refinement does not repeat every few steps).
    /// Otherwise the scene has become harder and probes start over.
    pub fn after_refinement(self, level: u32) -> Ladder {
        if self.probed {
            Ladder {
                level,
                calm_steps: 0,
                probe_after: (2 * self.probe_after).min(PROBE_LAST),
                probed: false,
                ..self
            }
        } else {
            Ladder::on(level)
        }
    }

    /// After a communication step on this rung whose largest ratio was `ratio` (`None`: no
    /// step was estimated).
    pub fn after_step(self, ratio: Option<f64>) -> Ladder {
        match ratio {
            Some(r) if r < PROBE_BELOW => Ladder {
                calm_steps: self.calm_steps.saturating_add(1),
                probed: self.probed && self.calm_steps + 1 < self.probe_after,
                ..self
            },
            Some(_) => Ladder {
                calm_steps: 0,
                ..self
            },
            None => self,
        }
    }

    /// The rung a communication step rejected on rung `level` with `e / allowance = ratio`
    /// (> 1) is redone on. On a rung reached by growth or a kept probe and not yet confirmed,
    /// the rung it came from, whose steps were quiet; elsewhere [`finer_level`]: the ratio
    /// between two rungs need not fall like `h²` (B3 at `model.accuracy = 1e-3` at 13.8 s:
    /// 0.12 of the allowance on 2.5 ms, 2.3 × on 5 ms, which [`finer_level`] took two rungs
    /// down, to 1.25 ms, for the 2.5 s its calm steps took to grow back).
    ///
    /// `taken` is the rung of the internal steps the communication step took
    /// ([`level_of_step`]), `level` or coarser ones' equal: a refinement counts from it.
    ///
    /// `finest`: the finest rung it may take ([`finest_level`]).
    pub fn redo_level(&self, level: u32, taken: u32, ratio: f64, finest: u32) -> u32 {
        if self.probed && level == self.level {
            (taken + 1).min(finest)
        } else {
            finer_level(taken, ratio, finest)
        }
    }

    /// After a probe from this rung that failed: the same rung, the next probe twice as far off.
    pub fn after_failed_probe(self) -> Ladder {
        Ladder {
            calm_steps: 0,
            probe_after: (2 * self.probe_after).min(PROBE_LAST),
            ..self
        }
    }
}

/// The internal step of rung `level`: `step_size / 2^level` (s).
pub fn rung(step_size: f64, level: u32) -> f64 {
    step_size / f64::from(1u32 << level)
}

/// The finest rung whose internal steps split a communication step as steps of `h` (s) do: the
/// largest `k ≤ MAX_LEVEL` with `rung(step_size, k) ≥ h`. Every rung longer than the
/// communication step takes it whole: refining from one of them to another changes nothing
/// (`solver.stepSize = 0.5 s` with 2 ms communication steps: the first seven rungs are the
/// same 2 ms step), so a refinement and the finest rung count from this one.
pub fn level_of_step(step_size: f64, h: f64) -> u32 {
    let mut level = 0;
    while level < MAX_LEVEL && rung(step_size, level + 1) >= h * (1.0 - 1e-9) {
        level += 1;
    }
    level
}

/// The rung after a rejected communication step whose largest `e / allowance` was `ratio` (> 1):
/// far enough down that the ratio falls below 1/2, at least one rung, at most `finest`
/// ([`finest_level`]).
pub fn finer_level(level: u32, ratio: f64, finest: u32) -> u32 {
    let rungs = ((2.0 * ratio).log2() / RATIO_ORDER).ceil().max(1.0);
    (level + rungs.min(finest as f64) as u32).min(finest)
}

/// The allowance of an internal step `h` (m): `max(ε D h / H, floor)`, `H` the horizon (s).
pub fn allowance(accuracy: f64, scale: f64, h: f64, horizon: f64, floor: f64) -> f64 {
    (accuracy * scale * h / horizon).max(floor)
}

/// The error of an internal step against what it may commit (docs/formulation.md, "Time error
/// control": the errors that last). The step's estimate is split into `low` (m), its part in
/// the lowest modes, and `high` (m), the rest, each weighted by the share of the horizon `H` its
/// errors persist ([`crate::body::lowest_modes::LowestModes::lasting_error`]). The accumulated error of
/// a mode cannot exceed twice its amplitude, and the modes above the lowest have at most the
/// amplitude `high_amplitude` `A` (m). With the budget `ε D` (m) and `allowance = ε D h / H`:
///
/// * if `2A ≤ ε D / √2`, no step size can make the high modes exceed `2A`: they are not
///   controlled, and the low modes get the rest of the budget in quadrature,
///   `ratio = low / (allowance √(1 − (2A / ε D)²))`;
/// * otherwise each part gets half of it: `ratio = max(low, high) / (allowance / √2)`.
///
/// Either way the ratio falls like `h²`. What a part is allowed never falls below `floor` (m),
/// the iteration's noise ([`ITERATION_NOISE`]).
pub fn error_ratio(
    low: f64,
    high: f64,
    high_amplitude: f64,
    budget: f64,
    allowance: f64,
    floor: f64,
) -> f64 {
    let saturated = 2.0 * high_amplitude / budget;
    if saturated <= FRAC_1_SQRT_2 {
        low / (allowance * (1.0 - saturated * saturated).sqrt()).max(floor)
    } else {
        low.max(high) / (allowance * FRAC_1_SQRT_2).max(floor)
    }
}

use std::f64::consts::FRAC_1_SQRT_2;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_settles_once_it_has_stopped_growing_for_a_sixteenth_of_the_period() {
        let period = 1.6;
        let window = SETTLED_FOR * period;
        // Growing by 5 % per 0.01 s: never settles (10 % within 0.02 s < 0.1 s).
        let mut s = ScaleSettling::at(0.0);
        for k in 1..200 {
            s = s.after_step(0.01 * k as f64, 1.05f64.powi(k), period, true);
            assert!(!s.settled, "at step {k}");
        }
        // Steady after 0.5 s: settles one window later, and stays settled when it grows again.
        let mut s = ScaleSettling::at(0.0);
        let scale = |t: f64| 1e-3 * (t / 0.5).min(1.0);
        let mut settled_at = None;
        for k in 1..=100 {
            let t = 0.01 * k as f64;
            s = s.after_step(t, scale(t) * if t > 0.9 { 10.0 } else { 1.0 }, period, true);
            if s.settled && settled_at.is_none() {
                settled_at = Some(t);
            }
        }
        let settled_at = settled_at.expect("settles");
        // The last growth by 10 % is counted at 0.50 s, where the ramp ends (the one before at
        // 0.45 s): settled a window (0.1 s) after it.
        assert!(
            settled_at >= 0.5 + window - 1e-9 && settled_at <= 0.5 + window + 0.01,
            "settled at {settled_at}"
        );
        assert!(s.settled);
        // Below the iteration's resolution nothing counts.
        let mut s = ScaleSettling::at(0.0);
        for k in 1..100 {
            s = s.after_step(0.01 * k as f64, 1e-20, period, false);
        }
        assert!(!s.settled);
    }

    #[test]
    fn the_finer_rung_brings_the_ratio_below_one_half() {
        // The ratio falls like h²: 4 per rung.
        for &(ratio, expected) in &[
            (1.01, 1),
            (1.9, 1),
            (2.1, 2),
            (7.9, 2),
            (8.1, 3),
            (1e9, MAX_LEVEL),
        ] {
            let level = finer_level(0, ratio, MAX_LEVEL);
            assert_eq!(level, expected, "ratio {ratio}");
            if level < MAX_LEVEL {
                assert!(ratio / 4f64.powi(level as i32) < 0.5);
            }
        }
        assert_eq!(finer_level(MAX_LEVEL - 1, 100.0, MAX_LEVEL), MAX_LEVEL);
        // Before the scale is established the ladder ends two rungs higher.
        assert_eq!(finest_level(false), EARLY_MAX_LEVEL);
        assert_eq!(finer_level(4, 1e9, finest_level(false)), EARLY_MAX_LEVEL);
        assert_eq!(finer_level(4, 1e9, finest_level(true)), MAX_LEVEL);
    }

    #[test]
    fn a_probe_comes_after_calm_steps_and_waits_longer_after_each_failure() {
        let mut ladder = Ladder::on(3);
        for _ in 0..PROBE_FIRST {
            assert!(!ladder.probes());
            ladder = ladder.after_step(Some(0.3));
        }
        assert!(ladder.probes());
        // A ratio at or above PROBE_BELOW starts the count again; no estimate leaves it.
        assert!(!ladder.after_step(Some(PROBE_BELOW)).probes());
        assert!(ladder.after_step(None).probes());
        // A kept probe keeps the wait; a refinement soon after it doubles the wait, one after the
        // probe was confirmed by calm steps starts over; quiet growth starts over.
        let kept = ladder.after_kept_probe(2);
        assert_eq!(
            (kept.level, kept.probe_after, kept.calm_steps),
            (2, PROBE_FIRST, 0)
        );
        let refined = kept.after_refinement(3);
        assert_eq!((refined.level, refined.probe_after), (3, 2 * PROBE_FIRST));
        let mut confirmed = kept;
        for _ in 0..PROBE_FIRST {
            confirmed = confirmed.after_step(Some(0.3));
        }
        assert!(!confirmed.probed);
        assert_eq!(confirmed.after_refinement(3).probe_after, PROBE_FIRST);
        assert_eq!(Ladder::on(2).probe_after, PROBE_FIRST);
        // Quiet growth is at once while nothing failed; the rung it reaches is unconfirmed, and
        // a refinement from it makes the next growth wait.
        let fresh = Ladder::on(3);
        assert!(fresh.may_grow());
        let grown = fresh.after_growth(2);
        assert!(grown.probed && grown.probe_after == PROBE_FIRST);
        // A failure on it goes back to the rung it grew from, however far the ratio would ask;
        // on a confirmed rung the ratio decides.
        assert_eq!(grown.redo_level(2, 2, 2.31, MAX_LEVEL), 3);
        assert_eq!(
            fresh.redo_level(3, 3, 2.31, MAX_LEVEL),
            finer_level(3, 2.31, MAX_LEVEL)
        );
        // Rungs longer than the communication step take it whole: the refinement counts from
        // the rung of the step taken.
        assert_eq!(level_of_step(0.5, 2e-3), 7);
        assert_eq!(level_of_step(2e-3, 2e-3), 0);
        assert_eq!(level_of_step(2e-3, 1e-3), 1);
        assert_eq!(level_of_step(2e-3, 2e-3 / 3.0), 1);
        assert_eq!(level_of_step(1.0, 1e-9), MAX_LEVEL);
        assert_eq!(fresh.redo_level(0, 7, 2.31, MAX_LEVEL), 9);
        assert_eq!(fresh.redo_level(0, 4, 2.31, MAX_LEVEL), 6);
        // An unconfirmed rung above rungs that take the same steps: from the step taken.
        assert_eq!(grown.redo_level(2, 5, 2.31, MAX_LEVEL), 6);
        // `internal_steps` splits a step within 1e-9 of a rung as that rung.
        assert_eq!(level_of_step(2e-3, 1e-3 * (1.0 + 5e-10)), 1);
        assert_eq!(level_of_step(2e-3, 1e-3 * (1.0 - 5e-10)), 1);
        assert_eq!(finer_level(3, 2.31, MAX_LEVEL), 5);
        let mut back = grown.after_refinement(3);
        assert_eq!(back.probe_after, 2 * PROBE_FIRST);
        for _ in 0..PROBE_FIRST {
            assert!(!back.may_grow());
            back = back.after_step(Some(0.01));
        }
        assert!(back.may_grow());
        let mut waits = Vec::new();
        for _ in 0..8 {
            ladder = ladder.after_failed_probe();
            waits.push(ladder.probe_after);
        }
        assert_eq!(waits, [16, 32, 64, 128, 256, 256, 256, 256]);
        assert_eq!(ladder.level, 3);
        // The top rung has nothing above it.
        let mut top = Ladder::on(0);
        for _ in 0..2 * PROBE_LAST {
            top = top.after_step(Some(0.0));
        }
        assert!(!top.probes());
    }

    #[test]
    fn the_ringing_window_holds_the_first_eight_internal_steps() {
        // After a sampled jump the steps with 0..7 steps before them are in it, the ninth not.
        assert!(within_ringing(0, 0) && within_ringing(0, MOTION_RINGING_STEPS as usize - 1));
        assert!(!within_ringing(0, MOTION_RINGING_STEPS as usize));
        assert!(within_ringing(5, 2) && !within_ringing(5, 3));
        // A motion that is not sampled starts the count at the window's end.
        assert!(!within_ringing(MOTION_RINGING_STEPS, 0));
    }

    #[test]
    fn rungs_halve() {
        assert_eq!(rung(1e-2, 0), 1e-2);
        assert_eq!(rung(1e-2, 3), 1.25e-3);
    }
}
