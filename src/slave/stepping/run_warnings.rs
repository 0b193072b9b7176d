//! What a run says about itself as it goes (docs/formulation.md, "Time error control"): the
//! communication steps the error control could not judge or could not bring within
//! `model.accuracy`, counted and warned of once, and the small-strain watch.

use super::super::step_control::{rung, MOTION_RINGING_STEPS, UNESTIMATED_WARN_AFTER};
use super::super::{LogEvent, Slave};
use crate::body::strain_monitor::DEFAULT_THRESHOLD;
use crate::model::category;

impl Slave {
    /// Counts a communication step (ending at `t`, internal steps of `h`) that nothing
    /// estimated, and warns once when [`UNESTIMATED_WARN_AFTER`] came in a row: their time error
    /// is not controlled (docs/formulation.md, "Time error control").
    pub(super) fn count_unestimated(&mut self, t: f64, h: f64) {
        if self.step_error.is_some() {
            self.unestimated.1 = 0;
            return;
        }
        self.unestimated.0 += 1;
        self.unestimated.1 += 1;
        if self.unestimated.1 == UNESTIMATED_WARN_AFTER && !self.unestimated.2 {
            self.unestimated.2 = true;
            self.events.push(LogEvent {
                category: category::EVENTS,
                message: format!(
                    "warning: model.accuracy: up to t = {t} the last {UNESTIMATED_WARN_AFTER} communication steps were not estimated: each was one internal step ({h:e} s) that starts where an input jumps (a motion interface's pose or velocity, or a force input, set anew), or lies within the first {MOTION_RINGING_STEPS} internal steps after a sampled motion input's jump, whose error the estimate cannot tell from the inputs' sampling. The time error of such steps is not controlled (a motion sampled with its velocities is estimated once they change from update to update and the poses follow them: docs/fmu.md, \"Inputs are samples in time\"). A shorter communication step reduces it, and so does solver.stepSize below the communication step, whose internal steps it then fixes (docs/formulation.md, \"Time error control\"); the run summary counts these steps"
                ),
            });
        }
    }

    /// Counts a communication step (ending at `t`) kept on the finest rung, internal steps of
    /// `h`, whose largest estimate was `ratio` (> 1) × its allowance, and warns once: its time
    /// error is not within `model.accuracy` (docs/formulation.md, "Time error control": the
    /// ladder). `finest`: the finest rung in force (`step_control::finest_level`).
    pub(super) fn count_beyond_finest(&mut self, t: f64, h: f64, ratio: f64, finest: u32) {
        self.beyond_finest.0 += 1;
        if !self.beyond_finest.1 {
            self.beyond_finest.1 = true;
            self.events.push(LogEvent {
                category: category::EVENTS,
                message: format!(
                    "warning: model.accuracy: the communication step up to t = {t} was kept on the finest rung (solver.stepSize / 2^{finest} = {:e} s; internal steps of {h:e} s), with an estimated error {ratio:.2} × its allowance: the time error of such steps is not within model.accuracy = {:e}. A smaller solver.stepSize moves the ladder down, a larger model.accuracy asks for less (docs/formulation.md, \"Time error control\"); the run summary counts these steps",
                    rung(self.parameters.step_size, finest),
                    self.parameters.accuracy
                ),
            });
        }
    }

    /// The small-strain watch: a message when `‖∇ū‖` crosses the threshold at time `t` (once
    /// per crossing; again after it fell below half of it).
    pub(super) fn watch_strain(&mut self, t: f64) {
        let model = self.model.as_mut().expect("the model exists after a step");
        let Some((monitor, above)) = &mut model.strain_monitor else {
            return;
        };
        let g = monitor.largest_gradient(model.forces.force_scratch().local_deformation());
        if g > DEFAULT_THRESHOLD && !*above {
            *above = true;
            self.events.push(LogEvent {
                category: category::EVENTS,
                message: format!(
                    "warning: at t = {t} the deformation gradient in the co-moving frame reached ‖∇ū‖ ≈ {g:.3} (> {DEFAULT_THRESHOLD}): beyond the small-strain range of the reduced strain the results lose accuracy without other signs; use model.frames > 1 for large bending or model.formulation = full"
                ),
            });
        } else if g < 0.5 * DEFAULT_THRESHOLD && *above {
            *above = false;
            self.events.push(LogEvent {
                category: category::EVENTS,
                message: format!("at t = {t} ‖∇ū‖ ≈ {g:.3} is back within the small-strain range"),
            });
        }
    }
}
