//! The integrator of a model (`solver.integrator`): the scheme with the factorizations it keeps
//! per internal step size (docs/formulation.md, "One factorization per step size").
//!
//! Generalized-α and Radau IIA factorise a constant iteration matrix per internal step size `h`
//! (Radau a real and a complex one); [`FactorCache`] keeps the last [`MATRIX_CACHE_SIZE`] of them,
//! so a step at a size seen before factorises nothing. The explicit central-difference scheme
//! factorises nothing and limits the internal step to its stable step.

use super::central_difference::CentralDifference;
use super::generalized_alpha::{self, GeneralizedAlpha, IterationMatrix, StepWorkspace};
use super::problem::{
    DynamicState, FreeNodes, IterationSettings, ResidualWorkspace, StepProblem, StepReport,
};
use super::radau::{self, RadauIIA, RadauMatrix, RadauProblem, RadauWorkspace};
use crate::body::Body;
use crate::error::Result;

/// Most factorizations kept, one per internal step size in use, least recently used evicted.
///
/// Memory: each entry holds the sparse Cholesky factor of the free DOFs' iteration matrix plus
/// its solve workspace (and, with pins or hinges, the small dense Schur complement). For the
/// default body (621 nodes, 1 800 free DOF) the factor holds 223 083 values (1.8 MB, about 3 MB
/// with its indices); the cache is bounded by four of them whatever sequence of communication
/// step sizes the importer sends (`tests/fmi2_capabilities.rs` checks the bound). With
/// `radauIIA` an entry holds that Cholesky factor and a complex (`c64`) LU factor of the same
/// matrix size besides (pivoting, COLAMD ordering: it is larger; factorization measured 3–6 ×
/// the Cholesky's time), so a Radau entry costs several times a generalized-α one.
/// Four covers a steady step size, a last partial step and the three step sizes of the retries
/// of a failed internal step (`slave::MAX_STEP_HALVINGS`); a fifth size evicts the least
/// recently used one, which is factorised again when it comes back.
pub const MATRIX_CACHE_SIZE: usize = 4;

/// Whether a factorization for step `cached` serves a step `h` (equal to 1e-9 relative).
pub fn same_step_size(cached: f64, h: f64) -> bool {
    (cached - h).abs() <= 1e-9 * h
}

/// A factorization made for one internal step size.
pub trait Factorization {
    /// The internal step it was made for (s).
    fn step_size(&self) -> f64;
}

impl Factorization for IterationMatrix {
    fn step_size(&self) -> f64 {
        self.step_size
    }
}

impl Factorization for RadauMatrix {
    fn step_size(&self) -> f64 {
        self.step_size
    }
}

/// Factorizations per internal step size, most recently used last, at most
/// [`MATRIX_CACHE_SIZE`] (a hit rotates the entries: no allocation).
pub struct FactorCache<T> {
    entries: Vec<T>,
}

impl<T: Factorization> FactorCache<T> {
    pub fn new() -> FactorCache<T> {
        FactorCache {
            entries: Vec::with_capacity(MATRIX_CACHE_SIZE),
        }
    }

    /// Makes the entry for `h` the most recently used, calling `factorise` on a miss (then the
    /// least recently used entry is evicted if the cache is full). Returns whether it was made
    /// now, and the seconds it took.
    pub fn prepare(
        &mut self,
        h: f64,
        factorise: impl FnOnce() -> Result<T>,
    ) -> Result<Option<(&T, f64)>> {
        if let Some(i) = self.position(h) {
            self.entries[i..].rotate_left(1);
            return Ok(None);
        }
        let started = std::time::Instant::now();
        let entry = factorise()?;
        if self.entries.len() >= MATRIX_CACHE_SIZE {
            self.entries.remove(0);
        }
        self.entries.push(entry);
        let entry = self.entries.last().expect("just pushed");
        Ok(Some((entry, started.elapsed().as_secs_f64())))
    }

    fn position(&self, h: f64) -> Option<usize> {
        self.entries
            .iter()
            .position(|m| same_step_size(m.step_size(), h))
    }

    /// The entry for `h`, if there is one.
    pub fn get(&self, h: f64) -> Option<&T> {
        self.position(h).map(|i| &self.entries[i])
    }

    /// The entry for `h` (prepared).
    fn get_mut(&mut self, h: f64) -> &mut T {
        self.find_mut(h)
            .expect("the factorization of a step is prepared before the step")
    }

    /// The entry for `h`, if there is one (the order of use is left as it is).
    pub fn find_mut(&mut self, h: f64) -> Option<&mut T> {
        self.position(h).map(|i| &mut self.entries[i])
    }

    /// The step sizes with an entry, most recently used last.
    pub fn step_sizes(&self) -> Vec<f64> {
        self.entries.iter().map(|m| m.step_size()).collect()
    }
}

impl<T: Factorization> Default for FactorCache<T> {
    fn default() -> Self {
        Self::new()
    }
}

/// The scheme of a model, with what it keeps between steps. (One per model, built once: the size
/// of its variants does not matter.)
#[allow(clippy::large_enum_variant)]
pub enum TimeIntegrator {
    /// Generalized-α: one factorization per step size.
    GeneralizedAlpha {
        scheme: GeneralizedAlpha,
        cache: FactorCache<IterationMatrix>,
        workspace: StepWorkspace,
    },
    /// Radau IIA: a real and a complex factorization per step size.
    RadauIIA {
        tableau: RadauIIA,
        cache: FactorCache<RadauMatrix>,
        workspace: RadauWorkspace,
    },
    /// Central difference: nothing to factorise, a stable step.
    CentralDifference(CentralDifference),
}

/// The damping of the iteration matrices: Rayleigh's `α` (1/s) and `β` (s).
#[derive(Debug, Clone, Copy)]
pub struct Damping {
    pub alpha: f64,
    pub beta: f64,
}

impl TimeIntegrator {
    /// The largest internal step for a requested `step_size`: the explicit scheme's stable
    /// step limits it.
    pub fn largest_step(&self, step_size: f64) -> f64 {
        match self {
            TimeIntegrator::CentralDifference(explicit) => step_size.min(explicit.stable_step()),
            _ => step_size,
        }
    }

    /// The explicit scheme, if it is the one.
    pub fn explicit(&self) -> Option<&CentralDifference> {
        match self {
            TimeIntegrator::CentralDifference(explicit) => Some(explicit),
            _ => None,
        }
    }

    /// Makes the factorization for internal step `h` ready (factorising on a miss); a
    /// description of a new one, for the log.
    pub fn prepare(
        &mut self,
        h: f64,
        body: &Body,
        free: &FreeNodes,
        damping: Damping,
    ) -> Result<Option<String>> {
        Ok(match self {
            TimeIntegrator::GeneralizedAlpha { scheme, cache, .. } => cache
                .prepare(h, || {
                    IterationMatrix::new(body, free, scheme, h, damping.alpha, damping.beta)
                })?
                .map(|(matrix, seconds)| {
                    format!(
                        "factorised the iteration matrix for internal step h = {h:e} s: nnz(L) = {} ({seconds:.3} s); it serves every step of this size",
                        matrix.factor.factor_nnz()
                    )
                }),
            TimeIntegrator::RadauIIA { tableau, cache, .. } => cache
                .prepare(h, || {
                    RadauMatrix::new(body, free, tableau, h, damping.alpha, damping.beta)
                })?
                .map(|(matrix, seconds)| {
                    format!(
                        "factorised the Radau IIA matrices for internal step h = {h:e} s: real Cholesky nnz(L) = {} and complex LU ({seconds:.3} s); they serve every step of this size",
                        matrix.real_factor_nnz()
                    )
                }),
            TimeIntegrator::CentralDifference(_) => None,
        })
    }

    /// One step `t → t + h` of `state` (prepared for `h`). Generalized-α and central difference
    /// take the loads at the end of the step (`problem`), Radau IIA at its stage times
    /// (`stages`).
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        problem: &StepProblem,
        stages: &RadauProblem,
        settings: &IterationSettings,
        h: f64,
        state: &mut DynamicState,
        forces: &mut ResidualWorkspace,
    ) -> Result<StepReport> {
        match self {
            TimeIntegrator::GeneralizedAlpha {
                cache, workspace, ..
            } => generalized_alpha::step(
                problem,
                cache.get_mut(h),
                settings,
                h,
                state,
                workspace,
                forces,
            ),
            TimeIntegrator::RadauIIA {
                cache, workspace, ..
            } => radau::step(
                stages,
                cache.get_mut(h),
                settings,
                h,
                state,
                workspace,
                forces,
            ),
            TimeIntegrator::CentralDifference(explicit) => explicit.step(problem, h, state, forces),
        }
    }

    /// Carries `state` over to a change of the internal force at it, from `old_force` to
    /// `body`'s ([`generalized_alpha::carry_over_force_change`], with the iteration matrix of
    /// `h`, prepared; unconstrained bodies). The other schemes take the state as it is
    /// (`None`).
    #[allow(clippy::too_many_arguments)]
    pub fn carry_over_force_change(
        &mut self,
        h: f64,
        body: &Body,
        free: &FreeNodes,
        state: &mut DynamicState,
        forces: &mut ResidualWorkspace,
        old_force: &[f64],
        remove_lowest: &dyn Fn(&mut [f64]),
        tolerance: f64,
    ) -> Option<generalized_alpha::Carried> {
        match self {
            TimeIntegrator::GeneralizedAlpha {
                cache, workspace, ..
            } => Some(generalized_alpha::carry_over_force_change(
                body,
                free,
                cache.get_mut(h),
                state,
                workspace,
                forces,
                old_force,
                remove_lowest,
                tolerance,
            )),
            _ => None,
        }
    }

    /// The step sizes with a factorization, most recently used last.
    pub fn cached_step_sizes(&self) -> Vec<f64> {
        match self {
            TimeIntegrator::GeneralizedAlpha { cache, .. } => cache.step_sizes(),
            TimeIntegrator::RadauIIA { cache, .. } => cache.step_sizes(),
            TimeIntegrator::CentralDifference(_) => Vec::new(),
        }
    }

    /// The leading term `d` of the local error of the last step that estimated it
    /// (generalized-α only: `IterationMatrix::local_error`; flat `3N`, global frame, m).
    pub fn local_error_field(&self) -> Option<&[f64]> {
        match self {
            TimeIntegrator::GeneralizedAlpha { workspace, .. } => {
                Some(workspace.local_error_field())
            }
            _ => None,
        }
    }

    /// Generalized-α's iteration matrix for `h`, if it is the scheme and has one.
    pub fn iteration_matrix(&self, h: f64) -> Option<&IterationMatrix> {
        match self {
            TimeIntegrator::GeneralizedAlpha { cache, .. } => cache.get(h),
            _ => None,
        }
    }

    /// [`Self::iteration_matrix`], to solve with (its solve workspace changes).
    pub fn iteration_matrix_mut(&mut self, h: f64) -> Option<&mut IterationMatrix> {
        match self {
            TimeIntegrator::GeneralizedAlpha { cache, .. } => cache.find_mut(h),
            _ => None,
        }
    }
}
