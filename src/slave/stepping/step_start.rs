//! What a communication step puts back when it fails or redoes an attempt (docs/formulation.md,
//! "Time error control" and "Geometric stiffening within the slabs").

use super::super::assembly::Model;
use super::super::auto_features::SLAB_STIFFENING_ON;
use super::super::{Dynamics, Features, LogEvent};

/// What a communication step may change besides the state and the driving frames, as it was at
/// its start: a failed step puts all of it back, a redone attempt the scales (a rejected
/// attempt's state, an unresolved ringing's overshoot among others, must not loosen the
/// allowance of its redo) and the slabs' own stiffening.
pub(super) struct StepStart {
    deformation_scale: f64,
    high_mode_scale: f64,
    estimate_floor: f64,
    slab_stiffening_ratio: f64,
    slab_stiffening_since: Option<f64>,
    pub(super) features: Features,
    quiet_since: [f64; 3],
    /// The iteration's error ratio carried into the step (`DynamicState::iteration_error_ratio`;
    /// the step may forget it before its backup is taken: an input's jump, a model change).
    iteration_error_ratio: f64,
    /// The log events queued before the step: the decisions it logged after them
    /// (`model.auto`'s switches, `model.accuracy`'s rungs) are undone with it.
    events: usize,
}

impl StepStart {
    pub(super) fn of(dynamics: &Dynamics, events: usize) -> StepStart {
        StepStart {
            deformation_scale: dynamics.deformation_scale,
            high_mode_scale: dynamics.high_mode_scale,
            estimate_floor: dynamics.estimate_floor,
            slab_stiffening_ratio: dynamics.slab_stiffening_ratio,
            slab_stiffening_since: dynamics.slab_stiffening_since,
            features: dynamics.features,
            quiet_since: dynamics.quiet_since,
            iteration_error_ratio: dynamics.state.iteration_error_ratio,
            events,
        }
    }

    /// `D` and `A` as they were.
    pub(super) fn restore_scales(&self, dynamics: &mut Dynamics) {
        dynamics.deformation_scale = self.deformation_scale;
        dynamics.high_mode_scale = self.high_mode_scale;
    }

    /// After a failed step: everything this holds as it was, the model's terms with it.
    pub(super) fn restore(&self, dynamics: &mut Dynamics, model: Option<&mut Model>) {
        self.restore_scales(dynamics);
        dynamics.estimate_floor = self.estimate_floor;
        dynamics.slab_stiffening_ratio = self.slab_stiffening_ratio;
        dynamics.slab_stiffening_since = self.slab_stiffening_since;
        dynamics.features = self.features;
        dynamics.quiet_since = self.quiet_since;
        dynamics.state.iteration_error_ratio = self.iteration_error_ratio;
        if let Some(model) = model {
            model.apply_features(self.features);
        }
    }

    /// Before a rejected attempt is redone on another rung: the scales as they were, and the
    /// slabs' own stiffening as it was, decided again on the redo's own carried-over state
    /// (an attempt's carry-over depends on its rung, and a rejected attempt's state is no part
    /// of the run; docs/formulation.md, "Geometric stiffening within the slabs"), its message
    /// withdrawn.
    pub(super) fn restore_attempt(
        &self,
        dynamics: &mut Dynamics,
        model: &mut Model,
        events: &mut Vec<LogEvent>,
    ) {
        self.restore_scales(dynamics);
        // A rejected attempt's measurement is no part of the run either (it feeds `due`).
        dynamics.slab_stiffening_ratio = self.slab_stiffening_ratio;
        if dynamics.features.slab_stiffening != self.features.slab_stiffening {
            dynamics.features.slab_stiffening = self.features.slab_stiffening;
            dynamics.slab_stiffening_since = self.slab_stiffening_since;
            model.apply_features(dynamics.features);
            self.withdraw(events, |message| message.contains(SLAB_STIFFENING_ON));
        }
    }

    /// Withdraws the messages logged since the step's start that `undone` names.
    pub(super) fn withdraw(&self, events: &mut Vec<LogEvent>, undone: impl Fn(&str) -> bool) {
        let mut index = 0;
        events.retain(|event| {
            index += 1;
            index <= self.events || !undone(&event.message)
        });
    }
}
