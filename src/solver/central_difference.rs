//! The explicit central-difference scheme with the HRZ-lumped mass (`solver.integrator =
//! centralDifference`), in its velocity-Verlet form:
//!
//! `v_{n+½} = v_n + h/2 a_n`, `x_{n+1} = x_n + h v_{n+½}`,
//! `a_{n+1} = M_L⁻¹ (f_ext(x_{n+1}) − f(x_{n+1}, v_{n+½}))`, `v_{n+1} = v_{n+½} + h/2 a_{n+1}`,
//!
//! second order, no solve at all: a step costs one internal-force evaluation. It is stable for
//! `h < h_crit = 2/ω_max` (undamped), `ω_max²` the largest eigenvalue of `M_L⁻¹ K` on the free
//! DOFs, estimated once per body by power iteration ([`CentralDifference::critical_step`]).
//! The reduced-strain force `R K ū` has the same spectrum as `K` under any rigid rotation, so
//! the bound holds for large motion too (stiffening and large strain shift it slightly: the
//! enforced step keeps a margin, [`STABILITY_MARGIN`]).
//!
//! Point constraints (pins, hinges) are not supported by this scheme (an error at setup); fixed
//! supports and motion interfaces are (their nodes are prescribed).

use super::problem::{
    last_residual, residual, DynamicState, FreeNodes, ResidualWorkspace, StepProblem, StepReport,
};
use crate::body::Body;
use crate::error::{Error, Result};

/// The enforced step is at most this fraction of the estimated `h_crit`: the power iteration
/// estimates `ω_max` from below (to about 1 % after [`POWER_ITERATIONS`]), and damping and
/// stiffening lower the true limit a little.
pub const STABILITY_MARGIN: f64 = 0.8;

/// Power iterations for `ω_max²` (each one `K` product: about the cost of one explicit step).
pub const POWER_ITERATIONS: usize = 200;

/// Inverse lumped masses and the critical step of one body.
#[derive(Debug, Clone)]
pub struct CentralDifference {
    /// `1/m_i` for each node (1/kg); zero for clamped nodes.
    inverse_mass: Vec<f64>,
    /// `ω_max` (rad/s) of `M_L⁻¹ K` on the free DOFs.
    pub highest_frequency: f64,
}

impl CentralDifference {
    /// For `body` with HRZ-lumped nodal masses `lumped` (kg) and free nodes `free`.
    pub fn new(body: &Body, lumped: &[f64], free: &FreeNodes) -> Result<CentralDifference> {
        if free.is_constrained() {
            return Err(Error::new(
                "solver.integrator = centralDifference does not support pin or hinge supports or rigid attachments (Lagrange-multiplier constraints); use generalizedAlpha",
            ));
        }
        let mut inverse_mass = vec![0.0; lumped.len()];
        for &i in &free.nodes {
            inverse_mass[i] = 1.0 / lumped[i];
        }
        // Power iteration on the M_L-symmetric operator A = M_L⁻¹ K (free DOFs): its Rayleigh
        // quotient xᵀ K x / xᵀ M_L x rises monotonically to ω_max².
        let n3 = body.reference.len();
        let mut x: Vec<f64> = (0..n3)
            .map(|k| {
                let i = k / 3;
                if inverse_mass[i] == 0.0 {
                    0.0
                } else {
                    // A deterministic start with components in every direction and mode.
                    1.0 + 0.5 * ((k as f64) * 0.754_877_666).sin()
                }
            })
            .collect();
        let mut y = vec![0.0; n3];
        let mut lambda: f64 = 0.0;
        for _ in 0..POWER_ITERATIONS {
            body.stiffness_product(&x, &mut y);
            let (mut xkx, mut xmx) = (0.0, 0.0);
            for k in 0..n3 {
                let w = inverse_mass[k / 3];
                if w == 0.0 {
                    y[k] = 0.0;
                    continue;
                }
                xkx += x[k] * y[k];
                xmx += x[k] * x[k] / w;
                y[k] *= w;
            }
            lambda = lambda.max(xkx / xmx);
            let norm = y.iter().map(|v| v * v).sum::<f64>().sqrt();
            if !(norm > 0.0 && norm.is_finite()) {
                break;
            }
            for (xk, yk) in x.iter_mut().zip(&y) {
                *xk = yk / norm;
            }
        }
        if !(lambda > 0.0 && lambda.is_finite()) {
            return Err(Error::new(
                "centralDifference: the stiffness has no positive eigenvalue on the free nodes",
            ));
        }
        Ok(CentralDifference {
            inverse_mass,
            highest_frequency: lambda.sqrt(),
        })
    }

    /// `h_crit = 2/ω_max` (s) of the undamped scheme.
    pub fn critical_step(&self) -> f64 {
        2.0 / self.highest_frequency
    }

    /// The largest step used: [`STABILITY_MARGIN`] × `h_crit` (s).
    pub fn stable_step(&self) -> f64 {
        STABILITY_MARGIN * self.critical_step()
    }

    /// The accelerations of the free nodes from the lumped mass at the current state:
    /// `a = M_L⁻¹ (f_ext − f(x, v))` (the start of a run, or after the inputs changed).
    pub fn accelerations(
        &self,
        body: &Body,
        free: &FreeNodes,
        loads: &dyn Fn(&[f64], &mut [f64]),
        state: &mut DynamicState,
        ws: &mut ResidualWorkspace,
    ) {
        for &i in &free.nodes {
            state.acceleration[3 * i..3 * i + 3].fill(0.0);
        }
        // The residual at zero free acceleration is f(x, v) − f_ext (+ the clamped nodes'
        // inertia coupling).
        residual(body, free, state, loads, ws);
        let r = last_residual(ws);
        for &i in &free.nodes {
            let w = self.inverse_mass[i];
            let nodal = &r[3 * i..3 * i + 3];
            for (a, r) in state.acceleration[3 * i..3 * i + 3].iter_mut().zip(nodal) {
                *a = -w * r;
            }
        }
        state
            .pseudo_acceleration
            .copy_from_slice(&state.acceleration);
    }

    /// One step `t → t + h` (h ≤ [`Self::stable_step`], checked). The clamped nodes follow
    /// `problem.prescribe`. A non-finite result is an [`crate::ErrorKind::Discard`]; the caller
    /// restores the state (the slave keeps a backup of the communication step's start).
    pub fn step(
        &self,
        problem: &StepProblem,
        h: f64,
        state: &mut DynamicState,
        ws: &mut ResidualWorkspace,
    ) -> Result<StepReport> {
        if h > self.stable_step() * (1.0 + 1e-12) {
            return Err(Error::discard(format!(
                "centralDifference: step {h} s exceeds the stable step {:.4e} s ({STABILITY_MARGIN} × 2/ω_max, ω_max = {:.4e} rad/s)",
                self.stable_step(),
                self.highest_frequency
            )));
        }
        let free = problem.free;
        let t1 = state.time + h;
        for &i in &free.nodes {
            for d in 3 * i..3 * i + 3 {
                state.velocity[d] += 0.5 * h * state.acceleration[d];
                state.position[d] += h * state.velocity[d];
            }
        }
        state.time = t1;
        (problem.prescribe)(t1, state);
        // a_{n+1} from f(x_{n+1}, v_{n+½}): the residual at zero free acceleration (the clamped
        // nodes' accelerations enter through the consistent mass coupling).
        for &i in &free.nodes {
            state.acceleration[3 * i..3 * i + 3].fill(0.0);
        }
        residual(problem.body, free, state, problem.loads, ws);
        let r = last_residual(ws);
        let mut finite = true;
        for &i in &free.nodes {
            let w = self.inverse_mass[i];
            let range = 3 * i..3 * i + 3;
            for ((a, v), r) in state.acceleration[range.clone()]
                .iter_mut()
                .zip(&mut state.velocity[range.clone()])
                .zip(&r[range.clone()])
            {
                *a = -w * r;
                *v += 0.5 * h * *a;
                finite &= v.is_finite();
            }
            finite &= state.position[range].iter().all(|x| x.is_finite());
        }
        state
            .pseudo_acceleration
            .copy_from_slice(&state.acceleration);
        if !finite {
            return Err(Error::discard(format!(
                "centralDifference: step to t = {t1} produced non-finite values"
            )));
        }
        Ok(StepReport {
            iterations: 0,
            last_correction: 0.0,
            error_estimate: None,
        })
    }
}
