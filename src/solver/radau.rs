//! The implicit Runge–Kutta scheme of the seed paper: Radau IIA with 3 stages (order 5, stage
//! order 3, L-stable; Hairer & Wanner, *Solving ODEs II*, section IV.8), in constant-matrix form
//! (`solver.integrator = radauIIA`).
//!
//! The equations of motion `M ẍ + f(x, ẋ) = f_ext(t, x)` on the free DOFs, written for the stage
//! position increments `Z_i = X_i − x_n` (`i = 1..3`, stage times `t_n + c_i h`): the collocation
//! polynomial gives the stage velocities and accelerations
//!
//! ```text
//! V = h⁻¹ (A⁻¹ ⊗ I) Z,        Ẍ = h⁻² (A⁻² ⊗ I) Z − h⁻¹ (A⁻¹𝟙 ⊗ ẋ_n)        (A the Radau matrix)
//! r_i(Z) = M Ẍ_i + f(X_i, V_i) − f_ext(t_n + c_i h, X_i) = 0                    (stage equations)
//! ```
//!
//! and, since `c_3 = 1` (stiffly accurate), `x_{n+1} = X_3`, `ẋ_{n+1} = V_3`, `ẍ_{n+1} = Ẍ_3`.
//! Simplified Newton on `Z` with the constant matrix of docs/formulation.md, "One factorization per step size"
//! (`∂f/∂x ≈ hR K hRᵀ`, `∂f/∂ẋ ≈ hR D hRᵀ`, `D = α M + β K` the Rayleigh damping):
//!
//! `J ≈ diag(R_s) (h⁻² A⁻² ⊗ M + h⁻¹ A⁻¹ ⊗ D + I ⊗ K) diag(R_s)ᵀ`, `R_s` the co-moving frame of
//! stage `s`: each stage's stiffness block is then exact up to the variation of `R`, and the
//! mass coupling of stages `s`, `j` carries their relative rotation (`≈ ω h`), which the
//! iteration resolves. (One frame for all stages instead rotates every stage's stiffness by
//! that angle: on B3 at 6 rad/s this took 10–33 iterations per step and step halvings, against
//! 4 with the frame per stage.)
//!
//! With `T⁻¹ A⁻¹ T = diag(γ, [[α, −β], [β, α]])` (one real eigenvalue `γ ≈ 3.6378` and the
//! pair `α ± iβ ≈ 2.6811 ± 3.0504 i`) the `3n` system decouples into one real system
//!
//! `S_γ = (γ²/h² + α_d γ/h) M + (1 + β_d γ/h) K`  (SPD: sparse Cholesky)
//!
//! and one complex one, `S_μ = (μ² + α_d μ) M + (1 + β_d μ) K`, `μ = (α + iβ)/h` (complex
//! symmetric, indefinite real part: sparse LU over `c64`, [`crate::linalg::complex_lu`]); `α_d`, `β_d`
//! are `damping.alpha`, `damping.beta`. Both are factorised once per step size and reused for
//! the whole run. An iteration: three internal-force evaluations, rotate each residual into its
//! stage's frame, transform with `T⁻¹`, one real and one complex solve, transform back with `T`,
//! rotate back; converged when the largest position correction is below the tolerance
//! ([`super::fixed_point::Convergence::correction_only`]: the `θ/(1−θ) Δ` estimate that stops
//! generalized-α is not trusted here). Where the
//! constant matrix misses part of the Jacobian (large bending relative to the one frame, `f_nl`,
//! stiffening, patches), Anderson's acceleration ([`super::anderson`], `solver.andersonDepth`)
//! mixes the corrections of all three stages, as for generalized-α.
//!
//! Supported: fixed supports and motion interfaces (their nodes are prescribed at the stage
//! times), damping, stiffening (its `K_G` frozen over the step, in the residual only), `f_nl`
//! and patches in the residual (iterated, no Woodbury correction), and point constraints (pins,
//! hinges): the stage multipliers `Λ_s` are transformed with `T` like the increments, and each
//! block system `[[S_k, Cᵀ], [C, 0]]` is solved through its constant Schur complement
//! `C S_k⁻¹ Cᵀ` (real for `S_γ`, complex for `S_μ`; `C = ŵ ⊗ I3` commutes with the stage
//! rotations, [`super::constraints`]), so that `C X_s = d` holds at every stage to the
//! iteration tolerance (index 3, no drift). Not supported (an error at setup): the full
//! formulation (its tangent is not the rotated constant `K`).

use super::anderson::{Anderson, DEFAULT_DEPTH};
use super::constraints::{ConstraintFactor, PointConstraint};
use super::fixed_point::{largest_correction, mix_update, Convergence};
use super::problem::{
    last_residual, residual, DynamicState, FreeNodes, IterationSettings, Prescription,
    ResidualWorkspace, StepReport,
};
use crate::body::frame::{node, set_node};
use crate::body::Body;
use crate::error::{Error, Result};
use crate::linalg::cholesky::{SolveWorkspace, SparseCholesky};
use crate::linalg::complex_lu::ComplexLu;
use faer::c64;
use nalgebra::{DMatrix, Matrix3, Vector3};

mod tableau;
pub use tableau::RadauIIA;

/// The two factorizations of one step size `h`: `S_γ` (real, Cholesky) and `S_μ` (complex, LU).
pub struct RadauMatrix {
    pub step_size: f64,
    pub tableau: RadauIIA,
    real: SparseCholesky,
    real_workspace: SolveWorkspace,
    complex: ComplexLu,
    /// With point constraints (pins, hinges): the Schur complements of both blocks.
    constraints: Option<StageConstraints>,
}

/// The point constraints' part of the two block systems `[[S_k, Cᵀ], [C, 0]]`: `Z_k = S_k⁻¹ Cᵀ`
/// (free DOFs × 3m, column-major) and `(C Z_k)⁻¹` for the real block `S_γ` and the complex
/// block `S_μ` (the constant selection Jacobian `C = ŵ ⊗ I3` commutes with the rotations, see
/// [`super::constraints`]). Block `k`'s constrained solution of `S_k y + Cᵀ μ = w`, `C y = q`
/// is `μ = (C Z_k)⁻¹ (C S_k⁻¹ w − q)`, `y = S_k⁻¹ w − Z_k μ`.
struct StageConstraints {
    real: ConstraintFactor,
    complex_z: Vec<c64>,
    complex_schur_inverse: DMatrix<c64>,
    /// Scratch (3m each): real and complex `C S⁻¹ w − q`, then `μ`.
    real_error: Vec<f64>,
    real_mu: Vec<f64>,
    complex_error: Vec<c64>,
    complex_mu: Vec<c64>,
}

impl StageConstraints {
    fn new(
        constraints: &[PointConstraint],
        real: &SparseCholesky,
        workspace: &mut SolveWorkspace,
        complex: &mut ComplexLu,
    ) -> Result<StageConstraints> {
        let real_factor = ConstraintFactor::new(constraints, &[], real, workspace)?;
        let n = complex.dim();
        let m = 3 * constraints.len();
        let mut z = vec![c64::new(0.0, 0.0); n * m];
        for (p, c) in constraints.iter().enumerate() {
            for d in 0..3 {
                let column = &mut z[(3 * p + d) * n..(3 * p + d + 1) * n];
                for (&row, &w) in c.free_rows.iter().zip(&c.weights) {
                    column[row + d] = c64::new(w, 0.0);
                }
                complex.solve_in_place(column);
            }
        }
        let mut a = DMatrix::from_element(m, m, c64::new(0.0, 0.0));
        for col in 0..m {
            let column = &z[col * n..(col + 1) * n];
            for (q, c) in constraints.iter().enumerate() {
                for e in 0..3 {
                    a[(3 * q + e, col)] = c.free_sum(column, e);
                }
            }
        }
        let complex_schur_inverse = a.try_inverse().ok_or_else(|| {
            Error::new(
                "radauIIA: the pin/hinge constraints are redundant (the complex Schur complement is singular)",
            )
        })?;
        Ok(StageConstraints {
            real: real_factor,
            complex_z: z,
            complex_schur_inverse,
            real_error: vec![0.0; m],
            real_mu: vec![0.0; m],
            complex_error: vec![c64::new(0.0, 0.0); m],
            complex_mu: vec![c64::new(0.0, 0.0); m],
        })
    }
}

impl RadauMatrix {
    /// Assembles and factorises `S_γ` and `S_μ` for step `h` on the free DOFs (the only
    /// factorizations of a run at this `h`), with the Schur complements of the point
    /// constraints if any. Error for the full formulation (not supported by this scheme).
    pub fn new(
        body: &Body,
        free: &FreeNodes,
        tableau: &RadauIIA,
        h: f64,
        damping_alpha: f64,
        damping_beta: f64,
    ) -> Result<RadauMatrix> {
        if body.full.is_some() {
            return Err(Error::new(
                "solver.integrator = radauIIA supports model.formulation = reducedStrain only (its constant iteration matrix is the rotated small-strain stiffness); use generalizedAlpha for the full formulation",
            ));
        }
        if !free.rigid.is_empty() {
            return Err(Error::new(
                "solver.integrator = radauIIA does not support rigid attachments (\"rigid\": true on a force interface, pin or hinge); use generalizedAlpha",
            ));
        }
        let g = tableau.gamma / h;
        let s_real = crate::linalg::SymmetricCsr::linear_combination(
            g * g + damping_alpha * g,
            &free.mass,
            1.0 + damping_beta * g,
            &free.stiffness,
        );
        let real = SparseCholesky::new(&s_real)?;
        let real_workspace = real.solve_scratch();
        let mu = c64::new(tableau.alpha / h, tableau.beta / h);
        let mut complex = ComplexLu::new(
            mu * mu + mu * damping_alpha,
            &free.mass,
            c64::new(1.0, 0.0) + mu * damping_beta,
            &free.stiffness,
        )?;
        let mut real_workspace = real_workspace;
        let constraints = if free.constraints.is_empty() {
            None
        } else {
            Some(StageConstraints::new(
                &free.constraints,
                &real,
                &mut real_workspace,
                &mut complex,
            )?)
        };
        Ok(RadauMatrix {
            step_size: h,
            tableau: *tableau,
            real,
            real_workspace,
            complex,
            constraints,
        })
    }

    /// Stored nonzeros of the real factor (the complex one is about as large, in `c64`).
    pub fn real_factor_nnz(&self) -> usize {
        self.real.factor_nnz()
    }
}

/// `loads(t, x, f_ext)`: adds the external loads (N) at time `t` (s) and positions `x` (m).
pub type TimedLoads<'a> = &'a dyn Fn(f64, &[f64], &mut [f64]);

/// What a Radau step needs besides the state: `loads(t, x, f_ext)` adds the external loads at
/// time `t` to a zeroed `f_ext` (the stages sit at `t_n + c_i h`), `prescribe(t, state)` sets the
/// clamped nodes' positions, velocities and accelerations at time `t`.
pub struct RadauProblem<'a> {
    pub body: &'a Body,
    pub free: &'a FreeNodes,
    pub loads: TimedLoads<'a>,
    pub prescribe: Prescription<'a>,
}

/// Work vectors of a Radau step besides the residual's (allocated once: a step allocates
/// nothing).
pub struct RadauWorkspace {
    /// The three stage states (all nodes; the clamped ones prescribed at the stage times).
    stages: Vec<DynamicState>,
    /// The iterate: stage increments `Z` on the free DOFs, stage-major (`3 × nf3`), then the
    /// stage multipliers `Λ` (`3 × 3m`, global) of the point constraints.
    increments: Vec<f64>,
    /// Stage residuals on the free DOFs (`3 × nf3`).
    residuals: Vec<f64>,
    /// The correction `[ΔZ, ΔΛ]` of an iteration and Anderson's acceleration of it (fitted on
    /// `ΔZ`, in metres).
    update: Vec<f64>,
    anderson: Anderson,
    /// The right-hand sides of the real and the complex block, then their solutions.
    real_rhs: Vec<f64>,
    complex_rhs: Vec<c64>,
    /// The state at the start of the step.
    previous: DynamicState,
}

impl RadauWorkspace {
    /// Workspace with Anderson's acceleration of the default depth ([`DEFAULT_DEPTH`]).
    pub fn new(body: &Body, free: &FreeNodes) -> RadauWorkspace {
        Self::with_anderson_depth(body, free, DEFAULT_DEPTH)
    }

    /// Workspace with Anderson's acceleration of history `depth` (0: the plain simplified
    /// Newton iteration) over all three stages' increments.
    pub fn with_anderson_depth(body: &Body, free: &FreeNodes, depth: usize) -> RadauWorkspace {
        let nf3 = free.dof_count();
        let nm = free.multiplier_count();
        let state = DynamicState::zeros(body.reference.len(), nm);
        RadauWorkspace {
            stages: vec![state.clone(), state.clone(), state.clone()],
            increments: vec![0.0; 3 * nf3 + 3 * nm],
            residuals: vec![0.0; 3 * nf3],
            update: vec![0.0; 3 * nf3 + 3 * nm],
            anderson: Anderson::new(depth, 3 * nf3 + 3 * nm, 3 * nf3),
            real_rhs: vec![0.0; nf3],
            complex_rhs: vec![c64::new(0.0, 0.0); nf3],
            previous: state,
        }
    }

    /// Stage `s`'s multipliers `Λ_s` in the iterate.
    fn stage_multipliers(&self, nf3: usize, nm: usize, s: usize) -> &[f64] {
        let start = 3 * nf3 + s * nm;
        &self.increments[start..start + nm]
    }
}

/// One Radau IIA step `t → t + h` of `state` (no allocation). `forces` holds the residual's
/// vectors and the geometric stiffness of stiffening, if set: after the step its force scratch
/// holds `ū`, `g` of stage 3 (`t_{n+1}`). On failure (no convergence in
/// `settings.max_iterations`, non-finite values) `state` is left as it was and the error is an
/// [`crate::ErrorKind::Discard`].
pub fn step(
    problem: &RadauProblem,
    matrix: &mut RadauMatrix,
    settings: &IterationSettings,
    h: f64,
    state: &mut DynamicState,
    ws: &mut RadauWorkspace,
    forces: &mut ResidualWorkspace,
) -> Result<StepReport> {
    ws.previous.copy_from(state);
    let result = iterate(problem, matrix, settings, h, state, ws, forces);
    if result.is_err() {
        state.copy_from(&ws.previous);
    }
    result
}

/// Stage `s`'s free positions, velocities and accelerations from the increments `Z`:
/// `X_s = x_n + Z_s`, `V_s = h⁻¹ (A⁻¹ Z)_s`, `Ẍ_s = h⁻² (A⁻² Z)_s − h⁻¹ (A⁻¹𝟙)_s ẋ_n`.
fn stage_kinematics(
    tableau: &RadauIIA,
    free: &FreeNodes,
    h: f64,
    s: usize,
    ws: &mut RadauWorkspace,
) {
    let nf3 = free.dof_count();
    let (prev, z) = (&ws.previous, &ws.increments);
    let stage = &mut ws.stages[s];
    let (ai, ai2, sum) = (tableau.a_inv, tableau.a_inv2, tableau.a_inv_sums[s]);
    for (k, &i) in free.nodes.iter().enumerate() {
        for d in 0..3 {
            let (f, g) = (3 * k + d, 3 * i + d);
            let (z0, z1, z2) = (z[f], z[nf3 + f], z[2 * nf3 + f]);
            stage.position[g] = prev.position[g] + [z0, z1, z2][s];
            stage.velocity[g] = (ai[(s, 0)] * z0 + ai[(s, 1)] * z1 + ai[(s, 2)] * z2) / h;
            stage.acceleration[g] = (ai2[(s, 0)] * z0 + ai2[(s, 1)] * z1 + ai2[(s, 2)] * z2)
                / (h * h)
                - sum * prev.velocity[g] / h;
        }
    }
}

/// The simplified Newton iteration on `[Z, Λ]` from the predictor: per iteration the stage
/// residuals, the transformed solve of the two blocks (with the constraints' Schur complements),
/// the stopping test ([`Convergence`]) and Anderson's mixing over all stages.
fn iterate(
    problem: &RadauProblem,
    matrix: &mut RadauMatrix,
    settings: &IterationSettings,
    h: f64,
    state: &mut DynamicState,
    ws: &mut RadauWorkspace,
    forces: &mut ResidualWorkspace,
) -> Result<StepReport> {
    let tableau = matrix.tableau;
    predict(problem, &tableau, h, ws);
    let mut convergence =
        Convergence::new("radauIIA ", settings, ws.previous.time + h, h).correction_only();
    ws.anderson.reset();
    for iteration in 1..=settings.max_iterations {
        let rotation = stage_residuals(problem, &tableau, h, ws, forces);
        matrix.solve_transformed(problem.free, &rotation, ws);
        let largest = stage_update(problem.free, &tableau, &rotation, ws);
        let converged = convergence.converged(largest)?;
        mix_update(&mut ws.anderson, converged, &ws.increments, &mut ws.update);
        for (z, dz) in ws.increments.iter_mut().zip(&ws.update) {
            *z += dz;
        }
        if converged {
            finish(problem.free, &tableau, h, state, ws);
            return Ok(StepReport {
                iterations: iteration,
                last_correction: convergence.last_correction(),
                error_estimate: None,
            });
        }
    }
    Err(convergence.failure())
}

/// The stage states at `t_n + c_i h` with the clamped nodes prescribed there, and the predictor
/// `Z_i = c_i h ẋ_n + ½ (c_i h)² ẍ_n`, `Λ_i = λ_n`.
fn predict(problem: &RadauProblem, tableau: &RadauIIA, h: f64, ws: &mut RadauWorkspace) {
    let free = problem.free;
    let nf3 = free.dof_count();
    let t0 = ws.previous.time;
    for s in 0..3 {
        ws.stages[s].copy_from(&ws.previous);
        ws.stages[s].time = t0 + tableau.c[s] * h;
        (problem.prescribe)(ws.stages[s].time, &mut ws.stages[s]);
        let tau = tableau.c[s] * h;
        for (k, &i) in free.nodes.iter().enumerate() {
            for d in 0..3 {
                let g = 3 * i + d;
                ws.increments[s * nf3 + 3 * k + d] =
                    tau * ws.previous.velocity[g] + 0.5 * tau * tau * ws.previous.acceleration[g];
            }
        }
    }
    let nm = free.multiplier_count();
    for s in 0..3 {
        let start = 3 * nf3 + s * nm;
        ws.increments[start..start + nm].copy_from_slice(&ws.previous.multipliers);
    }
}

/// The stage residuals `r_s = M Ẍ_s + f(X_s, V_s) + CᵀΛ_s − f_ext(t_s, X_s)` on the free DOFs
/// (into `ws.residuals`, [`residual`]), and each stage's co-moving frame `R_s`.
fn stage_residuals(
    problem: &RadauProblem,
    tableau: &RadauIIA,
    h: f64,
    ws: &mut RadauWorkspace,
    forces: &mut ResidualWorkspace,
) -> [Matrix3<f64>; 3] {
    let RadauProblem {
        body, free, loads, ..
    } = *problem;
    let (nf3, nm) = (free.dof_count(), free.multiplier_count());
    let mut rotation = [Matrix3::identity(); 3];
    for (s, stage_rotation) in rotation.iter_mut().enumerate() {
        stage_kinematics(tableau, free, h, s, ws);
        let start = 3 * nf3 + s * nm;
        ws.stages[s]
            .multipliers
            .copy_from_slice(&ws.increments[start..start + nm]);
        let stage = &ws.stages[s];
        let stage_loads = |x: &[f64], f: &mut [f64]| loads(stage.time, x, f);
        let kin = residual(body, free, stage, &stage_loads, forces);
        *stage_rotation = kin.frame.rotation;
        let r = last_residual(forces);
        let stage_residual = &mut ws.residuals[s * nf3..(s + 1) * nf3];
        for (k, &i) in free.nodes.iter().enumerate() {
            stage_residual[3 * k..3 * k + 3].copy_from_slice(&r[3 * i..3 * i + 3]);
        }
    }
    rotation
}

impl RadauMatrix {
    /// The transformed solve of an iteration: each stage's residual rotated into its frame
    /// (`R_sᵀ r_s`), `w = (T⁻¹ ⊗ I) (R_sᵀ r_s)_s`; the real block `S_γ δ_0 = w_0` and the complex
    /// one `S_μ (δ_1 + i δ_2) = w_1 + i w_2` (with the point constraints' Schur complements,
    /// which also set `ΔΛ` in `ws.update`); the solutions `δ` in `ws.real_rhs`, `ws.complex_rhs`.
    fn solve_transformed(
        &mut self,
        free: &FreeNodes,
        rotation: &[Matrix3<f64>; 3],
        ws: &mut RadauWorkspace,
    ) {
        let ti = self.tableau.t_inv;
        let nf3 = free.dof_count();
        for k in 0..free.nodes.len() {
            let r: [Vector3<f64>; 3] = std::array::from_fn(|s| {
                rotation[s].transpose() * node(&ws.residuals[s * nf3..(s + 1) * nf3], k)
            });
            let w: [Vector3<f64>; 3] =
                std::array::from_fn(|m| ti[(m, 0)] * r[0] + ti[(m, 1)] * r[1] + ti[(m, 2)] * r[2]);
            set_node(&mut ws.real_rhs, k, &w[0]);
            for (d, value) in ws.complex_rhs[3 * k..3 * k + 3].iter_mut().enumerate() {
                *value = c64::new(w[1][d], w[2][d]);
            }
        }
        self.real
            .solve_in_place(&mut ws.real_rhs, &mut self.real_workspace);
        self.complex.solve_in_place(&mut ws.complex_rhs);
        if let Some(sc) = &mut self.constraints {
            sc.constraint_errors(free, &self.tableau, rotation, ws);
            sc.solve_schur();
            sc.project(nf3, ws);
            sc.multiplier_update(free, &self.tableau, rotation, ws);
        }
    }
}

impl StageConstraints {
    /// The constraint errors of the blocks' unconstrained solutions: with the stage errors
    /// `g_s = R_sᵀ (C X_s − d)` in the stage frames and `q = (T⁻¹ ⊗ I) g`, `C y_k − q_k` for the
    /// real block (`k = 0`) and the complex one (`q_1 + i q_2`).
    fn constraint_errors(
        &mut self,
        free: &FreeNodes,
        tableau: &RadauIIA,
        rotation: &[Matrix3<f64>; 3],
        ws: &RadauWorkspace,
    ) {
        let ti = tableau.t_inv;
        for (p, c) in free.constraints.iter().enumerate() {
            let g: [Vector3<f64>; 3] = std::array::from_fn(|s| {
                rotation[s].transpose() * (c.centroid(&ws.stages[s].position) - c.target)
            });
            let q: [Vector3<f64>; 3] =
                std::array::from_fn(|m| ti[(m, 0)] * g[0] + ti[(m, 1)] * g[1] + ti[(m, 2)] * g[2]);
            let (mut cy_real, mut cy_complex) = (Vector3::<f64>::zeros(), [c64::new(0.0, 0.0); 3]);
            for (&row, &w) in c.free_rows.iter().zip(&c.weights) {
                for d in 0..3 {
                    cy_real[d] += w * ws.real_rhs[row + d];
                    cy_complex[d] += ws.complex_rhs[row + d] * w;
                }
            }
            for d in 0..3 {
                self.real_error[3 * p + d] = cy_real[d] - q[0][d];
                self.complex_error[3 * p + d] = cy_complex[d] - c64::new(q[1][d], q[2][d]);
            }
        }
    }

    /// `μ_k = (C Z_k)⁻¹ (C S_k⁻¹ w_k − q_k)` for both blocks.
    fn solve_schur(&mut self) {
        let m = self.real_error.len();
        for i in 0..m {
            self.real_mu[i] = (0..m)
                .map(|j| self.real.schur_inverse[(i, j)] * self.real_error[j])
                .sum();
            self.complex_mu[i] = (0..m)
                .map(|j| self.complex_schur_inverse[(i, j)] * self.complex_error[j])
                .sum();
        }
    }

    /// The constrained solutions `y_k = S_k⁻¹ w_k − Z_k μ_k` (in place, `n` free DOFs).
    fn project(&self, n: usize, ws: &mut RadauWorkspace) {
        for col in 0..self.real_error.len() {
            let (mu_r, mu_c) = (self.real_mu[col], self.complex_mu[col]);
            let zr = &self.real.z[col * n..(col + 1) * n];
            for (y, z) in ws.real_rhs.iter_mut().zip(zr) {
                *y -= z * mu_r;
            }
            let zc = &self.complex_z[col * n..(col + 1) * n];
            for (y, z) in ws.complex_rhs.iter_mut().zip(zc) {
                *y -= z * mu_c;
            }
        }
    }

    /// The stage multipliers' correction `ΔΛ_s = −R_s Σ_k T_sk μ_k` (per constraint) into
    /// `ws.update`.
    fn multiplier_update(
        &self,
        free: &FreeNodes,
        tableau: &RadauIIA,
        rotation: &[Matrix3<f64>; 3],
        ws: &mut RadauWorkspace,
    ) {
        let t = tableau.t;
        let (nf3, nm) = (free.dof_count(), free.multiplier_count());
        for p in 0..free.constraints.len() {
            let mu0 = Vector3::new(
                self.real_mu[3 * p],
                self.real_mu[3 * p + 1],
                self.real_mu[3 * p + 2],
            );
            let mu1 = Vector3::from_fn(|d, _| self.complex_mu[3 * p + d].re);
            let mu2 = Vector3::from_fn(|d, _| self.complex_mu[3 * p + d].im);
            for s in 0..3 {
                let dl = -(rotation[s] * (t[(s, 0)] * mu0 + t[(s, 1)] * mu1 + t[(s, 2)] * mu2));
                let start = 3 * nf3 + s * nm + 3 * p;
                ws.update[start..start + 3].copy_from_slice(dl.as_slice());
            }
        }
    }
}

/// The increments' correction `ΔZ_s = −R_s Σ_k T_sk δ_k` into `ws.update` from the blocks'
/// solutions `δ_0` (real) and `δ_1 + i δ_2` (complex); returns the largest entry
/// ([`largest_correction`]).
fn stage_update(
    free: &FreeNodes,
    tableau: &RadauIIA,
    rotation: &[Matrix3<f64>; 3],
    ws: &mut RadauWorkspace,
) -> f64 {
    let t = tableau.t;
    let nf3 = free.dof_count();
    let mut largest: f64 = 0.0;
    for k in 0..free.nodes.len() {
        let w0 = node(&ws.real_rhs, k);
        let (mut w1, mut w2) = (Vector3::zeros(), Vector3::zeros());
        for d in 0..3 {
            w1[d] = ws.complex_rhs[3 * k + d].re;
            w2[d] = ws.complex_rhs[3 * k + d].im;
        }
        for s in 0..3 {
            let dz = -(rotation[s] * (t[(s, 0)] * w0 + t[(s, 1)] * w1 + t[(s, 2)] * w2));
            largest = largest_correction(largest, dz.as_slice());
            set_node(&mut ws.update[s * nf3..(s + 1) * nf3], k, &dz);
        }
    }
    largest
}

/// The converged step's end state: stage 3 (`c_3 = 1`, stiffly accurate), `x_{n+1} = X_3`,
/// `ẋ_{n+1} = V_3`, `ẍ_{n+1} = Ẍ_3`, `λ_{n+1} = Λ_3`.
fn finish(
    free: &FreeNodes,
    tableau: &RadauIIA,
    h: f64,
    state: &mut DynamicState,
    ws: &mut RadauWorkspace,
) {
    stage_kinematics(tableau, free, h, 2, ws);
    let end = &ws.stages[2];
    state.time = ws.previous.time + h;
    state.position.copy_from_slice(&end.position);
    state.velocity.copy_from_slice(&end.velocity);
    state.acceleration.copy_from_slice(&end.acceleration);
    state.pseudo_acceleration.copy_from_slice(&end.acceleration);
    let (nf3, nm) = (free.dof_count(), free.multiplier_count());
    state
        .multipliers
        .copy_from_slice(ws.stage_multipliers(nf3, nm, 2));
}
