//! The internal steps of a communication step: each with its retries at halved steps, the
//! loads and driving motion at its end, and the error estimate where the error control asks
//! for one (docs/formulation.md, "Time error control").

use super::super::interfaces::{apply_loads, prescribe_motion};
use super::super::step_control::{
    above_resolution, allowance, error_ratio, within_ringing, FOLLOWING_TOLERANCE_FLOOR,
    GROW_BELOW, ITERATION_NOISE,
};
use super::super::{LogEvent, Slave};
use super::MAX_STEP_HALVINGS;
use crate::body::lowest_modes::LowestModes;
use crate::error::{Error, ErrorKind, Result};
use crate::model::category;
use crate::solver::problem::{DynamicState, IterationSettings, StepProblem};
use crate::solver::radau::RadauProblem;
use nalgebra::Vector3;

impl Slave {
    /// Internal step `i` of `n` (of length `h`) of the communication step from `t0` by `big_h`.
    /// If it does not converge it is redone as 2, 4, ... 2^[`MAX_STEP_HALVINGS`] steps (each
    /// halving logged under `logEvents`); the error of the last attempt is returned if none
    /// converges, with the state back at the start of this internal step. No allocation unless
    /// a step fails.
    pub(in crate::slave) fn internal_step(
        &mut self,
        t0: f64,
        big_h: f64,
        i: usize,
        n: usize,
        h: f64,
    ) -> Result<()> {
        let tau0 = i as f64 * h;
        let mut depth = 0;
        loop {
            let m = 1usize << depth;
            let hs = h / m as f64;
            self.prepare_step_size(hs)?;
            if depth > 0 {
                let state = &self.dynamics.as_ref().unwrap().state;
                self.retry_backup
                    .get_or_insert_with(|| state.clone())
                    .copy_from(state);
            }
            let result = self.advance(t0, big_h, tau0, (h, hs), m, i + 1 == n);
            let e = match result {
                Ok(()) => return Ok(()),
                Err(e) => e,
            };
            if depth > 0 {
                let state = &mut self.dynamics.as_mut().unwrap().state;
                state.copy_from(self.retry_backup.as_ref().unwrap());
            }
            if e.kind != ErrorKind::Discard {
                return Err(e);
            }
            if depth == MAX_STEP_HALVINGS {
                return Err(Error::discard(format!(
                    "the internal step from t = {} (h = {h:e}) did not converge, nor when retried with {m} steps of h/{m} = {hs:e}: {}",
                    t0 + tau0,
                    e.message
                )));
            }
            depth += 1;
            self.retries += 1;
            self.events.push(LogEvent {
                category: category::EVENTS,
                message: format!(
                    "internal step from t = {} (h = {hs:e}) did not converge ({}); retrying it as {} steps of {:e} s",
                    t0 + tau0,
                    e.message,
                    1usize << depth,
                    h / (1usize << depth) as f64
                ),
            });
        }
    }

    /// `m` internal steps of `hs` (prepared), from `tau0` after the
    /// communication point `t0`. Force inputs are taken at each internal step's end,
    /// `u(t0 + τ) = u + u'·τ + u''·τ²/2` (the generalized-α scheme here satisfies the equations
    /// of motion at the end of each internal step, so this is where the load enters); the last
    /// internal step of the communication step uses `τ = big_h` exactly.
    #[allow(clippy::too_many_arguments)]
    pub(in crate::slave) fn advance(
        &mut self,
        t0: f64,
        big_h: f64,
        tau0: f64,
        (rung, hs): (f64, f64),
        m: usize,
        last_of_step: bool,
    ) -> Result<()> {
        let controlled = self.error_controlled();
        let horizon = self.error_horizon();
        let accuracy = self.parameters.accuracy;
        let own_tolerance = self.parameters.iteration_tolerance();
        // Past the first period, or on a body without supports with the deformation scale
        // settled (while it still grows from 0, the floor is what the control needs), at the
        // start of these internal steps:
        // one test for the following tolerance and the floor's warning.
        let scale_established = self.scale_established();
        // The rung's tolerance, also for a retry in smaller steps (a retry is for an iteration
        // that did not converge, which a tighter tolerance would not help).
        let tolerance = scale_established
            .then(|| self.following_tolerance(rung))
            .flatten()
            .unwrap_or(own_tolerance);
        let floor = tolerance * self.size;
        if tolerance < own_tolerance && !self.tolerance_followed {
            self.tolerance_followed = true;
            self.events.push(LogEvent {
                category: category::EVENTS,
                message: format!(
                    "the iteration's tolerance follows model.accuracy from t = {:.6}: {tolerance:.3e} × size with internal steps of {hs:e} s, below the accuracy's own {own_tolerance:e}, whose floor {ITERATION_NOISE} × tolerance × size would pass their errors (the tolerance goes with the allowance of each internal step)",
                    t0 + tau0
                ),
            });
        }
        let mut settings = IterationSettings {
            absolute_tolerance: floor,
            carried_below: if tolerance < own_tolerance {
                own_tolerance * self.size
            } else {
                0.0
            },
            max_iterations: self.parameters.max_iterations.max(1) as usize,
            estimate_error: None,
        };
        let jumped = self.inputs_jumped;
        // Internal steps since a motion input's jump before this call's first (within a
        // communication step counted in this attempt's steps, `hs`, halved on a retry; across
        // communication steps in the accepted attempt's).
        let since_motion_jump = self.since_motion_jump;
        let ringing =
            |j: usize| within_ringing(since_motion_jump, (tau0 / hs).round() as usize + j);
        // The allowance of these internal steps, from the deformation scale (updated after
        // each step that is estimated, and at the end of each communication step).
        let noise = (ITERATION_NOISE * floor).max(self.dynamics.as_ref().unwrap().estimate_floor);
        let allowed = |scale: f64| match (controlled, horizon) {
            (true, Some(horizon)) => allowance(accuracy, scale, hs, horizon, noise),
            _ => f64::INFINITY,
        };
        let model = self.model.as_mut().expect("the model exists during a step");
        let dynamics = self.dynamics.as_mut().unwrap();
        let gravity = Vector3::from(self.parameters.gravity);
        let interfaces = &self.interfaces;
        let inputs = &self.inputs;
        let derivatives = &self.input_derivatives;
        let ages = &self.input_ages;
        let tau = std::cell::Cell::new(tau0);
        let body = &model.body;
        let loads = |x: &[f64], f: &mut [f64]| {
            apply_loads(
                body,
                interfaces,
                inputs,
                Some((derivatives, ages, tau.get())),
                &gravity,
                x,
                f,
            )
        };
        let driving = &self.driving;
        let prescribe = |t: f64, state: &mut DynamicState| {
            prescribe_motion(body, interfaces, driving, t, state)
        };
        let problem = StepProblem {
            body,
            free: &model.free,
            loads: &loads,
            prescribe: &prescribe,
        };
        // Radau's stages sit inside the step: its loads take the time.
        let timed_loads = |t: f64, x: &[f64], f: &mut [f64]| {
            tau.set(t - t0);
            loads(x, f)
        };
        let radau_problem = RadauProblem {
            body,
            free: &model.free,
            loads: &timed_loads,
            prescribe: &prescribe,
        };
        for j in 0..m {
            let last = last_of_step && j + 1 == m;
            tau.set(if last {
                big_h
            } else {
                tau0 + (j + 1) as f64 * hs
            });
            // The error is estimated on the first internal step of a communication step (where
            // the inputs jump) and on the last (where the outputs are read): docs/formulation.md,
            // "Time error control".
            let first = tau0 == 0.0 && j == 0;
            settings.estimate_error =
                (controlled && (last || first) && !(first && jumped) && !ringing(j)).then_some(
                    GROW_BELOW * allowed(dynamics.deformation_scale) / std::f64::consts::SQRT_2,
                );
            let report = model.integrator.step(
                &problem,
                &radau_problem,
                &settings,
                hs,
                &mut dynamics.state,
                &mut model.forces,
            )?;
            self.statistics.0 += 1;
            self.statistics.1 += report.iterations as u64;
            if let Some(e) = report.error_estimate {
                // The scales take the deformation this step reached (docs/formulation.md, "Time
                // error control"): a load applied at its start has deformed the body by now.
                let modes = model
                    .lowest_modes
                    .as_ref()
                    .expect("error control has the modes");
                observe_deformation(
                    body,
                    &model.free,
                    modes,
                    &mut model.forces,
                    &mut self.scale_scratch,
                    dynamics,
                );
                let rotation = body
                    .frame_weights
                    .best_fit(&dynamics.state.position)
                    .rotation;
                let d = model
                    .integrator
                    .local_error_field()
                    .expect("generalized-α estimated");
                let horizon = horizon.expect("controlled");
                let (low, high) = modes.lasting_error(&rotation, d, e, horizon);
                // What the accuracy alone allows this step (m), and the ratio above `floor` (m):
                // with the iteration's, and without it (with the learnt estimate floor).
                let accuracy_allows =
                    allowance(accuracy, dynamics.deformation_scale, hs, horizon, 0.0);
                let ratio_above = |floor: f64| {
                    error_ratio(
                        low,
                        high,
                        dynamics.high_mode_scale,
                        accuracy * dynamics.deformation_scale,
                        accuracy_allows,
                        floor,
                    )
                };
                let ratio = ratio_above(noise);
                let unfloored = ratio_above(dynamics.estimate_floor);
                self.step_error_unfloored = self.step_error_unfloored.max(unfloored);
                let judged_on_floor = ratio <= 1.0 && unfloored > 1.0;
                // The iteration's tolerance, not the accuracy, passed this step even at the
                // round-off's tolerance (docs/formulation.md, "Time error control": the
                // iteration's tolerance). While the deformation scale is still building up from
                // 0, a floor there is the one it needs.
                if judged_on_floor
                    && !self.floor_warned
                    && dynamics.estimate_floor < ITERATION_NOISE * floor
                    && scale_established
                {
                    self.floor_warned = true;
                    self.events.push(LogEvent {
                        category: category::EVENTS,
                        message: format!(
                            "warning: model.accuracy: at t = {:.6} an internal step of {hs:e} s was accepted on the iteration's floor, {ITERATION_NOISE} × tolerance × size = {:.3e} m, where model.accuracy allows {accuracy_allows:.3e} m: {}",
                            dynamics.state.time,
                            ITERATION_NOISE * floor,
                            if tolerance <= FOLLOWING_TOLERANCE_FLOOR {
                                format!("the iteration's tolerance is at its floor, {tolerance:e} (× size), below which the time error is not controlled")
                            } else {
                                format!("below the iteration's tolerance ({tolerance:e}) the time error is not controlled; solver.tolerance = {:.1e} would let the control go on", accuracy_allows / (2.0 * ITERATION_NOISE * self.size))
                            }
                        ),
                    });
                }
                self.step_estimate = self.step_estimate.max(e);
                self.step_error = Some(self.step_error.unwrap_or(0.0).max(ratio));
            }
        }
        Ok(())
    }
}

impl Slave {
    /// The iteration's relative tolerance (× size) where it follows the allowance of internal
    /// steps of `hs` (s): `allowance / (2 × ITERATION_NOISE × size)`, not below
    /// [`FOLLOWING_TOLERANCE_FLOOR`], where that is below the accuracy's own
    /// ([`Parameters::iteration_tolerance`](super::super::parameters::Parameters::iteration_tolerance));
    /// taken once the deformation scale is established ([`Self::scale_established`];
    /// docs/formulation.md, "Time error control": the iteration's tolerance). `None`: the
    /// accuracy's own tolerance holds (no error control, or an allowance above its floor).
    fn following_tolerance(&self, hs: f64) -> Option<f64> {
        let dynamics = self.dynamics.as_ref()?;
        let horizon = self.error_horizon()?;
        if !self.error_controlled() {
            return None;
        }
        // A deformation within `FOLLOW_ABOVE` of the iteration's own tolerances is at its
        // resolution: the floor stands (a nearly rigid pendulum, `D` 1e-8 of its size).
        let own = self.parameters.iteration_tolerance();
        if !above_resolution(
            self.parameters.accuracy,
            dynamics.deformation_scale,
            own,
            self.size,
        ) {
            return None;
        }
        let allows = allowance(
            self.parameters.accuracy,
            dynamics.deformation_scale,
            hs,
            horizon,
            0.0,
        );
        let tolerance =
            (allows / (2.0 * ITERATION_NOISE * self.size)).max(FOLLOWING_TOLERANCE_FLOOR);
        (tolerance < own).then_some(tolerance)
    }

    /// Whether the deformation scale is established: the body's time is past the first period
    /// `T₁` of its lowest mode since the start, or, on a body without supports (whose scale is
    /// the RMS of its local field itself), the scale has settled
    /// ([`ScaleSettling`](super::super::step_control::ScaleSettling)) (with the error control;
    /// docs/formulation.md, "Time error control": the iteration's tolerance).
    pub(super) fn scale_established(&self) -> bool {
        match (
            self.model.as_ref().and_then(|m| m.lowest_modes.as_ref()),
            self.dynamics.as_ref(),
        ) {
            (Some(modes), Some(dynamics)) => {
                (dynamics.scale_settling.settled && modes.without_supports())
                    || dynamics.state.time - self.start_time > modes.first_period()
            }
            _ => false,
        }
    }
}

/// The scales of the error control (docs/formulation.md, "Time error control") after a step:
/// `D` and `A` grow to the elastic displacement relative to the supports of the state the last
/// residual was evaluated at, and to its part above the lowest modes
/// ([`LowestModes::deformation`]; on a body without supports, no more than the RMS of `ū` by the
/// free DOFs' mass `free.mass`, [`LowestModes::free_body_rms`]); `y` is scratch of `3N`. No
/// allocation.
pub(super) fn observe_deformation(
    body: &crate::body::Body,
    free: &crate::solver::problem::FreeNodes,
    modes: &LowestModes,
    forces: &mut crate::solver::problem::ResidualWorkspace,
    y: &mut [f64],
    dynamics: &mut super::super::Dynamics,
) {
    // With patches the strain energy is theirs: the one frame's `ūᵀ K ū` holds its own
    // spurious strain of the slabs' turns (`θ²/2`, axial), an energy in the stiff modes that
    // the body does not have, which made the modes above the lowest look large enough to
    // control (docs/formulation.md, "Time error control"). The lowest modes' part still comes
    // from the one frame's `K ū`, projected as `(K φ_j)ᵀ ū` without the product: a bound of
    // mixed origin, the rest taken as 0 where that part exceeds the frames' energy.
    let scratch = forces.completed_force_scratch(body);
    let patch_energy = body.patches.as_ref().map(|_| 2.0 * scratch.strain_energy());
    let projected = patch_energy.and_then(|e| modes.deformation_of(e, scratch.local_deformation()));
    let (low, above) = projected.unwrap_or_else(|| {
        let elastic_force = body.local_elastic_force(scratch, y);
        let energy = patch_energy
            .unwrap_or_else(|| crate::linalg::dot(scratch.local_deformation(), elastic_force));
        modes.deformation(energy, elastic_force)
    });
    // On a body without supports `ū` is the elastic displacement itself, and the energy's bound
    // of the part above the lowest modes (`E/ω_top²`) can be far above it: a deformation far
    // above `ω_top` (a free beam's stretch under its spin) carries its energy in few metres.
    let above = modes
        .free_body_rms(&free.mass, scratch.local_deformation())
        .map_or(above, |rms| {
            above.min((rms * rms - low * low).max(0.0).sqrt())
        });
    dynamics.deformation_scale = dynamics.deformation_scale.max(low.hypot(above));
    dynamics.high_mode_scale = dynamics.high_mode_scale.max(above);
}
