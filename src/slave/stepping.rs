//! `fmi2DoStep`: a communication step as internal steps, with halving retries and rollback.

use super::auto_features::{
    carry_over_to_slabs, choose_driven_stiffening, choose_features, choose_slab_stiffening,
    linear_reach_exceeded, SlabStiffeningSwitch, LINEAR_AT, NOT_QUIET,
};
use super::interfaces::extrapolate;
use super::step_control::{
    above_resolution, finest_level, level_of_step, rung, within_ringing, Ladder, GROW_BELOW,
    MOTION_RINGING_STEPS, NOISE_MARGIN,
};
use super::{LogEvent, Slave};
use crate::body::stiffening::driven_inertial_coefficients;
use crate::error::{Error, ErrorKind, Result};
use crate::model::category;
use internal_steps::observe_deformation;
use step_start::StepStart;

mod internal_steps;
mod run_warnings;
mod step_start;

/// How often an internal step that did not converge is retried with halved internal steps
/// (2, 4, ..., 2^MAX_STEP_HALVINGS steps in its place) before the communication step is
/// discarded. Smaller steps help the fixed-point iteration: the mass term `M/(βh²)` of the
/// constant iteration matrix grows like `1/h²` and the neglected nonlinear terms do not.
pub const MAX_STEP_HALVINGS: u32 = 3;

impl Slave {
    /// `fmi2DoStep`: advances from `current_communication_point` (must match the internal time
    /// within a relative 1e-5 of the step) by `communication_step_size` > 0, in equal internal
    /// steps no longer than `solver.stepSize`. On error the state is unchanged; a step that does
    /// not converge is an [`ErrorKind::Discard`].
    pub fn do_step(
        &mut self,
        current_communication_point: f64,
        communication_step_size: f64,
    ) -> Result<()> {
        let t_c = current_communication_point;
        self.check_step_request(t_c, communication_step_size)?;
        let big_h = self.snapped_step(communication_step_size);
        // The FMU's own clock, which agrees with the importer's to a few ulps: steps are timed
        // on it (not on `t_c`, which importers compute differently), so that the same inputs
        // give the same bits in every importer.
        let t0 = self.time();
        let controlled = self.error_controlled();
        let mut ladder = self.dynamics.as_ref().unwrap().ladder;
        let slabs_before = self.dynamics.as_ref().unwrap().features.frames;
        self.jacobian_step = None;
        // The driving frames of the last step, put back if this one is rolled back (they tell
        // the next step whether its inputs jump).
        self.driving_before.copy_from_slice(&self.driving);
        let motion_jumped;
        (self.inputs_jumped, motion_jumped) = match self.update_driving_frames() {
            Ok(jumped) => jumped,
            Err(e) => {
                self.driving.copy_from_slice(&self.driving_before);
                return Err(e);
            }
        };
        if motion_jumped {
            // The kink a motion input's jump puts in the held coordinates' path rings for the
            // next internal steps, which are not estimated if the motion is sampled
            // (`MOTION_RINGING_STEPS`).
            ladder.sampled_motion = ladder.since_motion_jump < MOTION_RINGING_STEPS;
            ladder.since_motion_jump = 0;
        }
        self.since_motion_jump = if ladder.sampled_motion {
            ladder.since_motion_jump
        } else {
            MOTION_RINGING_STEPS
        };
        // What a failed step puts back besides the state and the driving frames.
        let before = StepStart::of(self.dynamics.as_ref().unwrap(), self.events.len());
        if self.inputs_jumped {
            // A jump's first correction is larger than the one the carried ratio was measured
            // after, and the iteration's contraction grows with it (docs/formulation.md, "The
            // stopping rule"): measured again.
            self.dynamics.as_mut().unwrap().state.iteration_error_ratio = f64::INFINITY;
        }
        // Whether the backup holds this step's start (an error before it must not restore it).
        let mut backed_up = false;
        // A probe takes this step on the rung above (step_control, "probes"), if the step's
        // last internal step there will be estimated: not the one after an input jump, nor one
        // within a sampled motion's ringing.
        let mut probing = controlled && ladder.probes();
        if probing && (self.inputs_jumped || within_ringing(self.since_motion_jump, 0)) {
            probing = match self.internal_steps(big_h, ladder.level - 1) {
                Ok((n, _)) => {
                    (n > 1 || !self.inputs_jumped) && !within_ringing(self.since_motion_jump, n - 1)
                }
                Err(e) => {
                    return Err(self.roll_back(t_c, communication_step_size, e, &before, false))
                }
            };
        }
        let mut level = ladder.level - u32::from(probing);
        // The finest rung this step may refine to (step_control::finest_level).
        let finest = finest_level(self.scale_established());
        self.step_inputs.copy_from(
            &self.inputs,
            &self.input_derivatives,
            &self.input_ages,
            self.parameters.gravity,
        );
        // Held inputs that jump at a communication point are not restarted from consistent
        // accelerations (`generalized_alpha::restart_for_load_change`): that makes one FMU's
        // ZOH response second order in h, but it destabilised the iterated coupling of two FMUs
        // (tests/python/test_coupling.py: the work on A grew from 2.3e-4 J to 1.1 J at
        // H = 2e-4 s). Input derivatives give continuous loads instead.
        let mut failed_probe = false;
        // The rung, the rung of its internal steps and the error ratio of the first attempt
        // that was refined.
        let mut refined_from: Option<(u32, u32, f64)> = None;
        let mut taken = (0, 0.0);
        // The slabs' carry-over is logged once, not per attempt.
        // Whether model.auto's slabs came on at this communication point (in this attempt).
        let (mut carry_over_logged, mut switch_rings, mut slabs_came_on) = (false, false, false);
        let slab_switch = self.slab_stiffening_switch();
        let result = loop {
            let (n, h) = match self.internal_steps(big_h, level) {
                Ok(step) => step,
                Err(e) => break Err(e),
            };
            taken = (n, h);
            // The rung of the steps taken: coarser rungs than the communication step are its.
            let taken_level = level.max(level_of_step(self.parameters.step_size, h));
            let slab_state = before.features.frames;
            if let Err(e) = self.prepare_step(h, big_h, slab_switch, slab_state) {
                break Err(e);
            }
            backed_up = true;
            let dynamics = self.dynamics.as_mut().unwrap();
            let model = self.model.as_mut().unwrap();
            slabs_came_on = dynamics.features.frames && !slabs_before && model.allowed.frames;
            if slabs_came_on {
                // model.auto's slabs came on at this communication point: the state is carried
                // over to them (each attempt from the backup, which holds the one frame's).
                // A body it cannot carry over (pins, hinges, rigid sets) rings.
                switch_rings = carry_over_to_slabs(
                    model,
                    dynamics,
                    h,
                    before.features,
                    &mut self.scale_scratch,
                    self.parameters.tolerance * self.size,
                    (!carry_over_logged).then_some(&mut self.events),
                )
                .is_none();
                carry_over_logged = true;
                // The slabs' own prestress is that of the state carried over to them. A body
                // it cannot carry over holds the one frame's state: measured at the next step.
                let carried = !switch_rings;
                choose_slab_stiffening(model, dynamics, slab_switch, &mut self.events, carried);
            }
            // With one internal step after an input jump nothing is estimated (see
            // `advance`): the deformation scale is not needed either.
            if controlled && (n > 1 || !self.inputs_jumped) {
                self.load_scale();
            }
            self.step_error = None;
            self.step_error_unfloored = 0.0;
            self.step_estimate = 0.0;
            let mut result = Ok(());
            for i in 0..n {
                result = self.internal_step(t0, big_h, i, n, h);
                let redo = self.step_error.is_some_and(|r| r > 1.0) && taken_level < finest;
                if result.is_err() || redo {
                    break;
                }
            }
            let dynamics = self.dynamics.as_mut().unwrap();
            let auto_slabs =
                dynamics.features.frames && self.model.as_ref().unwrap().allowed.frames;
            if auto_slabs && result.as_ref().is_err_and(|e| e.kind == ErrorKind::Discard) {
                // model.auto's slabs did not converge (switched on at this communication point,
                // or earlier and the body has gone on bending violently): the step is redone
                // with the one frame, for good.
                dynamics.state.copy_from(self.backup.as_ref().unwrap());
                dynamics.features.frames = false;
                dynamics.features.frames_refused = true;
                dynamics.features.slab_stiffening = false;
                dynamics.slab_stiffening_since = None;
                dynamics.state.iteration_error_ratio = f64::INFINITY;
                let model = self.model.as_mut().unwrap();
                model.apply_features(dynamics.features);
                self.events.push(LogEvent {
                    category: category::EVENTS,
                    message: format!(
                        "model.auto: the step from t = {t0} did not converge with the slabs {} ({}); redone with the one co-moving frame, which the body keeps",
                        if slabs_before { "on" } else { "switched on" },
                        result.unwrap_err().message
                    ),
                });
                before.restore_scales(self.dynamics.as_mut().unwrap());
                continue;
            }
            let beyond = (result.is_ok() && self.parameters.decides_linear())
                .then(|| {
                    linear_reach_exceeded(
                        self.model.as_ref().unwrap(),
                        &self.dynamics.as_ref().unwrap().state.position,
                        self.parameters.accuracy,
                    )
                })
                .flatten();
            if let Some(theta) = beyond {
                // The linear body went beyond its reach during the step (a load that came
                // with it): the step is redone with the frame following the body.
                let dynamics = self.dynamics.as_mut().unwrap();
                dynamics.state.copy_from(self.backup.as_ref().unwrap());
                dynamics.features.linear = false;
                dynamics.quiet_since[2] = NOT_QUIET;
                dynamics.state.iteration_error_ratio = f64::INFINITY;
                self.model
                    .as_mut()
                    .unwrap()
                    .apply_features(dynamics.features);
                self.events.push(LogEvent {
                    category: category::EVENTS,
                    message: format!(
                        "model.auto: the step from t = {t0} turned the linear body's frame {theta:.3e} rad from its placement, more than {LINEAR_AT} × model.accuracy = {:.3e}; redone with the frame following the body",
                        LINEAR_AT * self.parameters.accuracy
                    ),
                });
                before.restore_scales(self.dynamics.as_mut().unwrap());
                continue;
            }
            let ratio = self.step_error.unwrap_or(0.0);
            if let Some((first_level, coarser, estimate)) = refined_from {
                // The ratio falls like h² (4× per rung): one that fell by less than 2 is the
                // iteration's noise, or a ringing the step does not resolve, whose filtered
                // estimate is about its amplitude: below half the budget `ε D`, its error (at
                // most twice its amplitude) is within it either way. Where model.auto's slabs
                // came on without the state carried over (pins, hinges, rigid sets), less than 2
                // per rung refined: that ringing is the model change's (docs/formulation.md,
                // "The slabs' switch"). Not elsewhere: a ringing that falls only once resolved is
                // the time step's (B1's beam pulled by 10 kN ended 8 % off at 1e-2 with it).
                let dynamics = self.dynamics.as_ref().unwrap();
                let budget = self.parameters.accuracy * dynamics.deformation_scale;
                let fall = f64::from(
                    1u32 << if switch_rings {
                        taken_level - coarser
                    } else {
                        1
                    },
                );
                if result.is_ok()
                    && ratio > 1.0
                    && ratio >= estimate / fall
                    && self.step_estimate <= 0.5 * budget
                {
                    // Refining did not reduce the estimate: what is left is no error of the time
                    // step (docs/formulation.md, "Time error control": the estimate floor). The
                    // step is redone on the rung it came from, judged above that floor.
                    let dynamics = self.dynamics.as_mut().unwrap();
                    dynamics.estimate_floor = dynamics
                        .estimate_floor
                        .max(NOISE_MARGIN * self.step_estimate);
                    self.events.push(LogEvent {
                        category: category::EVENTS,
                        message: format!(
                            "model.accuracy: at t = {t0} the estimated error did not fall with the internal step ({ratio:.2} × its allowance with {h:e} s against {estimate:.2} × on the rung {:e} s): what is left is the iteration's or the model's own, and steps are no longer refined for an estimate below {:e} m",
                            rung(self.parameters.step_size, coarser),
                            dynamics.estimate_floor
                        ),
                    });
                    dynamics.state.copy_from(self.backup.as_ref().unwrap());
                    before.restore_attempt(
                        dynamics,
                        self.model.as_mut().unwrap(),
                        &mut self.events,
                    );
                    level = first_level;
                    refined_from = None;
                    continue;
                }
            }
            if result.is_ok() && ratio > 1.0 && taken_level < finest {
                // Redone from its start on a finer rung (docs/formulation.md, "Time error
                // control"): a probe on the rung it came from (unless that rung takes the same
                // internal steps); on a rung not yet confirmed, the rung it came from
                // (`Ladder::redo_level`); elsewhere as far down as the accuracy asks: a step
                // rejected on the iteration's floor has an estimate above that floor, error of
                // the time step, and must meet the allowance below it (docs/formulation.md, "The
                // iteration's tolerance").
                let finer = if probing && ladder.level > taken_level {
                    ladder.level
                } else {
                    ladder.redo_level(
                        level,
                        taken_level,
                        ratio.max(self.step_error_unfloored),
                        finest,
                    )
                };
                self.rejected += 1;
                self.events.push(LogEvent {
                    category: category::EVENTS,
                    message: format!(
                        "model.accuracy: the step from t = {t0} by {big_h} estimated {ratio:.2} × its allowed error with internal steps of {h:e} s; redone with internal steps of at most {:e} s{}",
                        rung(self.parameters.step_size, finer),
                        if probing {
                            format!(
                                " (a probe of the rung above failed; the next waits for {} steps)",
                                ladder.after_failed_probe().probe_after
                            )
                        } else {
                            String::new()
                        }
                    ),
                });
                let backup = self.backup.as_ref().unwrap();
                let dynamics = self.dynamics.as_mut().unwrap();
                dynamics.state.copy_from(backup);
                before.restore_attempt(dynamics, self.model.as_mut().unwrap(), &mut self.events);
                if !probing && refined_from.is_none() {
                    refined_from = Some((level, taken_level, ratio));
                }
                level = finer;
                if probing {
                    probing = false;
                    failed_probe = true;
                }
                continue;
            }
            break result;
        };
        let dynamics = self.dynamics.as_mut().unwrap();
        let result = result.and_then(|()| {
            if dynamics.state.position.iter().all(|x| x.is_finite()) {
                Ok(())
            } else {
                Err(Error::discard("the step produced non-finite positions"))
            }
        });
        match result {
            Ok(()) => {
                // A quiet step moves a rung up, unless it was just redone on a finer rung or
                // the rung above has failed soon after it was reached (step_control, "growth").
                let quiet = self.step_error.is_some_and(|r| r < GROW_BELOW);
                let grows = level <= ladder.level && ladder.may_grow();
                let next = if controlled && quiet && grows && level > 0 {
                    level - 1
                } else {
                    level
                };
                if next != ladder.level && (probing || next < level) && self.step_error.is_some() {
                    self.events.push(LogEvent {
                        category: category::EVENTS,
                        message: format!(
                            "model.accuracy: at t = {} the estimated error was {:.3} of its allowance{}; the next internal steps are at most {:e} s",
                            t0 + big_h,
                            self.step_error.unwrap_or(0.0),
                            if probing { " on the rung above (a probe)" } else { "" },
                            rung(self.parameters.step_size, next)
                        ),
                    });
                }
                self.jacobian_step = Some(super::step_jacobian::LastStep {
                    steps: taken.0,
                    step: taken.1,
                    start: t0,
                    length: big_h,
                    slabs_from: slabs_came_on.then_some(before.features),
                });
                dynamics.ladder = if probing && self.step_error.is_none() {
                    // Not estimated after all: back on the rung it probed from.
                    ladder.after_failed_probe()
                } else if failed_probe && next <= ladder.level {
                    // A failed probe's redo stays on its rung, even if quiet: the rung above has
                    // just failed.
                    Ladder {
                        level: ladder.level,
                        ..ladder.after_failed_probe()
                    }
                } else if next < level {
                    ladder.after_growth(next)
                } else if probing {
                    ladder.after_kept_probe(next)
                } else if next > ladder.level {
                    ladder.after_refinement(next)
                } else {
                    ladder.after_step(self.step_error)
                };
                dynamics.ladder.since_motion_jump = ladder
                    .since_motion_jump
                    .saturating_add(u32::try_from(taken.0).unwrap_or(u32::MAX));
                dynamics.ladder.sampled_motion = ladder.sampled_motion;
                if controlled {
                    self.count_unestimated(t0 + big_h, taken.1);
                }
                // Kept with its estimate above the allowance: only on the finest rung.
                if let Some(ratio) = self.step_error.filter(|&r| r > 1.0) {
                    self.count_beyond_finest(t0 + big_h, taken.1, ratio, finest);
                }
                self.finish_step(t0, big_h);
                Ok(())
            }
            Err(e) => Err(self.roll_back(t_c, communication_step_size, e, &before, backed_up)),
        }
    }

    /// The deformation scale's floor from the loads (docs/formulation.md, "Time error control"):
    /// the quasi-static displacement of the current accelerations over the lowest modes (m,
    /// [`crate::body::lowest_modes::LowestModes::quasi_static`]) at the communication point, so
    /// that a load that has just been applied sets the scale before the body has deformed.
    fn load_scale(&mut self) {
        let model = self.model.as_ref().unwrap();
        let dynamics = self.dynamics.as_mut().unwrap();
        let modes = model
            .lowest_modes
            .as_ref()
            .expect("error control has the modes");
        let frame = model.body.frame_weights.best_fit(&dynamics.state.position);
        let quasi_static = modes.quasi_static(&frame.rotation, &dynamics.state.acceleration);
        dynamics.deformation_scale = dynamics.deformation_scale.max(quasi_static);
    }

    /// Where `model.auto` switches the slabs' own stiffening on, for this run's horizon.
    pub(in crate::slave) fn slab_stiffening_switch(&self) -> SlabStiffeningSwitch {
        let period = self
            .model
            .as_ref()
            .and_then(|m| m.lowest_modes.as_ref())
            .map(|modes| modes.first_period());
        SlabStiffeningSwitch::new(self.parameters.accuracy, self.error_horizon(), period)
    }

    /// The horizon `H` (s) over which the time error control lets the errors of its steps add
    /// up to `model.accuracy × D` (docs/formulation.md, "Time error control": the horizon): the
    /// run, `stopTime − startTime`, when the importer defined its stop time, else the period
    /// `T₁` of the lowest mode. `None` without error control.
    pub(in crate::slave) fn error_horizon(&self) -> Option<f64> {
        let period = self.model.as_ref()?.lowest_modes.as_ref()?.first_period();
        Some(self.run_length().unwrap_or(period))
    }

    /// The run's length `stopTime − startTime` (s), when the importer defined a stop time after
    /// the start.
    pub(in crate::slave) fn run_length(&self) -> Option<f64> {
        let run = self.stop_time.map(|stop| stop - self.start_time);
        run.filter(|&run| run > 0.0)
    }

    /// Whether the internal step is chosen by the error estimate (`model.accuracy > 0` with
    /// generalized-α, the scheme that estimates its error).
    fn error_controlled(&self) -> bool {
        self.model
            .as_ref()
            .is_some_and(|m| m.lowest_modes.is_some())
    }

    /// Checks a `fmi2DoStep` request against the FMU's time and state.
    fn check_step_request(&self, t_c: f64, big_h: f64) -> Result<()> {
        if !(big_h.is_finite() && big_h > 0.0) {
            return Err(Error::invalid_value(
                "communicationStepSize",
                big_h,
                "must be positive and finite",
            ));
        }
        let t = self.time();
        if self.dynamics.is_none() {
            return Err(Error::new("doStep before the body was initialized"));
        }
        let slack = 1e-5 * big_h + 4.0 * f64::EPSILON * t.abs();
        if !t_c.is_finite() || (t_c - t).abs() > slack {
            return Err(Error::invalid_value(
                "currentCommunicationPoint",
                t_c,
                &format!("does not match the FMU's time {t} (restore a state with fmi2SetFMUstate to go back)"),
            ));
        }
        Ok(())
    }

    /// The number `n` and length `h` of the equal internal steps of a communication step
    /// `big_h` (snapped) on rung `level`: no longer than `solver.stepSize / 2^level` (and the
    /// explicit scheme's stable step).
    fn internal_steps(&self, big_h: f64, level: u32) -> Result<(usize, f64)> {
        let step_size = rung(self.parameters.step_size, level);
        let largest_step = self
            .model
            .as_ref()
            .map_or(step_size, |m| m.integrator.largest_step(step_size));
        let substeps = ((big_h / largest_step) * (1.0 - 1e-9)).ceil().max(1.0);
        if substeps > 1e9 {
            return Err(Error::invalid_value(
                "communicationStepSize",
                big_h,
                "needs more than 1e9 internal steps of solver.stepSize",
            ));
        }
        Ok((substeps as usize, big_h / substeps))
    }

    /// The communication step taken for `big_h`: importers that agree on the step compute it
    /// differently (fmpy as the difference of two grid times, off by an ulp; a loop with exact
    /// steps; OMSimulator's accumulated time), and the iteration's stopping point moves with
    /// the last bit. A step within a few ulps (16 ε of `|t| + H`) of the last one taken, or of
    /// a whole number of `solver.stepSize`, is taken as that step, so that the same inputs give
    /// the same bits in every importer (docs/fmu.md, "The same numbers in every importer").
    fn snapped_step(&self, big_h: f64) -> f64 {
        let slack = 16.0 * f64::EPSILON * (self.time().abs() + big_h);
        let s = self.parameters.step_size;
        let grid = (big_h / s).round() * s;
        [self.last_step_size, grid]
            .into_iter()
            .find(|&candidate| candidate > 0.0 && (big_h - candidate).abs() <= slack)
            .unwrap_or(big_h)
    }

    /// Everything a communication step needs before its first internal step (the driving frames
    /// are set before): the factorization for `h` (on a cache miss; an error here leaves the
    /// state), the terms in force, the geometric stiffness of the current prestress and the
    /// backup.
    fn prepare_step(
        &mut self,
        h: f64,
        big_h: f64,
        slab_switch: SlabStiffeningSwitch,
        slab_state: bool,
    ) -> Result<()> {
        self.prepare_step_size(h)?;
        let motion = self.motion_frame();
        let dynamics = self.dynamics.as_mut().unwrap();
        let model = self
            .model
            .as_mut()
            .expect("prepare_step_size built the model");
        // A reduced body's prestress is the driving motion's (docs/formulation.md, "The reduced
        // body": stiffening from the driving motion), in the body's axes at the step's start.
        let driven = motion
            .filter(|_| model.body.reduction.is_some() && model.stiffening.is_some())
            .map(|driving| {
                let frame = model.body.frame_weights.best_fit(&dynamics.state.position);
                driven_inertial_coefficients(&frame, &driving)
            });
        choose_driven_stiffening(
            model,
            dynamics,
            self.parameters.accuracy,
            driven.as_ref(),
            &mut self.events,
        );
        // Before the slabs may come on, and measured only on their own state (`slab_state`: the
        // slabs were in force at the communication step's start). Where they come on, the
        // state is the one carried over to them, and `do_step` measures after the carry-over.
        let measure = slab_state && slab_switch.due(dynamics, big_h);
        choose_slab_stiffening(model, dynamics, slab_switch, &mut self.events, measure);
        choose_features(
            model,
            dynamics,
            self.parameters.tolerance * self.size,
            self.parameters.accuracy,
            self.parameters.decides_linear(),
            &mut self.events,
            &mut self.scale_scratch,
        );
        if let (Some(stiffening), Some(k_g)) = (
            model.stiffening.as_mut(),
            model.forces.geometric_stiffness.as_mut(),
        ) {
            let s = &dynamics.state;
            stiffening.update(
                &self.mesh,
                &self.parameters.material,
                &model.body,
                &s.position,
                &s.velocity,
                &s.acceleration,
                driven.as_ref(),
                k_g,
            );
        }
        let backup = self.backup.get_or_insert_with(|| dynamics.state.clone());
        backup.copy_from(&dynamics.state);
        Ok(())
    }

    /// After a successful communication step of `big_h` from `t0`: the time, the loads the end
    /// state's accelerations belong to (the inputs extrapolated to `t0 + H`), the strain watch
    /// and the results.
    fn finish_step(&mut self, t0: f64, big_h: f64) {
        self.last_step_size = big_h;
        let dynamics = self.dynamics.as_mut().unwrap();
        dynamics.state.time = t0 + big_h;
        dynamics.loads.clone_from(&self.inputs);
        for ((load, d), age) in dynamics
            .loads
            .iter_mut()
            .zip(&self.input_derivatives)
            .zip(&self.input_ages)
        {
            extrapolate(load, d, age + big_h);
        }
        dynamics.gravity = self.parameters.gravity;
        // A linear step stops at its first correction: the scratch holds its predictor's
        // deformation, which the deformation scale and the strain watch must not read. (An
        // estimated step has evaluated its end already, and the last of a communication step is
        // estimated whenever one is.)
        let stale = self.step_error.is_none();
        if let Some(model) = self.model.as_mut().filter(|m| {
            stale
                && m.body.linear.is_some()
                && (m.lowest_modes.is_some() || m.strain_monitor.is_some())
        }) {
            let state = &self.dynamics.as_ref().unwrap().state;
            model
                .forces
                .observe(&model.body, state, &mut self.scale_scratch);
        }
        if let Some(model) = self.model.as_mut().filter(|m| m.lowest_modes.is_some()) {
            let modes = model.lowest_modes.as_ref().unwrap();
            let dynamics = self.dynamics.as_mut().unwrap();
            observe_deformation(
                &model.body,
                &model.free,
                modes,
                &mut model.forces,
                &mut self.scale_scratch,
                dynamics,
            );
            // Whether `D` has settled (docs/formulation.md, "The iteration's tolerance").
            let resolved = above_resolution(
                self.parameters.accuracy,
                dynamics.deformation_scale,
                self.parameters.iteration_tolerance(),
                self.size,
            );
            dynamics.scale_settling = dynamics.scale_settling.after_step(
                t0 + big_h,
                dynamics.deformation_scale,
                modes.first_period(),
                resolved,
            );
        }
        self.outputs.invalidate();
        self.watch_strain(t0 + big_h);
        if self.results.is_some() {
            self.write_results();
        }
    }

    /// After a failed communication step: the state back at `t_c` (from the backup, if it was
    /// taken: `backed_up`), the error control's scales and `model.auto`'s terms as they were
    /// (`before`), and the error `e` worded for the importer.
    fn roll_back(
        &mut self,
        t_c: f64,
        big_h: f64,
        e: Error,
        before: &StepStart,
        backed_up: bool,
    ) -> Error {
        let dynamics = self.dynamics.as_mut().unwrap();
        if backed_up {
            dynamics.state.copy_from(self.backup.as_ref().unwrap());
        }
        before.restore(dynamics, self.model.as_mut());
        self.driving.copy_from_slice(&self.driving_before);
        self.outputs.invalidate();
        // The failed step's decisions are undone, and so are their messages (a switch logged
        // and rolled back would tell the importer of a model the next step does not use).
        before.withdraw(&mut self.events, is_decision);
        let kind = e.kind;
        let message = format!(
            "doStep from t = {t_c} by communicationStepSize = {big_h}: {}; the state was rolled back to t = {t_c}{}",
            e.message,
            if kind == ErrorKind::Discard {
                "; retry with a smaller communication step (fmi2SetFMUstate to a saved state, or fmi2Reset)"
            } else {
                ""
            }
        );
        Error { kind, message }
    }
}

/// Whether a log message tells of a decision a failed step undoes: `model.auto`'s terms and
/// `model.accuracy`'s rungs (not the warnings, the factorizations, which stay cached, or
/// the counters).
fn is_decision(message: &str) -> bool {
    message.starts_with("model.auto:") || message.starts_with("model.accuracy:")
}
