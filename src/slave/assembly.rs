//! The assembled model for one set of parameters: body, free nodes, schemes and their
//! factorization caches, built when the parameters it depends on change.

use super::parameters::{
    ModelKey, FORMULATION_FULL, INTEGRATOR_CENTRAL_DIFFERENCE, INTEGRATOR_RADAU,
    STIFFENING_INERTIAL, STIFFENING_NONE, STIFFENING_STRESS,
};
use super::{LogEvent, Slave};
use crate::body::feature_indicators::{self, FeatureIndicators};
use crate::body::stiffening::Stiffening;
use crate::body::strain_monitor::StrainMonitor;
use crate::body::{Body, BodyOptions, NodeSet, Patches, Reduction};
use crate::error::{Error, Result};
use crate::fem::nonlinear::SvkSolid;
use crate::fem::{self, IsotropicMaterial};
use crate::model::InterfaceKind;
use crate::solver::central_difference::CentralDifference;
use crate::solver::consistent_acceleration::ConsistentAcceleration;
use crate::solver::generalized_alpha::{GeneralizedAlpha, IterationMatrix, StepWorkspace};
use crate::solver::problem::{FreeNodes, ResidualWorkspace};
use crate::solver::radau::{RadauIIA, RadauMatrix, RadauWorkspace};
use nalgebra::Vector3;

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
/// of a failed internal step ([`MAX_STEP_HALVINGS`]); a fifth size evicts the least recently used
/// one, which is factorised again when it comes back.
pub const MATRIX_CACHE_SIZE: usize = 4;

/// The terms in force during a step: with `model.auto` chosen per communication step by
/// [`FeatureIndicators`] among the allowed ones, otherwise the forced switches. Part of the
/// state (saved and restored with it), since the choice has hysteresis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Features {
    pub nonlinear_forces: bool,
    pub stiffening: bool,
}

/// The assembled model for one set of parameters.
pub(super) struct Model {
    pub(super) key: ModelKey,
    pub(super) body: Body,
    pub(super) free: FreeNodes,
    pub(super) scheme: GeneralizedAlpha,
    pub(super) matrices: Vec<IterationMatrix>,
    /// Generalized-α's work vectors.
    pub(super) workspace: StepWorkspace,
    /// The residual's work vectors, force scratch and geometric stiffness, shared by whichever
    /// scheme steps the model (and read by the strain watch and the outputs).
    pub(super) forces: ResidualWorkspace,
    /// Geometric stiffening (`model.stiffening` inertial or stress); its `K_G` lives in
    /// `forces.geometric_stiffness`.
    pub(super) stiffening: Option<Stiffening>,
    /// The constant-mass solve for consistent accelerations (initialization, load jumps).
    pub(super) mass: ConsistentAcceleration,
    /// The explicit scheme (`solver.integrator = centralDifference`), if chosen.
    pub(super) explicit: Option<CentralDifference>,
    /// Radau IIA (`solver.integrator = radauIIA`), if chosen: its factorization cache (used in
    /// place of `matrices`) and workspace. Its residual uses `forces`.
    pub(super) radau: Option<RadauModel>,
    /// The watch on `‖∇ū‖` (one co-moving frame only) and whether it is above the threshold.
    pub(super) strain_monitor: Option<(StrainMonitor, bool)>,
    /// `model.auto`'s indicators (one co-moving frame, reduced strain, some term allowed).
    pub(super) indicators: Option<FeatureIndicators>,
    /// The allowed terms: upper bounds of [`Features`].
    pub(super) allowed: Features,
    /// `K_G` while stiffening is switched off (it moves to `forces.geometric_stiffness` and
    /// back: no allocation).
    pub(super) parked_geometric_stiffness: Option<crate::linalg::SymmetricCsr>,
}

impl Model {
    /// Puts `features` into force: the body's `f_nl` switch and where `K_G` lives. The iteration
    /// matrices are not touched: they carry the Woodbury correction of `f_nl` whenever it is
    /// allowed (unused while it is off), and stiffening is on the right-hand side, absorbed by
    /// the fixed-point/Anderson iteration; so a switch never refactorises.
    pub(super) fn apply_features(&mut self, features: Features) {
        self.body.options.nonlinear_forces = features.nonlinear_forces;
        let active = self.forces.geometric_stiffness.is_some();
        if features.stiffening != active {
            std::mem::swap(
                &mut self.forces.geometric_stiffness,
                &mut self.parked_geometric_stiffness,
            );
        }
    }
}

/// Radau IIA's part of the model.
pub(super) struct RadauModel {
    pub(super) tableau: RadauIIA,
    pub(super) matrices: Vec<RadauMatrix>,
    pub(super) workspace: RadauWorkspace,
}

/// Index of the factorization for step `h` in `cache`, most recently used last (a rotation of
/// at most [`MATRIX_CACHE_SIZE`] entries: no allocation on a hit). On a miss `factorise()` builds
/// it, the least recently used (the first) is evicted when the cache is full, and
/// `describe(matrix, seconds)` is logged under `logEvents`.
pub(super) fn cached_factorization<T>(
    cache: &mut Vec<T>,
    h: f64,
    step_size: impl Fn(&T) -> f64,
    factorise: impl FnOnce() -> Result<T>,
    describe: impl Fn(&T, f64) -> String,
    events: &mut Vec<LogEvent>,
) -> Result<usize> {
    if let Some(i) = cache
        .iter()
        .position(|m| (step_size(m) - h).abs() <= 1e-9 * h)
    {
        cache[i..].rotate_left(1);
        return Ok(cache.len() - 1);
    }
    let started = std::time::Instant::now();
    let matrix = factorise()?;
    events.push(LogEvent {
        category: "logEvents",
        message: describe(&matrix, started.elapsed().as_secs_f64()),
    });
    if cache.len() >= MATRIX_CACHE_SIZE {
        cache.remove(0);
    }
    cache.push(matrix);
    Ok(cache.len() - 1)
}

impl Slave {
    /// Builds the model if the parameters it depends on changed (assembly and frames).
    pub(super) fn ensure_model(&mut self) -> Result<()> {
        let key = self.parameters.model_key();
        if self.model.as_ref().is_some_and(|m| m.key == key) {
            return Ok(());
        }
        let p = &self.parameters;
        p.material.validate()?;
        let reference: Vec<f64> = self.mesh.nodes().iter().flatten().copied().collect();
        // HRZ-lumped masses: the frame weights, the patches' weights, the explicit scheme's mass.
        // Material regions: each element's material (the body's outside every region).
        let regions = &self.body_file.regions;
        if !regions.is_empty() {
            let unsupported = if p.formulation == FORMULATION_FULL {
                Some("model.formulation = full")
            } else if p.stiffening != 1 {
                Some("model.stiffening other than none")
            } else if p.frames > 1 {
                Some("model.frames > 1")
            } else if !p.output_directory.is_empty() {
                Some("output.directory (the stress output uses one material)")
            } else {
                None
            };
            if let Some(what) = unsupported {
                return Err(Error::new(format!(
                    "material regions ('{}'{}) are supported by the reduced-strain body with one frame and no stiffening only, not with {what}",
                    regions[0].name,
                    if regions.len() > 1 { ", ..." } else { "" }
                )));
            }
        }
        let element_material = |e: usize| match self.element_regions[e] {
            Some(k) => IsotropicMaterial {
                youngs_modulus: regions[k].youngs_modulus,
                poisson_ratio: p.material.poisson_ratio,
                density: regions[k].density.unwrap_or(p.material.density),
            },
            None => p.material,
        };
        let density = |e: usize| element_material(e).density;
        let lumped = fem::lumped_masses_of(&self.mesh, &density);
        let options = BodyOptions {
            nonlinear_forces: p.nonlinear_forces,
            damping_alpha: p.damping_alpha,
            damping_beta: p.damping_beta,
        };
        let mass_matrix = fem::scalar_mass_matrix_of(&self.mesh, &density);
        let stiffness_matrix = fem::stiffness_matrix_of(&self.mesh, &element_material);
        if p.modes > 0 {
            self.check_reducible()?;
            let p = &self.parameters;
            let started = std::time::Instant::now();
            let (boundary, loaded): (Vec<&NodeSet>, Vec<&NodeSet>) = {
                let sets = |kinds: &[InterfaceKind]| {
                    self.interfaces
                        .iter()
                        .filter(|i| kinds.contains(&i.kind))
                        .map(|i| &i.set)
                        .collect::<Vec<_>>()
                };
                (
                    sets(&[InterfaceKind::Fixed, InterfaceKind::Motion]),
                    sets(&[InterfaceKind::Force]),
                )
            };
            let reduction = Reduction::new(
                &reference,
                &mass_matrix,
                &stiffness_matrix,
                &lumped,
                &boundary,
                &loaded,
                p.modes as usize,
            )?;
            let frequencies: Vec<String> = reduction
                .mode_eigenvalues
                .iter()
                .map(|l| format!("{:.4}", l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)))
                .collect();
            self.events.push(LogEvent {
                category: "logEvents",
                message: format!(
                    "reduced the body (model.modes = {}): {} nodes → {} fields ({} coordinates); fixed-interface mode frequencies [{}] Hz ({:.3} s)",
                    p.modes,
                    reduction.node_count,
                    reduction.field_count,
                    3 * reduction.field_count,
                    frequencies.join(", "),
                    started.elapsed().as_secs_f64()
                ),
            });
            let mut held = reduction.held.iter();
            for interface in &mut self.interfaces {
                let holds = matches!(interface.kind, InterfaceKind::Fixed | InterfaceKind::Motion);
                let coordinates = if holds {
                    held.next().cloned().unwrap_or_default()
                } else {
                    Vec::new()
                };
                interface.set.set_reduction(Some((&reduction, coordinates)));
            }
            let mut clamped = vec![false; reduction.field_count];
            for interface in &self.interfaces {
                if matches!(interface.kind, InterfaceKind::Fixed | InterfaceKind::Motion) {
                    for k in interface.set.held_indices() {
                        clamped[k] = true;
                    }
                }
            }
            let body = Body::reduced(reduction, options);
            return self.finish_model(key, body, clamped, &lumped);
        }
        for interface in &mut self.interfaces {
            interface.set.set_reduction(None);
        }
        let p = &self.parameters;
        let body = Body::new(
            reference,
            mass_matrix,
            stiffness_matrix,
            lumped.clone(),
            options,
        );
        let body = if p.formulation == FORMULATION_FULL {
            body.with_full_formulation(SvkSolid::new(&self.mesh, &p.material))
        } else if p.frames > 1 {
            body.with_patches(Patches::along_principal_axis(
                &self.mesh,
                &p.material,
                &lumped,
                p.frames as usize,
            )?)
        } else {
            body
        };
        let clamped = self.clamped.clone();
        self.finish_model(key, body, clamped, &lumped)
    }

    /// `model.modes > 0` supports one generalized-α, single-frame, reduced-strain body without
    /// stiffening, pins or hinges; anything else is an error naming the parameter.
    pub(super) fn check_reducible(&self) -> Result<()> {
        let p = &self.parameters;
        let reason = if p.formulation == FORMULATION_FULL {
            Some(
                "model.formulation = full is the nonlinear reference on the whole mesh".to_string(),
            )
        } else if p.frames > 1 {
            Some(format!(
                "model.frames = {}: a reduced body has one co-moving frame",
                p.frames
            ))
        } else if p.stiffening != STIFFENING_NONE {
            Some(format!(
                "model.stiffening = {}: geometric stiffening is not projected on the modes",
                if p.stiffening == STIFFENING_INERTIAL {
                    "inertial"
                } else {
                    "stress"
                }
            ))
        } else if p.integrator == INTEGRATOR_CENTRAL_DIFFERENCE {
            Some("solver.integrator = centralDifference needs a lumped (diagonal) mass; the reduced mass is dense".to_string())
        } else {
            self.interfaces
                .iter()
                .zip(&self.body_file.interfaces)
                .find(|(i, _)| matches!(i.kind, InterfaceKind::Pin | InterfaceKind::Hinge))
                .map(|(i, spec)| {
                    format!(
                        "interface '{}' is a {:?} support: pins and hinges are not available on a reduced body (use a fixed support or a motion interface)",
                        spec.name, i.kind
                    )
                })
        };
        match reason {
            Some(r) => Err(Error::invalid_value(
                "model.modes",
                self.parameters.modes,
                &r,
            )),
            None => Ok(()),
        }
    }

    /// The solver's side of a model build: free nodes, constraints, stiffening, the explicit
    /// scheme, the logs.
    pub(super) fn finish_model(
        &mut self,
        key: ModelKey,
        body: Body,
        clamped: Vec<bool>,
        lumped: &[f64],
    ) -> Result<()> {
        let p = &self.parameters;
        let started = std::time::Instant::now();
        let mut free = FreeNodes::new(&body, &clamped);
        for (k, interface) in self.interfaces.iter_mut().enumerate() {
            interface.first_constraint = free.constraints.len();
            for (nodes, weights) in &interface.point_constraints {
                // The target is set where the body is placed (ensure_initial_state).
                free.add_point_constraint(
                    &self.body_file.interfaces[k].name,
                    nodes,
                    weights,
                    Vector3::zeros(),
                )?;
            }
        }
        let workspace = StepWorkspace::with_anderson_depth(&body, &free, p.anderson_depth as usize);
        let mut forces = ResidualWorkspace::new(&body);
        let stiffening = match p.stiffening {
            STIFFENING_INERTIAL => Some(Stiffening::inertial(
                &self.mesh,
                &p.material,
                &body,
                &self.clamped,
            )?),
            STIFFENING_STRESS => Some(Stiffening::stress(&self.mesh, &body)),
            _ => None,
        };
        if stiffening.is_some() {
            forces.geometric_stiffness = Some(Stiffening::pattern(&self.mesh));
        }
        // model.auto: indicators for the allowed terms of the one-frame reduced-strain body
        // (patches and the full formulation have no switchable terms: forced as given).
        let allowed = Features {
            nonlinear_forces: p.nonlinear_forces,
            stiffening: stiffening.is_some(),
        };
        // The reduced body is forced as given too (its indicators would need the expanded mesh).
        let single = p.formulation != FORMULATION_FULL && p.frames == 1 && body.reduction.is_none();
        let indicators = (p.auto && single && (allowed.nonlinear_forces || allowed.stiffening))
            .then(|| {
                FeatureIndicators::new(
                    &self.mesh,
                    &body,
                    &free.nodes,
                    &free.stiffness,
                    &free.mass,
                    !free.clamped.is_empty(),
                    stiffening.as_ref(),
                )
            });
        let mut body = body;
        body.nonlinear_forces_switchable = indicators.is_some() && allowed.nonlinear_forces;
        if let Some(ind) = &indicators {
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
                category: "logEvents",
                message: format!(
                    "model.auto: f_nl {}; stiffening {}; lowest natural frequency {}; a term is switched on when {} × its estimated effect exceeds solver.tolerance × size = {:.3e} m, off when it stayed below {} of that for one period 2π/ω₁",
                    verdict(
                        allowed.nonlinear_forces,
                        ind.estimates_nonlinear_forces(),
                        "no estimate for a body without fixed supports or motion interfaces: its spurious moment accumulates"
                    ),
                    verdict(allowed.stiffening, ind.estimates_stiffening(), "no estimate"),
                    ind.first_frequency()
                        .map_or("not computed".to_string(), |w| format!("{w:.4e} rad/s")),
                    feature_indicators::SAFETY,
                    p.tolerance * self.size,
                    feature_indicators::HYSTERESIS
                ),
            });
        }
        self.events.push(LogEvent {
            category: "logEvents",
            message: format!(
                "assembled the body: {} {}, {} elements, {} DOF ({} free), nnz(K) = {}, mass {:.6e} kg ({:.3} s)",
                body.node_count(),
                if body.reduction.is_some() { "fields" } else { "nodes" },
                self.mesh.element_count(),
                body.reference.len(),
                free.dof_count(),
                body.stiffness_matrix.nnz(),
                body.total_mass,
                started.elapsed().as_secs_f64()
            ),
        });
        let explicit = if p.integrator == INTEGRATOR_CENTRAL_DIFFERENCE {
            let scheme = CentralDifference::new(&body, lumped, &free)?;
            self.events.push(LogEvent {
                category: "logEvents",
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
            Some(scheme)
        } else {
            None
        };
        let monitored =
            p.formulation != FORMULATION_FULL && p.frames == 1 && body.reduction.is_none();
        let radau = if p.integrator == INTEGRATOR_RADAU {
            // Radau's constant matrices hold the rotated small-strain stiffness: no tangent for
            // the full formulation.
            if p.formulation == FORMULATION_FULL {
                return Err(Error::new(
                    "solver.integrator = radauIIA supports model.formulation = reducedStrain only (its constant iteration matrices hold the rotated small-strain stiffness); use generalizedAlpha for the full formulation",
                ));
            }
            Some(RadauModel {
                tableau: RadauIIA::new(),
                matrices: Vec::new(),
                workspace: RadauWorkspace::with_anderson_depth(
                    &body,
                    &free,
                    p.anderson_depth as usize,
                ),
            })
        } else {
            None
        };
        self.model = Some(Model {
            key,
            radau,
            body,
            scheme: GeneralizedAlpha::new(p.rho_inf),
            matrices: Vec::new(),
            mass: ConsistentAcceleration::new(&free)?,
            explicit,
            strain_monitor: monitored.then(|| (StrainMonitor::new(&self.mesh), false)),
            free,
            workspace,
            forces,
            stiffening,
            indicators,
            allowed,
            parked_geometric_stiffness: None,
        });
        self.dynamics = None;
        // The backups have the old model's size (a changed model.modes changes it).
        self.backup = None;
        self.retry_backup = None;
        let size = self.model.as_ref().map_or(0, |m| m.body.reference.len());
        self.outputs.momentum = vec![0.0; size];
        Ok(())
    }

    /// Index of the factorization for internal step `h` in the cache (factorising on a miss and
    /// evicting the least recently used entry when [`MATRIX_CACHE_SIZE`] are kept).
    pub(super) fn matrix_index(&mut self, h: f64) -> Result<usize> {
        self.ensure_model()?;
        let p = &self.parameters;
        let model = self.model.as_mut().unwrap();
        if model.explicit.is_some() {
            return Ok(usize::MAX); // the explicit scheme factorises nothing
        }
        let events = &mut self.events;
        if let Some(radau) = &mut model.radau {
            return cached_factorization(
                &mut radau.matrices,
                h,
                |m| m.step_size,
                || {
                    RadauMatrix::new(
                        &model.body,
                        &model.free,
                        &radau.tableau,
                        h,
                        p.damping_alpha,
                        p.damping_beta,
                    )
                },
                |matrix, seconds| {
                    format!(
                    "factorised the Radau IIA matrices for internal step h = {h:e} s: real Cholesky nnz(L) = {} and complex LU ({seconds:.3} s); they serve every step of this size",
                    matrix.real_factor_nnz()
                )
                },
                events,
            );
        }
        cached_factorization(
            &mut model.matrices,
            h,
            |m| m.step_size,
            || {
                IterationMatrix::new(
                    &model.body,
                    &model.free,
                    &model.scheme,
                    h,
                    p.damping_alpha,
                    p.damping_beta,
                )
            },
            |matrix, seconds| {
                format!(
                "factorised the iteration matrix for internal step h = {h:e} s: nnz(L) = {} ({seconds:.3} s); it serves every step of this size",
                matrix.factor.factor_nnz()
            )
            },
            events,
        )
    }
}
