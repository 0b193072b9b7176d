//! The step Jacobian (docs/coupling.md, "Jacobians"; docs/formulation.md, "The step Jacobian"):
//! the derivative of outputs at the end of the last communication step with respect to inputs
//! held over it, for masters that couple implicitly.

use super::interfaces::apply_loads;
use super::{Inputs, OutputGroup, Slave};
use crate::body::frame::left_jacobian;
use crate::body::frame::set_node;
use crate::body::interface::{shedding, DrivingFrame, NodeSet};
use crate::error::{Error, Result};
use crate::model::enumerations::{Formulation, Integrator};
use crate::model::variables::InterfaceQuantity;
use crate::model::{Causality, InterfaceKind, Target, VariableType};
use crate::solver::generalized_alpha::sensitivity::{linear_step, SensitivityWorkspace};
use crate::solver::problem::{last_residual, residual, DynamicState, ResidualWorkspace};
use nalgebra::{Matrix3, Rotation3, Vector3};

/// The step Jacobian's vectors (allocated on its first use, with the model; more perturbations
/// when more inputs are asked for than before).
pub(super) struct JacobianWorkspace {
    /// Per input, the perturbation of the state `δs` carried through the step's internal steps.
    perturbations: Vec<DynamicState>,
    solver: SensitivityWorkspace,
    /// The perturbation of the external loads of a force seed (full `3N`).
    load: Vec<f64>,
    /// The end state and the loads while the step is redone and the outputs are evaluated.
    saved: DynamicState,
    saved_loads: Vec<Inputs>,
    /// The residual's directional derivative: its own workspace (the model's holds the frames
    /// the iteration matrix turns with) and the perturbed state.
    forces: ResidualWorkspace,
    probe: DynamicState,
    /// A rigid set's constraint values at a perturbed state.
    rows: Vec<f64>,
}

/// The last communication step: `steps` internal steps of `step` from `start` over `length`.
#[derive(Debug, Clone, Copy)]
pub(super) struct LastStep {
    pub(super) steps: usize,
    pub(super) step: f64,
    pub(super) start: f64,
    pub(super) length: f64,
    /// The terms in force before the step, if `model.auto`'s slabs came on at its start: the
    /// redo carries the state over to them as the step did
    /// ([`super::auto_features::carry_over_to_slabs`]).
    pub(super) slabs_from: Option<super::assembly::Features>,
}

/// The inputs a communication step was taken with: the inputs, their derivatives, how old
/// they were at its start (`Slave::input_ages`) and the gravity (a tunable parameter).
#[derive(Debug, Clone, Default)]
pub(super) struct StepInputs {
    inputs: Vec<Inputs>,
    derivatives: Vec<super::InputDerivatives>,
    ages: Vec<f64>,
    gravity: [f64; 3],
}

impl StepInputs {
    /// Copies the step's inputs (no allocation after the first step).
    pub(super) fn copy_from(
        &mut self,
        inputs: &[Inputs],
        derivatives: &[super::InputDerivatives],
        ages: &[f64],
        gravity: [f64; 3],
    ) {
        self.gravity = gravity;
        self.inputs.clear();
        self.inputs.extend_from_slice(inputs);
        self.derivatives.clear();
        self.derivatives.extend_from_slice(derivatives);
        self.ages.clear();
        self.ages.extend_from_slice(ages);
    }
}

/// The relative size of the perturbations along which the residual and the outputs are
/// differentiated (central differences): `ε max(|δx|, |δẋ| h, |δẍ| h²) = 1e-6 × size`, far
/// above round-off (the residual's differences are about 1e-9 of it) and small enough that the
/// differences' own error (the curvature of the frames' rotations, of the set's best-fit motion)
/// is below 1e-9 of the derivative with the residual's fourth-order and the outputs'
/// second-order differences.
const DIFFERENCE_STEP: f64 = 1e-6;

/// The outputs' differences take ten times the residual's step: their second-order differences
/// of the support's reaction (the stiffness times positions of 1 m, round-off about 1e-7 N)
/// were the noise that limited the reactions' derivatives to 6e-5 of their scale at the
/// residual's step; at ten times it is 5e-6, and their curvature error still below that.
const OUTPUT_DIFFERENCE: f64 = 10.0;

/// The step `ε` of central differences along `ds` (see [`DIFFERENCE_STEP`]) on a body of
/// `size`, velocities and accelerations weighed over the time `step` (the internal step for the
/// residual, the communication step for the outputs).
fn difference_step(ds: &DynamicState, size: f64, step: f64) -> f64 {
    let largest = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let reach = largest(&ds.position)
        .max(largest(&ds.velocity) * step)
        .max(largest(&ds.acceleration) * step * step);
    if reach > 0.0 {
        DIFFERENCE_STEP * size / reach
    } else {
        DIFFERENCE_STEP
    }
}

/// `state = saved + ε ds` in positions, velocities, accelerations and multipliers (the rest as
/// saved).
fn perturb(state: &mut DynamicState, saved: &DynamicState, ds: &DynamicState, epsilon: f64) {
    state.copy_from(saved);
    for (x, d) in [
        (&mut state.position, &ds.position),
        (&mut state.velocity, &ds.velocity),
        (&mut state.acceleration, &ds.acceleration),
        (&mut state.multipliers, &ds.multipliers),
    ] {
        for (x, d) in x.iter_mut().zip(d.iter()) {
            *x += epsilon * d;
        }
    }
}

/// What an input of the Jacobian perturbs.
#[derive(Clone, Copy)]
enum Seed {
    /// A force interface's force (`torque` false) or torque component.
    Load {
        interface: usize,
        torque: bool,
        component: usize,
    },
    /// A motion interface's driving frame: position, rotation entry (row-major), velocity or
    /// angular velocity component.
    Frame {
        interface: usize,
        quantity: InterfaceQuantity,
        component: usize,
    },
}

impl Slave {
    /// The step Jacobian of the last `fmi2DoStep` from `t₀` to `t₁ = t₀ + H`: `jacobian[i ×
    /// inputs.len() + j]` (row-major) is the derivative of output `outputs[i]` at `t₁` with
    /// respect to input `inputs[j]` at `t₀`, held over the step (extrapolated with the frame's
    /// velocities for a motion interface), the state at `t₀` fixed: for a force interface its
    /// dynamic compliance, for a motion interface its dynamic stiffness. Inputs: the `force` and
    /// `torque` of force interfaces, the `position`, `rotation`, `velocity` and
    /// `angularVelocity` of motion interfaces (a rotation entry seeds the rotation
    /// `δQ = Q skew(Qᵀ E)` its change makes after the input's orthonormalization); outputs:
    /// any. The state is linearised with the step's own iteration matrix (one solve per input
    /// and internal step) and the outputs are differentiated about the end state; the state is
    /// left as it was. Generalized-α with the reduced strain only: otherwise an error saying
    /// which. No allocation after the first call.
    pub fn step_jacobian(
        &mut self,
        outputs: &[u32],
        inputs: &[u32],
        jacobian: &mut [f64],
    ) -> Result<()> {
        if jacobian.len() != outputs.len() * inputs.len() {
            return Err(Error::new(format!(
                "the step Jacobian of {} outputs and {} inputs has {} entries, not {}",
                outputs.len(),
                inputs.len(),
                outputs.len() * inputs.len(),
                jacobian.len()
            )));
        }
        let last = self.jacobian_step.ok_or_else(|| {
            Error::new(
                "the step Jacobian describes the last fmi2DoStep: no step has been taken since the instance was initialized, reset or set to an FMU state",
            )
        })?;
        self.check_jacobian_model()?;
        for &vr in outputs {
            self.jacobian_output(vr)?;
        }
        for &vr in inputs {
            self.jacobian_seed(vr)?;
        }
        self.prepare_jacobian_workspace(inputs.len());
        let result = self.redo_with_perturbations(inputs, last);
        let columns = inputs.len();
        let result = result.and_then(|()| {
            for (j, &vr) in inputs.iter().enumerate() {
                let seed = self.jacobian_seed(vr)?;
                self.differentiate_outputs(seed, outputs, last.length, j, columns, jacobian)?;
            }
            Ok(())
        });
        // The outputs (and the residual's scratch) of the state as it is, whatever happened.
        self.outputs.invalidate();
        let outputs = self.ensure_outputs(OutputGroup::All);
        result.and(outputs)
    }

    /// The workspace, with a perturbation per input.
    fn prepare_jacobian_workspace(&mut self, inputs: usize) {
        let model = self.model.as_mut().unwrap();
        let n3 = model.body.reference.len();
        let multipliers = model.free.multiplier_count();
        let ws = model.jacobian.get_or_insert_with(|| JacobianWorkspace {
            perturbations: Vec::new(),
            solver: SensitivityWorkspace::new(&model.body, &model.free),
            load: vec![0.0; n3],
            saved: DynamicState::zeros(n3, multipliers),
            saved_loads: self.inputs.clone(),
            forces: ResidualWorkspace::new(&model.body),
            probe: DynamicState::zeros(n3, multipliers),
            rows: vec![0.0; multipliers],
        });
        while ws.perturbations.len() < inputs {
            ws.perturbations.push(DynamicState::zeros(n3, multipliers));
        }
        for ds in &mut ws.perturbations[..inputs] {
            for v in [
                &mut ds.position,
                &mut ds.velocity,
                &mut ds.acceleration,
                &mut ds.pseudo_acceleration,
                &mut ds.multipliers,
            ] {
                v.fill(0.0);
            }
            ds.time = 0.0;
        }
        // K_G of the step (its pattern is the model's: copy the values, allocate once).
        match (
            &mut ws.forces.geometric_stiffness,
            &model.forces.geometric_stiffness,
        ) {
            (Some(to), Some(from)) if to.values.len() == from.values.len() => {
                to.values.copy_from_slice(&from.values)
            }
            (to, from) => *to = from.clone(),
        }
    }

    /// Redoes the last communication step from its start (the backup) with the inputs it was
    /// taken with, internal step by internal step as it was taken, and after each carries every
    /// input's perturbation through the same internal step linearised about the state it
    /// reached. The redo reaches the end state again (the same arithmetic); the state, the
    /// inputs, the counters and the log are put back as they were, whatever happens.
    fn redo_with_perturbations(&mut self, inputs: &[u32], last: LastStep) -> Result<()> {
        {
            let ws = self.model.as_mut().unwrap().jacobian.as_mut().unwrap();
            let dynamics = self.dynamics.as_mut().unwrap();
            ws.saved.copy_from(&dynamics.state);
            ws.saved_loads.clone_from(&dynamics.loads);
            dynamics
                .state
                .copy_from(self.backup.as_ref().expect("a step was taken"));
            if let Some(old) = last.slabs_from {
                // The inputs do not enter the carry-over (the state at the step's start): the
                // perturbations start after it.
                super::auto_features::carry_over_to_slabs(
                    self.model.as_mut().unwrap(),
                    dynamics,
                    last.step,
                    old,
                    &mut self.scale_scratch,
                    self.parameters.tolerance * self.size,
                    None,
                );
            }
        }
        let counters = (
            self.statistics,
            self.retries,
            self.step_error,
            self.events.len(),
        );
        self.swap_step_inputs();
        let mut result = Ok(());
        for i in 0..last.steps {
            let retries = self.retries;
            result = self
                .internal_step(last.start, last.length, i, last.steps, last.step)
                .and_then(|()| {
                    if self.retries != retries {
                        // Its state came from 2, 4 or 8 steps of h/m, each with a factor and a
                        // change of step of its own: not linearised here.
                        return Err(Error::new(format!(
                            "the last fmi2DoStep retried its internal step from t = {} with halved steps, which the step Jacobian does not follow: take a smaller communication step or solver.stepSize",
                            last.start + i as f64 * last.step
                        )));
                    }
                    for (j, &vr) in inputs.iter().enumerate() {
                        let seed = self.jacobian_seed(vr)?;
                        self.linearised_step(seed, j, last.step)?;
                    }
                    Ok(())
                });
            if result.is_err() {
                break;
            }
        }
        self.swap_step_inputs();
        (self.statistics, self.retries, self.step_error) = (counters.0, counters.1, counters.2);
        self.events.truncate(counters.3);
        let ws = self.model.as_mut().unwrap().jacobian.as_mut().unwrap();
        let dynamics = self.dynamics.as_mut().unwrap();
        dynamics.state.copy_from(&ws.saved);
        dynamics.loads.clone_from(&ws.saved_loads);
        result
    }

    /// Exchanges the current inputs and gravity with those the last step was taken with
    /// (twice: back).
    fn swap_step_inputs(&mut self) {
        std::mem::swap(&mut self.parameters.gravity, &mut self.step_inputs.gravity);
        std::mem::swap(&mut self.inputs, &mut self.step_inputs.inputs);
        std::mem::swap(
            &mut self.input_derivatives,
            &mut self.step_inputs.derivatives,
        );
        std::mem::swap(&mut self.input_ages, &mut self.step_inputs.ages);
    }

    /// Refuses models the step Jacobian does not cover, naming why.
    fn check_jacobian_model(&self) -> Result<()> {
        let p = &self.parameters;
        if p.integrator != Integrator::GeneralizedAlpha {
            return Err(Error::new(format!(
                "the step Jacobian is computed with generalized-α's iteration matrix; solver.integrator = {} has none",
                p.integrator.item()
            )));
        }
        if p.formulation == Formulation::Full {
            return Err(Error::new(
                "the step Jacobian linearises the reduced-strain body; model.formulation = full is not supported",
            ));
        }
        Ok(())
    }

    /// Checks that `vr` is a Real output.
    fn jacobian_output(&self, vr: u32) -> Result<()> {
        match self.variables.get(VariableType::Real, vr) {
            Some(v) if v.causality == Causality::Output => Ok(()),
            Some(v) => Err(Error::new(format!(
                "{} (value reference {vr}) is not an output: the step Jacobian's unknowns are outputs",
                v.name
            ))),
            None => Err(Error::new(format!(
                "no Real variable has value reference {vr}"
            ))),
        }
    }

    /// The seed of input `vr`, or an error naming what the Jacobian takes.
    fn jacobian_seed(&self, vr: u32) -> Result<Seed> {
        let v = self
            .variables
            .get(VariableType::Real, vr)
            .ok_or_else(|| Error::new(format!("no Real variable has value reference {vr}")))?;
        use InterfaceQuantity as Q;
        match v.target {
            Target::Interface {
                index,
                quantity: q @ (Q::Force | Q::Torque),
                component,
            } if v.causality == Causality::Input
                && self.interfaces[index].kind == InterfaceKind::Force =>
            {
                Ok(Seed::Load {
                    interface: index,
                    torque: q == Q::Torque,
                    component,
                })
            }
            Target::Interface {
                index,
                quantity,
                component,
            } if v.causality == Causality::Input
                && self.interfaces[index].kind == InterfaceKind::Motion =>
            {
                Ok(Seed::Frame {
                    interface: index,
                    quantity,
                    component,
                })
            }
            _ => Err(Error::new(format!(
                "{} (value reference {vr}): the step Jacobian's knowns are the force and torque inputs of force interfaces and the position, rotation, velocity and angularVelocity inputs of motion interfaces",
                v.name
            ))),
        }
    }

    /// Input `j`'s perturbation (seed `seed`) carried through one internal step of `h`,
    /// linearised about the state it reached (the current one).
    fn linearised_step(&mut self, seed: Seed, j: usize, h: f64) -> Result<()> {
        let start = self.jacobian_step.map_or(0.0, |l| l.start);
        let model = self.model.as_mut().unwrap();
        let JacobianWorkspace {
            perturbations,
            solver,
            load,
            forces,
            probe,
            rows,
            ..
        } = model.jacobian.as_mut().unwrap();
        let (body, free) = (&model.body, &model.free);
        let dynamics = self.dynamics.as_ref().unwrap();
        let state = &dynamics.state;
        let gravity = Vector3::from(self.parameters.gravity);
        let (interfaces, inputs) = (&self.interfaces, &self.inputs);
        let (derivatives, ages) = (&self.input_derivatives, &self.input_ages);
        // The loads as the internal step just taken had them (the step's inputs at its end).
        let tau = state.time - start;
        let loads = |x: &[f64], f: &mut [f64]| {
            apply_loads(
                body,
                interfaces,
                inputs,
                Some((derivatives, ages, tau)),
                &gravity,
                x,
                f,
            )
        };
        // The frames the iteration matrix turns with, at this state.
        let frame = residual(body, free, state, &loads, &mut model.forces)
            .frame
            .rotation;
        load.fill(0.0);
        if let Seed::Load {
            interface,
            torque,
            component,
        } = seed
        {
            let unit = Vector3::ith(component, 1.0);
            let (f, t) = if torque {
                (Vector3::zeros(), unit)
            } else {
                (unit, Vector3::zeros())
            };
            self.interfaces[interface]
                .set
                .distribute(&state.position, &f, &t, load);
        }
        let driven = match seed {
            Seed::Frame {
                interface,
                quantity,
                component,
            } => {
                // Where the frame follows rates, `Δt` back to the change before (this step's own
                // when it changed at `start`): the rates come from the velocities given at
                // `start` (`DrivingFrame`), `a = (v − v_given) / Δt`, `∂a/∂v = 1 / Δt`; and a
                // change given at a followed update is carried in over `Δt`, as the sample's
                // bend is carried off (`DrivingFrame`, the offset): at `start` itself when the
                // frame changed there following its rates (it sheds), or at a new update at
                // `start` when it follows them since an earlier one.
                let f = self.driving[interface];
                let span = (f.rate_span > 0.0).then_some(if f.changed_at == start {
                    f.rate_span
                } else {
                    start - f.changed_at
                });
                let rate = span.map_or(0.0, f64::recip);
                let shed = span.filter(|_| f.changed_at != start || f.sheds);
                Some((
                    &self.interfaces[interface].set,
                    f.advanced_to(start),
                    (quantity, component, rate, shed),
                ))
            }
            Seed::Load { .. } => None,
        };
        let reference = &body.reference;
        let prescribe = |tau: f64, ds: &mut DynamicState| {
            if let Some((set, frame, seed)) = driven {
                frame_perturbation(set, reference, &frame, seed, tau, ds);
            }
        };
        // The residual's directional derivative at this state, less the seed's load.
        let size = self.size;
        let load = &*load;
        let mut derivative = |ds: &DynamicState, out: &mut [f64], values: &mut [f64]| {
            // The point constraints' `C δx` (their centroids are linear in x).
            for (p, c) in free.constraints.iter().enumerate() {
                values[3 * p..3 * p + 3].copy_from_slice(c.centroid(&ds.position).as_slice());
            }
            let points = 3 * free.constraints.len();
            values[points..].fill(0.0);
            out.fill(0.0);
            let still = [
                &ds.position,
                &ds.velocity,
                &ds.acceleration,
                &ds.multipliers,
            ]
            .iter()
            .all(|v| v.iter().all(|&x| x == 0.0));
            if still {
                // Along zero the derivative is zero: only the seed's load (the first linear
                // iteration of a force seed's first internal step).
                for (o, f) in out.iter_mut().zip(load) {
                    *o = -f;
                }
                return;
            }
            // Fourth-order central differences, (8 (r₊ − r₋) − (r₊₊ − r₋₋)) / 12ε, of the
            // residual and of the rigid sets' constraints: the frames' rotations make the
            // residual curved enough that the two-point difference at a step above its noise
            // is 4e-6 off (B1's torsion).
            let epsilon = difference_step(ds, size, h);
            for (multiple, weight) in [(1.0, 8.0), (-1.0, -8.0), (2.0, -1.0), (-2.0, 1.0)] {
                perturb(probe, state, ds, multiple * epsilon);
                residual(body, free, probe, &loads, forces);
                let r = last_residual(forces);
                for (o, r) in out.iter_mut().zip(r) {
                    *o += weight * r;
                }
                let mut row = points;
                for set in &free.rigid {
                    let k = set.rows();
                    set.violation(&probe.position, &mut rows[..k]);
                    for (v, h) in values[row..row + k].iter_mut().zip(&rows[..k]) {
                        *v += weight * h / (12.0 * epsilon);
                    }
                    row += k;
                }
            }
            for (o, f) in out.iter_mut().zip(load) {
                *o = *o / (12.0 * epsilon) - f;
            }
        };
        let matrix = model.integrator.iteration_matrix_mut(h).ok_or_else(|| {
            Error::new(format!(
                "the iteration matrix of the last step (h = {h:e} s) is no longer cached"
            ))
        })?;
        linear_step(
            matrix,
            body,
            free,
            state,
            &frame,
            &model.forces,
            h,
            &prescribe,
            &mut derivative,
            &mut perturbations[j],
            solver,
        )
        .map(|_| ())
    }

    /// Column `j` of the Jacobian: the outputs differentiated (central differences) about the
    /// end state along `δs` and, for a force seed, the load input.
    fn differentiate_outputs(
        &mut self,
        seed: Seed,
        outputs: &[u32],
        big_h: f64,
        j: usize,
        columns: usize,
        jacobian: &mut [f64],
    ) -> Result<()> {
        let model = self.model.as_mut().unwrap();
        let ws = model.jacobian.as_mut().unwrap();
        let dynamics = self.dynamics.as_mut().unwrap();
        ws.saved.copy_from(&dynamics.state);
        ws.saved_loads.clone_from(&dynamics.loads);
        let epsilon = OUTPUT_DIFFERENCE * difference_step(&ws.perturbations[j], self.size, big_h);
        let load_seed = match seed {
            Seed::Load {
                interface,
                torque,
                component,
            } => Some((
                interface,
                InterfaceQuantity::Force.slot() as usize + 3 * usize::from(torque) + component,
            )),
            Seed::Frame { .. } => None,
        };
        let mut result = Ok(());
        for sign in [1.0, -1.0] {
            let model = self.model.as_mut().unwrap();
            let ws = model.jacobian.as_mut().unwrap();
            let dynamics = self.dynamics.as_mut().unwrap();
            perturb(
                &mut dynamics.state,
                &ws.saved,
                &ws.perturbations[j],
                sign * epsilon,
            );
            if let Some((k, slot)) = load_seed {
                dynamics.loads[k][slot] = ws.saved_loads[k][slot] + sign * epsilon;
            }
            self.outputs.invalidate();
            for (i, &vr) in outputs.iter().enumerate() {
                match self.get_real(vr) {
                    Ok(y) if sign > 0.0 => jacobian[i * columns + j] = y,
                    Ok(y) => {
                        let entry = &mut jacobian[i * columns + j];
                        *entry = (*entry - y) / (2.0 * epsilon);
                    }
                    Err(e) => result = Err(e),
                }
            }
        }
        let model = self.model.as_mut().unwrap();
        let ws = model.jacobian.as_ref().unwrap();
        let dynamics = self.dynamics.as_mut().unwrap();
        dynamics.state.copy_from(&ws.saved);
        dynamics.loads.clone_from(&ws.saved_loads);
        self.outputs.invalidate();
        result
    }
}

/// The perturbation of motion interface `set`'s held coordinates `τ` into the step when its
/// driving frame `frame` (at the step's start) has its input `quantity[component]` changed by
/// one unit: `x = p + v τ + a τ²/2 + exp([ω τ + α τ²/2]×) Q d` (`Q d` for a direction)
/// differentiated, the rates depending on the velocities as `∂a/∂v = ∂α/∂ω = rate` (`seed =
/// (quantity, component, rate, shed)`; [`DrivingFrame`]); with `shed = Some(Δt)` the change
/// comes at an update the frame follows through and is carried in over `Δt` as its offset is
/// carried off ([`shedding`]: what is left of it at `τ` taken away).
fn frame_perturbation(
    set: &NodeSet,
    reference: &[f64],
    frame: &DrivingFrame,
    (quantity, component, rate, shed): (InterfaceQuantity, usize, f64, Option<f64>),
    tau: f64,
    ds: &mut DynamicState,
) {
    use InterfaceQuantity as Q;
    let t = frame.changed_at + tau;
    let turn = *Rotation3::from_scaled_axis(frame.turn(t)).matrix();
    let q = frame.rotation;
    let unit = Vector3::ith(component % 3, 1.0);
    // How far a unit change of a velocity moves the frame: `τ + rate τ²/2`.
    let reach = tau + 0.5 * rate * tau * tau;
    // What is left at τ of the offset a change at a followed update makes (`DrivingFrame`):
    // `−(δ h₀₀ + δ̇ Δt h₁₀)` of a change `δ` of the pose or `δ̇` of the velocities.
    let [left, left_of_rate] = shed
        .and_then(|span| shedding(tau, span))
        .map_or([0.0, 0.0], |[h00, h10]| [h00[0], h10[0]]);
    // δ(Q d) = D d, and δp for a point.
    let (rotation_change, point_change) = match quantity {
        Q::Position => (Matrix3::zeros(), (1.0 - left) * unit),
        Q::Velocity => (Matrix3::zeros(), (reach - left_of_rate) * unit),
        Q::Rotation => {
            let e = Matrix3::from_fn(|r, c| f64::from(u8::from(3 * r + c == component)));
            let a = q.transpose() * e;
            // δQ = Q S: the turn `[δθ]× = Q S Qᵀ` of the sample, less what is left of it.
            let s = 0.5 * (a - a.transpose());
            let change = turn * q * s - left * (q * s * q.transpose()) * turn * q;
            (change, Vector3::zeros())
        }
        Q::AngularVelocity => {
            let w = left_jacobian(&frame.turn(t)) * (reach * unit) - left_of_rate * unit;
            (w.cross_matrix() * turn * q, Vector3::zeros())
        }
        _ => (Matrix3::zeros(), Vector3::zeros()),
    };
    set.for_each_held(reference, |index, offset, point| {
        let mut dx = rotation_change * offset;
        if point {
            dx += point_change;
        }
        set_node(&mut ds.position, index, &dx);
    });
}
