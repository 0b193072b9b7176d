//! The parts of a model that step it: the time integrator of `solver.integrator` with its
//! factorization cache, the lowest modes the error control measures against, and
//! `model.auto`'s indicators.

use super::super::{LogEvent, Slave};
use super::Features;
use crate::body::feature_indicators::{self, FeatureIndicators};
use crate::body::lowest_modes::{LowestModes, MODES as LOWEST_MODES};
use crate::body::stiffening::GeometricStiffening;
use crate::body::Body;
use crate::error::{Error, Result};
use crate::fem;
use crate::linalg::SymmetricCsr;
use crate::model::category;
use crate::model::enumerations::{Formulation, Integrator};
use crate::solver::central_difference::CentralDifference;
use crate::solver::generalized_alpha::{GeneralizedAlpha, StepWorkspace};
use crate::solver::integrator::{Damping, FactorCache, TimeIntegrator};
use crate::solver::problem::FreeNodes;
use crate::solver::radau::{RadauIIA, RadauWorkspace};

impl Slave {
    /// `model.auto`'s indicators for the allowed terms of the one-frame reduced-strain body on
    /// the whole mesh (patches, the full formulation and the reduced body have no switchable
    /// terms: forced as given), with the decision logged.
    pub(super) fn feature_indicators(
        &mut self,
        body: &Body,
        free: &FreeNodes,
        stiffening: Option<&GeometricStiffening>,
        allowed: Features,
    ) -> Option<FeatureIndicators> {
        let p = &self.parameters;
        let single =
            p.formulation != Formulation::Full && p.frames == 1 && body.reduction.is_none();
        if !(p.auto && single && (allowed.nonlinear_forces || allowed.stiffening)) {
            return None;
        }
        let (stiffness, mass) = free.elastic_matrices();
        let ind = FeatureIndicators::new(
            &self.mesh,
            body,
            &free.nodes[..free.elastic_nodes],
            &stiffness,
            &mass,
            !free.clamped.is_empty(),
            stiffening,
        );
        let verdict = |allowed: bool, estimated: bool, why: &str| {
            if !allowed {
                "not allowed (off)".to_string()
            } else if estimated {
                "allowed, switched per communication step by its indicator".to_string()
            } else {
                format!("allowed, always on ({why})")
            }
        };
        self.events.push(LogEvent {
            category: category::EVENTS,
            message: format!(
                "model.auto: f_nl {}; stiffening {}; lowest natural frequency {}; a term is switched on when {} × its estimated effect exceeds the target solver.tolerance × size = {:.3e} m, off when it stayed below {} of that for one period 2π/ω₁",
                if allowed.nonlinear_forces && ind.estimates_nonlinear_forces() {
                    "allowed, kept off: on a body with supports and one co-moving frame it moved B3's peak 9 % away from the full reference (docs/fmu.md, \"Which terms a scene needs\")".to_string()
                } else {
                    verdict(
                        allowed.nonlinear_forces,
                        ind.estimates_nonlinear_forces(),
                        "no estimate for a body without fixed supports or motion interfaces: its spurious moment accumulates",
                    )
                },
                verdict(allowed.stiffening, ind.estimates_stiffening(), "no estimate"),
                ind.first_frequency()
                    .map_or("not computed".to_string(), |w| format!("{w:.4e} rad/s")),
                feature_indicators::SAFETY,
                p.tolerance * self.size,
                feature_indicators::HYSTERESIS
            ),
        });
        Some(ind)
    }

    /// The scheme of `solver.integrator`: generalized-α (ρ∞ = `solver.rhoInf`), Radau IIA (not
    /// with the full formulation: its constant matrices hold the rotated small-strain
    /// stiffness) or central difference (its stable step logged).
    pub(super) fn time_integrator(
        &mut self,
        body: &Body,
        lumped: &[f64],
        free: &FreeNodes,
    ) -> Result<TimeIntegrator> {
        let p = &self.parameters;
        let depth = p.anderson_depth as usize;
        Ok(match p.integrator {
            Integrator::GeneralizedAlpha => TimeIntegrator::GeneralizedAlpha {
                scheme: GeneralizedAlpha::new(p.rho_inf),
                cache: FactorCache::new(),
                workspace: StepWorkspace::with_anderson_depth(body, free, depth),
            },
            Integrator::RadauIIA if p.formulation == Formulation::Full => {
                return Err(Error::new(
                    "solver.integrator = radauIIA supports model.formulation = reducedStrain only (its constant iteration matrices hold the rotated small-strain stiffness); use generalizedAlpha for the full formulation",
                ))
            }
            Integrator::RadauIIA => TimeIntegrator::RadauIIA {
                tableau: RadauIIA::new(),
                cache: FactorCache::new(),
                workspace: RadauWorkspace::with_anderson_depth(body, free, depth),
            },
            Integrator::CentralDifference => {
                let scheme = CentralDifference::new(body, lumped, free)?;
                self.events.push(LogEvent {
                    category: category::EVENTS,
                    message: format!(
                        "central difference: highest frequency {:.4e} rad/s, stable step {:.4e} s ({} × 2/ω_max){}",
                        scheme.highest_frequency,
                        scheme.stable_step(),
                        crate::solver::central_difference::STABILITY_MARGIN,
                        if p.step_size > scheme.stable_step() {
                            format!(
                                "; solver.stepSize = {} exceeds it: internal steps are limited to the stable step",
                                p.step_size
                            )
                        } else {
                            String::new()
                        }
                    ),
                });
                TimeIntegrator::CentralDifference(scheme)
            }
        })
    }

    /// Builds the model if needed and makes the integrator ready for internal step `h`
    /// (factorising on a cache miss, logged under `logEvents`).
    pub(in crate::slave) fn prepare_step_size(&mut self, h: f64) -> Result<()> {
        self.ensure_model()?;
        let p = &self.parameters;
        let model = self.model.as_mut().unwrap();
        let damping = Damping {
            alpha: p.damping_alpha,
            beta: p.damping_beta,
        };
        if let Some(message) = model
            .integrator
            .prepare(h, &model.body, &model.free, damping)?
        {
            self.events.push(LogEvent {
                category: category::EVENTS,
                message,
            });
        }
        Ok(())
    }
}

/// The lowest elastic modes of the free DOFs' `K_FF`, `M_FF` ([`LowestModes`]), by subspace
/// iteration. A body without fixed supports or motion interfaces (pins and hinges included: the
/// free body's frequencies are the scale) has six rigid modes (`ω = 0`): they are computed on
/// `K + σM` (`σ` far below the elastic `ω²`, which the shift moves by `σ`) and the first six
/// are left out.
pub(super) fn lowest_modes(
    free: &FreeNodes,
    total_mass: f64,
    damping: (f64, f64),
) -> Result<LowestModes> {
    let supported = !free.clamped.is_empty();
    let (k_full, m_full) = free.elastic_matrices();
    // A reduced body's rigid sets held exactly: the analysis in the coordinates `y` of
    // `x = T y` (FreeNodes::rigid_set_motions), its modes mapped back.
    let motions = free.rigid_set_motions();
    let (k, m) = match &motions {
        Some(t) => (projected(&k_full, t), projected(&m_full, t)),
        None => (k_full.clone(), m_full.clone()),
    };
    let (k, m) = (&k, &m);
    let diagonal = |a: &SymmetricCsr, i: usize| {
        (a.row_ptr[i]..a.row_ptr[i + 1])
            .find(|&j| a.col_idx[j] == i)
            .map_or(0.0, |j| a.values[j])
    };
    let (shift, index) = if supported {
        (0.0, 0)
    } else {
        // 1e-8 of the mean diagonal ratio (a mean of ω² over the mesh, far above ω₁²)
        // keeps K + σM positive definite and costs a negligible part of ω₁² + σ's
        // digits.
        let trace = |a: &SymmetricCsr| (0..a.n).map(|i| diagonal(a, i)).sum::<f64>();
        (1e-8 * trace(k) / trace(m), 6)
    };
    let shifted = SymmetricCsr::linear_combination(1.0, k, shift, m);
    let count = (index + LOWEST_MODES + 1).min(k.n);
    let mut pairs = fem::modal::lowest_eigenpairs(&shifted, m, count, 1e-6, 200).map_err(|e| {
        Error::new(format!(
            "model.accuracy: the lowest natural frequency: {}",
            e.message
        ))
    })?;
    pairs
        .eigenvalues
        .iter_mut()
        .for_each(|w2| *w2 = (*w2 - shift).max(0.0));
    if let Some(t) = &motions {
        for mode in &mut pairs.modes {
            *mode = (t * nalgebra::DVector::from_column_slice(mode))
                .as_slice()
                .to_vec();
        }
    }
    let omega = pairs.eigenvalues[index.min(count - 1)].sqrt();
    if !(omega.is_finite() && omega > 0.0) {
        return Err(Error::new(format!(
            "model.accuracy: the lowest natural frequency came out as {omega} rad/s; set model.accuracy = 0 for a fixed internal step"
        )));
    }
    let modes = LowestModes::new(
        &free.nodes[..free.elastic_nodes],
        &m_full,
        &pairs,
        index,
        total_mass,
        damping,
    );
    // On a body without supports the deformation is measured from the nearest rigid motion,
    // and its RMS is the scale itself (docs/formulation.md, "The deformation scale").
    Ok(if supported || motions.is_some() {
        modes
    } else {
        modes.for_body_without_supports()
    })
}

/// `Tᵀ A T` of a symmetric `A` (dense: a reduced body's size).
fn projected(a: &SymmetricCsr, t: &nalgebra::DMatrix<f64>) -> SymmetricCsr {
    let mut dense = nalgebra::DMatrix::zeros(a.n, a.n);
    for row in 0..a.n {
        for k in a.row_ptr[row]..a.row_ptr[row + 1] {
            dense[(row, a.col_idx[k])] = a.values[k];
        }
    }
    let p = t.transpose() * dense * t;
    let n = p.nrows();
    let triplets: Vec<(usize, usize, f64)> = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| (i, j, 0.5 * (p[(i, j)] + p[(j, i)])))
        .filter(|&(_, _, v)| v != 0.0)
        .collect();
    SymmetricCsr::from_triplets(n, &triplets)
}
