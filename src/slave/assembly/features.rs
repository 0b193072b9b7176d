//! The terms in force on a model (`Features`): putting them in place, parking what is off, and
//! refreshing what follows from the state (docs/fmu.md, "model.auto").

use super::{Features, Model};

impl Model {
    /// Puts `features` into force: the body's `f_nl` switch and where `K_G` lives. The iteration
    /// matrices are not touched: they carry the Woodbury correction of `f_nl` whenever it is
    /// allowed (unused while it is off), and stiffening is on the right-hand side, absorbed by
    /// the fixed-point/Anderson iteration; so a switch never refactorises.
    pub(in crate::slave) fn apply_features(&mut self, features: Features) {
        self.body.options.nonlinear_forces = features.nonlinear_forces;
        if features.linear != self.body.linear.is_some() {
            std::mem::swap(&mut self.body.linear, &mut self.parked_linear);
        }
        let slabs = self.body.patches.is_some();
        if self.allowed.frames && features.frames != slabs {
            std::mem::swap(&mut self.body.patches, &mut self.parked_patches);
        }
        if let Some(patches) = self.body.patches.as_mut() {
            patches.stiffening_active = features.slab_stiffening && patches.has_stiffening();
        }
        let active = self.forces.geometric_stiffness.is_some();
        if features.stiffening != active {
            std::mem::swap(
                &mut self.forces.geometric_stiffness,
                &mut self.parked_geometric_stiffness,
            );
        }
    }

    /// Refreshes the slabs' own stiffening `G_p` from `positions` (docs/formulation.md,
    /// "Geometric stiffening within the slabs") where the state is put in place without a step
    /// that would refresh it: a restored FMU state, the initial state. No allocation.
    pub(in crate::slave) fn refresh_slab_stiffening(&mut self, positions: &[f64], scale: f64) {
        if self.body.reduction.is_some() {
            return;
        }
        if let Some(patches) = self.body.patches.as_mut().filter(|p| p.has_stiffening()) {
            patches.update_stiffening(positions, false, scale);
        }
    }

    /// Parks the linear body's placement, the best-fit frame of `positions` (the body placed
    /// rigidly), if the body may be linear; [`Self::apply_features`] puts it in force.
    pub(in crate::slave) fn place_linear_body(&mut self, positions: &[f64]) {
        if self.allowed.linear {
            self.body.linear = None;
            self.parked_linear = Some(self.body.linear_placement(positions));
        }
    }

    /// The number of `model.auto`'s slabs while they are parked (0 if the body has none).
    pub(in crate::slave) fn parked_slab_count(&self) -> usize {
        self.parked_patches.as_ref().map_or(0, |p| p.patches.len())
    }
}
