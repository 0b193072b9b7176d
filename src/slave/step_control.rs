//! `model.accuracy`: the internal step chosen by the time integration error (docs/formulation.md,
//! "Time error control").
//!
//! Every internal step of generalized-α estimates its local error `e` (m, mass-weighted RMS,
//! `generalized_alpha::IterationMatrix::local_error`). The step is accepted when
//!
//! ```text
//! e ≤ allowance(h) = max(ε D h / T₁,  ITERATION_NOISE × solver.tolerance × size)
//! ```
//!
//! with `ε = model.accuracy`, `D` the deformation scale (the largest mass-weighted RMS elastic
//! displacement `√(ūᵀ M ū / m)` seen so far, m) and `T₁ = 2π/ω₁` the period of the body's lowest
//! natural frequency: the errors committed over one period of the lowest mode add up to at most
//! `ε D`. The floor is above the iteration's own error: the estimate differences accelerations
//! of converged iterates, each off by up to `solver.tolerance × size` in position, which puts a
//! noise of `(β − 1/6)/β` of that into `e` whatever `h` is; asking the time step for less would
//! refine it down the whole ladder for nothing.
//!
//! The internal step lives on a ladder of rungs `h_k = solver.stepSize / 2^k`, `k ≤`
//! [`MAX_LEVEL`] (a communication step is split into equal internal steps no longer than the
//! rung). A communication step in which some internal step exceeds its allowance is redone from
//! its start on a finer rung (the local error is third order in `h` and the allowance first
//! order: the ratio falls like `h²`); one that stayed below [`GROW_BELOW`] moves one rung up for
//! the next. Steps on a rung seen before reuse its factorization (`MATRIX_CACHE_SIZE`).

/// The floor of the allowance in units of the iteration's tolerance `solver.tolerance × size`:
/// the estimate's noise from the iteration is below 0.4 of that (see the module documentation).
pub const ITERATION_NOISE: f64 = 10.0;

/// Finest rung: `solver.stepSize / 2^MAX_LEVEL`.
pub const MAX_LEVEL: u32 = 8;

/// A communication step whose largest `e / allowance` stayed below this moves one rung up (a
/// doubled step multiplies the ratio by about 4: it lands below 1/2 of the allowance).
pub const GROW_BELOW: f64 = 0.125;

/// The order of `e / allowance` in `h` (local error `h³` against an allowance `∝ h`).
pub const RATIO_ORDER: f64 = 2.0;

/// The internal step of rung `level`: `step_size / 2^level` (s).
pub fn rung(step_size: f64, level: u32) -> f64 {
    step_size / f64::from(1u32 << level)
}

/// The rung after a rejected communication step whose largest `e / allowance` was `ratio` (> 1):
/// far enough down that the ratio falls below 1/2, at least one rung, at most [`MAX_LEVEL`].
pub fn finer_level(level: u32, ratio: f64) -> u32 {
    let rungs = ((2.0 * ratio).log2() / RATIO_ORDER).ceil().max(1.0);
    (level + rungs.min(MAX_LEVEL as f64) as u32).min(MAX_LEVEL)
}

/// The allowance of an internal step `h` (m): `max(ε D h / T₁, floor)`.
pub fn allowance(accuracy: f64, scale: f64, h: f64, period: f64, floor: f64) -> f64 {
    (accuracy * scale * h / period).max(floor)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_finer_rung_brings_the_ratio_below_one_half() {
        // The ratio falls like h²: 4 per rung.
        for &(ratio, expected) in &[(1.01, 1), (1.9, 1), (2.1, 2), (7.9, 2), (8.1, 3), (1e9, 8)] {
            let level = finer_level(0, ratio);
            assert_eq!(level, expected, "ratio {ratio}");
            if level < MAX_LEVEL {
                assert!(ratio / 4f64.powi(level as i32) < 0.5);
            }
        }
        assert_eq!(finer_level(MAX_LEVEL - 1, 100.0), MAX_LEVEL);
    }

    #[test]
    fn rungs_halve() {
        assert_eq!(rung(1e-2, 0), 1e-2);
        assert_eq!(rung(1e-2, 3), 1.25e-3);
    }
}
