//! Component mode synthesis in absolute coordinates (`model.modes = n`, docs/formulation.md, "The reduced body",
//! "Reduced body").
//!
//! The positions of the `N` nodes are restricted to `x_i = Σ_k S_ik q_k`, `k = 1..s`: `s` scalar
//! fields `S_k` over the nodes, each with a vector coefficient `q_k ∈ R³` (global frame). In
//! matrix form `x = Ψ q` with `Ψ = S ⊗ I3`. Because every field is used in all three directions,
//! the subspace is invariant under a rotation of the whole body: `R_blk Ψ = Ψ (I_s ⊗ R)`. So the
//! formulation's structure survives the Galerkin projection unchanged:
//!
//! * reduced mass `M_r = Ψᵀ M Ψ = (Sᵀ Ms S) ⊗ I3`, constant;
//! * reduced stiffness `K_r = Ψᵀ K Ψ`, constant, and the elastic force
//!   `Ψᵀ R_blk K ū = (I ⊗ R) K_r ū_r`: the body's `R K ū` with `q_k` in place of the nodes;
//! * the co-moving frame of the expanded nodes is a linear function of `q` (see
//!   [`FrameWeights`]), computed in `O(s)`.
//!
//! A reduced body is therefore an ordinary [`super::Body`] whose "nodes" are the `q_k` (dense
//! matrices of size `3s`), and the solver, its one factorization per step size and the
//! allocation-free step serve it unchanged. The price of the rotation invariance is three
//! coordinates per scalar field where the floating frame of reference needs one per mode.
//!
//! The fields span (Craig–Bampton with the interface node sets as boundary, the boundary
//! motion restricted to the affine motions of each set):
//!
//! 1. the affine fields `1, X, Y, Z` (all rigid motions, exactly);
//! 2. constraint modes: for each boundary set (fixed support, motion interface) but the first,
//!    and each affine function `φ` of its nodes and direction `d`, the static response to
//!    `u = φ e_d` on the set (other boundary sets held). The first set needs none: the sets only
//!    ever move rigidly, and the response to a rigid motion of the first set with the others
//!    moving along is that rigid motion of the whole body, which the affine fields hold (the
//!    others' constraint modes add their motion relative to it). This holds to first order in
//!    the set's rotation against the co-moving frame: turned by `θ` against it (a bent body),
//!    the set's local data has a non-rigid part of `O(θ²)`, which the mesh answers with a field
//!    at the support and this basis with the affine fields only. That is of the order of the
//!    reduced strain's own small-rotation error; on B3 (a 10 m beam, 0.57 m peak deflection)
//!    the reduced body's error against `full` differs from the mesh body's by 2e-6 m
//!    (`cargo xtask bench`, 2026-11-23). B1 with 8 modes has 46 scalar fields (138
//!    coordinates) without its root's constraint modes, 62 (186) with them;
//! 3. the `n` lowest fixed-interface modes (boundary sets held; free-free modes when there is no
//!    boundary set, computed with a small shift);
//! 4. attachment modes: for each force interface, the static response to a unit force and a
//!    unit torque in each direction, distributed as the interface distributes them (boundary
//!    held; with inertia relief when there is no boundary set);
//! 5. with several frames (`model.frames > 1`, a supported body), the modal derivatives of the
//!    fixed-interface and attachment modes: `ψ = −K_ii⁻¹ f₂(φ)`, `f₂` the slabs' elastic force
//!    to second order (docs/formulation.md, "The reduced body": several frames);
//!
//! each vector mode contributing its three components as scalar fields. The basis is then
//! rearranged so that on boundary set `j` exactly `a_j` fields are non-zero, and there they are
//! the set's affine functions `1` and `t_a · (X − X_cs)` (`a_j = 3` for a planar set, 4
//! otherwise). Their coefficients are the set's motion: driven by a frame `(p, Q)`,
//! `q_0 = p + Q (X_cs − X_ref)` and `q_a = Q t_a` ([`HeldCoordinate`]), so a motion interface or
//! fixed support holds `a_j` coordinates exactly as it holds nodes on the full mesh.
//!
//! A rigid attachment (docs/formulation.md, "Rigid attachments", "The reduced body") is a
//! boundary set too, held in the static solves like a support, with its constraint modes and
//! without attachment modes (a load on a boundary set moves only its affine coordinates, whose
//! static responses the constraint modes are). Its held fields are made barycentric:
//! `φ_0 = 1 − Σ_a t_a · (X − X_cs)`, `φ_a = t_a · (X − X_cs)`, whose coefficients are points,
//! `P_0` at `X_cs` and `P_a` at `X_cs + t_a` (`x_i = Σ_b φ_b(X_i) P_b` on the set, `Σ_b φ_b = 1`).
//! The set moves rigidly exactly when these 3 or 4 points do, which the solver holds with the
//! mesh's rigid-set constraint over them ([`Reduction::rigid`]). A lumped body's mass points
//! belong to the set, so their mass enters `Sᵀ Ms S` through the set's affine fields.

use super::frame::{node, FrameWeights};
use super::interface::{FieldBasis, HeldCoordinate, NodeSet};
use crate::error::Result;
use crate::linalg::dense::DenseSymmetric;
use crate::linalg::{dot, SymmetricCsr};
use nalgebra::{DMatrix, Matrix3, Vector3};

mod construction;
mod static_responses;
use construction::{
    barycentric_fields, basis_fields, boundary_coefficients, candidate_fields, constraint_modes,
    expanded_frame, fixed_interface_modes, held_coordinates, reduced_mass, reduced_stiffness,
    InteriorSolve,
};
use static_responses::{attachment_modes, modal_derivatives};

/// Scalar fields from a vector mode whose mass norm is below this fraction of the mode's
/// largest component are dropped (round-off of components that vanish by symmetry).
pub const COMPONENT_CUTOFF: f64 = 1e-9;

/// A candidate field whose part independent of the fields before it is below this fraction of
/// its own mass norm is dropped (linear dependence, e.g. rigid constraint modes, which the
/// affine fields already hold). Far above the round-off of two Gram–Schmidt passes (~1e-15),
/// far below real content: a part small in the mass norm can be stiff (at 1e-6, B1 with 4 modes
/// lost a field whose absence raised f2 by 1.7e-7).
pub const DEPENDENCE_CUTOFF: f64 = 1e-9;

/// Relative tolerance of the subspace iteration for the fixed-interface modes (eigenvalues to
/// about this, mode shapes to its square root: ample for a basis).
pub const MODE_TOLERANCE: f64 = 1e-9;

/// The largest number of fixed-interface modes [`ModeCount::Accuracy`] takes: a body that
/// needs more for its inertial loads is better moved on its mesh (the choice says so).
pub const MAX_CHOSEN_MODES: usize = 128;

/// How many fixed-interface modes the basis takes (`model.modes`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModeCount {
    /// `n ≥ 1` modes (`model.modes = n`).
    Fixed(usize),
    /// The fewest modes whose static response to the body's inertial loads is within this
    /// relative error of the full mesh's (`model.modes = auto`, [`ModeChoice`]).
    Accuracy(f64),
}

/// The mode count [`ModeCount::Accuracy`] chose, and why (docs/formulation.md, "The reduced
/// body", "How many modes").
///
/// The loads a body meets that no interface carries are the inertial loads of its motion:
/// `f = M a` for the accelerations `a` of a rigid motion, which span the affine fields
/// `a = e_d` and `a = (X_b − X̄_b)/L e_d` (translation and gravity; angular and centripetal
/// acceleration, per unit of acceleration at the distance `L`, the body's largest RMS extent
/// along an axis). With the boundary held, the static response `u = K_ii⁻¹ f` has the modal
/// expansion `u = Σ_j φ_j c_j`, `c_j = φ_jᵀ M u` (mass-normalised fixed-interface modes), so
/// the `n` lowest modes leave the error `‖u − Σ_{j≤n} φ_j c_j‖²_M = ‖u‖²_M − Σ_{j≤n} c_j²`,
/// exactly and with one solve per load. The count is the smallest `n` whose largest error
/// over the twelve loads is at most `accuracy` times the largest response: below the modes'
/// frequencies a load is answered quasi-statically, so this is the reduced body's error in the
/// mass norm, relative to its deformation scale, that `model.accuracy` measures. (Interface
/// loads need no modes: their static responses, the attachment modes, are in the basis.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeChoice {
    /// The accuracy asked for.
    pub accuracy: f64,
    /// Modes taken.
    pub count: usize,
    /// The relative error of the inertial loads' static response with `count` modes, and with
    /// one fewer (1 with none: the largest response is then missed whole).
    pub error: f64,
    pub error_one_fewer: f64,
}

impl ModeChoice {
    /// Whether the accuracy was met within [`MAX_CHOSEN_MODES`].
    pub fn met(&self) -> bool {
        self.error <= self.accuracy
    }
}

/// The reduced body's basis and constant matrices.
#[derive(Debug, Clone)]
pub struct Reduction {
    /// `N`, nodes of the mesh.
    pub node_count: usize,
    /// `s`, scalar fields (the reduced body has `3s` coordinates).
    pub field_count: usize,
    /// `S`, row-major `N × s`: node `i`'s row is `fields[i s .. (i+1) s]`.
    pub fields: Vec<f64>,
    /// Reference positions of the mesh nodes `X` (flat `3N`, m).
    pub mesh_reference: Vec<f64>,
    /// `q_ref` with `Σ_k S_ik q_ref,k = X_i` (flat `3s`).
    pub reference: Vec<f64>,
    /// `e` with `Σ_k S_ik e_k = 1`.
    pub unit: Vec<f64>,
    /// `Sᵀ Ms S` (kg), `s × s`.
    pub mass_matrix: SymmetricCsr,
    /// `K_r = (S ⊗ I3)ᵀ K (S ⊗ I3)` (N/m), `3s × 3s`, dense.
    pub stiffness_matrix: SymmetricCsr,
    /// The co-moving frame of the expanded nodes (HRZ-lumped weights) in terms of `q`.
    pub frame_weights: FrameWeights,
    /// Per held set (`InterfaceSets::held`, in order): its held coordinates.
    pub held: Vec<Vec<HeldCoordinate>>,
    /// Per rigid set (`InterfaceSets::rigid`, in order): its barycentric fields, whose
    /// coefficients are points at the reference positions `reference` of these fields (see the
    /// module documentation).
    pub rigid: Vec<Vec<usize>>,
    /// `ω²` of the fixed-interface (or free-free elastic) modes in the basis (1/s²).
    pub mode_eigenvalues: Vec<f64>,
    /// How the mode count was chosen ([`ModeCount::Accuracy`]; `None` for a given count).
    pub mode_choice: Option<ModeChoice>,
}

/// `f₂(u)` written into its second argument ([`MeshData::second_order_force`]).
pub type SecondOrderForce<'f> = dyn Fn(&[f64], &mut [f64]) + 'f;

/// The mesh data a reduction starts from (`N` nodes: the mesh's, then any lumped body's mass
/// points).
#[derive(Clone, Copy)]
pub struct MeshData<'a> {
    /// Reference positions `X` (flat `3N`, m).
    pub reference: &'a [f64],
    /// `Ms`, the scalar consistent mass matrix (kg), `N × N`.
    pub mass: &'a SymmetricCsr,
    /// `K` (N/m), `3N × 3N`: the static solves and modes.
    pub stiffness: &'a SymmetricCsr,
    /// The elastic force's `K`, if it differs from `stiffness` (without the elements wholly
    /// inside rigid sets, docs/formulation.md "Rigid attachments"): `K_r` is projected from it.
    pub force_stiffness: Option<&'a SymmetricCsr>,
    /// HRZ-lumped masses (kg): the inertial loads of the mode choice, inertia relief.
    pub lumped: &'a [f64],
    /// The co-moving frame's weights per node (the lumped masses, zero on mass points).
    pub frame_weights: &'a [f64],
    /// The second-order internal force `f₂(u)` of a displacement `u` (flat `3N`, N): the
    /// part of the elastic force quadratic in `u`, `f(X + u) = K u + f₂(u) + O(u³)`. Given for
    /// a body with several frames (the slabs' force): the modal derivatives of the basis, see
    /// the module documentation.
    pub second_order_force: Option<&'a SecondOrderForce<'a>>,
}

/// The interfaces' node sets as the reduction treats them.
#[derive(Debug, Clone, Copy, Default)]
pub struct InterfaceSets<'a> {
    /// Fixed supports and motion interfaces: boundary sets whose coordinates are held.
    pub held: &'a [&'a NodeSet],
    /// Rigid attachments: boundary sets that move as one rigid body (see the module
    /// documentation).
    pub rigid: &'a [&'a NodeSet],
    /// Force interfaces that are not rigid: their attachment modes.
    pub loaded: &'a [&'a NodeSet],
}

impl Reduction {
    /// The basis of the module documentation for the mesh data, the interfaces' sets and
    /// `modes` fixed-interface modes (a count ≥ 1, or the fewest that meet an accuracy,
    /// [`ModeChoice`]).
    pub fn new(mesh: &MeshData, sets: &InterfaceSets, modes: ModeCount) -> Result<Reduction> {
        let MeshData {
            reference,
            mass,
            stiffness,
            lumped,
            ..
        } = *mesh;
        let boundary: Vec<&NodeSet> = sets.held.iter().chain(sets.rigid).copied().collect();
        let (boundary, loaded) = (&boundary[..], sets.loaded);
        let n = lumped.len();
        let fewest = match modes {
            ModeCount::Fixed(count) => count,
            ModeCount::Accuracy(_) => 1,
        };
        let mut solve = InteriorSolve::new(mass, stiffness, n, boundary, fewest)?;
        let mut vectors: Vec<Vec<f64>> = Vec::new();
        let set_functions =
            constraint_modes(&mut solve, stiffness, reference, boundary, &mut vectors);
        let first_mode = vectors.len();
        let (mode_eigenvalues, mode_choice) =
            fixed_interface_modes(&mut solve, modes, reference, lumped, &mut vectors)?;
        attachment_modes(&mut solve, reference, lumped, loaded, &mut vectors);
        if let Some(second_order_force) = mesh.second_order_force {
            modal_derivatives(&mut solve, second_order_force, first_mode, &mut vectors);
        }
        let candidates = candidate_fields(&vectors, mass, reference, n);
        let coefficients = boundary_coefficients(&candidates, boundary, &set_functions, reference)?;
        let (mut fields, held_count) = basis_fields(&coefficients, &candidates, mass, n)?;
        let rigid = barycentric_fields(&mut fields, &set_functions, sets.held.len());
        let s = fields.len();
        let (gram, unit, reduced_reference, row_major) = reduced_mass(&fields, mass, reference, n)?;
        let stiffness_r = reduced_stiffness(&fields, mesh.force_stiffness.unwrap_or(stiffness), n);
        let frame_weights = expanded_frame(
            mesh.frame_weights,
            reference,
            &row_major,
            &reduced_reference,
            &unit,
        );
        let mut held = held_coordinates(boundary, &set_functions, &reduced_reference, held_count);
        held.truncate(sets.held.len());
        Ok(Reduction {
            node_count: n,
            field_count: s,
            fields: row_major,
            mesh_reference: reference.to_vec(),
            reference: reduced_reference,
            unit,
            mass_matrix: dense_symmetric(&gram),
            stiffness_matrix: dense_symmetric(&stiffness_r),
            frame_weights,
            held,
            rigid,
            mode_eigenvalues,
            mode_choice,
        })
    }

    /// Row `S_i·` of node `i`.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.fields[i * self.field_count..(i + 1) * self.field_count]
    }

    /// The weighted centroid `Σ w_i x_i / W` of the mesh nodes `nodes` (weights `weights`) as
    /// fields and weights: `Σ_k c_k q_k / Σ_k c_k` with `c_k = Σ_i w_i S_ik` (fields whose `c_k`
    /// is below 1e-12 of the largest, round-off on a set where they vanish, are left out). On a
    /// boundary set the fields' sum is 1 there, so `Σ_k c_k = W`.
    pub fn centroid_weights(&self, nodes: &[usize], weights: &[f64]) -> (Vec<usize>, Vec<f64>) {
        let mut c = vec![0.0; self.field_count];
        for (&i, &w) in nodes.iter().zip(weights) {
            c.iter_mut()
                .zip(self.row(i))
                .for_each(|(ck, &s)| *ck += w * s);
        }
        let largest = c.iter().fold(0.0, |a: f64, &b| a.max(b.abs()));
        (0..self.field_count)
            .filter(|&k| c[k].abs() > 1e-12 * largest)
            .map(|k| (k, c[k]))
            .unzip()
    }

    /// The basis as a node set needs it ([`NodeSet::set_reduction`]).
    pub fn basis(&self) -> FieldBasis<'_> {
        FieldBasis {
            fields: &self.fields,
            field_count: self.field_count,
            mesh_reference: &self.mesh_reference,
        }
    }

    /// [`Self::expand`] into `x` (flat `3N`); no allocation.
    pub fn expand_into(&self, q: &[f64], x: &mut [f64]) {
        for i in 0..self.node_count {
            let mut xi = Vector3::zeros();
            for (k, &s) in self.row(i).iter().enumerate() {
                xi += s * node(q, k);
            }
            x[3 * i..3 * i + 3].copy_from_slice(xi.as_slice());
        }
    }

    /// The reduced vector `f_k = Σ_i S_ik f_i` (flat `3s`) of nodal forces `f` (flat `3N`): the
    /// generalized forces of the coordinates, `(S ⊗ I3)ᵀ f`. No allocation.
    pub fn project_into(&self, f: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for i in 0..self.node_count {
            let fi = node(f, i);
            if fi == Vector3::zeros() {
                continue;
            }
            for (k, &s) in self.row(i).iter().enumerate() {
                for d in 0..3 {
                    out[3 * k + d] += s * fi[d];
                }
            }
        }
    }

    /// The Galerkin projection `(S ⊗ I3)ᵀ (G ⊗ I3) (S ⊗ I3) = (Sᵀ G S) ⊗ I3` of a symmetric mesh
    /// matrix `G ⊗ I3` (`3N × 3N`, the same scalar `G_ij` on the diagonal of each 3×3 block: a
    /// geometric stiffness, `fem::geometric`) on the reduced coordinates (docs/formulation.md,
    /// "The reduced body": geometric stiffening), returned as its scalar factor `G_r = Sᵀ G S`
    /// (`s × s`, every entry stored, [`SymmetricCsr::mul_nodes`] applies `G_r ⊗ I3`): one product
    /// with the matrix per field, a third of the general projection's, and a ninth of the
    /// entries of the `3s × 3s` matrix to sum and multiply in a step. Allocates; set-up only.
    pub fn project_geometric_stiffness(&self, a: &SymmetricCsr) -> SymmetricCsr {
        let (s, n) = (self.field_count, self.node_count);
        let mut projected = DMatrix::<f64>::zeros(s, s);
        let (mut u, mut au) = (vec![0.0; 3 * n], vec![0.0; 3 * n]);
        for l in 0..s {
            // (G ⊗ I3) applied to the field `l` along x: `G S_l` in the x components.
            u.fill(0.0);
            for i in 0..n {
                u[3 * i] = self.row(i)[l];
            }
            a.mul_vec(&u, &mut au);
            debug_assert!(
                (0..n).all(|i| au[3 * i + 1] == 0.0 && au[3 * i + 2] == 0.0),
                "project_geometric_stiffness: the matrix is not G ⊗ I3"
            );
            for i in 0..n {
                for (k, &sik) in self.row(i).iter().enumerate() {
                    projected[(k, l)] += sik * au[3 * i];
                }
            }
        }
        dense_symmetric(&(0.5 * (&projected + projected.transpose())))
    }

    /// The best-fit frame of a part of the mesh (its `nodes` with `weights`, kg: a slab's) in
    /// terms of `q`, as [`Reduction::frame_weights`] is the whole body's: `Σ_i w_i x_i X̄_iᵀ =
    /// Σ_k q_k a_kᵀ` with the constant `a_k = Σ_i w_i S_ik X̄_i` over the part's nodes, `X̄_i` from
    /// the part's weighted centroid (docs/formulation.md, "The reduced body": several frames).
    /// Allocates; set-up only.
    pub fn part_frame(&self, nodes: &[usize], weights: &[f64]) -> FrameWeights {
        let mut part_weights = vec![0.0; self.node_count];
        for (&i, &w) in nodes.iter().zip(weights) {
            part_weights[i] = w;
        }
        expanded_frame(
            &part_weights,
            &self.mesh_reference,
            &self.fields,
            &self.reference,
            &self.unit,
        )
    }

    /// The projection `(S_p ⊗ I3)ᵀ A (S_p ⊗ I3)` (`3s × 3s`, dense) of a symmetric matrix `A`
    /// on a part's `nodes` (flat `3n` in their order, given by its product `product(x, A x)`),
    /// `S_p` the rows of `S` of those nodes: a slab's `K_p` as the reduced coordinates see it
    /// (docs/formulation.md, "The reduced body": several frames). Allocates; set-up only.
    pub fn project_part_matrix(
        &self,
        nodes: &[usize],
        product: impl Fn(&[f64], &mut [f64]),
    ) -> DenseSymmetric {
        let s = self.field_count;
        let (mut u, mut au) = (vec![0.0; 3 * nodes.len()], vec![0.0; 3 * nodes.len()]);
        let mut projected = faer::Mat::<f64>::zeros(3 * s, 3 * s);
        for l in 0..s {
            for d in 0..3 {
                for (k, &i) in nodes.iter().enumerate() {
                    u[3 * k + d] = self.row(i)[l];
                }
                product(&u, &mut au);
                for (k, &i) in nodes.iter().enumerate() {
                    for (m, &sim) in self.row(i).iter().enumerate() {
                        for e in 0..3 {
                            projected[(3 * m + e, 3 * l + d)] += sim * au[3 * k + e];
                        }
                    }
                }
                for k in 0..nodes.len() {
                    u[3 * k + d] = 0.0;
                }
            }
        }
        let symmetric = faer::Mat::<f64>::from_fn(3 * s, 3 * s, |r, c| {
            0.5 * (projected[(r, c)] + projected[(c, r)])
        });
        DenseSymmetric::new(symmetric)
    }

    /// The expanded nodal vector `x_i = Σ_k S_ik q_k` (flat `3N`) of a reduced vector `q`
    /// (flat `3s`): positions, velocities or accelerations.
    pub fn expand(&self, q: &[f64]) -> Vec<f64> {
        let mut x = vec![0.0; 3 * self.node_count];
        self.expand_into(q, &mut x);
        x
    }
}

/// The weighted centroid `X_cs` of a set and the orthonormal directions `t_a` of its extent
/// (eigenvectors of its weighted scatter with eigenvalue above 1e-9 of the largest: two for a
/// planar set, three otherwise).
fn affine_directions(set: &NodeSet, reference: &[f64]) -> (Vector3<f64>, Vec<Vector3<f64>>) {
    let fw = &set.frame_weights;
    let centroid = fw.reference_centroid;
    let mut scatter = Matrix3::zeros();
    for (&i, &w) in fw.nodes.iter().zip(&fw.weights) {
        let r = node(reference, i) - centroid;
        scatter += w * r * r.transpose();
    }
    let eigen = scatter.symmetric_eigen();
    let largest = eigen.eigenvalues.max();
    let directions = (0..3)
        .filter(|&a| eigen.eigenvalues[a] > 1e-9 * largest)
        .map(|a| eigen.eigenvectors.column(a).into_owned())
        .collect();
    (centroid, directions)
}

/// The six rigid modes of the mesh for inertia relief: `f ← f − M Φ (Φᵀ M Φ)⁻¹ Φᵀ f`, which
/// leaves a load without net force and moment (the load an unsupported body deforms under
/// while it accelerates rigidly).
struct RigidModes {
    modes: Vec<Vec<f64>>,
    mass_modes: Vec<Vec<f64>>,
    gram: nalgebra::Cholesky<f64, nalgebra::Const<6>>,
}

impl RigidModes {
    fn new(reference: &[f64], m3: &SymmetricCsr, lumped: &[f64]) -> RigidModes {
        let n = lumped.len();
        let c = mass_centroid(reference, lumped);
        let mut modes = Vec::with_capacity(6);
        for j in 0..6 {
            let e = Vector3::ith(j % 3, 1.0);
            let mut u = vec![0.0; 3 * n];
            for i in 0..n {
                let v = if j < 3 {
                    e
                } else {
                    e.cross(&(node(reference, i) - c))
                };
                u[3 * i..3 * i + 3].copy_from_slice(v.as_slice());
            }
            modes.push(u);
        }
        let mass_modes: Vec<Vec<f64>> = modes
            .iter()
            .map(|u| {
                let mut mu = vec![0.0; 3 * n];
                m3.mul_vec(u, &mut mu);
                mu
            })
            .collect();
        let mut g = nalgebra::Matrix6::<f64>::zeros();
        for a in 0..6 {
            for b in 0..6 {
                g[(a, b)] = dot(&modes[a], &mass_modes[b]);
            }
        }
        RigidModes {
            modes,
            mass_modes,
            gram: g
                .cholesky()
                .expect("the rigid modes of a mesh are independent"),
        }
    }

    fn relieve(&self, f: &mut [f64]) {
        let b = nalgebra::Vector6::from_fn(|a, _| dot(&self.modes[a], f));
        let y = self.gram.solve(&b);
        for (a, mu) in self.mass_modes.iter().enumerate() {
            f.iter_mut().zip(mu).for_each(|(v, m)| *v -= y[a] * m);
        }
    }
}

/// The centre of mass `Σ m_i X_i / Σ m_i` of the lumped masses (m).
fn mass_centroid(reference: &[f64], lumped: &[f64]) -> Vector3<f64> {
    let total: f64 = lumped.iter().sum();
    let mut c = Vector3::zeros();
    for (i, &w) in lumped.iter().enumerate() {
        c += w * node(reference, i) / total;
    }
    c
}

fn dense_symmetric(a: &DMatrix<f64>) -> SymmetricCsr {
    let n = a.nrows();
    let mut triplets = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            triplets.push((i, j, a[(i, j)]));
        }
    }
    SymmetricCsr::from_triplets(n, &triplets)
}
