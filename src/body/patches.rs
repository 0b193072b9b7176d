//! Several co-moving frames: the elements split into patches, each with its own best-fit frame
//! and its own constant stiffness (`model.frames`, docs/formulation.md, "Several co-moving frames").
//!
//! One frame per body measures the strain of a part that bends far against a frame that fits
//! the whole part: where a beam section turns by `θ` relative to the body frame, the linear
//! strain `ε(ū)` carries a spurious second-order term `~θ²/2` that dwarfs the true axial strain
//! of a spinning beam (measured on B3 by `examples/b3_strain.rs`). With patches `p`, each of
//! small angular extent, the strain energy is
//!
//! `V = Σ_p ½ ū_pᵀ K_p ū_p`, `ū_p,i = R_pᵀ (x_i − c_p) − X̄_p,i`,
//!
//! with `(c_p, R_p)` the best-fit frame of the patch's nodes (weights: the nodes' HRZ-lumped
//! masses), `K_p` the small-strain stiffness of the patch's elements (`Σ_p K_p = K`) and
//! `X̄_p,i` the reference offsets from the patch's weighted centroid. Its exact gradient is the
//! single-frame force applied patch by patch (docs/formulation.md, "The internal force"):
//!
//! `f_i = Σ_{p ∋ i} R_p (g_p,i − w_i X̄_p,i × z_p)`, `g_p = K_p ū_p`, `z_p = H_p⁻ᵀ Σ_i ū_p,i × g_p,i`.
//!
//! As the patches shrink to single elements this is the element-wise co-rotational finite
//! element method, which converges to the geometrically nonlinear solution for small strains;
//! one patch is the single-frame body. The mass matrix stays constant and so does the
//! iteration matrix: the body-frame factorization preconditions the patch forces, whose
//! Jacobian differs from it by the patches' rotations relative to the body frame.
//!
//! On a reduced body the same force acts on the coordinates `q` ([`Patches::reduce`],
//! [`ReducedSlab`]): each slab's frame, `ū_p` and `K_p` in terms of the fields, exactly the
//! projection of the nodal force (docs/formulation.md, "The reduced body": several frames).

use super::frame::{add_node, node, set_node, FrameWeights};
use super::reduction::Reduction;
use super::slab_stiffening::SlabStiffening;
use crate::error::{Error, Result};
use crate::fem::{self, IsotropicMaterial};
use crate::linalg::dense::DenseSymmetric;
use crate::linalg::sparse::BlockCsr3;
use crate::mesh::Mesh;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// One patch: its nodes (global numbers, in local order), its frame weights and `K_p`.
#[derive(Debug, Clone)]
pub struct Patch {
    /// Elements of the patch (mesh numbering).
    pub elements: Vec<usize>,
    /// The best-fit frame of the patch's nodes (its `nodes` are the global node numbers; local
    /// node `k` is `frame_weights.nodes[k]`).
    pub frame_weights: FrameWeights,
    /// `K_p` on the patch's local nodes (N/m).
    stiffness: BlockCsr3,
    /// The patch's elements on its local nodes.
    mesh: Mesh,
    /// The material of each of the patch's elements, in its order (material regions; no
    /// stiffness inside a rigid set).
    materials: Vec<IsotropicMaterial>,
    /// The geometric stiffness of the patch's own prestress ([`Patches::with_stiffening`]).
    stiffening: Option<SlabStiffening>,
}

/// The patches of a body and the length of the largest one (for scratch).
#[derive(Debug, Clone)]
pub struct Patches {
    pub patches: Vec<Patch>,
    /// For each node, the first patch that contains it (whose frame rotates the node's part of
    /// the iteration, see `solver::generalized_alpha`).
    pub node_patch: Vec<usize>,
    largest: usize,
    /// Whether the slabs' own stiffening ([`Patches::with_stiffening`]) is in their force.
    pub stiffening_active: bool,
    /// `ū_p` and `K_p ū_p` of [`Patches::update_stiffening`] (the largest patch's length).
    update_scratch: (Vec<f64>, Vec<f64>),
    /// On a reduced body, the slabs on its coordinates ([`Patches::reduce`]; empty otherwise).
    reduced: Vec<ReducedSlab>,
}

/// A slab on a reduced body's coordinates `q` (docs/formulation.md, "The reduced body":
/// several frames): its best-fit frame in terms of `q` ([`Reduction::part_frame`]) and
/// `K_rp = (S_p ⊗ I3)ᵀ K_p (S_p ⊗ I3)` (`3s × 3s`). On the slab's nodes `ū_p = (S_p ⊗ I3) ū_r`
/// with `ū_r,k = R_pᵀ (q_k − e_k c_p) − (q_ref,k − e_k C_p)`, so the slab's force on the
/// coordinates, `(S ⊗ I3)ᵀ` of its nodal force, is `(I ⊗ R_p)(K_rp ū_r − a_k × z_p)` with the
/// frame's constant arms `a_k`, and `m̄_p = Σ_i ū_i × g_i = Σ_k ū_r,k × (K_rp ū_r)_k`: the
/// nodal force projected, without expanding the nodes.
#[derive(Debug, Clone)]
struct ReducedSlab {
    frame_weights: FrameWeights,
    stiffness: DenseSymmetric,
}

/// Scratch of [`Patches::internal_force`]: `ū_p` and `g_p` of the largest patch, and the
/// patches' rotations `R_p` of the last call.
#[derive(Debug, Clone)]
pub struct PatchScratch {
    local_deformation: Vec<f64>,
    elastic_force: Vec<f64>,
    pub rotations: Vec<Matrix3<f64>>,
}

/// The body's principal axis of least inertia (its longest direction): the eigenvector of the
/// largest eigenvalue of the nodes' mass-weighted second moment about their centroid
/// (`lumped_masses`, kg, positive).
fn principal_axis(mesh: &Mesh, lumped_masses: &[f64]) -> Vector3<f64> {
    let nodes = mesh.nodes();
    let total: f64 = lumped_masses.iter().sum();
    let centre: Vector3<f64> = nodes
        .iter()
        .zip(lumped_masses)
        .map(|(p, &w)| w * Vector3::from(*p))
        .sum::<Vector3<f64>>()
        / total;
    let mut second_moment = Matrix3::zeros();
    for (p, &w) in nodes.iter().zip(lumped_masses) {
        let d = Vector3::from(*p) - centre;
        second_moment += w * d * d.transpose();
    }
    let eigen = SymmetricEigen::new(second_moment);
    eigen
        .eigenvectors
        .column(eigen.eigenvalues.imax())
        .into_owned()
}

impl Patches {
    /// Splits the elements of `mesh` into `count` slabs of equal length along the body's
    /// principal axis of least inertia (its longest direction), by element centroid; empty slabs
    /// are dropped. `lumped_masses` (kg, positive) weight the patch frames; `materials` holds
    /// each element's material (its stiffness's: material regions, none inside a rigid set).
    pub fn along_principal_axis(
        mesh: &Mesh,
        materials: &[IsotropicMaterial],
        lumped_masses: &[f64],
        count: usize,
    ) -> Result<Patches> {
        if count == 0 {
            return Err(Error::invalid_value(
                "model.frames",
                0.0,
                "must be at least 1",
            ));
        }
        let nodes = mesh.nodes();
        let axis = principal_axis(mesh, lumped_masses);
        let centroids: Vec<f64> = (0..mesh.element_count())
            .map(|e| {
                let el = mesh.element(e);
                el.iter()
                    .map(|&n| Vector3::from(nodes[n]).dot(&axis))
                    .sum::<f64>()
                    / el.len() as f64
            })
            .collect();
        let lo = centroids.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = centroids.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let width = (hi - lo).max(f64::MIN_POSITIVE);
        let mut groups = vec![Vec::new(); count];
        for (e, &s) in centroids.iter().enumerate() {
            let slot = (((s - lo) / width * count as f64) as usize).min(count - 1);
            groups[slot].push(e);
        }
        groups.retain(|g| !g.is_empty());
        Self::from_groups(mesh, materials, lumped_masses, groups)
    }

    /// The number of element layers along the body's principal axis of least inertia (as in
    /// [`Patches::along_principal_axis`]): the nodes' extent along the axis over the elements'
    /// mean extent along it, rounded, at least 1. On a structured beam mesh of `n` elements
    /// along its length it is `n`: slabs of one layer each, the finest the mesh allows.
    pub fn element_layers(mesh: &Mesh, lumped_masses: &[f64]) -> usize {
        let axis = principal_axis(mesh, lumped_masses);
        let nodes = mesh.nodes();
        let along = |n: usize| Vector3::from(nodes[n]).dot(&axis);
        let extent = |it: &mut dyn Iterator<Item = f64>| {
            let (lo, hi) = it.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                (lo.min(s), hi.max(s))
            });
            (hi - lo).max(0.0)
        };
        let body = extent(&mut (0..nodes.len()).map(along));
        let elements = mesh.element_count();
        if elements == 0 {
            return 1;
        }
        let mean = (0..elements)
            .map(|e| extent(&mut mesh.element(e).iter().map(|&n| along(n))))
            .sum::<f64>()
            / elements as f64;
        if mean > 0.0 {
            ((body / mean).round() as usize).clamp(1, elements)
        } else {
            1
        }
    }

    /// Patches from groups of elements (each element in exactly one group), with each
    /// element's material `materials[e]`.
    pub fn from_groups(
        mesh: &Mesh,
        materials: &[IsotropicMaterial],
        lumped_masses: &[f64],
        groups: Vec<Vec<usize>>,
    ) -> Result<Patches> {
        let reference: Vec<f64> = mesh.nodes().iter().flatten().copied().collect();
        let mut patches = Vec::with_capacity(groups.len());
        let mut local = vec![usize::MAX; mesh.node_count()];
        for elements in groups {
            // Local numbering of the patch's nodes in order of first appearance.
            let mut global = Vec::new();
            let mut connectivity = Vec::new();
            for &e in &elements {
                for &n in mesh.element(e) {
                    if local[n] == usize::MAX {
                        local[n] = global.len();
                        global.push(n);
                    }
                    connectivity.push(local[n]);
                }
            }
            let sub = Mesh::new(
                global.iter().map(|&n| mesh.nodes()[n]).collect(),
                mesh.kind(),
                connectivity,
            )?;
            let materials: Vec<IsotropicMaterial> =
                elements.iter().map(|&e| materials[e]).collect();
            let stiffness = BlockCsr3::from_csr(&fem::stiffness_matrix_of(&sub, &|e| materials[e]));
            let weights = global.iter().map(|&n| lumped_masses[n]).collect();
            for &n in &global {
                local[n] = usize::MAX;
            }
            patches.push(Patch {
                elements,
                frame_weights: FrameWeights::new(global, weights, &reference),
                stiffness,
                mesh: sub,
                materials,
                stiffening: None,
            });
        }
        let largest = patches
            .iter()
            .map(|p| p.frame_weights.nodes.len())
            .max()
            .unwrap_or(0);
        let mut node_patch = vec![usize::MAX; mesh.node_count()];
        for (k, p) in patches.iter().enumerate() {
            for &n in &p.frame_weights.nodes {
                if node_patch[n] == usize::MAX {
                    node_patch[n] = k;
                }
            }
        }
        Ok(Patches {
            patches,
            node_patch,
            largest,
            stiffening_active: false,
            update_scratch: (vec![0.0; 3 * largest], vec![0.0; 3 * largest]),
            reduced: Vec::new(),
        })
    }

    /// The patches with their own geometric stiffening, `R_p (G_p ⊗ I3) ū_p` in each patch's
    /// force while [`Self::stiffening_active`] (zero until [`Self::update_stiffening`];
    /// docs/formulation.md, "Geometric stiffening within the slabs"). Set-up only (allocates).
    pub fn with_stiffening(mut self) -> Patches {
        for patch in &mut self.patches {
            patch.stiffening = Some(SlabStiffening::new(&patch.mesh, &patch.materials));
        }
        self
    }

    /// Whether the patches have their own stiffening ([`Self::with_stiffening`]).
    pub fn has_stiffening(&self) -> bool {
        self.patches.iter().all(|p| p.stiffening.is_some())
    }

    /// Refreshes each slab's `G_p` from its local deformation `ū_p` at positions `x` (flat, m):
    /// the prestress of the state at a communication step's start. With `measure`, returns how
    /// much the stiffening changes the slabs' stiffness, the energy ratio
    /// `Σ_p |ū_pᵀ (G_p ⊗ I3) ū_p| / Σ_p ū_pᵀ K_p ū_p` (0 without deformation; on B3 it bounds the
    /// slabs' model error without it within 3×). No allocation.
    pub fn update_stiffening(&mut self, x: &[f64], measure: bool, scale: f64) -> Option<f64> {
        let (mut elastic, mut stiffening_energy) = (0.0, 0.0);
        for patch in &mut self.patches {
            let Some(stiffening) = patch.stiffening.as_mut() else {
                continue;
            };
            let fw = &patch.frame_weights;
            let m = 3 * fw.nodes.len();
            let ubar = &mut self.update_scratch.0[..m];
            let frame = fw.best_fit(x);
            let rt = frame.rotation.transpose();
            for (k, &n) in fw.nodes.iter().enumerate() {
                let u = rt * (node(x, n) - frame.origin) - fw.reference_offsets[k];
                set_node(ubar, k, &u);
            }
            stiffening.update(ubar, if measure { 1.0 } else { scale });
            if measure {
                let force = &mut self.update_scratch.1[..m];
                patch.stiffness.mul_vec(ubar, force);
                elastic += 0.5 * crate::linalg::dot(ubar, force);
                force.fill(0.0);
                // Per slab: slabs in tension and in compression do not cancel.
                stiffening_energy += stiffening.add_force(ubar, force).abs();
            }
        }
        measure.then(|| {
            if elastic > 0.0 {
                stiffening_energy / elastic
            } else {
                0.0
            }
        })
    }

    /// The patches of a body with `total` nodes, the mesh's and after them a lumped body's mass
    /// points, which belong to no patch (no stiffness): their rows turn with the first patch.
    pub fn covering(mut self, total: usize) -> Patches {
        self.node_patch.resize(total, 0);
        self
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.patches.len()
    }

    /// Whether there are no patches.
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// Scratch for [`Self::internal_force`].
    pub fn scratch(&self) -> PatchScratch {
        PatchScratch {
            local_deformation: vec![0.0; 3 * self.largest],
            elastic_force: vec![0.0; 3 * self.largest],
            rotations: vec![Matrix3::identity(); self.patches.len()],
        }
    }

    /// The part of the elastic force at `X + u` quadratic in the displacement `u` (flat, N;
    /// `reference` the positions `X` of the nodes the slabs cover, `u` and `f` at least as
    /// long, `f`'s entries beyond them zero): `f(X + u) = K u + f₂(u) + O(u³)`, by central
    /// differences, `f₂(u) = (f(X + εu) + f(X − εu)) / (2ε²)` (the odd orders cancel), `ε`
    /// scaling the largest entry of `u` to 1e-3 of `size` (m). With `nonlinear_forces`, `f_nl`'s
    /// second order too. The modal derivatives of a reduced body with several frames take it
    /// (docs/formulation.md, "The reduced body"). Allocates (set-up only).
    pub fn second_order_force(
        &self,
        reference: &[f64],
        u: &[f64],
        nonlinear_forces: bool,
        size: f64,
        f: &mut [f64],
    ) {
        assert!(
            !self.acts_on_coordinates(),
            "Patches::second_order_force: the slabs act on a reduced body's coordinates"
        );
        let dofs = reference.len();
        let largest = u[..dofs].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        f.fill(0.0);
        if largest == 0.0 {
            return;
        }
        let epsilon = 1e-3 * size / largest;
        let mut scratch = self.scratch();
        let mut x = reference.to_vec();
        let mut twice = vec![0.0; dofs];
        for sign in [1.0, -1.0] {
            for (x, (r, u)) in x.iter_mut().zip(reference.iter().zip(u)) {
                *x = r + sign * epsilon * u;
            }
            self.internal_force(&x, nonlinear_forces, &mut scratch, &mut twice);
        }
        for (f, t) in f.iter_mut().zip(&twice) {
            *f = t / (2.0 * epsilon * epsilon);
        }
    }

    /// Adds the elastic force `f_i = Σ_p R_p (g_p,i − w_i X̄_p,i × z_p)` of positions `x` to `f`
    /// (global frame, N; `z_p = 0` without `nonlinear_forces`) and returns the strain energy
    /// `V = Σ_p ½ ū_pᵀ K_p ū_p` (J). On a reduced body whose slabs are on its coordinates
    /// ([`Patches::acts_on_coordinates`]), `x` and `f` are the coordinates `q` and the force on
    /// them, the same as the nodal force's projection. No allocation.
    pub fn internal_force(
        &self,
        x: &[f64],
        nonlinear_forces: bool,
        scratch: &mut PatchScratch,
        f: &mut [f64],
    ) -> f64 {
        let mut energy = 0.0;
        if self.acts_on_coordinates() {
            for (p, slab) in self.reduced.iter().enumerate() {
                let fw = &slab.frame_weights;
                let arm = |k: usize, z: &Vector3<f64>| fw.arms[k].cross(z);
                let product = |u: &[f64], g: &mut [f64]| slab.stiffness.mul_vec(u, g);
                let no_extra = |_: &[f64], _: &mut [f64]| {};
                energy += part_force(
                    fw,
                    product,
                    no_extra,
                    arm,
                    x,
                    nonlinear_forces,
                    scratch,
                    p,
                    f,
                );
            }
            return energy;
        }
        for (p, patch) in self.patches.iter().enumerate() {
            let fw = &patch.frame_weights;
            let arm = |k: usize, z: &Vector3<f64>| fw.weights[k] * fw.reference_offsets[k].cross(z);
            let product = |u: &[f64], g: &mut [f64]| patch.stiffness.mul_vec(u, g);
            // The stiffening's force is a frozen-prestress term, as the one frame's `K_G ū`: it
            // adds nothing to the strain energy (the output `body.strainEnergy`, the error
            // control's scale of the modes above the lowest), so it comes after the energy.
            let stiffening = patch.stiffening.as_ref().filter(|_| self.stiffening_active);
            let add_stiffening = |u: &[f64], g: &mut [f64]| {
                if let Some(stiffening) = stiffening {
                    stiffening.add_force(u, g);
                }
            };
            energy += part_force(
                fw,
                product,
                add_stiffening,
                arm,
                x,
                nonlinear_forces,
                scratch,
                p,
                f,
            );
        }
        energy
    }

    /// Puts the slabs on a reduced body's coordinates ([`ReducedSlab`]): from then on
    /// [`Patches::internal_force`] takes `q` and gives the force on it, `P` products with
    /// `3s × 3s` matrices instead of the expansion to the nodes, every slab's `K_p` and the
    /// projection back. Allocates; set-up only.
    ///
    /// Panics if the slabs have their own stiffening ([`Patches::with_stiffening`]), which is
    /// refreshed on the nodes: a reduced body's slabs take none (`model.auto` takes no slabs for
    /// it, and `model.stiffening = stress` is refused).
    pub fn reduce(&mut self, reduction: &Reduction) {
        assert!(
            !self.has_stiffening(),
            "Patches::reduce: slabs with their own stiffening act on the nodes"
        );
        self.reduced = self
            .patches
            .iter()
            .map(|patch| {
                let fw = &patch.frame_weights;
                ReducedSlab {
                    frame_weights: reduction.part_frame(&fw.nodes, &fw.weights),
                    stiffness: reduction
                        .project_part_matrix(&fw.nodes, |u, g| patch.stiffness.mul_vec(u, g)),
                }
            })
            .collect();
        self.largest = self.largest.max(reduction.field_count);
    }

    /// Whether [`Patches::internal_force`] acts on a reduced body's coordinates
    /// ([`Patches::reduce`]).
    pub fn acts_on_coordinates(&self) -> bool {
        !self.reduced.is_empty()
    }
}

/// One part's force (a slab on the nodes or on a reduced body's coordinates): its best-fit
/// frame `fw` of `x` (kept in `scratch.rotations[p]`), `ū`, `g = product(ū)`, then
/// `extra(ū, g)` added to `g` after the energy is taken (the slabs' own stiffening), `f_nl`'s
/// `z = H⁻ᵀ Σ_k ū_k × g_k`, and `R (g_k − arm(k, z))` added to `f`; returns `½ ūᵀ product(ū)`
/// (J).
#[allow(clippy::too_many_arguments)]
fn part_force(
    fw: &FrameWeights,
    product: impl Fn(&[f64], &mut [f64]),
    extra: impl Fn(&[f64], &mut [f64]),
    arm: impl Fn(usize, &Vector3<f64>) -> Vector3<f64>,
    x: &[f64],
    nonlinear_forces: bool,
    scratch: &mut PatchScratch,
    p: usize,
    f: &mut [f64],
) -> f64 {
    let m = 3 * fw.nodes.len();
    let ubar = &mut scratch.local_deformation[..m];
    let g = &mut scratch.elastic_force[..m];
    let frame = fw.best_fit(x);
    scratch.rotations[p] = frame.rotation;
    let rt = frame.rotation.transpose();
    for (k, &n) in fw.nodes.iter().enumerate() {
        let u = rt * (node(x, n) - fw.unit(k) * frame.origin) - fw.reference_offsets[k];
        set_node(ubar, k, &u);
    }
    product(ubar, g);
    let energy = 0.5 * crate::linalg::dot(ubar, g);
    extra(ubar, g);
    let z = if nonlinear_forces {
        let mut mbar = Vector3::zeros();
        for k in 0..fw.nodes.len() {
            mbar += node(ubar, k).cross(&node(g, k));
        }
        let h_inv = fw
            .rotation_sensitivity(&frame, x)
            .try_inverse()
            .unwrap_or_else(Matrix3::zeros);
        h_inv.transpose() * mbar
    } else {
        Vector3::zeros()
    };
    for (k, &n) in fw.nodes.iter().enumerate() {
        let local = node(g, k) - arm(k, &z);
        add_node(f, n, &(frame.rotation * local));
    }
    energy
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{generator, ElementKind};

    fn beam() -> (Mesh, IsotropicMaterial, Vec<f64>) {
        let mesh = generator::beam(1.0, 0.1, 0.1, [6, 1, 1], ElementKind::Hex8).unwrap();
        let material = IsotropicMaterial::STEEL;
        let lumped = fem::lumped_masses(&mesh, material.density);
        (mesh, material, lumped)
    }

    /// The beam's slabs, `count` of them, every element of `material`.
    fn slabs(mesh: &Mesh, material: IsotropicMaterial, lumped: &[f64], count: usize) -> Patches {
        let materials = vec![material; mesh.element_count()];
        Patches::along_principal_axis(mesh, &materials, lumped, count).unwrap()
    }

    #[test]
    fn a_structured_beam_has_one_layer_per_element_along_it_and_one_slab_per_layer() {
        let (mesh, material, lumped) = beam();
        assert_eq!(Patches::element_layers(&mesh, &lumped), 6);
        let slabs = slabs(&mesh, material, &lumped, 6);
        assert_eq!(slabs.len(), 6);
        assert!(slabs.patches.iter().all(|p| p.elements.len() == 1));
        // Across the beam (2 × 3 elements in the section) the layers still run along it.
        let mesh = generator::beam(2.0, 0.1, 0.1, [8, 2, 3], ElementKind::Hex20).unwrap();
        let lumped = fem::lumped_masses(&mesh, material.density);
        assert_eq!(Patches::element_layers(&mesh, &lumped), 8);
    }

    #[test]
    fn slabs_cover_every_element_once_and_their_stiffness_sums_to_k() {
        let (mesh, material, lumped) = beam();
        let patches = slabs(&mesh, material, &lumped, 3);
        assert_eq!(patches.len(), 3);
        let mut seen = vec![0; mesh.element_count()];
        for p in &patches.patches {
            assert_eq!(p.elements.len(), 2);
            p.elements.iter().for_each(|&e| seen[e] += 1);
        }
        assert!(seen.iter().all(|&s| s == 1));
        // At x = reference + small u (no rotation), Σ_p K_p u = K u to round-off.
        let reference: Vec<f64> = mesh.nodes().iter().flatten().copied().collect();
        let u: Vec<f64> = (0..reference.len())
            .map(|k| 1e-6 * ((k * 7919 % 13) as f64 - 6.0))
            .collect();
        let k = fem::stiffness_matrix(&mesh, &material);
        let mut ku = vec![0.0; u.len()];
        k.mul_vec(&u, &mut ku);
        // Remove each patch's rigid part: compare energies instead of forces (frames absorb
        // the rigid parts of u, which K annihilates too).
        let x: Vec<f64> = reference.iter().zip(&u).map(|(a, b)| a + b).collect();
        let mut f = vec![0.0; u.len()];
        let v = patches.internal_force(&x, true, &mut patches.scratch(), &mut f);
        let linear = 0.5 * crate::linalg::dot(&u, &ku);
        assert!(
            (v - linear).abs() < 1e-4 * linear,
            "patch energy {v} vs linear {linear}"
        );
    }

    #[test]
    fn force_is_the_gradient_of_the_energy_under_large_rotation() {
        let (mesh, material, lumped) = beam();
        let patches = slabs(&mesh, material, &lumped, 3);
        let reference: Vec<f64> = mesh.nodes().iter().flatten().copied().collect();
        let q = nalgebra::Rotation3::from_euler_angles(0.4, -0.7, 1.1);
        // A bent configuration: y += 0.05 x², then rotated and shifted.
        let x: Vec<f64> = reference
            .chunks_exact(3)
            .flat_map(|p| {
                let bent = Vector3::new(p[0], p[1] + 0.05 * p[0] * p[0], p[2] + 1e-3 * p[0]);
                let y = q * bent + Vector3::new(0.3, -0.2, 0.1);
                [y.x, y.y, y.z]
            })
            .collect();
        let mut scratch = patches.scratch();
        let mut f = vec![0.0; x.len()];
        patches.internal_force(&x, true, &mut scratch, &mut f);
        let scale = f.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        let eps = 1e-7;
        let mut worst: f64 = 0.0;
        let mut dummy = vec![0.0; x.len()];
        for k in (0..x.len()).step_by(5) {
            let mut xp = x.clone();
            xp[k] += eps;
            let vp = patches.internal_force(&xp, true, &mut scratch, &mut dummy);
            xp[k] -= 2.0 * eps;
            let vm = patches.internal_force(&xp, true, &mut scratch, &mut dummy);
            worst = worst.max(((vp - vm) / (2.0 * eps) - f[k]).abs());
        }
        assert!(worst < 1e-5 * scale, "worst {worst:e} vs scale {scale:e}");
        // Exact gradient of a rotation-invariant energy: no net force, no net moment.
        let (mut force, mut moment) = (Vector3::zeros(), Vector3::zeros());
        for i in 0..mesh.node_count() {
            force += node(&f, i);
            moment += node(&x, i).cross(&node(&f, i));
        }
        assert!(force.norm() < 1e-9 * scale && moment.norm() < 1e-9 * scale);
    }

    #[test]
    fn rigid_motion_has_no_force() {
        let (mesh, material, lumped) = beam();
        let patches = slabs(&mesh, material, &lumped, 4);
        let q = nalgebra::Rotation3::from_euler_angles(2.0, 0.3, -1.0);
        let x: Vec<f64> = mesh
            .nodes()
            .iter()
            .flat_map(|p| {
                let y = q * Vector3::from(*p) + Vector3::new(5.0, 1.0, 2.0);
                [y.x, y.y, y.z]
            })
            .collect();
        let mut f = vec![0.0; x.len()];
        let v = patches.internal_force(&x, true, &mut patches.scratch(), &mut f);
        assert!(v.abs() < 1e-12);
        assert!(f.iter().all(|v| v.abs() < 1e-3), "{:?}", &f[..6]);
    }
}
