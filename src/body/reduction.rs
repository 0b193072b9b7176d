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
//!
//! each vector mode contributing its three components as scalar fields. The basis is then
//! rearranged so that on boundary set `j` exactly `a_j` fields are non-zero, and there they are
//! the set's affine functions `1` and `t_a · (X − X_cs)` (`a_j = 3` for a planar set, 4
//! otherwise). Their coefficients are the set's motion: driven by a frame `(p, Q)`,
//! `q_0 = p + Q (X_cs − X_ref)` and `q_a = Q t_a` ([`HeldCoordinate`]), so a motion interface or
//! fixed support holds `a_j` coordinates exactly as it holds nodes on the full mesh.

use super::frame::{node, FrameWeights};
use super::interface::{FieldBasis, HeldCoordinate, NodeSet};
use crate::error::{Error, Result};
use crate::fem::modal::lowest_eigenpairs;
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::{dot, SymmetricCsr};
use nalgebra::{DMatrix, Matrix3, Vector3};

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
    /// Per boundary set (in the order given to [`Reduction::new`]): its held coordinates.
    pub held: Vec<Vec<HeldCoordinate>>,
    /// `ω²` of the fixed-interface (or free-free elastic) modes in the basis (1/s²).
    pub mode_eigenvalues: Vec<f64>,
}

impl Reduction {
    /// The basis of the module documentation for the mesh data (`reference` flat `3N`, `Ms`,
    /// `K`, HRZ `lumped` masses), boundary sets `boundary` (fixed supports and motion
    /// interfaces), force interfaces `loaded` and `modes` fixed-interface modes (≥ 1).
    pub fn new(
        reference: &[f64],
        mass: &SymmetricCsr,
        stiffness: &SymmetricCsr,
        lumped: &[f64],
        boundary: &[&NodeSet],
        loaded: &[&NodeSet],
        modes: usize,
    ) -> Result<Reduction> {
        let n = lumped.len();
        let n3 = 3 * n;
        let mut on_boundary = vec![false; n];
        for set in boundary {
            for &i in &set.frame_weights.nodes {
                on_boundary[i] = true;
            }
        }
        let interior: Vec<usize> = (0..n3).filter(|&d| !on_boundary[d / 3]).collect();
        let free_body = boundary.is_empty();
        let m3 = mass.kron_i3();
        let k_ii = stiffness.submatrix(&interior);
        let m_ii = m3.submatrix(&interior);
        if modes == 0 || modes + if free_body { 6 } else { 0 } > interior.len() {
            return Err(Error::invalid_value(
                "model.modes",
                modes as f64,
                &format!(
                    "must lie in 1..={} for this mesh and its supports",
                    interior.len().saturating_sub(if free_body { 6 } else { 0 })
                ),
            ));
        }
        // An unsupported body: K + σM with σ far below the first elastic eigenvalue (the
        // rigid modes become eigenvalue σ, the static solves are regularised by it).
        let shift = if free_body {
            let kd: f64 = k_ii.diagonal().iter().sum();
            let md: f64 = m_ii.diagonal().iter().sum();
            1e-8 * kd / md
        } else {
            0.0
        };
        let k_solve = if free_body {
            SymmetricCsr::linear_combination(1.0, &k_ii, shift, &m_ii)
        } else {
            k_ii
        };
        let factor = SparseCholesky::new(&k_solve).map_err(|e| {
            Error::new(format!(
                "model.modes: the stiffness with the boundary sets held is singular ({})",
                e.message
            ))
        })?;
        let mut workspace = factor.solve_scratch();
        let expand = |values: &[f64]| {
            let mut u = vec![0.0; n3];
            for (&dof, v) in interior.iter().zip(values) {
                u[dof] = *v;
            }
            u
        };

        let mut vectors: Vec<Vec<f64>> = Vec::new();
        // 2. Constraint modes, of every boundary set but the first (see the module
        //    documentation).
        let mut set_functions = Vec::with_capacity(boundary.len());
        for (j, set) in boundary.iter().enumerate() {
            let (centroid, directions) = affine_directions(set, reference);
            let functions = if j == 0 { 0 } else { 1 + directions.len() };
            for a in 0..functions {
                let phi = |i: usize| match a {
                    0 => 1.0,
                    a => directions[a - 1].dot(&(node(reference, i) - centroid)),
                };
                for d in 0..3 {
                    let mut u = vec![0.0; n3];
                    for &i in &set.frame_weights.nodes {
                        u[3 * i + d] = phi(i);
                    }
                    let mut ku = vec![0.0; n3];
                    stiffness.mul_vec(&u, &mut ku);
                    let mut rhs: Vec<f64> = interior.iter().map(|&dof| -ku[dof]).collect();
                    factor.solve_in_place(&mut rhs, &mut workspace);
                    for (&dof, v) in interior.iter().zip(&rhs) {
                        u[dof] = *v;
                    }
                    vectors.push(u);
                }
            }
            set_functions.push((centroid, directions));
        }
        // 3. Fixed-interface (or free-free) modes.
        let rigid = if free_body { 6 } else { 0 };
        let pairs = lowest_eigenpairs(&k_solve, &m_ii, modes + rigid, MODE_TOLERANCE, 500)
            .map_err(|e| Error::new(format!("model.modes: {}", e.message)))?;
        let mode_eigenvalues = pairs.eigenvalues[rigid..]
            .iter()
            .map(|l| l - shift)
            .collect();
        for mode in &pairs.modes {
            vectors.push(expand(mode));
        }
        // 4. Attachment modes.
        let rigid_modes = free_body.then(|| RigidModes::new(reference, &m3, lumped));
        for set in loaded {
            for j in 0..6 {
                let unit = Vector3::ith(j % 3, 1.0);
                let (force, torque) = if j < 3 {
                    (unit, Vector3::zeros())
                } else {
                    (Vector3::zeros(), unit)
                };
                let mut load = vec![0.0; n3];
                set.distribute(reference, &force, &torque, &mut load);
                if let Some(r) = &rigid_modes {
                    r.relieve(&mut load);
                }
                let mut rhs: Vec<f64> = interior.iter().map(|&dof| load[dof]).collect();
                factor.solve_in_place(&mut rhs, &mut workspace);
                vectors.push(expand(&rhs));
            }
        }

        // Candidate scalar fields (unit mass norm): affine fields, then mode components.
        let mass_norm = |f: &[f64]| {
            let mut mf = vec![0.0; n];
            mass.mul_vec(f, &mut mf);
            dot(f, &mf).max(0.0).sqrt()
        };
        let mut candidates: Vec<Vec<f64>> = Vec::new();
        let mut push_normalized = |mut f: Vec<f64>, norm: f64| {
            f.iter_mut().for_each(|v| *v /= norm);
            candidates.push(f);
        };
        let ones = vec![1.0; n];
        let norm = mass_norm(&ones);
        push_normalized(ones, norm);
        for d in 0..3 {
            let f: Vec<f64> = (0..n).map(|i| reference[3 * i + d]).collect();
            let norm = mass_norm(&f);
            push_normalized(f, norm);
        }
        for u in &vectors {
            let components: Vec<Vec<f64>> = (0..3)
                .map(|d| (0..n).map(|i| u[3 * i + d]).collect())
                .collect();
            let norms: Vec<f64> = components.iter().map(|c| mass_norm(c)).collect();
            let largest = norms.iter().cloned().fold(0.0, f64::max);
            for (c, &norm) in components.into_iter().zip(&norms) {
                if norm > COMPONENT_CUTOFF * largest && norm > 0.0 {
                    push_normalized(c, norm);
                }
            }
        }
        let c = candidates.len();

        // The boundary coefficients: on set j every candidate is Φ_j C_j (exactly, by
        // construction), Φ_j = [1, t_a · (X − X_cs)].
        let a_total: usize = set_functions.iter().map(|(_, t)| 1 + t.len()).sum();
        let mut coefficients = DMatrix::<f64>::zeros(a_total, c);
        let mut row = 0;
        for (set, (centroid, directions)) in boundary.iter().zip(&set_functions) {
            let fw = &set.frame_weights;
            let a = 1 + directions.len();
            let phi = |i: usize| {
                let r = node(reference, i) - centroid;
                let mut p = vec![1.0];
                p.extend(directions.iter().map(|t| t.dot(&r)));
                p
            };
            let mut gram = DMatrix::<f64>::zeros(a, a);
            for (&i, &w) in fw.nodes.iter().zip(&fw.weights) {
                let p = phi(i);
                for r in 0..a {
                    for s in 0..a {
                        gram[(r, s)] += w * p[r] * p[s];
                    }
                }
            }
            let gram = gram.cholesky().ok_or_else(|| {
                Error::new("model.modes: a boundary set has a singular affine Gram matrix")
            })?;
            for (col, f) in candidates.iter().enumerate() {
                let mut rhs = nalgebra::DVector::<f64>::zeros(a);
                for (&i, &w) in fw.nodes.iter().zip(&fw.weights) {
                    let p = phi(i);
                    for r in 0..a {
                        rhs[r] += w * p[r] * f[i];
                    }
                }
                let coef = gram.solve(&rhs);
                let scale = fw.nodes.iter().map(|&i| f[i].abs()).fold(0.0, f64::max);
                let misfit = fw
                    .nodes
                    .iter()
                    .map(|&i| {
                        let p = phi(i);
                        (f[i] - (0..a).map(|r| p[r] * coef[r]).sum::<f64>()).abs()
                    })
                    .fold(0.0, f64::max);
                if misfit > 1e-6 * scale.max(1e-300) && misfit > 1e-12 {
                    return Err(Error::new(format!(
                        "model.modes: a basis field is not affine on a boundary set (misfit {misfit:.3e} of {scale:.3e})"
                    )));
                }
                for r in 0..a {
                    coefficients[(row + r, col)] = coef[r];
                }
            }
            row += a;
        }

        // D = F C⁺ (the held fields), Z = F (I − C⁺C) orthonormalised (zero on every set).
        let mut fields: Vec<Vec<f64>> = Vec::new();
        let mut projector = DMatrix::<f64>::identity(c, c);
        if a_total > 0 {
            let svd = coefficients.clone().svd(true, true);
            let (u, v_t) = (svd.u.unwrap(), svd.v_t.unwrap());
            let sigma = &svd.singular_values;
            let largest = sigma.max();
            if sigma.min() <= 1e-10 * largest {
                return Err(Error::new(
                    "model.modes: the boundary sets' affine motions are not independent in the basis (do two boundary sets share nodes?)",
                ));
            }
            let sigma_inv = DMatrix::from_diagonal(&sigma.map(|s| 1.0 / s));
            let pseudo_inverse = v_t.transpose() * sigma_inv * u.transpose(); // c × A
            for col in 0..a_total {
                let mut f = vec![0.0; n];
                for (k, candidate) in candidates.iter().enumerate() {
                    let w = pseudo_inverse[(k, col)];
                    if w != 0.0 {
                        f.iter_mut().zip(candidate).for_each(|(a, b)| *a += w * b);
                    }
                }
                fields.push(f);
            }
            projector -= v_t.transpose() * v_t;
        }
        let held_count = fields.len();
        let mut orthonormal: Vec<(Vec<f64>, Vec<f64>)> = Vec::new(); // (z, Ms z)
        for col in 0..c {
            let mut z = vec![0.0; n];
            for (k, candidate) in candidates.iter().enumerate() {
                let w = projector[(k, col)];
                if w != 0.0 {
                    z.iter_mut().zip(candidate).for_each(|(a, b)| *a += w * b);
                }
            }
            // Two passes of Gram–Schmidt in the mass inner product; candidate norm is 1.
            for _ in 0..2 {
                for (q, mq) in &orthonormal {
                    let r = dot(&z, mq);
                    z.iter_mut().zip(q).for_each(|(a, b)| *a -= r * b);
                }
            }
            let mut mz = vec![0.0; n];
            mass.mul_vec(&z, &mut mz);
            let norm = dot(&z, &mz).max(0.0).sqrt();
            if norm > DEPENDENCE_CUTOFF {
                z.iter_mut().for_each(|v| *v /= norm);
                mz.iter_mut().for_each(|v| *v /= norm);
                orthonormal.push((z, mz));
            }
        }
        fields.extend(orthonormal.into_iter().map(|(z, _)| z));
        let s = fields.len();

        // Reduced mass G = Sᵀ Ms S, reference coefficients and the unit coefficients.
        let mass_fields: Vec<Vec<f64>> = fields
            .iter()
            .map(|f| {
                let mut mf = vec![0.0; n];
                mass.mul_vec(f, &mut mf);
                mf
            })
            .collect();
        let mut gram = DMatrix::<f64>::zeros(s, s);
        for k in 0..s {
            for l in k..s {
                let g = dot(&fields[k], &mass_fields[l]);
                gram[(k, l)] = g;
                gram[(l, k)] = g;
            }
        }
        let mut rhs = DMatrix::<f64>::zeros(s, 4);
        for k in 0..s {
            for i in 0..n {
                let m = mass_fields[k][i];
                rhs[(k, 0)] += m;
                for d in 0..3 {
                    rhs[(k, d + 1)] += m * reference[3 * i + d];
                }
            }
        }
        let solution = gram
            .clone()
            .cholesky()
            .ok_or_else(|| Error::new("model.modes: the reduced mass matrix is singular"))?
            .solve(&rhs);
        let unit: Vec<f64> = (0..s).map(|k| solution[(k, 0)]).collect();
        let reduced_reference: Vec<f64> = (0..s)
            .flat_map(|k| [solution[(k, 1)], solution[(k, 2)], solution[(k, 3)]])
            .collect();
        let mut row_major = vec![0.0; n * s];
        for (k, f) in fields.iter().enumerate() {
            for i in 0..n {
                row_major[i * s + k] = f[i];
            }
        }
        let (lo, hi) =
            crate::mesh::bounding_box(reference.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        let (lo, hi) = (Vector3::from(lo), Vector3::from(hi));
        let size = (hi - lo).norm();
        for i in 0..n {
            let row = &row_major[i * s..(i + 1) * s];
            let e: f64 = row.iter().zip(&unit).map(|(a, b)| a * b).sum();
            let mut x = Vector3::zeros();
            for (k, &sk) in row.iter().enumerate() {
                x += sk * node(&reduced_reference, k);
            }
            if (e - 1.0).abs() > 1e-7 || (x - node(reference, i)).norm() > 1e-7 * size {
                return Err(Error::new(format!(
                    "model.modes: the basis does not reproduce the reference configuration at node {i} (constant field {e}, position error {:.3e} m)",
                    (x - node(reference, i)).norm()
                )));
            }
        }

        // K_r, column by column: K (S_l ⊗ e_b), then (S ⊗ I3)ᵀ.
        let mut stiffness_r = DMatrix::<f64>::zeros(3 * s, 3 * s);
        let mut u = vec![0.0; n3];
        let mut ku = vec![0.0; n3];
        for l in 0..s {
            for b in 0..3 {
                u.fill(0.0);
                for i in 0..n {
                    u[3 * i + b] = fields[l][i];
                }
                stiffness.mul_vec(&u, &mut ku);
                for k in 0..s {
                    let f = &fields[k];
                    for a in 0..3 {
                        stiffness_r[(3 * k + a, 3 * l + b)] =
                            (0..n).map(|i| f[i] * ku[3 * i + a]).sum();
                    }
                }
            }
        }
        let stiffness_r = 0.5 * (&stiffness_r + stiffness_r.transpose());

        // The frame of the expanded nodes.
        let total_weight: f64 = lumped.iter().sum();
        let mut centroid = Vector3::zeros();
        for (i, &w) in lumped.iter().enumerate() {
            centroid += w * node(reference, i);
        }
        centroid /= total_weight;
        let mut weights = vec![0.0; s];
        let mut arms = vec![Vector3::zeros(); s];
        for (i, &w) in lumped.iter().enumerate() {
            let xbar = node(reference, i) - centroid;
            for k in 0..s {
                let ws = w * row_major[i * s + k];
                weights[k] += ws;
                arms[k] += ws * xbar;
            }
        }
        let offsets = (0..s)
            .map(|k| node(&reduced_reference, k) - unit[k] * centroid)
            .collect();
        let frame_weights =
            FrameWeights::reduced(weights, total_weight, centroid, offsets, arms, unit.clone());

        // Held coordinates: the first a_j fields of the D block belong to set j.
        let mut held = Vec::with_capacity(boundary.len());
        let mut index = 0;
        for (set, (_, directions)) in boundary.iter().zip(&set_functions) {
            let mut coordinates = vec![HeldCoordinate {
                index,
                offset: node(&reduced_reference, index) - set.reference_point,
                point: true,
            }];
            for a in 1..=directions.len() {
                coordinates.push(HeldCoordinate {
                    index: index + a,
                    offset: node(&reduced_reference, index + a),
                    point: false,
                });
            }
            index += 1 + directions.len();
            held.push(coordinates);
        }
        debug_assert_eq!(index, held_count);

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
            mode_eigenvalues,
        })
    }

    /// Row `S_i·` of node `i`.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.fields[i * self.field_count..(i + 1) * self.field_count]
    }

    /// The basis as a node set needs it ([`NodeSet::set_reduction`]).
    pub fn basis(&self) -> FieldBasis<'_> {
        FieldBasis {
            fields: &self.fields,
            field_count: self.field_count,
            mesh_reference: &self.mesh_reference,
        }
    }

    /// The expanded nodal vector `x_i = Σ_k S_ik q_k` (flat `3N`) of a reduced vector `q`
    /// (flat `3s`): positions, velocities or accelerations.
    pub fn expand(&self, q: &[f64]) -> Vec<f64> {
        let mut x = vec![0.0; 3 * self.node_count];
        for i in 0..self.node_count {
            let mut xi = Vector3::zeros();
            for (k, &s) in self.row(i).iter().enumerate() {
                xi += s * node(q, k);
            }
            x[3 * i..3 * i + 3].copy_from_slice(xi.as_slice());
        }
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
        let total: f64 = lumped.iter().sum();
        let mut c = Vector3::zeros();
        for (i, &w) in lumped.iter().enumerate() {
            c += w * node(reference, i) / total;
        }
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
