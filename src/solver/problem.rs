//! The vocabulary every time integration scheme shares: the equations of motion on the free
//! DOFs, the state they advance, the residual, and what a step reports.
//!
//! The body's `N` nodes carry positions `x`, velocities `ẋ` and accelerations `ẍ` (flat `3N`).
//! The clamped nodes (fixed supports, motion interfaces) follow a prescription; the free ones
//! satisfy
//!
//! ```text
//! r(x, ẋ, ẍ, λ) = M ẍ + f(x, ẋ) + Cᵀλ − f_ext(x) = 0        (free DOFs)
//! C x = d                                                   (point constraints: pins, hinges)
//! ```
//!
//! with `M = Ms ⊗ I3` the consistent mass, `f` the body's internal force (elastic, damping,
//! `f_nl`, stiffening), `C` the point constraints' selection Jacobian and `λ` their Lagrange
//! multipliers (the constraint load on the body is `−Cᵀλ`), `f_ext` the external loads. Each
//! scheme (generalized-α, Radau IIA, central difference: the modules above this one)
//! discretises `ẋ`, `ẍ` in time and drives `r` to zero on the free DOFs; they all evaluate it
//! with [`residual`] in a [`ResidualWorkspace`].

use super::constraints::{add_constraint_forces, PointConstraint, RigidConstraint};
use crate::body::frame::{add_node, node};
use crate::body::{Body, BodyKinematics, ElasticTerm, ForceScratch};
use crate::error::{Error, Result};
use crate::linalg::SymmetricCsr;
use nalgebra::Matrix3;

/// Which nodes move: the others are clamped (a `fixed` support) and keep their positions.
#[derive(Debug, Clone)]
pub struct FreeNodes {
    /// Free node indices, ascending; free node `k` owns rows `3k..3k+3` of the reduced system.
    pub nodes: Vec<usize>,
    /// The clamped (prescribed) nodes, ascending.
    pub clamped: Vec<usize>,
    /// `M ⊗ I3` restricted to the free DOFs.
    pub mass: SymmetricCsr,
    /// `K` restricted to the free DOFs.
    pub stiffness: SymmetricCsr,
    /// `Ms` restricted to the free nodes (scalar).
    pub scalar_mass: SymmetricCsr,
    /// Point constraints (pins) on free nodes, solved with Lagrange multipliers.
    pub constraints: Vec<PointConstraint>,
    /// Rigid sets (rigid attachments) of free nodes, with Lagrange multipliers after the point
    /// constraints'.
    pub rigid: Vec<RigidConstraint>,
    /// The first `elastic_nodes` free nodes are the mesh's; the others are lumped bodies' mass
    /// points (no stiffness).
    pub elastic_nodes: usize,
    /// `Body::modal_stiffness` restricted to the free DOFs, if the body has one.
    modal_stiffness: Option<SymmetricCsr>,
    /// Whether a modal analysis holds the rigid sets ([`Self::rigid_set_motions`]: a reduced
    /// body).
    rigid_sets_in_modes: bool,
}

impl FreeNodes {
    /// Free nodes of `body` when `clamped` nodes are held.
    pub fn new(body: &Body, clamped: &[bool]) -> FreeNodes {
        let nodes: Vec<usize> = (0..body.node_count()).filter(|&i| !clamped[i]).collect();
        let mesh_nodes = body.node_count() - body.lumped_points;
        let elastic_nodes = nodes.iter().filter(|&&i| i < mesh_nodes).count();
        let dofs = node_dofs(&nodes);
        let mass = body.mass_matrix.kron_i3().submatrix(&dofs);
        let stiffness = body.stiffness_matrix.submatrix(&dofs);
        let modal_stiffness = body.modal_stiffness.as_ref().map(|k| k.submatrix(&dofs));
        let scalar_mass = body.mass_matrix.submatrix(&nodes);
        FreeNodes {
            nodes,
            clamped: (0..body.node_count()).filter(|&i| clamped[i]).collect(),
            mass,
            stiffness,
            scalar_mass,
            constraints: Vec::new(),
            rigid: Vec::new(),
            elastic_nodes,
            modal_stiffness,
            rigid_sets_in_modes: body.reduction.is_some(),
        }
    }

    /// `K` and `M ⊗ I3` on the free mesh nodes' DOFs (without the lumped bodies' mass points,
    /// whose zero stiffness would add zero frequencies, and with the elements inside rigid sets,
    /// whose constraints a modal analysis does not see): what a modal analysis of the elastic
    /// body takes (a reduced body's analysis holds its rigid sets on top of these:
    /// [`Self::rigid_set_motions`]).
    pub fn elastic_matrices(&self) -> (SymmetricCsr, SymmetricCsr) {
        let stiffness = self.modal_stiffness.as_ref().unwrap_or(&self.stiffness);
        let dofs: Vec<usize> = (0..3 * self.elastic_nodes).collect();
        if dofs.len() == stiffness.n {
            return (stiffness.clone(), self.mass.clone());
        }
        (stiffness.submatrix(&dofs), self.mass.submatrix(&dofs))
    }

    /// On a reduced body with rigid sets, `T` (free DOFs × kept coordinates) with `x = T y`:
    /// every free DOF outside the rigid sets kept, each set's points (3 or 4,
    /// `body::reduction`) replaced by the set's six rigid motions at the reference
    /// (`δx_i = u + θ × X̂_i`); `None` otherwise. A modal analysis in `y` (`Tᵀ K T`, `Tᵀ M T`)
    /// holds the sets rigid exactly: a set's fourth point may move only mass points, which
    /// would leave `K` a null space there. (The mesh body's analysis leaves the sets' constraints
    /// out.)
    pub fn rigid_set_motions(&self) -> Option<nalgebra::DMatrix<f64>> {
        let sets: Vec<&RigidConstraint> = self.rigid.iter().filter(|s| s.lock.is_none()).collect();
        if !self.rigid_sets_in_modes || sets.is_empty() {
            return None;
        }
        let n = self.dof_count();
        let mut in_set = vec![false; n];
        for set in &sets {
            for &r in &set.free_rows {
                in_set[r..r + 3].iter_mut().for_each(|f| *f = true);
            }
        }
        let kept = in_set.iter().filter(|&&f| !f).count();
        let mut t = nalgebra::DMatrix::zeros(n, kept + 6 * sets.len());
        for (column, row) in (0..n).filter(|&r| !in_set[r]).enumerate() {
            t[(row, column)] = 1.0;
        }
        for (j, set) in sets.iter().enumerate() {
            let first = kept + 6 * j;
            for (&r, offset) in set.free_rows.iter().zip(&set.offsets) {
                for d in 0..3 {
                    t[(r + d, first + d)] = 1.0;
                    let rotation = nalgebra::Vector3::ith(d, 1.0).cross(offset);
                    for e in 0..3 {
                        t[(r + e, first + 3 + d)] = rotation[e];
                    }
                }
            }
        }
        Some(t)
    }

    /// The global DOFs of the free nodes, in the order of the reduced system.
    pub fn dofs(&self) -> Vec<usize> {
        node_dofs(&self.nodes)
    }

    /// Adds a point constraint holding the weighted centroid of `nodes` (weights `weights`, any
    /// positive scale) at `target` (m). Error if a node is clamped.
    pub fn add_point_constraint(
        &mut self,
        name: &str,
        nodes: &[usize],
        weights: &[f64],
        target: nalgebra::Vector3<f64>,
    ) -> Result<()> {
        let total: f64 = weights.iter().sum();
        let free_rows = self.free_rows(name, nodes)?;
        self.constraints.push(PointConstraint {
            nodes: nodes.to_vec(),
            weights: weights.iter().map(|w| w / total).collect(),
            free_rows,
            target,
        });
        Ok(())
    }

    /// Makes the free nodes `nodes` one rigid set ([`RigidConstraint`]) with reference positions
    /// `reference` (flat, all nodes). Error if a node is clamped or the nodes are collinear.
    pub fn add_rigid_set(&mut self, name: &str, nodes: &[usize], reference: &[f64]) -> Result<()> {
        let free_rows = self.free_rows(name, nodes)?;
        self.rigid
            .push(RigidConstraint::new(name, nodes, free_rows, reference)?);
        Ok(())
    }

    /// Locks the rotation of the free nodes `nodes` (a rigid set) about every axis but `axis`
    /// (reference coordinates): a hinge on a rigid set ([`RigidConstraint::axis_lock`]).
    pub fn add_axis_lock(
        &mut self,
        name: &str,
        nodes: &[usize],
        reference: &[f64],
        axis: nalgebra::Vector3<f64>,
    ) -> Result<()> {
        let free_rows = self.free_rows(name, nodes)?;
        self.rigid.push(RigidConstraint::axis_lock(
            name, nodes, free_rows, reference, axis,
        )?);
        Ok(())
    }

    fn free_rows(&self, name: &str, nodes: &[usize]) -> Result<Vec<usize>> {
        nodes
            .iter()
            .map(|&n| match self.nodes.binary_search(&n) {
                Ok(k) => Ok(3 * k),
                Err(_) => Err(Error::new(format!(
                    "interface '{name}': node {n} is also held by a fixed support or motion interface"
                ))),
            })
            .collect()
    }

    /// Whether any Lagrange multiplier constraint (point or rigid set) is present.
    pub fn is_constrained(&self) -> bool {
        !self.constraints.is_empty() || !self.rigid.is_empty()
    }

    /// Number of Lagrange multipliers (3 per point constraint, `3n − 6` per rigid set).
    pub fn multiplier_count(&self) -> usize {
        3 * self.constraints.len() + self.rigid.iter().map(RigidConstraint::rows).sum::<usize>()
    }

    /// Number of free DOFs.
    pub fn dof_count(&self) -> usize {
        3 * self.nodes.len()
    }
}

/// The DOFs `3i, 3i+1, 3i+2` of each node `i` of `nodes`.
fn node_dofs(nodes: &[usize]) -> Vec<usize> {
    nodes
        .iter()
        .flat_map(|&i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect()
}

/// Positions, velocities, accelerations and pseudo-accelerations (flat `3N`) at `time`.
#[derive(Debug, Clone, PartialEq)]
pub struct DynamicState {
    pub time: f64,
    pub position: Vec<f64>,
    pub velocity: Vec<f64>,
    pub acceleration: Vec<f64>,
    pub pseudo_acceleration: Vec<f64>,
    /// Lagrange multipliers of the point constraints (N, global; 3 per constraint): the
    /// constraint load on the body is `−Cᵀλ`.
    pub multipliers: Vec<f64>,
    /// The length of the generalized-α step that produced this state (s); 0 when no step did
    /// (initialization). A step of another length first carries the state over to it
    /// (`generalized_alpha::change_step`).
    pub step_size: f64,
    /// The error ratio `η = θ/(1−θ)` the iteration of the step that produced this state ended
    /// with (`fixed_point::Convergence::error_ratio`): the next step of the same length and
    /// model judges its first correction with it. Infinity: none (initialization, a new step
    /// length or model).
    pub iteration_error_ratio: f64,
}

impl DynamicState {
    /// A state at rest at the origin with `dofs` entries (`3N`) and `multipliers` multipliers.
    pub fn zeros(dofs: usize, multipliers: usize) -> DynamicState {
        DynamicState {
            time: 0.0,
            position: vec![0.0; dofs],
            velocity: vec![0.0; dofs],
            acceleration: vec![0.0; dofs],
            pseudo_acceleration: vec![0.0; dofs],
            multipliers: vec![0.0; multipliers],
            step_size: 0.0,
            iteration_error_ratio: f64::INFINITY,
        }
    }

    /// Copies `other` into `self` without allocating.
    pub fn copy_from(&mut self, other: &DynamicState) {
        self.time = other.time;
        self.position.copy_from_slice(&other.position);
        self.velocity.copy_from_slice(&other.velocity);
        self.acceleration.copy_from_slice(&other.acceleration);
        self.pseudo_acceleration
            .copy_from_slice(&other.pseudo_acceleration);
        self.multipliers.copy_from_slice(&other.multipliers);
        self.step_size = other.step_size;
        self.iteration_error_ratio = other.iteration_error_ratio;
    }
}

/// What a step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    pub iterations: usize,
    /// Largest position correction of the last iteration (m).
    pub last_correction: f64,
    /// The step's estimated local error (m, mass-weighted RMS over the body), when
    /// [`IterationSettings::estimate_error`] asked for it and the scheme has an estimate
    /// (generalized-α: `generalized_alpha::IterationMatrix::local_error`).
    pub error_estimate: Option<f64>,
}

/// Settings of the fixed-point iteration of the implicit schemes (`fixed_point::Convergence`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IterationSettings {
    /// Converged when the estimated position error of the iterate is below this (m): the
    /// largest correction, or from the second iteration on its estimated remaining error
    /// (`fixed_point::error_ratio`), or on the first with the ratio carried from the step
    /// before (below, [`Self::carried_below`]).
    pub absolute_tolerance: f64,
    /// A first correction at most this large (m) may stop the iteration on the error ratio
    /// carried from the step before (`fixed_point::Convergence::carrying`): the iteration's own
    /// tolerance where a tighter `absolute_tolerance` follows the error control (the first
    /// correction then leaves what the own tolerance's plain test would); 0: never.
    pub carried_below: f64,
    pub max_iterations: usize,
    /// `Some(enough)`: the step estimates its local error ([`StepReport::error_estimate`], m;
    /// for the slave's step-size control, docs/formulation.md "Time error control"), and may
    /// stop refining the estimate once it knows it is below `enough`.
    pub estimate_error: Option<f64>,
}

/// Sets the positions, velocities and accelerations of the clamped (prescribed) nodes at a time.
pub type Prescription<'a> = &'a dyn Fn(f64, &mut DynamicState);

/// What a step of any scheme needs besides the state: the body, its free nodes and constraints,
/// the external loads (`loads(x, f_ext)` adds them to a zeroed `f_ext`) and the prescription of
/// the clamped nodes. (The scheme's coefficients live in its iteration matrix, the iteration
/// settings are an argument of its `step`.)
pub struct StepProblem<'a> {
    pub body: &'a Body,
    pub free: &'a FreeNodes,
    pub loads: &'a dyn Fn(&[f64], &mut [f64]),
    pub prescribe: Prescription<'a>,
}

/// The vectors and body scratch of a residual evaluation (allocated once: evaluating the
/// residual allocates nothing). One per model, shared by whichever scheme steps it: its owner
/// sets the geometric stiffness before a step and reads the force scratch after one.
pub struct ResidualWorkspace {
    /// The internal force `f(x, ẋ)`, then the residual `r` (full `3N`).
    pub(super) internal: Vec<f64>,
    /// The external loads `f_ext(x)` (full `3N`; scratch between residuals).
    pub(super) external: Vec<f64>,
    /// The inertia force `M ẍ` (full `3N`; scratch between residuals).
    pub(super) inertia: Vec<f64>,
    /// [`folded_residual`]'s `ẍ − κ hR ū_F` and `K_FH ū_H` (full `3N`; scratch).
    folded: Vec<f64>,
    held_coupling: Vec<f64>,
    /// The body's force scratch: `ū`, `g` and the patch frames of the last residual.
    pub(super) force_scratch: ForceScratch,
    /// The geometric stiffness `K_G` of the current prestress (stiffening), if any: set by the
    /// owner before a step, constant during it.
    pub geometric_stiffness: Option<SymmetricCsr>,
}

impl ResidualWorkspace {
    pub fn new(body: &Body) -> ResidualWorkspace {
        let n3 = body.reference.len();
        ResidualWorkspace {
            internal: vec![0.0; n3],
            external: vec![0.0; n3],
            inertia: vec![0.0; n3],
            folded: vec![0.0; n3],
            held_coupling: vec![0.0; n3],
            force_scratch: body.force_scratch(),
            geometric_stiffness: None,
        }
    }

    /// The body's force scratch: `ū`, `g` of the last residual.
    pub fn force_scratch(&self) -> &ForceScratch {
        &self.force_scratch
    }

    /// The force scratch with `g = K ū` of the last residual, computed once if that residual
    /// was [`folded_residual`] ([`Body::complete_elastic_force`]).
    pub fn completed_force_scratch(&mut self, body: &Body) -> &ForceScratch {
        body.complete_elastic_force(&mut self.force_scratch);
        &self.force_scratch
    }

    /// Evaluates the internal force at `state` into `force` (full `3N`), so that the force
    /// scratch holds that state's `ū` and `g`: after a linear step, which stops at its first
    /// correction with the predictor's in it (docs/formulation.md, "The linear body"). The last
    /// residual's vectors are left alone. No allocation.
    pub fn observe(&mut self, body: &Body, state: &DynamicState, force: &mut [f64]) {
        body.internal_force(
            &state.position,
            &state.velocity,
            self.geometric_stiffness.as_ref(),
            &mut self.force_scratch,
            force,
        );
    }
}

/// The residual `r = M ẍ + f(x, ẋ) + Cᵀλ − f_ext(x)` (full `3N`, in `ws`, read it with
/// [`last_residual`]), and the body's kinematics on the way. `loads(x, f_ext)` adds the
/// external loads to a zeroed `f_ext`.
pub fn residual(
    body: &Body,
    free: &FreeNodes,
    state: &DynamicState,
    loads: &dyn Fn(&[f64], &mut [f64]),
    ws: &mut ResidualWorkspace,
) -> BodyKinematics {
    evaluate(body, free, state, loads, ws, None)
}

/// The residual with the one frame's elastic term folded into the generalized-α solve
/// (docs/formulation.md, "The stiffness folded into the solve"), for a body whose iteration
/// matrix is `S = hR S̄ hRᵀ`, `S̄ = c' M + k' K` on the free DOFs `F` (held `H`), with the frame
/// `R` of this residual. On the free DOFs it is
///
/// ```text
/// r° = r − hR K_FF ū_F − κ hR M_FF ū_F,   κ = c'/k'
///    = M (ẍ − κ hR ū⁰) + f'(x, ẋ) + hR K_FH ū_H + Cᵀλ − f_ext(x)
/// ```
///
/// (`ū⁰`: `ū` with its held part zeroed; `f'` the internal force without `hR K ū`; `M`
/// commutes with `hR`), so that `S̄⁻¹ hRᵀ r = S̄⁻¹ hRᵀ r° + ū_F / k'`: the solve gives the
/// iteration's correction without the product `K ū`, for one product with `M` (which the
/// inertia takes anyway) and `K`'s held columns. The held rows of `r°` are not the residual's.
/// The force scratch holds `ū` but not `K ū` ([`Body::complete_elastic_force`] computes it).
pub fn folded_residual(
    body: &Body,
    free: &FreeNodes,
    state: &DynamicState,
    loads: &dyn Fn(&[f64], &mut [f64]),
    ws: &mut ResidualWorkspace,
    kappa: f64,
) -> BodyKinematics {
    evaluate(body, free, state, loads, ws, Some(kappa))
}

/// [`residual`] (`kappa` `None`) or [`folded_residual`].
fn evaluate(
    body: &Body,
    free: &FreeNodes,
    state: &DynamicState,
    loads: &dyn Fn(&[f64], &mut [f64]),
    ws: &mut ResidualWorkspace,
    kappa: Option<f64>,
) -> BodyKinematics {
    let elastic = match kappa {
        None => ElasticTerm::Included,
        Some(_) => ElasticTerm::LeftOut,
    };
    let kin = body.internal_force_of(
        elastic,
        &state.position,
        &state.velocity,
        ws.geometric_stiffness.as_ref(),
        &mut ws.force_scratch,
        &mut ws.internal,
    );
    ws.external.fill(0.0);
    loads(&state.position, &mut ws.external);
    match kappa {
        None => body.mass_times(&state.acceleration, &mut ws.inertia),
        Some(kappa) => fold_stiffness(body, free, state, ws, &kin.frame.rotation, kappa),
    }
    for k in 0..ws.internal.len() {
        ws.internal[k] += ws.inertia[k] - ws.external[k];
    }
    add_constraint_forces(
        &free.constraints,
        &free.rigid,
        &state.position,
        &state.multipliers,
        &mut ws.internal,
    );
    kin
}

/// [`folded_residual`]'s terms in place of `hR K ū`: `M (ẍ − κ hR ū⁰)` into `ws.inertia`, and
/// `hR K_FH ū_H` added to the internal force's free rows.
fn fold_stiffness(
    body: &Body,
    free: &FreeNodes,
    state: &DynamicState,
    ws: &mut ResidualWorkspace,
    rotation: &Matrix3<f64>,
    kappa: f64,
) {
    let ubar = ws.force_scratch.local_deformation();
    ws.folded.copy_from_slice(&state.acceleration);
    for &i in &free.nodes {
        add_node(&mut ws.folded, i, &(-kappa * (rotation * node(ubar, i))));
    }
    body.mass_times(&ws.folded, &mut ws.inertia);
    // K_FH ū_H, in the co-moving frame (none on a body that holds no node).
    if free.clamped.is_empty() {
        return;
    }
    body.held_stiffness_product(&free.clamped, ubar, &mut ws.held_coupling);
    for &i in &free.nodes {
        add_node(
            &mut ws.internal,
            i,
            &(rotation * node(&ws.held_coupling, i)),
        );
    }
}

/// The residual left in `ws` by the last [`residual`] call.
pub fn last_residual(ws: &ResidualWorkspace) -> &[f64] {
    &ws.internal
}
