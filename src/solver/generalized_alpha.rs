//! Generalized-α time integration (Chung & Hulbert 1993, in the form of Arnold & Brüls 2007) of
//! `M ẍ + f(x, ẋ) = f_ext(x)` on the free DOFs, with the constant iteration matrix of docs/formulation.md
//! ("One factorization per step size"): `S = hR S̄ hRᵀ`, `S̄ = c_m M + c_d D + K`, factorised once per step size.
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

use super::anderson::{Anderson, DEFAULT_DEPTH};
use super::constraints::ConstraintFactor;
use super::fixed_point::{largest_correction, mix_update, Convergence};
use super::problem::{
    folded_residual, residual, DynamicState, FreeNodes, IterationSettings, ResidualWorkspace,
    StepProblem, StepReport,
};
use super::woodbury::NonlinearForceCorrection;
use crate::body::frame::{node, set_node};
use crate::body::{Body, BodyKinematics};
use crate::error::Result;
use crate::linalg::cholesky::{SolveWorkspace, SparseCholesky};
use crate::linalg::SymmetricCsr;
use nalgebra::Matrix3;

mod consistent;
mod local_error;
mod model_change;
pub mod sensitivity;
mod step_change;
mod tangent;
pub use consistent::{initial_acceleration, restart_for_load_change};
pub use model_change::{carry_over_force_change, Carried};
pub use tangent::TangentMatrix;

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

/// The factor of `S̄ = c_m M + c_d (α M + β K) + K` on the free DOFs for one step size, with its
/// solve workspace.
pub struct IterationMatrix {
    pub step_size: f64,
    /// The scheme whose coefficients `c_m`, `c_d` at `step_size` the matrix holds.
    pub scheme: GeneralizedAlpha,
    /// The coefficient of `M` in `S̄`, `c_m + c_d α` (1/s²).
    mass_coefficient: f64,
    /// The coefficient of `K` in `S̄`, `1 + c_d β`.
    stiffness_coefficient: f64,
    pub factor: SparseCholesky,
    workspace: SolveWorkspace,
    /// `Z = S̄⁻¹ Cᵀ` and the inverse Schur complement when there are point constraints.
    constraint: Option<ConstraintFactor>,
    /// For the full formulation: the tangent, refactorised every iteration (Newton).
    newton: Option<TangentMatrix>,
    /// With `f_nl`: the rank-3 Woodbury correction of its Jacobian.
    nonlinear: Option<NonlinearForceCorrection>,
    /// `ρ`, the forward error of a solve relative to its solution ([`forward_error_ratio`]):
    /// what a linear body's first correction leaves (docs/formulation.md, "The linear body").
    linear_error_ratio: f64,
}

/// A linear step stops after its first correction `Δx₁` when `LINEAR_SAFETY × ρ × |Δx₁|` (with
/// the stiffness folded into the solve, `× (|Δx₁| + |ū_F| / k')`) is
/// within the iteration's tolerance (`ρ`: [`forward_error_ratio`]): the forward error of the
/// solve, about `cond(S̄) ε` of the correction, depends on the right-hand side; a tenth of the
/// tolerance covers its spread.
pub const LINEAR_SAFETY: f64 = 10.0;

/// `ρ = |δ|∞ / |x|∞` for `x = S̄⁻¹ b` and its correction `δ = S̄⁻¹ (b − S̄ x)`, on a right-hand
/// side `b` with a part in every direction (a low-discrepancy sequence in `[−½, ½]`): the
/// forward error of one solve with `factor` relative to its solution, rounding of the residual
/// included (docs/formulation.md, "The linear body"). The same for every run at this matrix,
/// so a run repeats bit for bit. Allocates (once per factorization).
fn forward_error_ratio(
    s: &SymmetricCsr,
    factor: &SparseCholesky,
    workspace: &mut SolveWorkspace,
) -> f64 {
    let b: Vec<f64> = (0..s.n)
        .map(|i| (i as f64 * 0.618_033_988_749_895).fract() - 0.5)
        .collect();
    let mut x = b.clone();
    factor.solve_in_place(&mut x, workspace);
    let mut r = vec![0.0; s.n];
    s.mul_vec(&x, &mut r);
    r.iter_mut().zip(&b).for_each(|(r, b)| *r = b - *r);
    factor.solve_in_place(&mut r, workspace);
    let largest = |v: &[f64]| v.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    largest(&r) / largest(&x).max(f64::MIN_POSITIVE)
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
        let constraint = if !free.is_constrained() {
            None
        } else {
            Some(ConstraintFactor::new(
                &free.constraints,
                &free.rigid,
                &factor,
                &mut workspace,
            )?)
        };
        let nonlinear = ((body.options.nonlinear_forces || body.nonlinear_forces_switchable)
            && body.single_frame())
        .then(|| NonlinearForceCorrection::new(body, free, &factor, &mut workspace));
        let linear_error_ratio = forward_error_ratio(&s, &factor, &mut workspace);
        Ok(IterationMatrix {
            step_size: h,
            scheme: *scheme,
            mass_coefficient: c_m + c_d * damping_alpha,
            stiffness_coefficient: 1.0 + c_d * damping_beta,
            factor,
            workspace,
            constraint,
            newton,
            nonlinear,
            linear_error_ratio,
        })
    }
}

/// Generalized-α's work vectors of a step besides the residual's (allocated once: a step
/// allocates nothing).
pub struct StepWorkspace {
    /// The free part of the residual in the co-moving frame, then the solution of `S̄ y = r̄`.
    reduced: Vec<f64>,
    /// The state at the start of the step (carried over to the step's length).
    previous: DynamicState,
    /// The state at the start of a step of a new length before it was carried over
    /// ([`step_change::change_step`]): what a step that fails leaves.
    unchanged: DynamicState,
    /// Anderson's acceleration: its history, the iterate `z = [x_F, λ]` and its update.
    anderson: Anderson,
    iterate: Vec<f64>,
    update: Vec<f64>,
    /// `Δλ` of [`restart_for_load_change`].
    multiplier_change: Vec<f64>,
    /// The local error's `d` and `M d` ([`IterationMatrix::local_error`]), flat `3N`.
    error: Vec<f64>,
    error_mass: Vec<f64>,
}

impl StepWorkspace {
    /// `d` of the last [`IterationMatrix::local_error`] (flat `3N`, global frame, m).
    pub fn local_error_field(&self) -> &[f64] {
        &self.error
    }

    /// Workspace with Anderson's acceleration of the default depth ([`DEFAULT_DEPTH`]).
    pub fn new(body: &Body, free: &FreeNodes) -> StepWorkspace {
        Self::with_anderson_depth(body, free, DEFAULT_DEPTH)
    }

    /// Workspace with Anderson's acceleration of history `depth` (0: the plain iteration).
    pub fn with_anderson_depth(body: &Body, free: &FreeNodes, depth: usize) -> StepWorkspace {
        let nz = free.dof_count() + free.multiplier_count();
        StepWorkspace {
            anderson: Anderson::new(depth, nz, free.dof_count()),
            iterate: vec![0.0; nz],
            update: vec![0.0; nz],
            multiplier_change: vec![0.0; free.multiplier_count()],
            reduced: vec![0.0; free.dof_count()],
            previous: DynamicState::zeros(body.reference.len(), free.multiplier_count()),
            unchanged: DynamicState::zeros(body.reference.len(), free.multiplier_count()),
            error: vec![0.0; body.reference.len()],
            error_mass: vec![0.0; body.reference.len()],
        }
    }
}

/// One step `t → t + h` of `state`. The clamped nodes are set by `prescribe(t + h, state)`; the
/// free ones follow from the iteration. `forces` holds the residual's vectors and the geometric
/// stiffness of stiffening, if set; after the step its force scratch holds `ū`, `g` of the last
/// iterate. On failure (no convergence, non-finite values) `state` is left as it was and the
/// error is an [`crate::ErrorKind::Discard`].
pub fn step(
    problem: &StepProblem,
    matrix: &mut IterationMatrix,
    settings: &IterationSettings,
    h: f64,
    state: &mut DynamicState,
    ws: &mut StepWorkspace,
    forces: &mut ResidualWorkspace,
) -> Result<StepReport> {
    let changed = state.step_size > 0.0 && state.step_size != h;
    if changed {
        ws.unchanged.copy_from(state);
        step_change::change_step(&matrix.scheme, problem.body, problem.free, h, state);
    }
    ws.previous.copy_from(state);
    let result = iterate(problem, matrix, settings, h, state, ws, forces);
    match result {
        Ok(_) => state.step_size = h,
        Err(_) if changed => state.copy_from(&ws.unchanged),
        Err(_) => state.copy_from(&ws.previous),
    }
    result
}

/// The fixed-point iteration of a step from the predictor: per iteration the residual, the
/// plain correction `g = −P⁻¹ r` ([`IterationMatrix::plain_update`]), the stopping test
/// ([`Convergence`]), Anderson's mixing and the update of `x`, `ẋ`, `ẍ` and `λ`.
fn iterate(
    problem: &StepProblem,
    matrix: &mut IterationMatrix,
    settings: &IterationSettings,
    h: f64,
    state: &mut DynamicState,
    ws: &mut StepWorkspace,
    forces: &mut ResidualWorkspace,
) -> Result<StepReport> {
    let StepProblem {
        body, free, loads, ..
    } = *problem;
    let scheme = matrix.scheme;
    predict(&scheme, problem, h, &ws.previous, state);
    // Newton's matrix is refactored at every iteration: its last contraction says nothing of
    // the next step's first correction.
    let carried = if matrix.newton.is_none() {
        ws.previous.iteration_error_ratio
    } else {
        f64::INFINITY
    };
    let mut convergence = Convergence::new("", settings, state.time, h).carrying(carried);
    ws.anderson.reset();
    // A linear body's step is linear with the iteration matrix as its exact Jacobian: the
    // first correction solves it, up to the solve's forward error (docs/formulation.md, "The
    // linear body").
    let linear = body.steps_linearly(forces.geometric_stiffness.is_some())
        && matrix.constraint.is_none()
        && matrix.newton.is_none();
    // The one frame's elastic term folded into the solve (docs/formulation.md, "The stiffness
    // folded into the solve"): the iteration's corrections without the product `K ū`.
    let folded = matrix.folds_stiffness(body);
    let kappa = matrix.mass_coefficient / matrix.stiffness_coefficient;
    for iteration in 1..=settings.max_iterations {
        let kin = if folded {
            folded_residual(body, free, state, loads, forces, kappa)
        } else {
            residual(body, free, state, loads, forces)
        };
        if iteration == 1 {
            matrix.freeze_nonlinear_jacobian(body, free, &kin, &state.position, forces);
        }
        let frame = matrix.iteration_frame(body, free, &kin, &state.position)?;
        let largest = matrix.plain_update(body, free, &frame, state, ws, forces, folded);
        // The solve's forward error is `ρ` of its solution, which folded is
        // `−hRᵀ Δx₁ − ū_F / k'`.
        let solved = linear
            && iteration == 1
            && LINEAR_SAFETY
                * matrix.linear_error_ratio
                * (largest
                    + if folded {
                        matrix.folded_size(free, forces)
                    } else {
                        0.0
                    })
                <= settings.absolute_tolerance;
        let converged = convergence.converged(largest)? || solved;
        if matrix.newton.is_none() {
            mix_update(&mut ws.anderson, converged, &ws.iterate, &mut ws.update);
        }
        apply_update(&scheme, h, free, state, ws);
        if converged {
            update_pseudo_acceleration(&scheme, free, &ws.previous, state);
            if iteration == 1 && settings.estimate_error.is_some() {
                // The error control reads the deformation from the last residual's scratch:
                // the end of the step's, not the predictor's (a linear step stops at once).
                residual(body, free, state, loads, forces);
            }
            state.iteration_error_ratio = convergence.error_ratio();
            let error_estimate = settings
                .estimate_error
                .map(|enough| matrix.local_error(body, free, &frame, state, ws, forces, enough));
            return Ok(StepReport {
                iterations: iteration,
                last_correction: convergence.last_correction(),
                error_estimate,
            });
        }
    }
    Err(convergence.failure())
}

/// The predictor at `t_{n+1} = t_n + h` from the step's start `prev`: for the free nodes
/// `ẍ_{n+1} = ẍ_n`, then `a_{n+1}`, `x_{n+1}`, `ẋ_{n+1}` from the update formulas; the clamped
/// nodes' positions are prescribed at `t_{n+1}` ([`follow_prescribed_positions`]).
fn predict(
    scheme: &GeneralizedAlpha,
    problem: &StepProblem,
    h: f64,
    prev: &DynamicState,
    state: &mut DynamicState,
) {
    predict_free(scheme, problem.free, h, prev, state);
    state.time = prev.time + h;
    (problem.prescribe)(state.time, state);
    follow_prescribed_positions(scheme, problem.free, h, prev, state);
}

/// The predictor's free nodes ([`predict`]).
fn predict_free(
    scheme: &GeneralizedAlpha,
    free: &FreeNodes,
    h: f64,
    prev: &DynamicState,
    state: &mut DynamicState,
) {
    let GeneralizedAlpha {
        alpha_m,
        alpha_f,
        beta,
        gamma,
    } = *scheme;
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
}

/// The clamped nodes' velocities, accelerations and pseudo-accelerations at `t_{n+1}` from
/// their prescribed positions, by the same update formulas as the free nodes' (solved for
/// `a_{n+1}` from `x_{n+1}`), so that the scheme sees one consistent motion: a jump of the
/// driving velocity at a communication point becomes a finite acceleration over the step, whose
/// inertia the reaction then carries.
fn follow_prescribed_positions(
    scheme: &GeneralizedAlpha,
    free: &FreeNodes,
    h: f64,
    prev: &DynamicState,
    state: &mut DynamicState,
) {
    let GeneralizedAlpha {
        alpha_m,
        alpha_f,
        beta,
        gamma,
    } = *scheme;
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
}

impl IterationMatrix {
    /// The Woodbury correction of `f_nl`, while `f_nl` is on (`model.auto` switches it between
    /// steps).
    fn active_nonlinear(&mut self, body: &Body) -> Option<&mut NonlinearForceCorrection> {
        self.nonlinear
            .as_mut()
            .filter(|_| body.options.nonlinear_forces && body.single_frame())
    }

    /// Freezes the `f_nl` Jacobian of the Woodbury correction over the step at the predictor
    /// (the first residual's `ū`, `g` and `H⁻¹`, `H` the frame's rotation sensitivity).
    fn freeze_nonlinear_jacobian(
        &mut self,
        body: &Body,
        free: &FreeNodes,
        kin: &BodyKinematics,
        position: &[f64],
        forces: &ResidualWorkspace,
    ) {
        if let Some(correction) = self.active_nonlinear(body) {
            let h_inv = body
                .frame_weights
                .rotation_sensitivity(&kin.frame, position)
                .try_inverse()
                .unwrap_or_else(Matrix3::zeros);
            correction.update(
                body,
                free,
                forces.force_scratch.local_deformation(),
                forces.force_scratch.elastic_force(),
                &h_inv,
            );
        }
    }

    /// The rotation `R` of this iteration's matrix `hR S̄ hRᵀ`: reduced strain, the constant
    /// matrix in the co-moving frame (`R` the frame's rotation); full formulation, Newton on the
    /// tangent at the current positions `x` in the global frame (`R = I`, the factor and the
    /// constraints' Schur complement refactorised).
    fn iteration_frame(
        &mut self,
        body: &Body,
        free: &FreeNodes,
        kin: &BodyKinematics,
        x: &[f64],
    ) -> Result<Matrix3<f64>> {
        let Some(newton) = &mut self.newton else {
            return Ok(kin.frame.rotation);
        };
        newton.refactor(body, free, x, &mut self.factor)?;
        if self.constraint.is_some() {
            self.constraint = Some(ConstraintFactor::new(
                &free.constraints,
                &free.rigid,
                &self.factor,
                &mut self.workspace,
            )?);
        }
        Ok(Matrix3::identity())
    }

    /// The plain update `g = [Δx_F, Δλ]` of the iterate `z = [x_F, λ]` (both into `ws`): the free
    /// residual rotated into each node's frame, one solve with the constant factor (with the
    /// Woodbury correction of `f_nl` and the constraints' Schur complement, which sets the new
    /// `λ` in `state`), rotated back. Each node's rotation is the frame's `frame`, or with patches
    /// (and no point constraints, whose Schur complement is built in the body frame, nor Newton)
    /// the frame of the node's patch, so that the matrix follows each part of a strongly bent
    /// body. Returns the largest position correction ([`largest_correction`]).
    #[allow(clippy::too_many_arguments)]
    fn plain_update(
        &mut self,
        body: &Body,
        free: &FreeNodes,
        frame: &Matrix3<f64>,
        state: &mut DynamicState,
        ws: &mut StepWorkspace,
        forces: &ResidualWorkspace,
        folded: bool,
    ) -> f64 {
        let rotation = self.node_rotation(body, frame, forces);
        gather_iterate(free, state, &mut ws.iterate);
        for (k, &i) in free.nodes.iter().enumerate() {
            let r = rotation(i).transpose() * node(&forces.internal, i);
            set_node(&mut ws.reduced, k, &r);
        }
        self.factor
            .solve_in_place(&mut ws.reduced, &mut self.workspace);
        if folded {
            // S̄⁻¹ hRᵀ r = S̄⁻¹ hRᵀ r° + ū_F / k' (`folded_residual`).
            let ubar = forces.force_scratch.local_deformation();
            let inverse = 1.0 / self.stiffness_coefficient;
            for (k, &i) in free.nodes.iter().enumerate() {
                for d in 0..3 {
                    ws.reduced[3 * k + d] += inverse * ubar[3 * i + d];
                }
            }
        }
        if let Some(correction) = self.active_nonlinear(body) {
            correction.correct(&mut ws.reduced);
        }
        if let Some(constraint) = &mut self.constraint {
            let (x, lambda) = (&state.position, &mut state.multipliers);
            constraint.correct(
                &free.constraints,
                &free.rigid,
                x,
                frame,
                &mut ws.reduced,
                lambda,
            );
        }
        for (k, &i) in free.nodes.iter().enumerate() {
            let dx = -(rotation(i) * node(&ws.reduced, k));
            set_node(&mut ws.update, k, &dx);
        }
        let nf3 = free.dof_count();
        let largest = largest_correction(0.0, &ws.update[..nf3]);
        for (u, (&new, &old)) in ws.update[nf3..]
            .iter_mut()
            .zip(state.multipliers.iter().zip(&ws.iterate[nf3..]))
        {
            *u = new - old;
        }
        largest
    }
}

impl IterationMatrix {
    /// Whether the iteration folds `body`'s elastic term into its solve ([`folded_residual`]):
    /// the term must be the one frame's `hR K ū` with this matrix's `K` and `hR` the residual's
    /// own frame, so one frame, no `f_nl` (its moment reads `K ū`), not the full formulation
    /// and not Newton's tangent.
    fn folds_stiffness(&self, body: &Body) -> bool {
        body.single_frame()
            && body.full.is_none()
            && !body.options.nonlinear_forces
            && self.newton.is_none()
    }

    /// `|ū_F|∞ / k'`: the part of a folded solve's solution that the correction does not hold
    /// (a linear step's forward error is `ρ` of the whole solution).
    fn folded_size(&self, free: &FreeNodes, forces: &ResidualWorkspace) -> f64 {
        let ubar = forces.force_scratch.local_deformation();
        let largest = free.nodes.iter().fold(0.0_f64, |m, &i| {
            ubar[3 * i..3 * i + 3].iter().fold(m, |m, u| m.max(u.abs()))
        });
        largest / self.stiffness_coefficient
    }

    /// The rotation of node `i`'s rows in `hR S̄ hRᵀ`: its patch's frame with several frames
    /// (unconstrained, reduced strain), else the iteration's `frame`.
    fn node_rotation<'a>(
        &self,
        body: &'a Body,
        frame: &'a Matrix3<f64>,
        forces: &'a ResidualWorkspace,
    ) -> impl Fn(usize) -> Matrix3<f64> + 'a {
        // (A reduced body's coordinates belong to no patch: each slab's force acts on all of
        // them.)
        let patches = body.patches.as_ref().filter(|_| {
            self.constraint.is_none() && self.newton.is_none() && body.reduction.is_none()
        });
        let scratch = &forces.force_scratch;
        move |i: usize| match patches {
            Some(p) => scratch.patch_rotation(p.node_patch[i]),
            None => *frame,
        }
    }
}

/// The iterate `z = [x_F, λ]` of Anderson's acceleration: the free positions and the multipliers.
fn gather_iterate(free: &FreeNodes, state: &DynamicState, z: &mut [f64]) {
    for (k, &i) in free.nodes.iter().enumerate() {
        z[3 * k..3 * k + 3].copy_from_slice(&state.position[3 * i..3 * i + 3]);
    }
    z[free.dof_count()..].copy_from_slice(&state.multipliers);
}

/// Applies the update `[Δx_F, Δλ]` of `ws`: `x += Δx`, `ẋ += c_d Δx`, `ẍ += c_m Δx` on the free
/// DOFs, `λ = λ_z + Δλ` from the iterate's `λ_z`.
fn apply_update(
    scheme: &GeneralizedAlpha,
    h: f64,
    free: &FreeNodes,
    state: &mut DynamicState,
    ws: &StepWorkspace,
) {
    let c_m = scheme.mass_coefficient(h);
    let c_d = scheme.damping_coefficient(h);
    for (k, &i) in free.nodes.iter().enumerate() {
        for d in 0..3 {
            let (j, dx) = (3 * i + d, ws.update[3 * k + d]);
            state.position[j] += dx;
            state.velocity[j] += c_d * dx;
            state.acceleration[j] += c_m * dx;
        }
    }
    let nf3 = free.dof_count();
    for (l, (&z, &u)) in state
        .multipliers
        .iter_mut()
        .zip(ws.iterate[nf3..].iter().zip(&ws.update[nf3..]))
    {
        *l = z + u;
    }
}

/// The converged step's pseudo-accelerations of the free nodes:
/// `a_{n+1} = (α_f ẍ_n − α_m a_n + (1 − α_f) ẍ_{n+1}) / (1 − α_m)`.
fn update_pseudo_acceleration(
    scheme: &GeneralizedAlpha,
    free: &FreeNodes,
    prev: &DynamicState,
    state: &mut DynamicState,
) {
    let GeneralizedAlpha {
        alpha_m, alpha_f, ..
    } = *scheme;
    for &i in &free.nodes {
        for d in 3 * i..3 * i + 3 {
            state.pseudo_acceleration[d] = (alpha_f * prev.acceleration[d]
                - alpha_m * prev.pseudo_acceleration[d]
                + (1.0 - alpha_f) * state.acceleration[d])
                / (1.0 - alpha_m);
        }
    }
}
