//! The total-Lagrangian St. Venant–Kirchhoff solid: the `full` reference formulation
//! (docs/formulation.md, "The full formulation") on the same meshes, quadrature and DOF numbering (`3 * node + direction`)
//! as the linear matrices of [`super::assembly`].
//!
//! With reference positions `X`, current positions `x = X + u` (m), the displacement gradient
//! `H = ∂u/∂X`, the deformation gradient `F = I + H` and the Green–Lagrange strain
//! `E = ½ (FᵀF − I) = ½ (H + Hᵀ + HᵀH)` (computed from `H`, so that small strains keep their
//! relative precision), the strain energy (J) is
//!
//! ```text
//! W(x) = ∫ ½ λ (tr E)² + μ E:E dV     (reference volume, the rule of `integration_rule`: 2×2×2 Hex8, 3×3×3 Hex20, 1 point Tet4, 4 Tet10)
//! ```
//!
//! the second Piola–Kirchhoff stress (Pa) `S = λ tr(E) I + 2μ E`, the first Piola–Kirchhoff stress
//! `P = F S`, the internal force (N) `f_a = ∂W/∂x_a = ∫ P ∇N_a dV` and the tangent stiffness (N/m)
//! `K_T = ∂f/∂x`, whose 3×3 block coupling nodes `a` and `b` is
//!
//! ```text
//! K_ab = ∫ λ g_a g_bᵀ + μ g_b g_aᵀ + μ (∇N_a·∇N_b) F Fᵀ      (material part)
//!        + (∇N_a · S ∇N_b) I                                  (geometric part)   dV,
//! ```
//!
//! with `∇N_a` the reference gradient of shape function `a` and `g_a = F ∇N_a`. At `x = X`
//! (`F = I`, `S = 0`) it is the linear small-strain `K` of [`super::stiffness_matrix`]. `K_T` is
//! symmetric (the Hessian of `W`) but not necessarily positive semi-definite (compressive states).
//!
//! Everything mesh-dependent that does not depend on `x` is precomputed by [`SvkSolid::new`]:
//! reference gradients and weights `det J · w_q` at every Gauss point and the positions of every
//! element block in the CSR values of `K`; the per-call routines use fixed-size stack arrays and
//! do not allocate.

use super::{stiffness_matrix, IsotropicMaterial};
use crate::element::{integration_rule, physical_gradients, shape_functions, MAX_NODES};
use crate::linalg::SymmetricCsr;
use crate::mesh::{ElementKind, Mesh};

/// A St. Venant–Kirchhoff solid on a fixed reference mesh: the precomputed data of the strain
/// energy, internal force and tangent stiffness routines (module documentation for the math).
#[derive(Debug, Clone)]
pub struct SvkSolid {
    kind: ElementKind,
    /// Nodes per element.
    nodes_per_element: usize,
    /// Gauss points per element (8 for Hex8, 27 for Hex20).
    points_per_element: usize,
    /// Element node indices, `nodes_per_element` per element, flat.
    connectivity: Vec<usize>,
    /// Reference positions `X` (m), flat `3 * node + direction`.
    reference: Vec<f64>,
    /// `∇N_a` (1/m) at Gauss point `q` of element `e`: entry `(e · points + q) · nodes + a`.
    gradients: Vec<[f64; 3]>,
    /// Integration weights `det J · w_q` (m³) at Gauss point `q` of element `e`: entry `e · points + q`.
    weights: Vec<f64>,
    /// Reference positions (m) of the Gauss points, same order as `weights`.
    gauss_positions: Vec<[f64; 3]>,
    /// Lamé's `λ` (Pa).
    lambda: f64,
    /// Shear modulus `μ` (Pa).
    mu: f64,
    /// CSR pattern of `K` (that of [`stiffness_matrix`]).
    row_ptr: Vec<usize>,
    col_idx: Vec<usize>,
    /// For element `e` and local nodes `(a, b)`: the index into the CSR values of entry
    /// `(3 · node_a, 3 · node_b)`, at `(e · nodes + a) · nodes + b`. Entry `(3 node_a + d,
    /// 3 node_b + c)` is at that index `+ d · row_length[node_a] + c`.
    block_offsets: Vec<usize>,
    /// Length of the CSR rows `3i`, `3i + 1`, `3i + 2` of node `i` (three times its neighbour count).
    row_length: Vec<usize>,
}

/// `[xx, yy, zz, yz, xz, xy]` tensor components of a symmetric 3×3 matrix (Voigt order of
/// [`IsotropicMaterial::elasticity_matrix`], shear components *not* doubled).
fn voigt(m: &[[f64; 3]; 3]) -> [f64; 6] {
    [m[0][0], m[1][1], m[2][2], m[1][2], m[0][2], m[0][1]]
}

/// The Green–Lagrange strain `E = ½ (H + Hᵀ + HᵀH)` of a displacement gradient `H`.
#[inline(always)]
fn green_strain(h: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut e = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in i..3 {
            let hth = h[0][i] * h[0][j] + h[1][i] * h[1][j] + h[2][i] * h[2][j];
            let v = 0.5 * (h[i][j] + h[j][i] + hth);
            e[i][j] = v;
            e[j][i] = v;
        }
    }
    e
}

impl SvkSolid {
    /// Precomputes the Gauss-point data of `mesh` (validated: every `det J > 0`) and the
    /// sparsity pattern of `K` for `material` (only `λ` and `μ` are used; no mass here).
    pub fn new(mesh: &Mesh, material: &IsotropicMaterial) -> SvkSolid {
        let kind = mesh.kind();
        let n = kind.node_count();
        let rule = integration_rule(kind);
        let points = rule.len();
        let element_count = mesh.element_count();
        let node_count = mesh.node_count();

        let mut values = Vec::with_capacity(points);
        let mut derivatives = Vec::with_capacity(points);
        for q in &rule {
            let mut v = [0.0; MAX_NODES];
            let mut d = [[0.0; 3]; MAX_NODES];
            shape_functions(kind, q.xi, &mut v, &mut d);
            values.push(v);
            derivatives.push(d);
        }

        let mut connectivity = Vec::with_capacity(element_count * n);
        let mut gradients = Vec::with_capacity(element_count * points * n);
        let mut weights = Vec::with_capacity(element_count * points);
        let mut gauss_positions = Vec::with_capacity(element_count * points);
        let mut coords = [[0.0; 3]; MAX_NODES];
        let mut g = [[0.0; 3]; MAX_NODES];
        for e in 0..element_count {
            let nodes = mesh.element(e);
            connectivity.extend_from_slice(nodes);
            for (c, &node) in coords.iter_mut().zip(nodes) {
                *c = mesh.nodes()[node];
            }
            for (q, point) in rule.iter().enumerate() {
                let det = physical_gradients(&coords[..n], &derivatives[q][..n], &mut g[..n]);
                assert!(
                    det > 0.0,
                    "SvkSolid::new: element {e} has det J = {det} at Gauss point {q}"
                );
                gradients.extend_from_slice(&g[..n]);
                weights.push(det * point.weight);
                let mut p = [0.0; 3];
                for (c, v) in coords[..n].iter().zip(&values[q][..n]) {
                    for d in 0..3 {
                        p[d] += v * c[d];
                    }
                }
                gauss_positions.push(p);
            }
        }

        // The pattern of the linear K (values discarded): identical by construction.
        let linear = stiffness_matrix(mesh, material);
        let row_length: Vec<usize> = (0..node_count)
            .map(|i| linear.row_ptr[3 * i + 1] - linear.row_ptr[3 * i])
            .collect();
        let mut block_offsets = Vec::with_capacity(element_count * n * n);
        for e in 0..element_count {
            let nodes = mesh.element(e);
            for &i in nodes {
                let start = linear.row_ptr[3 * i];
                let row = &linear.col_idx[start..start + row_length[i]];
                for &j in nodes {
                    let p = row
                        .binary_search(&(3 * j))
                        .expect("element nodes are neighbours in the pattern of K");
                    block_offsets.push(start + p);
                }
            }
        }

        SvkSolid {
            kind,
            nodes_per_element: n,
            points_per_element: points,
            connectivity,
            reference: mesh.nodes().iter().flatten().copied().collect(),
            gradients,
            weights,
            gauss_positions,
            lambda: material.lame_lambda(),
            mu: material.shear_modulus(),
            row_ptr: linear.row_ptr,
            col_idx: linear.col_idx,
            block_offsets,
            row_length,
        }
    }

    /// The element kind of the mesh.
    pub fn kind(&self) -> ElementKind {
        self.kind
    }

    /// Number of DOF, `3 × nodes`.
    pub fn dof_count(&self) -> usize {
        self.reference.len()
    }

    /// Number of elements.
    pub fn element_count(&self) -> usize {
        self.connectivity.len() / self.nodes_per_element
    }

    /// Reference positions `X` (m), flat `3 * node + direction`.
    pub fn reference_positions(&self) -> &[f64] {
        &self.reference
    }

    /// Gauss points per element (8 for Hex8, 27 for Hex20).
    pub fn gauss_points_per_element(&self) -> usize {
        self.points_per_element
    }

    /// Reference positions `X` (m) of all Gauss points, element by element, within an element in
    /// the order of [`integration_rule`] (ξ fastest for the hexahedra). The order of
    /// [`Self::green_strain_at_gauss_points`].
    pub fn gauss_point_positions(&self) -> &[[f64; 3]] {
        &self.gauss_positions
    }

    /// A matrix with the sparsity pattern of `K` (that of [`stiffness_matrix`]) and zero values:
    /// the storage [`Self::tangent_stiffness`] writes into. A sparse Cholesky analysed on `K` (or on
    /// any matrix with this pattern, e.g. `c_m M + K`) can refactor it numerically.
    pub fn tangent_pattern(&self) -> SymmetricCsr {
        SymmetricCsr {
            n: self.dof_count(),
            row_ptr: self.row_ptr.clone(),
            col_idx: self.col_idx.clone(),
            values: vec![0.0; self.col_idx.len()],
        }
    }

    /// Copies the displacements `u_a = x_a − X_a` of the nodes of element `e` into `u`.
    #[inline(always)]
    fn element_displacements(&self, e: usize, x: &[f64], u: &mut [[f64; 3]; MAX_NODES]) {
        let n = self.nodes_per_element;
        for (ua, &node) in u.iter_mut().zip(&self.connectivity[e * n..(e + 1) * n]) {
            for d in 0..3 {
                ua[d] = x[3 * node + d] - self.reference[3 * node + d];
            }
        }
    }

    /// Reference gradients `∇N_a` at Gauss point `q` of element `e`, and the weight `det J · w_q`.
    #[inline(always)]
    fn point(&self, e: usize, q: usize) -> (&[[f64; 3]], f64) {
        let n = self.nodes_per_element;
        let k = e * self.points_per_element + q;
        (&self.gradients[k * n..(k + 1) * n], self.weights[k])
    }

    /// `H = Σ_a u_a ⊗ ∇N_a`.
    #[inline(always)]
    fn displacement_gradient(u: &[[f64; 3]], g: &[[f64; 3]]) -> [[f64; 3]; 3] {
        let mut h = [[0.0; 3]; 3];
        for (ua, ga) in u.iter().zip(g) {
            for i in 0..3 {
                for j in 0..3 {
                    h[i][j] += ua[i] * ga[j];
                }
            }
        }
        h
    }

    fn check_positions(&self, x: &[f64], what: &str) {
        assert_eq!(
            x.len(),
            self.dof_count(),
            "SvkSolid::{what}: x has length {} instead of {}",
            x.len(),
            self.dof_count()
        );
    }

    /// The strain energy `W(x) = ∫ ½ λ (tr E)² + μ E:E dV` (J) at positions `x` (m, flat).
    pub fn strain_energy(&self, x: &[f64]) -> f64 {
        self.check_positions(x, "strain_energy");
        let mut u = [[0.0; 3]; MAX_NODES];
        let n = self.nodes_per_element;
        let mut energy = 0.0;
        for e in 0..self.element_count() {
            self.element_displacements(e, x, &mut u);
            for q in 0..self.points_per_element {
                let (g, w) = self.point(e, q);
                let strain = green_strain(&Self::displacement_gradient(&u[..n], g));
                let trace = strain[0][0] + strain[1][1] + strain[2][2];
                let ee: f64 = strain.iter().flatten().map(|v| v * v).sum();
                energy += w * (0.5 * self.lambda * trace * trace + self.mu * ee);
            }
        }
        energy
    }

    /// The internal force `f = ∂W/∂x`, `f_a = ∫ F S ∇N_a dV` (N), written into `f` (length
    /// [`Self::dof_count`]; overwritten). No allocation.
    pub fn internal_force(&self, x: &[f64], f: &mut [f64]) {
        self.check_positions(x, "internal_force");
        assert_eq!(
            f.len(),
            x.len(),
            "SvkSolid::internal_force: f has the wrong length"
        );
        f.fill(0.0);
        let n = self.nodes_per_element;
        let mut u = [[0.0; 3]; MAX_NODES];
        let mut fe = [[0.0; 3]; MAX_NODES];
        for e in 0..self.element_count() {
            self.element_displacements(e, x, &mut u);
            fe[..n].fill([0.0; 3]);
            for q in 0..self.points_per_element {
                let (g, w) = self.point(e, q);
                let h = Self::displacement_gradient(&u[..n], g);
                let wp = self.weighted_first_piola(&h, w);
                for (fa, ga) in fe.iter_mut().zip(g) {
                    for i in 0..3 {
                        fa[i] += wp[i][0] * ga[0] + wp[i][1] * ga[1] + wp[i][2] * ga[2];
                    }
                }
            }
            self.scatter_force(e, &fe, f);
        }
    }

    /// `w P = w F S` for the displacement gradient `h` and the weight `w`.
    #[inline(always)]
    fn weighted_first_piola(&self, h: &[[f64; 3]; 3], w: f64) -> [[f64; 3]; 3] {
        let s = self.weighted_second_piola(h, w);
        let mut p = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                // F = I + H.
                p[i][j] = s[i][j] + h[i][0] * s[0][j] + h[i][1] * s[1][j] + h[i][2] * s[2][j];
            }
        }
        p
    }

    /// `w S = w (λ tr(E) I + 2μ E)`.
    #[inline(always)]
    fn weighted_second_piola(&self, h: &[[f64; 3]; 3], w: f64) -> [[f64; 3]; 3] {
        let strain = green_strain(h);
        let trace = strain[0][0] + strain[1][1] + strain[2][2];
        let two_mu = 2.0 * self.mu * w;
        let mut s = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                s[i][j] = two_mu * strain[i][j];
            }
            s[i][i] += self.lambda * w * trace;
        }
        s
    }

    #[inline(always)]
    fn scatter_force(&self, e: usize, fe: &[[f64; 3]; MAX_NODES], f: &mut [f64]) {
        let n = self.nodes_per_element;
        for (fa, &node) in fe.iter().zip(&self.connectivity[e * n..(e + 1) * n]) {
            for d in 0..3 {
                f[3 * node + d] += fa[d];
            }
        }
    }

    /// The tangent stiffness `K_T = ∂f/∂x` (N/m) at `x`, written into the values of `k`, which
    /// must have the pattern of [`Self::tangent_pattern`] (its values are overwritten). No
    /// allocation.
    pub fn tangent_stiffness(&self, x: &[f64], k: &mut SymmetricCsr) {
        self.assemble(x, None, k);
    }

    /// [`Self::internal_force`] and [`Self::tangent_stiffness`] in one pass (what a Newton
    /// iteration needs). No allocation.
    pub fn internal_force_and_tangent(&self, x: &[f64], f: &mut [f64], k: &mut SymmetricCsr) {
        assert_eq!(
            f.len(),
            x.len(),
            "SvkSolid::internal_force_and_tangent: f has the wrong length"
        );
        self.assemble(x, Some(f), k);
    }

    fn assemble(&self, x: &[f64], mut f: Option<&mut [f64]>, k: &mut SymmetricCsr) {
        self.check_positions(x, "tangent_stiffness");
        assert!(
            k.n == self.dof_count()
                && k.row_ptr.len() == self.row_ptr.len()
                && k.nnz() == self.col_idx.len(),
            "SvkSolid::tangent_stiffness: k does not have the pattern of tangent_pattern()"
        );
        debug_assert!(k.row_ptr == self.row_ptr && k.col_idx == self.col_idx);
        k.values.fill(0.0);
        if let Some(f) = f.as_deref_mut() {
            f.fill(0.0);
        }
        let n = self.nodes_per_element;
        let (lambda, mu) = (self.lambda, self.mu);
        let mut u = [[0.0; 3]; MAX_NODES];
        let mut fe = [[0.0; 3]; MAX_NODES];
        // Upper-triangle blocks (b ≥ a) of the element tangent, block (a, b) row-major 3×3.
        let mut ke = [[[0.0f64; 9]; MAX_NODES]; MAX_NODES];
        // Per Gauss point: g_a = F ∇N_a, λw g_a, μw g_a, w S ∇N_a, μw ∇N_a.
        let mut cur = [[0.0; 3]; MAX_NODES];
        let mut lam_cur = [[0.0; 3]; MAX_NODES];
        let mut mu_cur = [[0.0; 3]; MAX_NODES];
        let mut s_grad = [[0.0; 3]; MAX_NODES];
        let mut mu_grad = [[0.0; 3]; MAX_NODES];
        for e in 0..self.element_count() {
            self.element_displacements(e, x, &mut u);
            for (a, row) in ke.iter_mut().enumerate().take(n) {
                row[a..n].fill([0.0; 9]);
            }
            fe[..n].fill([0.0; 3]);
            for q in 0..self.points_per_element {
                let (g, w) = self.point(e, q);
                let h = Self::displacement_gradient(&u[..n], g);
                let ws = self.weighted_second_piola(&h, w);
                // F = I + H; B = F Fᵀ.
                let mut fm = h;
                for (i, row) in fm.iter_mut().enumerate() {
                    row[i] += 1.0;
                }
                let mut bm = [[0.0; 3]; 3];
                for i in 0..3 {
                    for j in i..3 {
                        let v = fm[i][0] * fm[j][0] + fm[i][1] * fm[j][1] + fm[i][2] * fm[j][2];
                        bm[i][j] = v;
                        bm[j][i] = v;
                    }
                }
                for a in 0..n {
                    let ga = g[a];
                    let mut c = [0.0; 3];
                    let mut sg = [0.0; 3];
                    for i in 0..3 {
                        c[i] = fm[i][0] * ga[0] + fm[i][1] * ga[1] + fm[i][2] * ga[2];
                        sg[i] = ws[i][0] * ga[0] + ws[i][1] * ga[1] + ws[i][2] * ga[2];
                    }
                    cur[a] = c;
                    s_grad[a] = sg;
                    for i in 0..3 {
                        lam_cur[a][i] = lambda * w * c[i];
                        mu_cur[a][i] = mu * w * c[i];
                        mu_grad[a][i] = mu * w * ga[i];
                    }
                    // f_a += w P ∇N_a = F (w S ∇N_a).
                    for i in 0..3 {
                        fe[a][i] += fm[i][0] * sg[0] + fm[i][1] * sg[1] + fm[i][2] * sg[2];
                    }
                }
                for a in 0..n {
                    let (la, ma, sa, mga) = (lam_cur[a], mu_cur[a], s_grad[a], mu_grad[a]);
                    let row = &mut ke[a];
                    for b in a..n {
                        let (gb, cb) = (g[b], cur[b]);
                        let material = mga[0] * gb[0] + mga[1] * gb[1] + mga[2] * gb[2];
                        let geometric = sa[0] * gb[0] + sa[1] * gb[1] + sa[2] * gb[2];
                        let block = &mut row[b];
                        for d in 0..3 {
                            for c in 0..3 {
                                block[3 * d + c] +=
                                    la[d] * cb[c] + ma[c] * cb[d] + material * bm[d][c];
                            }
                            block[4 * d] += geometric;
                        }
                    }
                }
            }
            let nodes = &self.connectivity[e * n..(e + 1) * n];
            let offsets = &self.block_offsets[e * n * n..(e + 1) * n * n];
            for a in 0..n {
                let stride = self.row_length[nodes[a]];
                for b in 0..n {
                    let base = offsets[a * n + b];
                    for d in 0..3 {
                        let dst = &mut k.values[base + d * stride..base + d * stride + 3];
                        for (c, v) in dst.iter_mut().enumerate() {
                            // K_ba = K_abᵀ; the diagonal blocks are read from their upper
                            // triangle so that the stored matrix is symmetric to the last bit.
                            *v += if b > a || (b == a && c >= d) {
                                ke[a][b][3 * d + c]
                            } else {
                                ke[b][a][3 * c + d]
                            };
                        }
                    }
                }
            }
            if let Some(f) = f.as_deref_mut() {
                self.scatter_force(e, &fe, f);
            }
        }
    }

    /// The Green–Lagrange strain `E = ½ (FᵀF − I)` (dimensionless) at every Gauss point, as
    /// `[E_xx, E_yy, E_zz, E_yz, E_xz, E_xy]` tensor components (shear not doubled), in the order
    /// of [`Self::gauss_point_positions`].
    pub fn green_strain_at_gauss_points(&self, x: &[f64]) -> Vec<[f64; 6]> {
        let mut out = vec![[0.0; 6]; self.weights.len()];
        self.green_strain_into(x, &mut out);
        out
    }

    /// [`Self::green_strain_at_gauss_points`] into `out` (length: number of Gauss points).
    pub fn green_strain_into(&self, x: &[f64], out: &mut [[f64; 6]]) {
        self.check_positions(x, "green_strain_into");
        assert_eq!(
            out.len(),
            self.weights.len(),
            "SvkSolid::green_strain_into: out has the wrong length"
        );
        let n = self.nodes_per_element;
        let mut u = [[0.0; 3]; MAX_NODES];
        for e in 0..self.element_count() {
            self.element_displacements(e, x, &mut u);
            for q in 0..self.points_per_element {
                let (g, _) = self.point(e, q);
                let strain = green_strain(&Self::displacement_gradient(&u[..n], g));
                out[e * self.points_per_element + q] = voigt(&strain);
            }
        }
    }
}

#[cfg(test)]
mod tests;
