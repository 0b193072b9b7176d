//! Generalized-α time integration (Chung & Hulbert 1993, in the form of Arnold & Brüls 2007) of
//! `M ẍ + f(x, ẋ) = f_ext(x)` on the free DOFs, with the constant iteration matrix of DESIGN.md
//! section 3: `S = hR S̄ hRᵀ`, `S̄ = c_m M + c_d D + K`, factorised once per step size.
//!
//! Per step, with the pseudo-acceleration `a` (Arnold & Brüls):
//!
//! ```text
//! (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) ẍ_{n+1} + α_f ẍ_n
//! x_{n+1} = x_n + h ẋ_n + h² (½ − β) a_n + h² β a_{n+1}
//! ẋ_{n+1} = ẋ_n + h (1 − γ) a_n + h γ a_{n+1}
//! M ẍ_{n+1} + f(x_{n+1}, ẋ_{n+1}) = f_ext(x_{n+1})          (equilibrium at t_{n+1})
//! ```
//!
//! The unknown is `ẍ_{n+1}`; a correction `Δx` of the positions moves `ẍ` by `c_m Δx` and `ẋ` by
//! `c_d Δx` with `c_m = (1 − α_m) / ((1 − α_f) β h²)` and `c_d = γ / (β h)`, so the Newton matrix is
//! `c_m M + c_d D + K_T`. The fixed-point (modified Newton) iteration replaces `K_T` with the
//! rotated constant `hR K hRᵀ`: each iteration rotates the residual into the co-moving frame, does
//! one forward and one backward triangular solve with the constant factor of `S̄` and rotates back.
//! With `ρ∞ = 1` the scheme is the trapezoidal rule (energy-conserving on linear problems).

use super::anderson::Anderson;
use super::consistent_acceleration::ConsistentAcceleration;
use super::constraints::{add_constraint_forces, ConstraintFactor, PointConstraint};
use super::woodbury::NonlinearForceCorrection;
use crate::body::frame::{node, set_node};
use crate::body::{Body, BodyKinematics, ForceScratch};
use crate::error::{Error, Result};
use crate::linalg::cholesky::{SolveWorkspace, SparseCholesky};
use crate::linalg::SymmetricCsr;

/// Generalized-α coefficients from the spectral radius at infinite frequency `ρ∞ ∈ [0, 1]`:
/// `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`, `γ = ½ − α_m + α_f`, `β = ¼ (1 − α_m + α_f)²`
/// (second order, unconditionally stable on linear problems).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneralizedAlpha {
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub beta: f64,
    pub gamma: f64,
}

impl GeneralizedAlpha {
    pub fn new(rho_inf: f64) -> GeneralizedAlpha {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        GeneralizedAlpha {
            alpha_m,
            alpha_f,
            gamma: 0.5 - alpha_m + alpha_f,
            beta: 0.25 * (1.0 - alpha_m + alpha_f).powi(2),
        }
    }

    /// `c_m = (1 − α_m) / ((1 − α_f) β h²)` (1/s²): `∂ẍ_{n+1}/∂x_{n+1}`.
    pub fn mass_coefficient(&self, h: f64) -> f64 {
        (1.0 - self.alpha_m) / ((1.0 - self.alpha_f) * self.beta * h * h)
    }

    /// `c_d = γ / (β h)` (1/s): `∂ẋ_{n+1}/∂x_{n+1}`.
    pub fn damping_coefficient(&self, h: f64) -> f64 {
        self.gamma / (self.beta * h)
    }
}

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
}

impl FreeNodes {
    /// Free nodes of `body` when `clamped` nodes are held.
    pub fn new(body: &Body, clamped: &[bool]) -> FreeNodes {
        let nodes: Vec<usize> = (0..body.node_count()).filter(|&i| !clamped[i]).collect();
        let dofs: Vec<usize> = nodes
            .iter()
            .flat_map(|&i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect();
        let mass = body.mass_matrix.kron_i3().submatrix(&dofs);
        let stiffness = body.stiffness_matrix.submatrix(&dofs);
        let scalar_mass = body.mass_matrix.submatrix(&nodes);
        FreeNodes {
            nodes,
            clamped: (0..body.node_count()).filter(|&i| clamped[i]).collect(),
            mass,
            stiffness,
            scalar_mass,
            constraints: Vec::new(),
        }
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
        let mut free_rows = Vec::with_capacity(nodes.len());
        for &n in nodes {
            match self.nodes.binary_search(&n) {
                Ok(k) => free_rows.push(3 * k),
                Err(_) => {
                    return Err(Error::new(format!(
                        "interface '{name}': node {n} is also held by a fixed support or motion interface"
                    )))
                }
            }
        }
        self.constraints.push(PointConstraint {
            nodes: nodes.to_vec(),
            weights: weights.iter().map(|w| w / total).collect(),
            free_rows,
            target,
        });
        Ok(())
    }

    /// Number of Lagrange multipliers (3 per point constraint).
    pub fn multiplier_count(&self) -> usize {
        3 * self.constraints.len()
    }

    /// Number of free DOFs.
    pub fn dof_count(&self) -> usize {
        3 * self.nodes.len()
    }
}

/// The factor of `S̄ = c_m M + c_d (α M + β K) + K` on the free DOFs for one step size, with its
/// solve workspace.
pub struct IterationMatrix {
    pub step_size: f64,
    /// The scheme whose coefficients `c_m`, `c_d` at `step_size` the matrix holds.
    pub scheme: GeneralizedAlpha,
    pub factor: SparseCholesky,
    workspace: SolveWorkspace,
    /// `Z = S̄⁻¹ Cᵀ` and the inverse Schur complement when there are point constraints.
    constraint: Option<ConstraintFactor>,
    /// For the full formulation: the tangent, refactorised every iteration (Newton).
    newton: Option<TangentMatrix>,
    /// With `f_nl`: the rank-3 Woodbury correction of its Jacobian.
    nonlinear: Option<NonlinearForceCorrection>,
}

/// Newton's iteration matrix of the full formulation, `S = c_m' M + c_k K_T(x)` on the free DOFs
/// (`c_m' = c_m + c_d α`, `c_k = 1 + c_d β`: the damping enters with the linear `K`'s
/// coefficients), reassembled from the tangent `K_T` at every iteration.
pub struct TangentMatrix {
    tangent: SymmetricCsr,
    iteration: SymmetricCsr,
    /// For each entry of `iteration`: its index in `tangent` and in `FreeNodes::mass` (or
    /// `usize::MAX` where `M` has none).
    tangent_index: Vec<usize>,
    mass_index: Vec<usize>,
    mass_coefficient: f64,
    stiffness_coefficient: f64,
}

impl TangentMatrix {
    fn new(
        body: &Body,
        free: &FreeNodes,
        pattern: SymmetricCsr,
        mass_coefficient: f64,
        stiffness_coefficient: f64,
    ) -> TangentMatrix {
        let full = body.full.as_ref().expect("the full formulation");
        let tangent = full.tangent_pattern();
        let dofs: Vec<usize> = free
            .nodes
            .iter()
            .flat_map(|&i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect();
        let find = |m: &SymmetricCsr, row: usize, col: usize| {
            let range = m.row_ptr[row]..m.row_ptr[row + 1];
            m.col_idx[range.clone()]
                .binary_search(&col)
                .map(|k| range.start + k)
                .unwrap_or(usize::MAX)
        };
        let mut tangent_index = Vec::with_capacity(pattern.nnz());
        let mut mass_index = Vec::with_capacity(pattern.nnz());
        for row in 0..pattern.n {
            for k in pattern.row_ptr[row]..pattern.row_ptr[row + 1] {
                let col = pattern.col_idx[k];
                tangent_index.push(find(&tangent, dofs[row], dofs[col]));
                mass_index.push(find(&free.mass, row, col));
            }
        }
        TangentMatrix {
            tangent,
            iteration: pattern,
            tangent_index,
            mass_index,
            mass_coefficient,
            stiffness_coefficient,
        }
    }

    /// Assembles `S` at positions `x` and refactorises `factor` numerically (symbolic reused).
    fn refactor(
        &mut self,
        body: &Body,
        free: &FreeNodes,
        x: &[f64],
        factor: &mut SparseCholesky,
    ) -> Result<()> {
        let full = body.full.as_ref().expect("the full formulation");
        full.tangent_stiffness(x, &mut self.tangent);
        self.fill(free);
        if factor.refactor(&self.iteration).is_ok() {
            return Ok(());
        }
        // An iterate far from equilibrium (e.g. the first one after a step load) can make the
        // St. Venant–Kirchhoff tangent indefinite: this iteration uses the linear K instead
        // (a modified-Newton step); the next one tries the tangent again.
        self.tangent
            .values
            .copy_from_slice(&body.stiffness_matrix.values);
        self.fill(free);
        factor.refactor(&self.iteration).map_err(|e| {
            Error::discard(format!(
                "the iteration matrix of the full formulation is not positive definite ({})",
                e.message
            ))
        })
    }

    /// `S = c_m' M + c_k K_T` on the free DOFs from the current `tangent`.
    fn fill(&mut self, free: &FreeNodes) {
        for (k, value) in self.iteration.values.iter_mut().enumerate() {
            let t = self.tangent_index[k];
            let m = self.mass_index[k];
            *value = self.stiffness_coefficient
                * if t == usize::MAX {
                    0.0
                } else {
                    self.tangent.values[t]
                }
                + self.mass_coefficient
                    * if m == usize::MAX {
                        0.0
                    } else {
                        free.mass.values[m]
                    };
        }
    }
}

impl IterationMatrix {
    /// Assembles and factorises `S̄` for step `h` (the only factorization of a run at this `h`).
    pub fn new(
        body: &Body,
        free: &FreeNodes,
        scheme: &GeneralizedAlpha,
        h: f64,
        damping_alpha: f64,
        damping_beta: f64,
    ) -> Result<IterationMatrix> {
        let c_m = scheme.mass_coefficient(h);
        let c_d = scheme.damping_coefficient(h);
        let s = SymmetricCsr::linear_combination(
            c_m + c_d * damping_alpha,
            &free.mass,
            1.0 + c_d * damping_beta,
            &free.stiffness,
        );
        let factor = SparseCholesky::new(&s)?;
        let newton = body.full.is_some().then(|| {
            TangentMatrix::new(
                body,
                free,
                s.clone(),
                c_m + c_d * damping_alpha,
                1.0 + c_d * damping_beta,
            )
        });
        let mut workspace = factor.solve_scratch();
        let constraint = if free.constraints.is_empty() {
            None
        } else {
            Some(ConstraintFactor::new(
                &free.constraints,
                &factor,
                &mut workspace,
            )?)
        };
        let nonlinear = ((body.options.nonlinear_forces || body.nonlinear_forces_switchable)
            && body.single_frame())
        .then(|| NonlinearForceCorrection::new(body, free, &factor, &mut workspace));
        Ok(IterationMatrix {
            step_size: h,
            scheme: *scheme,
            factor,
            workspace,
            constraint,
            newton,
            nonlinear,
        })
    }
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
}

impl DynamicState {
    /// Copies `other` into `self` without allocating.
    pub fn copy_from(&mut self, other: &DynamicState) {
        self.time = other.time;
        self.position.copy_from_slice(&other.position);
        self.velocity.copy_from_slice(&other.velocity);
        self.acceleration.copy_from_slice(&other.acceleration);
        self.pseudo_acceleration
            .copy_from_slice(&other.pseudo_acceleration);
        self.multipliers.copy_from_slice(&other.multipliers);
    }
}

/// What a step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    pub iterations: usize,
    /// Largest position correction of the last iteration (m).
    pub last_correction: f64,
}

/// Settings of the fixed-point iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IterationSettings {
    /// Converged when the estimated position error of the iterate is below this (m): the
    /// largest correction, or after the second iteration [`remaining_error`] of it.
    pub absolute_tolerance: f64,
    pub max_iterations: usize,
}

/// The largest contraction `θ = ‖Δ_k‖/‖Δ_{k−1}‖` of successive corrections for which the
/// error estimate [`remaining_error`] is trusted (Hairer & Wanner, *Solving ODEs II*, IV.8: the
/// simplified Newton iteration of implicit Runge–Kutta methods stops on this estimate). Above it
/// the iteration runs until the correction itself is below the tolerance.
pub const TRUSTED_CONTRACTION: f64 = 0.5;

/// The position error left after applying correction `Δ_k` of a linearly converging iteration
/// with contraction `θ = ‖Δ_k‖/‖Δ_{k−1}‖`: the corrections still to come sum to at most
/// `θ/(1−θ) ‖Δ_k‖` (infinity when `θ` exceeds [`TRUSTED_CONTRACTION`] or is unknown). With the
/// constant iteration matrix `θ` is small (the rotation of the frame over a step: 1e-4 to 1e-6 on
/// B1), so this accepts after two iterations a step that the correction alone accepts after
/// three, with an estimated error far below the tolerance.
pub fn remaining_error(correction: f64, previous_correction: f64) -> f64 {
    let theta = correction / previous_correction;
    if previous_correction.is_finite() && theta.is_finite() && theta <= TRUSTED_CONTRACTION {
        theta / (1.0 - theta) * correction
    } else {
        f64::INFINITY
    }
}

/// Default history depth of Anderson's acceleration ([`super::anderson`]) of the fixed-point
/// iteration: 5 columns cost 10 vectors of the free DOFs and `O(5 n)` per iteration; on B3 with
/// patches deeper histories gave no fewer iterations (`examples/iteration_policy.rs`).
pub const DEFAULT_ANDERSON_DEPTH: usize = 5;

/// Work vectors of a step (allocated once: a step allocates nothing).
pub struct StepWorkspace {
    internal: Vec<f64>,
    external: Vec<f64>,
    inertia: Vec<f64>,
    reduced: Vec<f64>,
    force_scratch: ForceScratch,
    previous: DynamicState,
    /// Anderson's acceleration: its history, the iterate `z = [x_F, λ]` and its update.
    anderson: Anderson,
    iterate: Vec<f64>,
    update: Vec<f64>,
    multiplier_change: Vec<f64>,
    /// The geometric stiffness `K_G` of the current prestress (stiffening), if any: set by the
    /// owner before a step, constant during it.
    pub geometric_stiffness: Option<SymmetricCsr>,
}

impl StepWorkspace {
    /// The body's force scratch: `ū`, `g` of the last residual.
    pub fn force_scratch(&self) -> &ForceScratch {
        &self.force_scratch
    }

    /// The geometric stiffness (if any) and the force scratch, for another scheme's residual
    /// ([`super::radau`]) that shares this workspace's stiffening and strain watch.
    pub fn force_parts(&mut self) -> (Option<&SymmetricCsr>, &mut ForceScratch) {
        (self.geometric_stiffness.as_ref(), &mut self.force_scratch)
    }

    pub fn new(body: &Body, free: &FreeNodes) -> StepWorkspace {
        Self::with_anderson_depth(body, free, DEFAULT_ANDERSON_DEPTH)
    }

    /// Workspace with Anderson's acceleration of history `depth` (0: the plain iteration).
    pub fn with_anderson_depth(body: &Body, free: &FreeNodes, depth: usize) -> StepWorkspace {
        let n3 = body.reference.len();
        let nz = free.dof_count() + free.multiplier_count();
        StepWorkspace {
            anderson: Anderson::new(depth, nz, free.dof_count()),
            iterate: vec![0.0; nz],
            update: vec![0.0; nz],
            multiplier_change: vec![0.0; free.multiplier_count()],
            internal: vec![0.0; n3],
            external: vec![0.0; n3],
            inertia: vec![0.0; n3],
            reduced: vec![0.0; free.dof_count()],
            force_scratch: body.force_scratch(),
            previous: DynamicState {
                time: 0.0,
                position: vec![0.0; n3],
                velocity: vec![0.0; n3],
                acceleration: vec![0.0; n3],
                pseudo_acceleration: vec![0.0; n3],
                multipliers: vec![0.0; free.multiplier_count()],
            },
            geometric_stiffness: None,
        }
    }
}

/// The residual `r = M ẍ + f(x, ẋ) + Cᵀλ − f_ext(x)` (full `3N`, in `ws.internal`), and the
/// body's kinematics on the way. `loads(x, f_ext)` adds the external loads to a zeroed `f_ext`.
pub fn residual(
    body: &Body,
    free: &FreeNodes,
    state: &DynamicState,
    loads: &dyn Fn(&[f64], &mut [f64]),
    ws: &mut StepWorkspace,
) -> BodyKinematics {
    let kin = body.internal_force(
        &state.position,
        &state.velocity,
        ws.geometric_stiffness.as_ref(),
        &mut ws.force_scratch,
        &mut ws.internal,
    );
    ws.external.fill(0.0);
    loads(&state.position, &mut ws.external);
    body.mass_times(&state.acceleration, &mut ws.inertia);
    for k in 0..ws.internal.len() {
        ws.internal[k] += ws.inertia[k] - ws.external[k];
    }
    add_constraint_forces(&free.constraints, &state.multipliers, &mut ws.internal);
    kin
}

/// The residual left in `ws` by the last [`residual`] call.
pub fn last_residual(ws: &StepWorkspace) -> &[f64] {
    &ws.internal
}

/// Sets the positions, velocities and accelerations of the clamped (prescribed) nodes at a time.
pub type Prescription<'a> = &'a dyn Fn(f64, &mut DynamicState);

/// What a step of any scheme needs besides the state: the body, its free nodes and constraints,
/// the external loads (`loads(x, f_ext)` adds them to a zeroed `f_ext`) and the prescription of
/// the clamped nodes. (Generalized-α's own scheme lives in its [`IterationMatrix`], its iteration
/// settings are an argument of [`step`].)
pub struct StepProblem<'a> {
    pub body: &'a Body,
    pub free: &'a FreeNodes,
    pub loads: &'a dyn Fn(&[f64], &mut [f64]),
    pub prescribe: Prescription<'a>,
}

/// One step `t → t + h` of `state`. The clamped nodes are set by `prescribe(t + h, state)`; the
/// free ones follow from the iteration. On failure (no convergence, non-finite values) `state` is
/// left as it was and the error is an [`crate::ErrorKind::Discard`].
pub fn step(
    problem: &StepProblem,
    matrix: &mut IterationMatrix,
    settings: &IterationSettings,
    h: f64,
    state: &mut DynamicState,
    ws: &mut StepWorkspace,
) -> Result<StepReport> {
    ws.previous.copy_from(state);
    let result = iterate(problem, matrix, settings, h, state, ws);
    if result.is_err() {
        state.copy_from(&ws.previous);
    }
    result
}

fn iterate(
    problem: &StepProblem,
    matrix: &mut IterationMatrix,
    settings: &IterationSettings,
    h: f64,
    state: &mut DynamicState,
    ws: &mut StepWorkspace,
) -> Result<StepReport> {
    let StepProblem {
        body,
        free,
        loads,
        prescribe,
    } = *problem;
    let scheme = matrix.scheme;
    let GeneralizedAlpha {
        alpha_m,
        alpha_f,
        beta,
        gamma,
    } = scheme;
    let c_m = scheme.mass_coefficient(h);
    let c_d = scheme.damping_coefficient(h);
    let prev = &ws.previous;
    // Predictor ẍ_{n+1} = ẍ_n, then a, x, ẋ from the update formulas (free nodes only).
    for &i in &free.nodes {
        for d in 3 * i..3 * i + 3 {
            let acc = prev.acceleration[d];
            let a_new = (alpha_f * prev.acceleration[d] - alpha_m * prev.pseudo_acceleration[d]
                + (1.0 - alpha_f) * acc)
                / (1.0 - alpha_m);
            let a_old = prev.pseudo_acceleration[d];
            state.acceleration[d] = acc;
            state.position[d] = prev.position[d]
                + h * prev.velocity[d]
                + h * h * ((0.5 - beta) * a_old + beta * a_new);
            state.velocity[d] = prev.velocity[d] + h * ((1.0 - gamma) * a_old + gamma * a_new);
        }
    }
    state.time = prev.time + h;
    // Clamped nodes: positions prescribed at t_{n+1}; their velocities and accelerations follow
    // from the same update formulas as the free nodes', so that the scheme sees one consistent
    // motion (a jump of the driving velocity at a communication point becomes a finite
    // acceleration over the step, whose inertia the reaction then carries).
    prescribe(state.time, state);
    for &i in &free.clamped {
        for d in 3 * i..3 * i + 3 {
            let a_old = prev.pseudo_acceleration[d];
            let a_new = (state.position[d]
                - prev.position[d]
                - h * prev.velocity[d]
                - h * h * (0.5 - beta) * a_old)
                / (beta * h * h);
            state.velocity[d] = prev.velocity[d] + h * ((1.0 - gamma) * a_old + gamma * a_new);
            state.acceleration[d] = ((1.0 - alpha_m) * a_new + alpha_m * a_old
                - alpha_f * prev.acceleration[d])
                / (1.0 - alpha_f);
            state.pseudo_acceleration[d] = a_new;
        }
    }

    let mut last_correction = f64::INFINITY;
    ws.anderson.reset();
    for iteration in 1..=settings.max_iterations {
        let kin = residual(body, free, state, loads, ws);
        // The correction only while f_nl is on (`model.auto` switches it between steps).
        let nonlinear = matrix
            .nonlinear
            .as_mut()
            .filter(|_| body.options.nonlinear_forces);
        if let (1, Some(correction)) = (iteration, nonlinear) {
            // The f_nl Jacobian, frozen over the step at the predictor.
            let h_inv = body
                .frame_weights
                .rotation_sensitivity(&kin.frame, &state.position)
                .try_inverse()
                .unwrap_or_else(nalgebra::Matrix3::zeros);
            correction.update(
                body,
                free,
                ws.force_scratch.local_deformation(),
                ws.force_scratch.elastic_force(),
                &h_inv,
            );
        }
        // Reduced strain: the constant matrix in the co-moving frame. Full: Newton on the
        // tangent at the current positions, in the global frame.
        let r = if let Some(newton) = &mut matrix.newton {
            newton.refactor(body, free, &state.position, &mut matrix.factor)?;
            if matrix.constraint.is_some() {
                matrix.constraint = Some(ConstraintFactor::new(
                    &free.constraints,
                    &matrix.factor,
                    &mut matrix.workspace,
                )?);
            }
            nalgebra::Matrix3::identity()
        } else {
            kin.frame.rotation
        };
        // Each node's rotation: the body frame's, or with patches (and no point constraints,
        // whose Schur complement is built in the body frame) the frame of the node's patch, so
        // that the iteration matrix follows each part of a strongly bent body.
        let patches = body
            .patches
            .as_ref()
            .filter(|_| matrix.constraint.is_none() && matrix.newton.is_none());
        let scratch = &ws.force_scratch;
        let rotation = |i: usize| match patches {
            Some(p) => scratch.patch_rotation(p.node_patch[i]),
            None => r,
        };
        // The iterate z = [x_F, λ] before this correction (Anderson's acceleration).
        let nf3 = free.dof_count();
        for (k, &i) in free.nodes.iter().enumerate() {
            ws.iterate[3 * k..3 * k + 3].copy_from_slice(&state.position[3 * i..3 * i + 3]);
        }
        ws.iterate[nf3..].copy_from_slice(&state.multipliers);
        // Rotate the free part of the residual into the co-moving frame, solve, rotate back.
        for (k, &i) in free.nodes.iter().enumerate() {
            set_node(
                &mut ws.reduced,
                k,
                &(rotation(i).transpose() * node(&ws.internal, i)),
            );
        }
        matrix
            .factor
            .solve_in_place(&mut ws.reduced, &mut matrix.workspace);
        if let Some(correction) = matrix
            .nonlinear
            .as_ref()
            .filter(|_| body.options.nonlinear_forces)
        {
            correction.correct(&mut ws.reduced);
        }
        if let Some(constraint) = &mut matrix.constraint {
            constraint.correct(
                &free.constraints,
                &state.position,
                &r,
                &mut ws.reduced,
                &mut state.multipliers,
            );
        }
        // The plain update g = [Δx_F, Δλ]; Anderson's method mixes it with the history.
        let mut largest: f64 = 0.0;
        for (k, &i) in free.nodes.iter().enumerate() {
            let dx = -(rotation(i) * node(&ws.reduced, k));
            set_node(&mut ws.update, k, &dx);
            // A non-finite correction never counts as converged (f64::max would drop a NaN).
            largest = if dx.iter().all(|v| v.is_finite()) {
                largest.max(dx.amax())
            } else {
                f64::INFINITY
            };
        }
        for (u, (&new, &old)) in ws.update[nf3..]
            .iter_mut()
            .zip(state.multipliers.iter().zip(&ws.iterate[nf3..]))
        {
            *u = new - old;
        }
        // Decided on the plain correction, which is then the one applied: Anderson's mixed
        // update is not what the estimate describes.
        let converged = largest <= settings.absolute_tolerance
            || remaining_error(largest, last_correction) <= settings.absolute_tolerance;
        if largest.is_finite() && !converged && matrix.newton.is_none() {
            ws.anderson.accelerate(&ws.iterate, &mut ws.update);
        }
        for (k, &i) in free.nodes.iter().enumerate() {
            for d in 0..3 {
                let (j, dx) = (3 * i + d, ws.update[3 * k + d]);
                state.position[j] += dx;
                state.velocity[j] += c_d * dx;
                state.acceleration[j] += c_m * dx;
            }
        }
        for (l, (&z, &u)) in state
            .multipliers
            .iter_mut()
            .zip(ws.iterate[nf3..].iter().zip(&ws.update[nf3..]))
        {
            *l = z + u;
        }
        if !largest.is_finite() {
            return Err(Error::discard(format!(
                "step to t = {} (h = {h}): the iteration produced a non-finite correction",
                state.time
            )));
        }
        last_correction = largest;
        if converged {
            let prev = &ws.previous;
            for &i in &free.nodes {
                for d in 3 * i..3 * i + 3 {
                    state.pseudo_acceleration[d] = (alpha_f * prev.acceleration[d]
                        - alpha_m * prev.pseudo_acceleration[d]
                        + (1.0 - alpha_f) * state.acceleration[d])
                        / (1.0 - alpha_m);
                }
            }
            return Ok(StepReport {
                iterations: iteration,
                last_correction,
            });
        }
    }
    Err(Error::discard(format!(
        "step to t = {} (h = {h}) did not converge in {} iterations (last position correction {last_correction:.3e} m, tolerance {:.3e} m)",
        state.time, settings.max_iterations, settings.absolute_tolerance
    )))
}

/// Consistent initial acceleration on the free DOFs and multipliers:
/// `M_FF ẍ_F + Cᵀλ = (f_ext − f(x, ẋ) − M_FC ẍ_C)_F`, `C ẍ = 0`, with the clamped nodes'
/// accelerations `ẍ_C` as given in `state` ([`ConsistentAcceleration`]).
pub fn initial_acceleration(
    body: &Body,
    free: &FreeNodes,
    loads: &dyn Fn(&[f64], &mut [f64]),
    state: &mut DynamicState,
    ws: &mut StepWorkspace,
    mass: &mut ConsistentAcceleration,
) -> Result<()> {
    for &i in &free.nodes {
        state.acceleration[3 * i..3 * i + 3].fill(0.0);
    }
    state.multipliers.fill(0.0);
    residual(body, free, state, loads, ws);
    ws.internal.iter_mut().for_each(|r| *r = -*r);
    mass.solve(
        free,
        &ws.internal,
        &mut state.acceleration,
        &mut state.multipliers,
    );
    state
        .pseudo_acceleration
        .copy_from_slice(&state.acceleration);
    Ok(())
}

/// Restarts the scheme after the external loads jumped at `state.time` (held inputs change at a
/// communication point): the accelerations and the pseudo-accelerations of the free nodes gain
/// `Δẍ` and the multipliers `Δλ` from `M_FF Δẍ_F + CᵀΔλ = Δf_ext`, `C Δẍ = 0`, with
/// `Δf_ext = new_loads(x) − old_loads(x)`. Without it the scheme starts the step from the old
/// loads' acceleration (the left limit) and a jump costs an error of order `h`, which made the
/// scheme first order under inputs that change (`tests/convergence_order.rs`). For a linear
/// system this is exact superposition: the jump's response is a fresh start from rest with
/// the consistent acceleration `M⁻¹ Δf` (initialization's `a_0 = ẍ_0`). No allocation.
///
/// The slave does not call it: restarting at every jump of held inputs destabilised the
/// iterated coupling of two FMUs (see `Slave::do_step`); it is kept for importers' schemes that
/// want the zero-order-hold response of one FMU to second order.
pub fn restart_for_load_change(
    free: &FreeNodes,
    mass: &mut ConsistentAcceleration,
    old_loads: &dyn Fn(&[f64], &mut [f64]),
    new_loads: &dyn Fn(&[f64], &mut [f64]),
    state: &mut DynamicState,
    ws: &mut StepWorkspace,
) {
    ws.external.fill(0.0);
    new_loads(&state.position, &mut ws.external);
    ws.inertia.fill(0.0);
    old_loads(&state.position, &mut ws.inertia);
    for (new, old) in ws.external.iter_mut().zip(&ws.inertia) {
        *new -= old;
    }
    ws.inertia.fill(0.0);
    mass.solve(
        free,
        &ws.external,
        &mut ws.inertia,
        &mut ws.multiplier_change,
    );
    for &i in &free.nodes {
        for d in 3 * i..3 * i + 3 {
            state.acceleration[d] += ws.inertia[d];
            state.pseudo_acceleration[d] += ws.inertia[d];
        }
    }
    for (l, dl) in state.multipliers.iter_mut().zip(&ws.multiplier_change) {
        *l += dl;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn remaining_error_of_a_contraction() {
        // x_{k+1} = θ x_k: after a correction Δ the corrections still to come sum to
        // θ/(1−θ) Δ exactly.
        let theta: f64 = 0.1;
        let corrections: Vec<f64> = (0..6).map(|k| theta.powi(k)).collect();
        for k in 1..5 {
            let still_to_come: f64 =
                corrections[k + 1..].iter().sum::<f64>() + theta.powi(6) / (1.0 - theta); // the tail beyond the sample
            let estimate = remaining_error(corrections[k], corrections[k - 1]);
            assert!(
                (estimate - still_to_come).abs() <= 1e-12 * still_to_come,
                "{estimate} {still_to_come}"
            );
        }
        // No estimate from the first correction, a slow or a diverging iteration.
        assert_eq!(remaining_error(1e-3, f64::INFINITY), f64::INFINITY);
        assert_eq!(remaining_error(0.6, 1.0), f64::INFINITY);
        assert_eq!(remaining_error(2.0, 1.0), f64::INFINITY);
        assert_eq!(remaining_error(f64::NAN, 1.0), f64::INFINITY);
    }
}
