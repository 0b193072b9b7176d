//! The construction of the reduced body's basis, phase by phase (the module documentation of
//! `reduction` states the basis): interior solves, constraint and fixed-interface modes (the
//! static responses to loads are in `static_responses`), candidate scalar fields, their coefficients on the boundary sets, the held and free
//! fields, the reduced mass and stiffness, the frame of the expanded nodes, the held
//! coordinates.

use super::{
    affine_directions, mass_centroid, ModeChoice, ModeCount, RigidModes, COMPONENT_CUTOFF,
    DEPENDENCE_CUTOFF, MAX_CHOSEN_MODES, MODE_TOLERANCE,
};
use crate::body::frame::{node, FrameWeights};
use crate::body::interface::{HeldCoordinate, NodeSet};
use crate::error::{Error, Result};
use crate::fem::modal::lowest_eigenpairs;
use crate::linalg::cholesky::{SolveWorkspace, SparseCholesky};
use crate::linalg::{dot, SymmetricCsr};
use nalgebra::{DMatrix, Vector3};

/// The static solves of the interior (every DOF not on a boundary set), with `K + σM`
/// regularising an unsupported body (`σ` far below its first elastic eigenvalue).
pub(super) struct InteriorSolve {
    n3: usize,
    interior: Vec<usize>,
    free_body: bool,
    m3: SymmetricCsr,
    m_ii: SymmetricCsr,
    k_solve: SymmetricCsr,
    shift: f64,
    factor: SparseCholesky,
    workspace: SolveWorkspace,
}

impl InteriorSolve {
    /// Factorises the interior stiffness of `n` nodes with `boundary` held, after checking that
    /// `modes` fit.
    pub(super) fn new(
        mass: &SymmetricCsr,
        stiffness: &SymmetricCsr,
        n: usize,
        boundary: &[&NodeSet],
        modes: usize,
    ) -> Result<InteriorSolve> {
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
        let workspace = factor.solve_scratch();

        Ok(InteriorSolve {
            n3,
            interior,
            free_body,
            m3,
            m_ii,
            k_solve,
            shift,
            factor,
            workspace,
        })
    }

    /// A full vector (flat `3N`) with the interior `values` and zero on the boundary.
    /// The static response `u = K_ii⁻¹ f_i` of the interior to the load `f` (flat `3N`, N), the
    /// boundary held, expanded to `3N` (m).
    pub(super) fn static_response(&mut self, load: &[f64]) -> Vec<f64> {
        let mut rhs: Vec<f64> = self.interior.iter().map(|&dof| load[dof]).collect();
        self.factor.solve_in_place(&mut rhs, &mut self.workspace);
        self.expand(&rhs)
    }

    /// Whether the body has no boundary set (its solve is shifted, with inertia relief).
    pub(super) fn free_body(&self) -> bool {
        self.free_body
    }

    /// `3N`.
    pub(super) fn dof_count(&self) -> usize {
        self.n3
    }

    /// The mass matrix `Ms ⊗ I3` (kg, `3N × 3N`).
    pub(super) fn mass(&self) -> &SymmetricCsr {
        &self.m3
    }

    fn expand(&self, values: &[f64]) -> Vec<f64> {
        let mut u = vec![0.0; self.n3];
        for (&dof, v) in self.interior.iter().zip(values) {
            u[dof] = *v;
        }
        u
    }
}

/// A boundary set's affine functions: its weighted centroid and the directions `t_a` of
/// `Φ = [1, t_a · (X − X_c)]`.
pub(super) type SetFunctions = (Vector3<f64>, Vec<Vector3<f64>>);

/// The constraint modes of every boundary set but the first (static responses to the affine
/// motions of its node set, see the module documentation), appended to `vectors`; the sets'
/// affine functions.
pub(super) fn constraint_modes(
    solve: &mut InteriorSolve,
    stiffness: &SymmetricCsr,
    reference: &[f64],
    boundary: &[&NodeSet],
    vectors: &mut Vec<Vec<f64>>,
) -> Vec<SetFunctions> {
    let n3 = solve.n3;
    let (interior, factor, workspace) = (&solve.interior, &solve.factor, &mut solve.workspace);
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
                factor.solve_in_place(&mut rhs, workspace);
                for (&dof, v) in interior.iter().zip(&rhs) {
                    u[dof] = *v;
                }
                vectors.push(u);
            }
        }
        set_functions.push((centroid, directions));
    }
    set_functions
}

/// The fixed-interface (free-free for an unsupported body) modes, the `n` lowest for
/// [`ModeCount::Fixed`] or as many as [`ModeChoice`] finds for [`ModeCount::Accuracy`],
/// appended to `vectors`; their eigenvalues `ω²` and the choice.
pub(super) fn fixed_interface_modes(
    solve: &mut InteriorSolve,
    modes: ModeCount,
    reference: &[f64],
    lumped: &[f64],
    vectors: &mut Vec<Vec<f64>>,
) -> Result<(Vec<f64>, Option<ModeChoice>)> {
    // 3. Fixed-interface (or free-free) modes.
    let rigid = if solve.free_body { 6 } else { 0 };
    let eigenpairs = |solve: &InteriorSolve, count: usize| {
        lowest_eigenpairs(
            &solve.k_solve,
            &solve.m_ii,
            count + rigid,
            MODE_TOLERANCE,
            500,
        )
        .map_err(|e| Error::new(format!("model.modes: {}", e.message)))
    };
    let (pairs, count, choice) = match modes {
        ModeCount::Fixed(count) => (eigenpairs(solve, count)?, count, None),
        ModeCount::Accuracy(accuracy) => {
            let loads = inertial_responses(solve, reference, lumped);
            let available = (solve.interior.len() - rigid).min(MAX_CHOSEN_MODES);
            let mut batch = 8.min(available);
            loop {
                let pairs = eigenpairs(solve, batch)?;
                let errors = truncation_errors(&loads, &pairs.modes, rigid);
                let found = errors.iter().position(|&e| e <= accuracy);
                if found.is_some() || batch == available {
                    let count = found.map_or(batch, |k| k + 1);
                    let choice = ModeChoice {
                        accuracy,
                        count,
                        error: errors[count - 1],
                        error_one_fewer: if count > 1 { errors[count - 2] } else { 1.0 },
                    };
                    break (pairs, count, Some(choice));
                }
                batch = (2 * batch).min(available);
            }
        }
    };
    let mode_eigenvalues = pairs.eigenvalues[rigid..rigid + count]
        .iter()
        .map(|l| l - solve.shift)
        .collect();
    for mode in &pairs.modes[..rigid + count] {
        vectors.push(solve.expand(mode));
    }
    Ok((mode_eigenvalues, choice))
}

/// The static responses `u = K_ii⁻¹ f` of the interior to the inertial loads `f = M a` of the
/// affine accelerations `a = e_d` and `(X_b − X̄_b)/L e_d` ([`ModeChoice`]; `L` the largest
/// mass-weighted RMS extent of the body along an axis; with inertia relief for an unsupported
/// body), with `M u` (interior vectors).
fn inertial_responses(
    solve: &mut InteriorSolve,
    reference: &[f64],
    lumped: &[f64],
) -> Vec<(Vec<f64>, Vec<f64>)> {
    let n3 = solve.n3;
    let centre = mass_centroid(reference, lumped);
    let total: f64 = lumped.iter().sum();
    let extent = (0..3)
        .map(|b| {
            let spread: f64 = lumped
                .iter()
                .enumerate()
                .map(|(i, &m)| m * (reference[3 * i + b] - centre[b]).powi(2))
                .sum();
            (spread / total).sqrt()
        })
        .fold(0.0_f64, f64::max);
    let rigid_modes = solve
        .free_body
        .then(|| RigidModes::new(reference, &solve.m3, lumped));
    let mut responses = Vec::with_capacity(12);
    for field in 0..4 {
        for d in 0..3 {
            let mut a = vec![0.0; n3];
            for i in 0..n3 / 3 {
                a[3 * i + d] = match field {
                    0 => 1.0,
                    b => (reference[3 * i + b - 1] - centre[b - 1]) / extent,
                };
            }
            let mut load = vec![0.0; n3];
            solve.m3.mul_vec(&a, &mut load);
            if let Some(r) = &rigid_modes {
                r.relieve(&mut load);
            }
            let mut u: Vec<f64> = solve.interior.iter().map(|&dof| load[dof]).collect();
            solve.factor.solve_in_place(&mut u, &mut solve.workspace);
            let mut mu = vec![0.0; u.len()];
            solve.m_ii.mul_vec(&u, &mut mu);
            responses.push((u, mu));
        }
    }
    responses
}

/// `errors[n − 1]`: the largest mass-norm error over the `loads` of their static responses
/// expanded in the first `n` elastic `modes` (after `rigid` rigid ones), `n = 1..`, relative
/// to the largest response ([`ModeChoice`]).
fn truncation_errors(loads: &[(Vec<f64>, Vec<f64>)], modes: &[Vec<f64>], rigid: usize) -> Vec<f64> {
    let count = modes.len() - rigid;
    let mut errors = vec![0.0_f64; count];
    let mut largest = 0.0_f64;
    for (u, mu) in loads {
        let c: Vec<f64> = modes.iter().map(|phi| dot(phi, mu)).collect();
        // The elastic part of the response (an unsupported body's relieved load has a rigid
        // part of the order of the shift only).
        let total = dot(u, mu) - c[..rigid].iter().map(|c| c * c).sum::<f64>();
        largest = largest.max(total);
        let mut captured = 0.0;
        for (n, c) in c[rigid..].iter().enumerate() {
            captured += c * c;
            errors[n] = errors[n].max((total - captured).max(0.0));
        }
    }
    if largest > 0.0 {
        errors.iter_mut().for_each(|e| *e = (*e / largest).sqrt());
    }
    errors
}

/// The candidate scalar fields, of unit mass norm: the affine fields, then the components of
/// the vector modes (those not vanishing by symmetry).
pub(super) fn candidate_fields(
    vectors: &[Vec<f64>],
    mass: &SymmetricCsr,
    reference: &[f64],
    n: usize,
) -> Vec<Vec<f64>> {
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
    for u in vectors {
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
    candidates
}

/// The coefficients `C` of every candidate on the boundary sets' affine functions: on set `j`
/// every candidate is `Φ_j C_j` (exactly, by construction); an error if one is not affine there.
pub(super) fn boundary_coefficients(
    candidates: &[Vec<f64>],
    boundary: &[&NodeSet],
    set_functions: &[SetFunctions],
    reference: &[f64],
) -> Result<DMatrix<f64>> {
    let c = candidates.len();
    // The boundary coefficients: on set j every candidate is Φ_j C_j (exactly, by
    // construction), Φ_j = [1, t_a · (X − X_cs)].
    let a_total: usize = set_functions.iter().map(|(_, t)| 1 + t.len()).sum();
    let mut coefficients = DMatrix::<f64>::zeros(a_total, c);
    let mut row = 0;
    for (set, (centroid, directions)) in boundary.iter().zip(set_functions) {
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
    Ok(coefficients)
}

/// The basis fields: the held fields `D = F C⁺` (one per affine function of each set) and then
/// `Z = F (I − C⁺C)` orthonormalised in the mass inner product (zero on every set); the number
/// of held fields.
pub(super) fn basis_fields(
    coefficients: &DMatrix<f64>,
    candidates: &[Vec<f64>],
    mass: &SymmetricCsr,
    n: usize,
) -> Result<(Vec<Vec<f64>>, usize)> {
    let (a_total, c) = (coefficients.nrows(), candidates.len());
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
    Ok((fields, held_count))
}

/// The reduced mass `G = Sᵀ Ms S`, the unit coefficients `e` (`Σ_k S_ik e_k = 1`), the reference
/// coefficients `q_ref` (`Σ_k S_ik q_ref,k = X_i`) and `S` row-major; an error if the basis does
/// not reproduce the reference configuration.
#[allow(clippy::type_complexity)]
pub(super) fn reduced_mass(
    fields: &[Vec<f64>],
    mass: &SymmetricCsr,
    reference: &[f64],
    n: usize,
) -> Result<(DMatrix<f64>, Vec<f64>, Vec<f64>, Vec<f64>)> {
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
    let (lo, hi) = crate::mesh::bounding_box(reference.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
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
    Ok((gram, unit, reduced_reference, row_major))
}

/// `K_r = (S ⊗ I3)ᵀ K (S ⊗ I3)`, column by column: `K (S_l ⊗ e_b)`, then `(S ⊗ I3)ᵀ`.
pub(super) fn reduced_stiffness(
    fields: &[Vec<f64>],
    stiffness: &SymmetricCsr,
    n: usize,
) -> DMatrix<f64> {
    let (s, n3) = (fields.len(), 3 * n);
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
    0.5 * (&stiffness_r + stiffness_r.transpose())
}

/// The co-moving frame of the expanded nodes (HRZ-lumped weights) in terms of `q`.
pub(super) fn expanded_frame(
    lumped: &[f64],
    reference: &[f64],
    row_major: &[f64],
    reduced_reference: &[f64],
    unit: &[f64],
) -> FrameWeights {
    let s = unit.len();
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
        .map(|k| node(reduced_reference, k) - unit[k] * centroid)
        .collect();
    FrameWeights::reduced(
        weights,
        total_weight,
        centroid,
        offsets,
        arms,
        unit.to_vec(),
    )
}

/// Makes the held fields of the rigid sets (the boundary sets from `first_rigid` on)
/// barycentric: `φ_0 = f_0 − Σ_a f_a` in place of the field `f_0` that is 1 on the set, the
/// fields `f_a = t_a · (X − X_cs)` kept (module documentation of `reduction`: a rigid set's
/// coefficients are then points). Returns each rigid set's field indices.
pub(super) fn barycentric_fields(
    fields: &mut [Vec<f64>],
    set_functions: &[SetFunctions],
    first_rigid: usize,
) -> Vec<Vec<usize>> {
    let mut index = 0;
    let mut rigid = Vec::new();
    for (j, (_, directions)) in set_functions.iter().enumerate() {
        let a = directions.len();
        if j >= first_rigid {
            for b in 1..=a {
                let (head, tail) = fields.split_at_mut(index + b);
                head[index]
                    .iter_mut()
                    .zip(&tail[0])
                    .for_each(|(f0, fb)| *f0 -= fb);
            }
            rigid.push((index..=index + a).collect());
        }
        index += 1 + a;
    }
    rigid
}

/// The coordinates each boundary set holds: the first `a_j` held fields belong to set `j`.
pub(super) fn held_coordinates(
    boundary: &[&NodeSet],
    set_functions: &[SetFunctions],
    reduced_reference: &[f64],
    held_count: usize,
) -> Vec<Vec<HeldCoordinate>> {
    // Held coordinates: the first a_j fields of the D block belong to set j.
    let mut held = Vec::with_capacity(boundary.len());
    let mut index = 0;
    for (set, (_, directions)) in boundary.iter().zip(set_functions) {
        let mut coordinates = vec![HeldCoordinate {
            index,
            offset: node(reduced_reference, index) - set.reference_point,
            point: true,
        }];
        for a in 1..=directions.len() {
            coordinates.push(HeldCoordinate {
                index: index + a,
                offset: node(reduced_reference, index + a),
                point: false,
            });
        }
        index += 1 + directions.len();
        held.push(coordinates);
    }
    debug_assert_eq!(index, held_count);
    held
}
