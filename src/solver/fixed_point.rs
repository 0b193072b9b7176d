//! The fixed-point (simplified Newton) iteration shared by the implicit schemes: when it stops,
//! and how a correction is mixed with Anderson's history.
//!
//! Each scheme iterates `z_{k+1} = z_k + g_k`, `g_k = −P⁻¹ r(z_k)` with its constant iteration
//! matrix `P` (generalized-α: positions and multipliers; Radau IIA: the stage increments and
//! stage multipliers). With `Δ_k = ‖g_k‖_∞` over the position entries, the iteration
//!
//! - is converged when `Δ_k ≤ tol`, or (generalized-α; not Radau IIA, see
//!   [`Convergence::correction_only`]) when the error estimate of a linearly converging
//!   iteration, `θ/(1−θ) Δ_k` with `θ = Δ_k/Δ_{k−1}` ([`error_ratio`]), is `≤ tol`; on the
//!   first correction, with the ratio the step before ended with ([`Convergence::carrying`]),
//!   when `η₀ Δ₁ ≤ 0.1 tol` ([`CARRIED_MARGIN`]) and `Δ₁` is within the iteration's own
//!   tolerance where `tol` follows the error control below it;
//! - fails (an [`Error::discard`]) when a correction is not finite, or after the iteration limit;
//! - otherwise replaces the plain `g_k` with Anderson's mixed update ([`super::anderson`]) before
//!   it is applied; the stopping test is decided on the plain correction, which is then the one
//!   applied (the estimate describes it, not the mixed one).

use super::anderson::Anderson;
use super::problem::IterationSettings;
use crate::error::{Error, Result};

/// The largest contraction `θ = ‖Δ_k‖/‖Δ_{k−1}‖` of successive corrections for which the
/// error estimate `η ‖Δ_k‖` ([`error_ratio`]) is trusted (Hairer & Wanner, *Solving ODEs II*, IV.8: the
/// simplified Newton iteration of implicit Runge–Kutta methods stops on this estimate). Above it
/// the iteration runs until the correction itself is below the tolerance.
pub const TRUSTED_CONTRACTION: f64 = 0.5;

/// The error ratio `η = θ/(1−θ)` of a linearly converging iteration with contraction
/// `θ = ‖Δ_k‖/‖Δ_{k−1}‖`: after applying correction `Δ_k` the corrections still to come sum to at
/// most `η ‖Δ_k‖` (infinity when `θ` exceeds [`TRUSTED_CONTRACTION`] or is unknown). With the
/// constant iteration matrix `θ` is small (the rotation of the frame over a step: 1e-4 to 1e-6 on
/// B1), so `η ‖Δ_k‖ ≤ tol` accepts after two iterations a step that the correction alone accepts
/// after three, with an estimated error far below the tolerance.
pub fn error_ratio(correction: f64, previous_correction: f64) -> f64 {
    let theta = correction / previous_correction;
    if previous_correction.is_finite() && theta.is_finite() && theta <= TRUSTED_CONTRACTION {
        theta / (1.0 - theta)
    } else {
        f64::INFINITY
    }
}

/// The error ratio a step's first correction is judged with, from the ratio `η` its
/// predecessor's iteration ended with (Hairer & Wanner, *Solving ODEs II*, IV.8):
/// `η₀ = max(η, ε)^0.8`, `ε` the machine epsilon. The power lets a ratio carried over steps
/// that stop on their first correction grow, so that every few steps a second correction
/// measures it again (1e-6 grows past 1e-2 in five steps).
pub fn carried_error_ratio(previous: f64) -> f64 {
    previous.max(f64::EPSILON).powf(CARRIED_GROWTH)
}

/// See [`carried_error_ratio`].
pub const CARRIED_GROWTH: f64 = 0.8;

/// A first correction `Δ₁` judged with the carried ratio `η₀` ([`carried_error_ratio`]) stops
/// the iteration when `η₀ Δ₁ ≤ CARRIED_MARGIN × tol` (and `Δ₁` is within the own tolerance,
/// [`IterationSettings::carried_below`]): the carried ratio predicts this step's contraction,
/// which the load or the motion may have changed since (docs/formulation.md, "The stopping
/// rule").
pub const CARRIED_MARGIN: f64 = 0.1;

/// `max(largest, ‖dx‖_∞)`, or infinity if an entry of `dx` is not finite: a non-finite
/// correction never counts as converged (`f64::max` would drop a NaN).
pub fn largest_correction(largest: f64, dx: &[f64]) -> f64 {
    // One pass: the largest magnitude, and whether any entry is not finite (`|v| ≤ ∞` fails
    // for a NaN only; an infinity is caught by the comparison with `f64::MAX`).
    let (mut m, mut finite) = (largest, true);
    for v in dx {
        let a = v.abs();
        finite &= a <= f64::MAX;
        m = if a > m { a } else { m };
    }
    if finite {
        m
    } else {
        f64::INFINITY
    }
}

/// The stopping rule of one step's iteration: it remembers the previous correction.
#[derive(Debug, Clone, Copy)]
pub struct Convergence {
    /// Names the scheme in messages (`""` or e.g. `"radauIIA "`).
    scheme: &'static str,
    settings: IterationSettings,
    /// The step's end time and size, for messages.
    time: f64,
    step_size: f64,
    /// The largest position correction of the last iteration (∞ before the first).
    last_correction: f64,
    /// Whether the estimate `η ‖Δ_k‖` ([`error_ratio`]) may accept an iterate (see
    /// [`Self::correction_only`]).
    trust_estimate: bool,
    /// The error ratio `η` ([`error_ratio`]) of the last iteration, or before the second the
    /// one carried from the previous step ([`carried_error_ratio`]; infinity: none).
    ratio: f64,
    /// The ratio to carry to the next step ([`Self::error_ratio`]): the second correction's
    /// against the first, both plain (Anderson's mixing starts with the second update), or
    /// before the second the one carried.
    carry: f64,
    /// Corrections judged so far.
    corrections: u32,
}

impl Convergence {
    /// A fresh iteration of the step of size `h` to time `time`.
    pub fn new(
        scheme: &'static str,
        settings: &IterationSettings,
        time: f64,
        h: f64,
    ) -> Convergence {
        Convergence {
            scheme,
            settings: *settings,
            time,
            step_size: h,
            last_correction: f64::INFINITY,
            trust_estimate: true,
            ratio: f64::INFINITY,
            carry: f64::INFINITY,
            corrections: 0,
        }
    }

    /// The same tracker judging the first correction with the error ratio `previous` that
    /// the step before ended with ([`Self::error_ratio`]), grown by [`carried_error_ratio`]:
    /// a step whose iteration contracts as its predecessor's stops on its first correction
    /// `Δ₁` when `η₀ Δ₁ ≤` [`CARRIED_MARGIN`] `× tol` and `Δ₁ ≤`
    /// [`IterationSettings::carried_below`]. Infinity (a new step size or model, no step yet)
    /// carries nothing.
    pub fn carrying(mut self, previous: f64) -> Convergence {
        self.ratio = carried_error_ratio(previous);
        self.carry = self.ratio;
        self
    }

    /// The error ratio `η` to carry to the next step: the second correction's against the
    /// first (a later one's contraction is that of Anderson's mixed iterates), or if the step
    /// stopped on its first correction the one it was judged with.
    pub fn error_ratio(&self) -> f64 {
        self.carry
    }

    /// The same tracker accepting on the correction alone (`Δ_k ≤ tol`), never on the estimate.
    /// Radau IIA uses it: there the ratio `Δ_2/Δ_1` of its first two corrections (the first
    /// mostly the predictor's error in the smooth motion) understates the contraction of what is
    /// left, so that the estimate accepted iterates whose error accumulated far above the
    /// tolerance (the pinned pendulum of `tests/radau.rs` at tolerance 1e-13 m: 2.4e-11 to
    /// 3.4e-11 m against the truncation error 5.1e-12 m at h = 8 ms, whatever the tolerance down
    /// to 1e-15 m).
    pub fn correction_only(mut self) -> Convergence {
        self.trust_estimate = false;
        self
    }

    /// Judges an iteration whose plain correction has the largest position entry `largest`
    /// ([`largest_correction`]): `Ok(true)` when converged (the correction or `η` times it,
    /// [`error_ratio`], is within the tolerance), `Ok(false)` when the iteration goes on, a
    /// discard when the correction is not finite.
    pub fn converged(&mut self, largest: f64) -> Result<bool> {
        if !largest.is_finite() {
            return Err(Error::discard(format!(
                "{}step to t = {} (h = {}): the iteration produced a non-finite correction",
                self.scheme, self.time, self.step_size
            )));
        }
        let tolerance = self.settings.absolute_tolerance;
        self.corrections += 1;
        if self.corrections > 1 {
            self.ratio = error_ratio(largest, self.last_correction);
            if self.corrections == 2 {
                self.carry = self.ratio;
            }
        }
        // A ratio measured in this step's iteration judges its correction as it is; one carried
        // from the step before is a prediction: it judges a first correction with a margin, and
        // only one the plain test would pass at `carried_below`.
        let estimated = if self.corrections > 1 {
            self.ratio * largest <= tolerance
        } else {
            largest <= self.settings.carried_below
                && self.ratio * largest <= CARRIED_MARGIN * tolerance
        };
        let converged = largest <= tolerance || (self.trust_estimate && estimated);
        self.last_correction = largest;
        Ok(converged)
    }

    /// The largest position correction of the last iteration (m).
    pub fn last_correction(&self) -> f64 {
        self.last_correction
    }

    /// The discard after `settings.max_iterations` iterations without convergence.
    pub fn failure(&self) -> Error {
        Error::discard(format!(
            "{}step to t = {} (h = {}) did not converge in {} iterations (last position correction {:.3e} m, tolerance {:.3e} m)",
            self.scheme,
            self.time,
            self.step_size,
            self.settings.max_iterations,
            self.last_correction,
            self.settings.absolute_tolerance
        ))
    }
}

/// Replaces the plain update `g` at the iterate `z` with Anderson's mixed one unless the
/// iteration `converged` (then the plain correction, which the stopping test judged, is applied).
pub fn mix_update(anderson: &mut Anderson, converged: bool, z: &[f64], g: &mut [f64]) {
    if !converged {
        anderson.accelerate(z, g);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_ratio_of_a_contraction() {
        // x_{k+1} = θ x_k: after a correction Δ the corrections still to come sum to
        // θ/(1−θ) Δ exactly.
        let theta: f64 = 0.1;
        let corrections: Vec<f64> = (0..6).map(|k| theta.powi(k)).collect();
        for k in 1..5 {
            let still_to_come: f64 =
                corrections[k + 1..].iter().sum::<f64>() + theta.powi(6) / (1.0 - theta); // the tail beyond the sample
            let estimate = error_ratio(corrections[k], corrections[k - 1]) * corrections[k];
            assert!(
                (estimate - still_to_come).abs() <= 1e-12 * still_to_come,
                "{estimate} {still_to_come}"
            );
        }
        // No estimate from the first correction, a slow or a diverging iteration.
        assert_eq!(error_ratio(1e-3, f64::INFINITY), f64::INFINITY);
        assert_eq!(error_ratio(0.6, 1.0), f64::INFINITY);
        assert_eq!(error_ratio(2.0, 1.0), f64::INFINITY);
        assert_eq!(error_ratio(f64::NAN, 1.0), f64::INFINITY);
    }

    #[test]
    fn a_step_judges_its_first_correction_with_the_ratio_carried_from_the_step_before() {
        // A tolerance of 1e-6 m followed below the own 1e-2 m.
        let settings = IterationSettings {
            absolute_tolerance: 1e-6,
            carried_below: 1e-2,
            max_iterations: 10,
            estimate_error: None,
        };
        // The step before contracted by θ = 1e-6: η₀ = (1e-6/(1 − 1e-6))^0.8 = 1.6e-5, and a
        // first correction of 1e-4 m leaves 1.6e-9 m ≤ 0.1 × 1e-6.
        let eta = 1e-6 / (1.0 - 1e-6);
        let mut c = Convergence::new("", &settings, 1.0, 0.1).carrying(eta);
        assert!(c.converged(1e-4).unwrap());
        let grown = c.error_ratio();
        assert!((grown - eta.powf(0.8)).abs() <= 1e-12 * grown, "{grown}");
        // Carried on over steps that stop at once, it grows until a first correction is no
        // longer enough: two more steps judged with 1.4e-4 and 8.5e-4 (a correction of 1e-4 m
        // leaves 8.5e-8 m), then 3.5e-3 (3.5e-7 m: not).
        let mut steps = 1;
        let mut ratio = grown;
        loop {
            let mut c = Convergence::new("", &settings, 1.0, 0.1).carrying(ratio);
            if !c.converged(1e-4).unwrap() {
                // The second correction measures the contraction again: θ = 1e-4.
                assert!(c.converged(1e-8).unwrap());
                let measured = c.error_ratio();
                assert!((measured - 1e-4 / (1.0 - 1e-4)).abs() <= 1e-12 * measured);
                break;
            }
            ratio = c.error_ratio();
            steps += 1;
        }
        assert_eq!(steps, 3);
        // A first correction above the own tolerance goes on whatever the ratio says; so does
        // one with nothing carried (a new step size or model), and Radau IIA's.
        let mut c = Convergence::new("", &settings, 1.0, 0.1).carrying(eta);
        assert!(!c.converged(2e-2).unwrap());
        let mut c = Convergence::new("", &settings, 1.0, 0.1).carrying(f64::INFINITY);
        assert!(!c.converged(1e-4).unwrap());
        let mut c = Convergence::new("radauIIA ", &settings, 1.0, 0.1)
            .correction_only()
            .carrying(eta);
        assert!(!c.converged(1e-4).unwrap());
        // What is carried on is the second correction's ratio to the first: a third one's is
        // that of Anderson's mixed iterates.
        let mut c = Convergence::new("", &settings, 1.0, 0.1).carrying(f64::INFINITY);
        assert!(!c.converged(1.0).unwrap());
        assert!(!c.converged(0.1).unwrap());
        assert!(c.converged(1e-7).unwrap());
        assert!(
            (c.error_ratio() - 0.1 / 0.9).abs() <= 1e-12,
            "{}",
            c.error_ratio()
        );
        // Without a followed tolerance (`carried_below` 0) the plain test alone.
        let plain = IterationSettings {
            carried_below: 0.0,
            ..settings
        };
        let mut c = Convergence::new("", &plain, 1.0, 0.1).carrying(eta);
        assert!(!c.converged(1e-4).unwrap());
    }

    #[test]
    fn convergence_stops_on_the_estimate_and_refuses_non_finite_corrections() {
        let settings = IterationSettings {
            absolute_tolerance: 1e-6,
            carried_below: 0.0,
            max_iterations: 10,
            estimate_error: None,
        };
        let mut c = Convergence::new("", &settings, 1.0, 0.1);
        // First correction above the tolerance: no estimate yet.
        assert!(!c.converged(1e-3).unwrap());
        // θ = 1.5e-3: the estimate 2.3e-9 m is within the tolerance, the correction is not.
        assert!(c.converged(1.5e-6).unwrap());
        assert_eq!(c.last_correction(), 1.5e-6);
        let mut c = Convergence::new("radauIIA ", &settings, 1.0, 0.1);
        assert!(!c.converged(1e-2).unwrap());
        assert!(c.converged(2e-6).unwrap(), "θ = 2e-4: estimate 4e-10 m");
        let e = c.converged(f64::INFINITY).unwrap_err();
        assert_eq!(e.kind, crate::ErrorKind::Discard);
        assert!(
            e.message.contains("radauIIA step to t = 1"),
            "{}",
            e.message
        );
        // Radau's tracker accepts on the correction alone.
        let mut c = Convergence::new("", &settings, 1.0, 0.1).correction_only();
        assert!(!c.converged(1e-2).unwrap());
        assert!(!c.converged(2e-6).unwrap());
        assert!(c.converged(1e-6).unwrap());
        assert_eq!(largest_correction(0.0, &[1.0, f64::NAN]), f64::INFINITY);
        assert_eq!(largest_correction(0.5, &[-2.0, 1.0]), 2.0);
    }
}
