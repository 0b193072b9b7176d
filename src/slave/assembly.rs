//! The assembled model for one set of parameters: body, free nodes, schemes and their
//! factorization caches, built when the parameters it depends on change.

use super::parameters::AssemblyKey;
use super::{LogEvent, Slave};
use crate::body::feature_indicators::FeatureIndicators;
use crate::body::lowest_modes::{LowestModes, MODES};
use crate::body::stiffening::{geometric_stiffness_product, GeometricStiffening};
use crate::body::strain_monitor::StrainMonitor;
use crate::body::{
    Body, BodyOptions, InterfaceSets, LinearPlacement, MeshData, ModeCount, NodeSet, Patches,
    Reduction, SecondOrderForce,
};
use crate::error::{Error, Result};
use crate::fem::nonlinear::SvkSolid;
use crate::fem::{self, IsotropicMaterial};
use crate::linalg::SymmetricCsr;
use crate::model::category;
use crate::model::enumerations::{Formulation, Integrator, Stiffening};
use crate::model::InterfaceKind;
use crate::solver::consistent_acceleration::ConsistentAcceleration;
use crate::solver::integrator::TimeIntegrator;
use crate::solver::problem::{FreeNodes, ResidualWorkspace};
use nalgebra::Vector3;

mod checks;
mod features;
mod schemes;

/// The terms in force during a step: with `model.auto` chosen per communication step by
/// [`FeatureIndicators`] among the allowed ones, otherwise the forced switches. Part of the
/// state (saved and restored with it), since the choice has hysteresis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Features {
    pub nonlinear_forces: bool,
    pub stiffening: bool,
    /// `model.auto`'s slabs (one co-moving frame per element layer, [`Patches::element_layers`])
    /// in place of the one frame.
    pub frames: bool,
    /// The slabs were tried and the communication step did not converge with them: the body
    /// keeps its one frame (`Slave::do_step`).
    pub frames_refused: bool,
    /// The linear body (docs/formulation.md, "The linear body"): the frame held at the
    /// placement, [`Model::parked_linear`].
    pub linear: bool,
    /// The slabs' own stiffening (docs/formulation.md, "Geometric stiffening within the
    /// slabs"): `model.auto`'s slabs take it once it changes their stiffness by more than
    /// [`SlabStiffeningSwitch::threshold`](super::auto_features::SlabStiffeningSwitch::threshold);
    /// forced slabs with `model.stiffening = stress` have it throughout.
    pub slab_stiffening: bool,
}

/// The assembled model for one set of parameters.
pub(super) struct Model {
    pub(super) key: AssemblyKey,
    pub(super) body: Body,
    pub(super) free: FreeNodes,
    /// The scheme of `solver.integrator` with its factorizations per step size.
    pub(super) integrator: TimeIntegrator,
    /// The residual's work vectors, force scratch and geometric stiffness, shared by whichever
    /// scheme steps the model (and read by the strain watch and the outputs).
    pub(super) forces: ResidualWorkspace,
    /// Geometric stiffening (`model.stiffening` inertial or stress); its `K_G` lives in
    /// `forces.geometric_stiffness`.
    pub(super) stiffening: Option<GeometricStiffening>,
    /// The constant-mass solve for consistent accelerations (initialization, load jumps).
    pub(super) mass: ConsistentAcceleration,
    /// The watch on `‖∇ū‖` (one co-moving frame only) and whether it is above the threshold.
    pub(super) strain_monitor: Option<(StrainMonitor, bool)>,
    /// `model.auto`'s indicators (one co-moving frame, reduced strain, some term allowed).
    pub(super) indicators: Option<FeatureIndicators>,
    /// The allowed terms: upper bounds of [`Features`].
    pub(super) allowed: Features,
    /// `K_G` while stiffening is switched off (it moves to `forces.geometric_stiffness` and
    /// back: no allocation).
    pub(super) parked_geometric_stiffness: Option<crate::linalg::SymmetricCsr>,
    /// `model.auto`'s slabs while they are not in force (they move to `body.patches` once, see
    /// [`Features::frames`]); `None`: the body gets none (several frames given, the full
    /// formulation, a reduced body, or no accuracy to decide by).
    pub(super) parked_patches: Option<Patches>,
    /// The linear body's placement while the frame follows the body ([`Features::linear`]
    /// off; it moves to `body.linear` and back: no allocation); set at initialization.
    pub(super) parked_linear: Option<LinearPlacement>,
    /// The body's lowest elastic modes on its supports (of a body without supports: its lowest
    /// elastic ones), for the error control (`slave::step_control`): the period `T₁ = 2π/ω₁`
    /// over which it lets the errors add up to `model.accuracy`, the quasi-static displacement
    /// of the accelerations and the part of a field in these modes. `None` without error
    /// control.
    pub(super) lowest_modes: Option<LowestModes>,
    /// The step Jacobian's vectors, allocated on its first use (`Slave::step_jacobian`).
    pub(super) jacobian: Option<super::step_jacobian::JacobianWorkspace>,
    /// A reduced body's stiffening switched by `model.auto` from its driving motion: the twelve
    /// unit cases projected on the lowest modes, `G_k = Φᵀ K_G,k Φ`
    /// (`auto_features::choose_driven_stiffening`). `None`: forced as given.
    pub(super) driven_stiffening: Option<Vec<[[f64; MODES]; MODES]>>,
}

/// A rigid set of more nodes than this gets a warning about its cost (its `3n − 6` multipliers).
const LARGE_RIGID_SET: usize = 100;

/// The matrices of the reference mesh: positions `X` (flat `3N`), the scalar mass matrix `Ms`
/// and the small-strain stiffness `K` (docs/formulation.md, "mass_matrix", "stiffness_matrix").
struct MeshMatrices {
    reference: Vec<f64>,
    mass_matrix: SymmetricCsr,
    stiffness_matrix: SymmetricCsr,
    /// `K` without the elements wholly inside rigid sets (when there are such elements): the
    /// body's `K`, the elastic force's and the iteration matrix's.
    force_stiffness: Option<SymmetricCsr>,
}

impl Slave {
    /// Builds the model if the parameters it depends on changed (assembly and frames).
    pub(super) fn ensure_model(&mut self) -> Result<()> {
        let key = self.parameters.assembly_key();
        if self.model.as_ref().is_some_and(|m| m.key == key) {
            return Ok(());
        }
        // The build changes the interfaces' sets before it can fail: no old model may outlive
        // a failed one (a reduced body's sets would then be the mesh's).
        self.model = None;
        let p = &self.parameters;
        p.material.validate()?;
        self.check_regions()?;
        self.check_stiffening_frames()?;
        let reference: Vec<f64> = self.mesh.nodes().iter().flatten().copied().collect();
        // HRZ-lumped masses: the frame weights, the patches' weights, the explicit scheme's mass.
        // Material regions: each element's material (the body's outside every region).
        let regions = &self.body_file.regions;
        let element_material = |e: usize| match self.element_regions[e] {
            Some(k) => IsotropicMaterial {
                youngs_modulus: regions[k].youngs_modulus,
                poisson_ratio: p.material.poisson_ratio,
                density: regions[k].density.unwrap_or(p.material.density),
            },
            None => p.material,
        };
        let density = |e: usize| element_material(e).density;
        // Elements wholly inside a rigid set carry no stiffness: they cannot deform, and with one
        // co-moving frame their linear strain of the set's rotation against the frame (second
        // order in it) would stay in them as energy, a spring against that rotation
        // (docs/formulation.md, "Rigid attachments").
        let inside = self.elements_inside_rigid_sets();
        let element_stiffness = |e: usize| IsotropicMaterial {
            youngs_modulus: if inside[e] {
                0.0
            } else {
                element_material(e).youngs_modulus
            },
            ..element_material(e)
        };
        // The slabs' elements take the same materials as the body's elastic force.
        let slab_materials: Vec<IsotropicMaterial> = (0..self.mesh.element_count())
            .map(element_stiffness)
            .collect();
        let mut lumped = fem::lumped_masses_of(&self.mesh, &density);
        let mut matrices = MeshMatrices {
            reference,
            mass_matrix: fem::scalar_mass_matrix_of(&self.mesh, &density),
            stiffness_matrix: fem::stiffness_matrix_of(&self.mesh, &element_material),
            force_stiffness: inside
                .iter()
                .any(|&i| i)
                .then(|| fem::stiffness_matrix_of(&self.mesh, &element_stiffness)),
        };
        if !self.mass_points.is_empty() {
            self.check_mass_points()?;
            // The lumped bodies' mass points: nodes after the mesh's with `m/6` on the diagonal
            // of `Ms` and no stiffness (docs/formulation.md, "Rigid attachments").
            let masses: Vec<f64> = self.mass_points.iter().map(|p| p.mass).collect();
            for point in &self.mass_points {
                matrices
                    .reference
                    .extend_from_slice(point.position.as_slice());
            }
            matrices.mass_matrix = matrices.mass_matrix.extended(&masses);
            let none = vec![0.0; 3 * masses.len()];
            matrices.stiffness_matrix = matrices.stiffness_matrix.extended(&none);
            matrices.force_stiffness = matrices.force_stiffness.map(|k| k.extended(&none));
            lumped.extend_from_slice(&masses);
        }
        let options = BodyOptions {
            nonlinear_forces: p.nonlinear_forces,
            damping_alpha: p.damping_alpha,
            damping_beta: p.damping_beta,
        };
        let (body, clamped, reduced_stiffening) = if let Some(modes) = p.mode_count() {
            self.reduced_body(&matrices, &lumped, options, modes, &slab_materials)?
        } else {
            (
                self.mesh_body(matrices, &lumped, options, &slab_materials)?,
                self.clamped.clone(),
                None,
            )
        };
        self.finish_model(
            key,
            body,
            clamped,
            (&lumped, &slab_materials),
            reduced_stiffening,
        )
    }

    /// For each interface, whether it is a rigid attachment (a force interface, pin or hinge
    /// with `"rigid": true`).
    fn rigid_attachments(&self) -> Vec<bool> {
        self.interfaces
            .iter()
            .zip(&self.body_file.interfaces)
            .map(|(i, spec)| {
                spec.rigid
                    && matches!(
                        i.kind,
                        InterfaceKind::Force | InterfaceKind::Pin | InterfaceKind::Hinge
                    )
            })
            .collect()
    }

    /// For each element, whether all its nodes belong to one rigid set (of a force interface,
    /// pin or hinge with `"rigid": true`).
    fn elements_inside_rigid_sets(&self) -> Vec<bool> {
        let mut inside = vec![false; self.mesh.element_count()];
        let rigid = self.rigid_attachments();
        for (interface, _) in self.interfaces.iter().zip(&rigid).filter(|(_, &r)| r) {
            let mut in_set = vec![false; self.mesh.node_count()];
            for &n in &interface.set.frame_weights.nodes {
                if n < in_set.len() {
                    in_set[n] = true;
                }
            }
            for (e, flag) in inside.iter_mut().enumerate() {
                *flag |= self.mesh.element(e).iter().all(|&n| in_set[n]);
            }
        }
        inside
    }

    /// The body on the whole mesh: one co-moving frame, several (`model.frames`), or the full
    /// formulation.
    fn mesh_body(
        &mut self,
        matrices: MeshMatrices,
        lumped: &[f64],
        options: BodyOptions,
        slab_materials: &[IsotropicMaterial],
    ) -> Result<Body> {
        for interface in &mut self.interfaces {
            interface.set.set_reduction(None);
        }
        let p = &self.parameters;
        // The co-moving frame fits the mesh's nodes: a lumped body's mass points weigh nothing
        // in it.
        let mesh_nodes = self.mesh.node_count();
        let frame_weights = (0..lumped.len())
            .map(|i| if i < mesh_nodes { lumped[i] } else { 0.0 })
            .collect();
        // With rigid sets, the body's K leaves out the elements inside them; the modal analyses
        // keep them (they do not see the sets' constraints).
        let (stiffness, modal_stiffness) = match matrices.force_stiffness {
            Some(k) => (k, Some(matrices.stiffness_matrix)),
            None => (matrices.stiffness_matrix, None),
        };
        let mut body = Body::new(
            matrices.reference,
            matrices.mass_matrix,
            stiffness,
            frame_weights,
            options,
        );
        body.lumped_points = self.mass_points.len();
        body.modal_stiffness = modal_stiffness;

        Ok(if p.formulation == Formulation::Full {
            body.with_full_formulation(SvkSolid::new(&self.mesh, &p.material))
        } else if p.frames > 1 {
            let total = body.node_count();
            let mut slabs = Patches::along_principal_axis(
                &self.mesh,
                slab_materials,
                &lumped[..mesh_nodes],
                p.frames as usize,
            )?
            .covering(total);
            if p.stiffening == Stiffening::Stress {
                // Each slab's own prestress (docs/formulation.md, "Geometric stiffening within
                // the slabs"); the one frame's `K_G` is not built (`finish_model`).
                slabs = slabs.with_stiffening();
            }
            body.with_patches(slabs)
        } else {
            body
        })
    }

    /// The reduced body with `modes` (`model.modes ≠ 0`, docs/formulation.md, "The reduced
    /// body") and which of its fields are held by supports and motion interfaces; the
    /// interfaces' node sets are expressed in its fields.
    fn reduced_body(
        &mut self,
        matrices: &MeshMatrices,
        lumped: &[f64],
        options: BodyOptions,
        modes: ModeCount,
        slab_materials: &[IsotropicMaterial],
    ) -> Result<(Body, Vec<bool>, Option<GeometricStiffening>)> {
        self.check_reducible()?;
        // The sets' loads and motions are the mesh's while the basis is built (its attachment
        // modes distribute unit loads over the nodes), not a previous reduction's.
        for interface in &mut self.interfaces {
            interface.set.set_reduction(None);
        }
        let p = &self.parameters;
        let started = std::time::Instant::now();
        // Rigid attachments are boundary sets of their own (body::reduction).
        let rigid = self.rigid_attachments();
        let sets = |held: bool, want_rigid: bool| {
            self.interfaces
                .iter()
                .zip(&rigid)
                .filter(|(i, &r)| {
                    if held {
                        matches!(i.kind, InterfaceKind::Fixed | InterfaceKind::Motion)
                    } else if want_rigid {
                        r
                    } else {
                        i.kind == InterfaceKind::Force && !r
                    }
                })
                .map(|(i, _)| &i.set)
                .collect::<Vec<&NodeSet>>()
        };
        // The co-moving frame fits the mesh's nodes: a lumped body's mass points weigh nothing
        // in it (as on the mesh body).
        let mesh_nodes = self.mesh.node_count();
        let frame_weights: Vec<f64> = (0..lumped.len())
            .map(|i| if i < mesh_nodes { lumped[i] } else { 0.0 })
            .collect();
        // Several frames need the basis's second order in the slabs' own force
        // (`modal_derivatives`, `Patches::second_order_force`).
        let slabs = if p.frames > 1 {
            Some(Patches::along_principal_axis(
                &self.mesh,
                slab_materials,
                &lumped[..mesh_nodes],
                p.frames as usize,
            )?)
        } else {
            None
        };
        let (size, reference) = (self.size, &matrices.reference[..3 * mesh_nodes]);
        let second_order_force = slabs.as_ref().map(|slabs| {
            move |u: &[f64], f: &mut [f64]| {
                slabs.second_order_force(reference, u, options.nonlinear_forces, size, f)
            }
        });
        let reduction = Reduction::new(
            &MeshData {
                reference: &matrices.reference,
                mass: &matrices.mass_matrix,
                stiffness: &matrices.stiffness_matrix,
                force_stiffness: matrices.force_stiffness.as_ref(),
                lumped,
                frame_weights: &frame_weights,
                second_order_force: second_order_force
                    .as_ref()
                    .map(|f| f as &SecondOrderForce<'_>),
            },
            &InterfaceSets {
                held: &sets(true, false),
                rigid: &sets(false, true),
                loaded: &sets(false, false),
            },
            modes,
        )?;
        if let Some(choice) = &reduction.mode_choice {
            self.events.push(LogEvent {
                category: category::EVENTS,
                message: if choice.met() {
                    format!(
                        "model.modes = auto: {} fixed-interface modes, the fewest whose static response to the body's inertial loads is within {:e} of the full mesh's (mass norm): {:.2e} ({:.2e} with one fewer)",
                        choice.count, choice.accuracy, choice.error, choice.error_one_fewer
                    )
                } else {
                    format!(
                        "warning: model.modes = auto: {} fixed-interface modes (the most it takes) leave {:.2e} of the static response to the body's inertial loads, more than the {:e} asked: this body needs its mesh (model.modes = 0) for that accuracy",
                        choice.count, choice.error, choice.accuracy
                    )
                },
            });
        }
        let frequencies: Vec<String> = reduction
            .mode_eigenvalues
            .iter()
            .map(|l| format!("{:.4}", l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)))
            .collect();
        self.events.push(LogEvent {
            category: category::EVENTS,
            message: format!(
                "reduced the body (model.modes = {}): {} nodes → {} fields ({} coordinates); fixed-interface mode frequencies [{}] Hz ({:.3} s)",
                p.modes,
                self.mesh.node_count(),
                reduction.field_count,
                3 * reduction.field_count,
                frequencies.join(", "),
                started.elapsed().as_secs_f64()
            ),
        });
        let stiffening = if self.reduced_stiffening() {
            let (stiffness, modal_stiffness) = match &matrices.force_stiffness {
                Some(k) => (k.clone(), Some(matrices.stiffness_matrix.clone())),
                None => (matrices.stiffness_matrix.clone(), None),
            };
            let mut mesh_body = Body::new(
                matrices.reference.clone(),
                matrices.mass_matrix.clone(),
                stiffness,
                frame_weights,
                options,
            );
            mesh_body.modal_stiffness = modal_stiffness;
            Some(GeometricStiffening::inertial_reduced(
                &self.mesh,
                &p.material,
                &mesh_body,
                &self.clamped,
                &reduction,
            )?)
        } else {
            None
        };
        let mut held = reduction.held.iter();
        let mut clamped = vec![false; reduction.field_count];
        for interface in &mut self.interfaces {
            let holds = matches!(interface.kind, InterfaceKind::Fixed | InterfaceKind::Motion);
            let coordinates = if holds {
                held.next().cloned().unwrap_or_default()
            } else {
                Vec::new()
            };
            interface
                .set
                .set_reduction(Some((reduction.basis(), coordinates)));
            if holds {
                for k in interface.set.held_indices() {
                    clamped[k] = true;
                }
            }
        }
        let mut body = Body::reduced(reduction, options);
        if let Some(slabs) = slabs {
            // Several co-moving frames act on the coordinates (docs/formulation.md, "The
            // reduced body"): the slabs the basis took its modal derivatives from.
            body = body.with_patches(slabs);
        }
        Ok((body, clamped, stiffening))
    }

    /// The solver's side of a model build: free nodes, constraints, stiffening, `model.auto`'s
    /// indicators, the schemes, the logs.
    pub(super) fn finish_model(
        &mut self,
        key: AssemblyKey,
        mut body: Body,
        clamped: Vec<bool>,
        (lumped, slab_materials): (&[f64], &[IsotropicMaterial]),
        reduced_stiffening: Option<GeometricStiffening>,
    ) -> Result<()> {
        let started = std::time::Instant::now();
        let free = self.constrained_free_nodes(&body, &clamped)?;
        for (set, spec) in free.rigid.iter().filter(|r| r.lock.is_none()).zip(
            self.body_file.interfaces.iter().filter(|s| {
                s.rigid && !matches!(s.kind, InterfaceKind::Fixed | InterfaceKind::Motion)
            }),
        ) {
            if set.nodes.len() > LARGE_RIGID_SET {
                self.events.push(LogEvent {
                    category: category::EVENTS,
                    message: format!(
                        "warning: interface '{}': its rigid set has {} nodes, {} Lagrange multipliers: one solve each per step size and a dense product per iteration (docs/formulation.md, \"Rigid attachments\": the connecting rod's small eye made rigid costs 35 s to set up and 3 times the step)",
                        spec.name,
                        set.nodes.len(),
                        set.rows()
                    ),
                });
            }
        }
        let p = &self.parameters;
        // model.auto's slabs: built now, with the force scratch that serves them, and parked.
        let auto_slabs = p.auto
            && !p.linear
            && p.accuracy > 0.0
            && p.integrator == Integrator::GeneralizedAlpha
            && body.single_frame()
            && body.reduction.is_none();
        if auto_slabs {
            // One slab per element layer, the finest the mesh allows: on B3 (40 elements along
            // the beam) 40 slabs for the whole run are within 0.23 % of `full`'s peak, 10 within
            // 0.47 %, one frame 1.57 %, and 40 cost no more than 10 (2.3 s against 2.6 s for
            // 20 s simulated; the slab forces are element-sized products either way).
            // The mesh's nodes only: a lumped body's mass points would tilt the slabs' axis.
            let mesh_lumped = &lumped[..self.mesh.node_count()];
            let layers = Patches::element_layers(&self.mesh, mesh_lumped);
            // With their own stiffening, whatever `model.stiffening` allows, switched on where
            // the accuracy asks for it (`auto_features::choose_slab_stiffening`): on B3 it takes
            // the slabs' model error from 2.5e-4 to 4.1e-5 of the peak (40 slabs at a fixed
            // 2.5 ms against `full` at 2.5 ms; docs/formulation.md, "Geometric stiffening within
            // the slabs").
            body.patches = Some(
                Patches::along_principal_axis(&self.mesh, slab_materials, mesh_lumped, layers)?
                    .covering(body.node_count())
                    .with_stiffening(),
            );
        }
        let mut forces = ResidualWorkspace::new(&body);
        let parked_patches = if auto_slabs {
            body.patches.take()
        } else {
            None
        };
        let stiffening = match (reduced_stiffening, p.stiffening) {
            (Some(reduced), _) => Some(reduced),
            (None, Stiffening::Inertial) => Some(GeometricStiffening::inertial(
                &self.mesh,
                &p.material,
                &body,
                &self.clamped,
            )?),
            // Forced slabs carry the stress stiffening themselves (`Patches::with_stiffening`).
            (None, Stiffening::Stress) if body.patches.is_some() => None,
            (None, Stiffening::Stress) => Some(GeometricStiffening::stress(&self.mesh, &body)),
            (None, Stiffening::None) => None,
        };
        forces.geometric_stiffness = stiffening.as_ref().map(|s| s.pattern(&self.mesh));
        let allowed = Features {
            nonlinear_forces: p.nonlinear_forces,
            stiffening: stiffening.is_some(),
            frames: auto_slabs,
            frames_refused: false,
            linear: self.linear_allowed()?,
            slab_stiffening: auto_slabs
                || body.patches.as_ref().is_some_and(|p| p.has_stiffening()),
        };
        let indicators = self.feature_indicators(&body, &free, stiffening.as_ref(), allowed);
        // f_nl is switched only on a body without supports; with supports and one frame
        // model.auto keeps it off (see `auto_features::choose_features`).
        body.nonlinear_forces_switchable = indicators
            .as_ref()
            .is_some_and(|i| !i.estimates_nonlinear_forces())
            && allowed.nonlinear_forces;
        self.events.push(LogEvent {
            category: category::EVENTS,
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
        let integrator = self.time_integrator(&body, lumped, &free)?;
        let p = &self.parameters;
        let lowest_modes = (p.accuracy > 0.0 && p.integrator == Integrator::GeneralizedAlpha)
            .then(|| {
                schemes::lowest_modes(&free, body.total_mass, (p.damping_alpha, p.damping_beta))
            })
            .transpose()?
            .map(|modes| {
                // With slabs the deformation scale projects `K ū` from `K φ_j` (no product per
                // step: `LowestModes::deformation_of`).
                if body.patches.is_some() || parked_patches.is_some() {
                    let size = body.reference.len();
                    modes.with_stiffness_modes(|x, y| body.stiffness_product(x, y), size)
                } else {
                    modes
                }
            });
        let driven_stiffening = match (&lowest_modes, &stiffening) {
            (Some(modes), Some(stiffening))
                if body.reduction.is_some() && self.decides_reduced_stiffening() =>
            {
                stiffening.unit_cases().map(|cases| {
                    cases
                        .iter()
                        .map(|k| {
                            modes.project_matrix(
                                |x, y| geometric_stiffness_product(k, x, y),
                                body.reference.len(),
                            )
                        })
                        .collect()
                })
            }
            _ => None,
        };
        if driven_stiffening.is_some() {
            let accuracy = self.parameters.accuracy;
            self.events.push(LogEvent {
                category: category::EVENTS,
                message: format!(
                    "model.auto: the reduced body's inertial stiffening from its motion interface's driving motion is switched per communication step: on while it changes the lowest modes' stiffness by more than {} × model.accuracy = {:.3e}, off once below half of that for a period of the lowest mode (model.auto = false forces model.stiffening as given)",
                    super::auto_features::DRIVEN_STIFFENING_AT,
                    super::auto_features::DRIVEN_STIFFENING_AT * accuracy
                ),
            });
        }
        let p = &self.parameters;
        let monitored =
            p.formulation != Formulation::Full && p.frames == 1 && body.reduction.is_none();
        self.model = Some(Model {
            key,
            body,
            integrator,
            mass: ConsistentAcceleration::new(&free)?,
            strain_monitor: monitored.then(|| (StrainMonitor::new(&self.mesh), false)),
            free,
            forces,
            stiffening,
            indicators,
            allowed,
            parked_geometric_stiffness: None,
            parked_patches,
            parked_linear: None,
            lowest_modes,
            jacobian: None,
            driven_stiffening,
        });
        self.dynamics = None;
        // The backups have the old model's size (a changed model.modes changes it).
        self.backup = None;
        self.retry_backup = None;
        let size = self.model.as_ref().map_or(0, |m| m.body.reference.len());
        self.outputs.momentum = vec![0.0; size];
        self.scale_scratch = vec![0.0; size];
        Ok(())
    }

    /// The free nodes of `body` (all but the `clamped` ones) with the point constraints of the
    /// pins and hinges and the rigid sets of rigid attachments; each interface learns where its
    /// point constraints start.
    fn constrained_free_nodes(&mut self, body: &Body, clamped: &[bool]) -> Result<FreeNodes> {
        let mut free = FreeNodes::new(body, clamped);
        // On a reduced body a rigid set's nodes are its barycentric fields (body::reduction),
        // the `j`-th rigid attachment's `reduction.rigid[j]`.
        let rigid = self.rigid_attachments();
        let set_nodes: Vec<Vec<usize>> = (0..self.interfaces.len())
            .map(|k| match &body.reduction {
                Some(reduction) if rigid[k] => {
                    reduction.rigid[rigid[..k].iter().filter(|&&r| r).count()].clone()
                }
                _ => self.interfaces[k].set.frame_weights.nodes.clone(),
            })
            .collect();
        for (k, spec) in self.body_file.interfaces.iter().enumerate() {
            if rigid[k] {
                if self.parameters.formulation == Formulation::Full {
                    return Err(Error::new(format!(
                        "interface '{}': rigid attachments are not available with model.formulation = full (its Newton iteration works in the global frame); use reducedStrain",
                        spec.name
                    )));
                }
                free.add_rigid_set(&spec.name, &set_nodes[k], &body.reference)?;
            }
        }
        self.check_held_points_on_rigid_sets()?;
        for (k, interface) in self.interfaces.iter_mut().enumerate() {
            interface.first_constraint = free.constraints.len();
            for (nodes, weights) in &interface.point_constraints {
                let name = &self.body_file.interfaces[k].name;
                // The target is set where the body is placed (ensure_initial_state).
                match &body.reduction {
                    Some(reduction) => {
                        let (fields, weights) = reduction.centroid_weights(nodes, weights);
                        free.add_point_constraint(name, &fields, &weights, Vector3::zeros())?
                    }
                    None => free.add_point_constraint(name, nodes, weights, Vector3::zeros())?,
                }
            }
        }
        for k in 0..self.interfaces.len() {
            if let Some(rigid) = self.interfaces[k].locks {
                let spec = &self.body_file.interfaces[k];
                self.interfaces[k].lock_constraint = free.rigid.len();
                free.add_axis_lock(
                    &spec.name,
                    &set_nodes[rigid],
                    &body.reference,
                    Vector3::from(spec.axis.unwrap_or_default()),
                )?;
            }
        }
        Ok(free)
    }
}
