//! Point constraints with Lagrange multipliers (seed paper eq. 9) and their Schur complement.
//!
//! A point constraint (a `pin` support) holds the weighted centroid of a node set at a point:
//! `c_p(x) = Σ_i ŵ_i x_i − d_p = 0` with `ŵ_i = w_i / Σ w`. Stacked, `C x = d` with a constant
//! Jacobian `C = (ŵ ⊗ I3)` per constraint, which commutes with the block rotation:
//! `C hR = hR_c C` (`hR_c = diag(R, …)` on the constraint rows). With `S = hR S̄ hRᵀ` the Schur
//! complement is therefore constant in the co-moving frame (docs/formulation.md, "One factorization per step size"):
//!
//! ```text
//! C S⁻¹ Cᵀ = hR_c Ā hR_cᵀ,   Ā = C Z,   Z = S̄⁻¹ Cᵀ   (3m columns, one solve each, once per h)
//! ```
//!
//! A modified-Newton iteration of `r(x) + Cᵀλ = 0`, `C x = d` is then: the unconstrained
//! correction `Δx_u = −hR S̄⁻¹ hRᵀ (r + Cᵀλ)` (the one sparse solve), the constraint error
//! `e = C (x + Δx_u) − d`, `μ = Ā⁻¹ hR_cᵀ e` (a small dense product), `Δλ = hR_c μ` and
//! `Δx = Δx_u − hR Z μ`. After each iteration `C x = d` holds to round-off: the constraints do
//! not drift (index 3, solved exactly for the multipliers; no stabilisation needed).

use crate::body::frame::{nearest_rotation, node};
use crate::error::{Error, Result};
use crate::linalg::cholesky::{SolveWorkspace, SparseCholesky};
use nalgebra::{DMatrix, Matrix3, Vector3};

/// One point constraint: the weighted centroid of `nodes` held at `target` (m).
#[derive(Debug, Clone)]
pub struct PointConstraint {
    /// Global node indices.
    pub nodes: Vec<usize>,
    /// Normalised weights `ŵ_i` (sum 1).
    pub weights: Vec<f64>,
    /// Rows of the free DOF vector of each node (`3k` for free node `k`).
    pub free_rows: Vec<usize>,
    pub target: Vector3<f64>,
}

impl PointConstraint {
    /// `Σ ŵ_i x_i`.
    pub fn centroid(&self, x: &[f64]) -> Vector3<f64> {
        let mut c = Vector3::zeros();
        for (&n, &w) in self.nodes.iter().zip(&self.weights) {
            c += w * node(x, n);
        }
        c
    }

    /// Row `e` of the constraint on a free-DOF column: `Σ ŵ_i v[row_i + e]` (real or complex).
    pub fn free_sum<T>(&self, column: &[T], e: usize) -> T
    where
        T: Copy + std::ops::Mul<f64, Output = T> + std::iter::Sum<T>,
    {
        self.free_rows
            .iter()
            .zip(&self.weights)
            .map(|(&row, &w)| column[row + e] * w)
            .sum()
    }
}

/// A rigid node set (an RBE2 spider, docs/formulation.md "Rigid attachments"): the set's
/// nodes keep their reference shape, `x_i = c + R_s X̂_i`, exactly.
///
/// With the set's centroid `c = Σ x_i / n`, its best-fit rotation `R_s` (the nearest rotation
/// of `Σ (x_i − c) X̂_iᵀ`) and the local deformation `ū_i = R_sᵀ (x_i − c) − X̂_i`, the
/// constraint is `h(x) = Vᵀ ū = 0`: `V` (`3n × k`, `k = 3n − 6`) an orthonormal basis of the
/// set's deformations, the complement of its six rigid motions. At `ū = 0` the Jacobian is
/// `∂h/∂x = Vᵀ hR_sᵀ` (the best fit takes the rigid part out of `δū`): constant in the set's
/// frame, like the body's stiffness. The constraint force `hR_s V λ` has no resultant and no
/// moment (`V` is orthogonal to the rigid motions): it holds the shape and nothing else.
///
/// An axis lock on a rigid set (a hinge on it) holds instead the set's rotation about every
/// axis but the hinge's: `h_j = b_jᵀ R_sᵀ a = 0`, `j = 1, 2`, with `a` the hinge axis (global) and
/// `b_1`, `b_2` perpendicular to its reference direction `a_ref` (`a = R_s a_ref` at placement).
/// With `δR_s = R_s [δθ]×` and the best fit's `δθ = J̄⁻¹ Σ_i X̂_i × δx̂_i`
/// (`J̄ = Σ_i (|X̂_i|² 1 − X̂_i X̂_iᵀ)`), `δh_j = −δθ · (a_ref × b_j)`: the rows
/// `g_j,i = −(J̄⁻¹ (a_ref × b_j)) × X̂_i` are constant in the set's frame, and the force
/// `hR_s g λ` is a pure moment about axes perpendicular to the hinge's (the bearing's moment).
#[derive(Debug, Clone)]
pub struct RigidConstraint {
    /// Global node indices.
    pub nodes: Vec<usize>,
    /// Rows of the free DOF vector of each node.
    pub free_rows: Vec<usize>,
    /// `X̂_i = X_i − X̄` (m), the reference offsets from the set's centroid.
    pub offsets: Vec<Vector3<f64>>,
    /// `V` (the shape), or the rows `g_j` of an axis lock, column-major (`k` columns of `3n`).
    pub basis: Vec<f64>,
    /// An axis lock's directions, in place of the shape constraint.
    pub lock: Option<AxisLock>,
}

/// The directions of an axis lock ([`RigidConstraint`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisLock {
    /// `b_1`, `b_2`: perpendicular to the hinge axis in reference coordinates.
    pub directions: [Vector3<f64>; 2],
    /// `a_ref`, the hinge axis in reference coordinates (unit).
    pub reference_axis: Vector3<f64>,
    /// `a`, the hinge axis in global coordinates (unit): `R_s a_ref` where the body was placed.
    pub axis: Vector3<f64>,
}

impl RigidConstraint {
    /// The rigid set of `nodes` with reference positions `reference` (flat, all nodes); `free_rows`
    /// as in [`PointConstraint`]. Error if the nodes are collinear (the set has no rotation
    /// about their line to hold).
    pub fn new(
        name: &str,
        nodes: &[usize],
        free_rows: Vec<usize>,
        reference: &[f64],
    ) -> Result<Self> {
        let n = nodes.len();
        let centroid = nodes
            .iter()
            .map(|&i| node(reference, i))
            .sum::<Vector3<f64>>()
            / n as f64;
        let offsets: Vec<Vector3<f64>> = nodes
            .iter()
            .map(|&i| node(reference, i) - centroid)
            .collect();
        // The six rigid motions, orthonormalised; V spans the eigenvectors of I − Q Qᵀ with
        // eigenvalue 1.
        let rigid = DMatrix::from_fn(3 * n, 6, |row, col| {
            let (i, e) = (row / 3, row % 3);
            if col < 3 {
                f64::from(u8::from(e == col))
            } else {
                Vector3::ith(col - 3, 1.0).cross(&offsets[i])[e]
            }
        });
        let svd = rigid.svd(true, false);
        let largest = svd.singular_values.max();
        if svd.singular_values.min() <= 1e-9 * largest {
            return Err(Error::new(format!(
                "interface '{name}': a rigid set needs at least three nodes that are not on one line"
            )));
        }
        let q = svd.u.expect("u requested");
        let projection = DMatrix::identity(3 * n, 3 * n) - &q * q.transpose();
        let eigen = projection.symmetric_eigen();
        let mut basis = Vec::with_capacity(3 * n * (3 * n - 6));
        for (j, &value) in eigen.eigenvalues.iter().enumerate() {
            if value > 0.5 {
                basis.extend(eigen.eigenvectors.column(j).iter());
            }
        }
        debug_assert_eq!(basis.len(), 3 * n * (3 * n - 6));
        Ok(RigidConstraint {
            nodes: nodes.to_vec(),
            free_rows,
            offsets,
            basis,
            lock: None,
        })
    }

    /// The axis lock of a hinge with reference axis `axis` on the rigid set of `nodes` (see the
    /// type's documentation); its global axis is `axis` until [`Self::place`] sets it.
    pub fn axis_lock(
        name: &str,
        nodes: &[usize],
        free_rows: Vec<usize>,
        reference: &[f64],
        axis: Vector3<f64>,
    ) -> Result<Self> {
        let shape = RigidConstraint::new(name, nodes, free_rows, reference)?;
        let a = axis.normalize();
        let helper = if a.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let b1 = a.cross(&helper).normalize();
        let b2 = a.cross(&b1);
        let polar = shape.offsets.iter().fold(Matrix3::zeros(), |j, o| {
            j + Matrix3::identity() * o.norm_squared() - o * o.transpose()
        });
        let polar_inverse = polar.try_inverse().ok_or_else(|| {
            Error::new(format!(
                "interface '{name}': the rigid set cannot carry a moment"
            ))
        })?;
        let mut basis = Vec::with_capacity(6 * nodes.len());
        for b in [b1, b2] {
            let arm = polar_inverse * a.cross(&b);
            for o in &shape.offsets {
                basis.extend((-arm.cross(o)).iter());
            }
        }
        Ok(RigidConstraint {
            basis,
            lock: Some(AxisLock {
                directions: [b1, b2],
                reference_axis: a,
                axis: a,
            }),
            ..shape
        })
    }

    /// Sets an axis lock's global axis from the positions `x` where the body was placed.
    pub fn place(&mut self, x: &[f64]) {
        let r = self.rotation(x);
        if let Some(lock) = &mut self.lock {
            lock.axis = r * lock.reference_axis;
        }
    }

    /// The number of multipliers: `k = 3n − 6` for the shape, 2 for an axis lock.
    pub fn rows(&self) -> usize {
        if self.lock.is_some() {
            2
        } else {
            3 * self.nodes.len() - 6
        }
    }

    /// Column `j` of `V` (`3n`).
    pub fn column(&self, j: usize) -> &[f64] {
        let n3 = 3 * self.nodes.len();
        &self.basis[j * n3..(j + 1) * n3]
    }

    /// The set's best-fit rotation `R_s` at positions `x` (flat, all nodes).
    pub fn rotation(&self, x: &[f64]) -> Matrix3<f64> {
        let c = self.centroid(x);
        let a = self
            .nodes
            .iter()
            .zip(&self.offsets)
            .fold(Matrix3::zeros(), |a, (&i, o)| {
                a + (node(x, i) - c) * o.transpose()
            });
        nearest_rotation(&a)
    }

    fn centroid(&self, x: &[f64]) -> Vector3<f64> {
        self.nodes.iter().map(|&i| node(x, i)).sum::<Vector3<f64>>() / self.nodes.len() as f64
    }

    /// `h(x) = Vᵀ ū` (or an axis lock's `b_jᵀ R_sᵀ a`) into `h` (`k`); returns `R_s`.
    pub fn violation(&self, x: &[f64], h: &mut [f64]) -> Matrix3<f64> {
        let (c, r) = (self.centroid(x), self.rotation(x));
        let rt = r.transpose();
        if let Some(lock) = &self.lock {
            let local_axis = rt * lock.axis;
            for (hj, b) in h.iter_mut().zip(&lock.directions) {
                *hj = b.dot(&local_axis);
            }
            return r;
        }
        h.fill(0.0);
        for (k, (&i, o)) in self.nodes.iter().zip(&self.offsets).enumerate() {
            let u = rt * (node(x, i) - c) - o;
            for (j, hj) in h.iter_mut().enumerate() {
                let v = &self.column(j)[3 * k..3 * k + 3];
                *hj += v[0] * u[0] + v[1] * u[1] + v[2] * u[2];
            }
        }
        r
    }

    /// `Σ_i v_i · y_{row_i}` for column `j` of `V` on a free-DOF vector `y` (frame coordinates).
    pub fn free_dot(&self, j: usize, y: &[f64]) -> f64 {
        let v = self.column(j);
        self.free_rows
            .iter()
            .enumerate()
            .map(|(k, &row)| {
                v[3 * k] * y[row] + v[3 * k + 1] * y[row + 1] + v[3 * k + 2] * y[row + 2]
            })
            .sum()
    }

    /// The moment about `point` of the constraint force `hR_s V λ` at positions `x` (N m; zero
    /// for the shape constraint, the bearing's moment for an axis lock).
    pub fn moment(&self, x: &[f64], multipliers: &[f64], point: &Vector3<f64>) -> Vector3<f64> {
        let r = self.rotation(x);
        let mut moment = Vector3::zeros();
        for (k, &i) in self.nodes.iter().enumerate() {
            let mut local = Vector3::zeros();
            for (j, &l) in multipliers.iter().enumerate() {
                let v = &self.column(j)[3 * k..3 * k + 3];
                local += l * Vector3::new(v[0], v[1], v[2]);
            }
            moment += (node(x, i) - point).cross(&(r * local));
        }
        moment
    }

    /// Adds the constraint force `hR_s V λ` (`λ`: this set's `k` multipliers) to `f` (flat `3N`).
    pub fn add_force(&self, x: &[f64], multipliers: &[f64], f: &mut [f64]) {
        let r = self.rotation(x);
        for (k, &i) in self.nodes.iter().enumerate() {
            let mut local = Vector3::zeros();
            for (j, &l) in multipliers.iter().enumerate() {
                let v = &self.column(j)[3 * k..3 * k + 3];
                local += l * Vector3::new(v[0], v[1], v[2]);
            }
            let g = r * local;
            for d in 0..3 {
                f[3 * i + d] += g[d];
            }
        }
    }
}

/// The constraint-dependent part of one iteration matrix: `Z = S̄⁻¹ Cᵀ` (free DOFs × 3m,
/// column-major) and `Ā⁻¹` (3m × 3m).
#[derive(Debug, Clone)]
pub struct ConstraintFactor {
    pub z: Vec<f64>,
    pub schur_inverse: DMatrix<f64>,
    /// Scratch: `hR_cᵀ e` and `μ` (3m each).
    pub error: Vec<f64>,
    pub mu: Vec<f64>,
    /// Scratch: a rigid set's part of `y` turned into the set's frame (`3n` of the largest set).
    set_part: Vec<f64>,
}

impl ConstraintFactor {
    /// `Z` and `Ā⁻¹` for the factor of `S̄` (one solve per multiplier; at factorization time
    /// only). The point constraints' rows come first (3 each), then the rigid sets' (`k` each).
    pub fn new(
        constraints: &[PointConstraint],
        rigid: &[RigidConstraint],
        factor: &SparseCholesky,
        workspace: &mut SolveWorkspace,
    ) -> Result<ConstraintFactor> {
        let n = factor.dim();
        let points = 3 * constraints.len();
        let m = points + rigid.iter().map(RigidConstraint::rows).sum::<usize>();
        let mut z = vec![0.0; n * m];
        for (p, c) in constraints.iter().enumerate() {
            for d in 0..3 {
                let column = &mut z[(3 * p + d) * n..(3 * p + d + 1) * n];
                for (&row, &w) in c.free_rows.iter().zip(&c.weights) {
                    column[row + d] = w;
                }
                factor.solve_in_place(column, workspace);
            }
        }
        let mut col = points;
        for set in rigid {
            for j in 0..set.rows() {
                let column = &mut z[col * n..(col + 1) * n];
                let v = set.column(j);
                for (k, &row) in set.free_rows.iter().enumerate() {
                    column[row..row + 3].copy_from_slice(&v[3 * k..3 * k + 3]);
                }
                factor.solve_in_place(column, workspace);
                col += 1;
            }
        }
        // Ā = C Z: row (q, e) of C picks Σ ŵ_i over constraint q's nodes at direction e; a rigid
        // set's row j is column j of its V on its nodes.
        let mut a: DMatrix<f64> = DMatrix::zeros(m, m);
        for col in 0..m {
            let column = &z[col * n..(col + 1) * n];
            for (q, c) in constraints.iter().enumerate() {
                for e in 0..3 {
                    a[(3 * q + e, col)] = c.free_sum(column, e);
                }
            }
            let mut row = points;
            for set in rigid {
                for j in 0..set.rows() {
                    a[(row, col)] = set.free_dot(j, column);
                    row += 1;
                }
            }
        }
        let a = (&a + a.transpose()) * 0.5;
        let schur_inverse = a.cholesky().map(|c| c.inverse()).ok_or_else(|| {
            Error::new(if rigid.is_empty() {
                "the pin constraints are redundant (their Schur complement is singular): two pins on the same nodes?"
            } else {
                "the pin, hinge and rigid-set constraints are redundant (their Schur complement is singular): two rigid interfaces on the same nodes?"
            })
        })?;
        Ok(ConstraintFactor {
            z,
            schur_inverse,
            error: vec![0.0; m],
            mu: vec![0.0; m],
            set_part: vec![0.0; 3 * rigid.iter().map(|r| r.nodes.len()).max().unwrap_or(0)],
        })
    }

    /// One constrained correction, in place. On entry `reduced` holds `y = S̄⁻¹ hRᵀ (r + Cᵀλ)`
    /// on the free DOFs (the unconstrained correction is `Δx_u = −hR y`); on return it holds
    /// `y + Z μ`, so that the constrained correction is `Δx = −hR (y + Z μ)`, and `multipliers`
    /// has been increased by `Δλ` (`hR_c μ` for the point constraints, global; `μ` for the rigid
    /// sets, whose multipliers live in the set's frame). `x` are the current positions, `r` the
    /// rotation of the co-moving frame. A rigid set's linearised error is
    /// `h(x) − Vᵀ hR_sᵀ hR y ≈ h(x) − Vᵀ y` (its frame taken as the body's in the matrix only:
    /// the residual and `h` are exact).
    pub fn correct(
        &mut self,
        constraints: &[PointConstraint],
        rigid: &[RigidConstraint],
        x: &[f64],
        r: &Matrix3<f64>,
        reduced: &mut [f64],
        multipliers: &mut [f64],
    ) {
        self.correct_towards(constraints, rigid, x, None, r, reduced, multipliers);
    }

    /// [`Self::correct`] for the step Jacobian's linearised step (docs/formulation.md, "The step
    /// Jacobian"): the constraints' values are not `C x − d` and `h(x)` but their derivatives
    /// along the perturbation, `values` (the point constraints' `C δx` in global coordinates, 3
    /// rows each, then each rigid set's `h'(δx)`), the rigid sets' frames those at `x`; the
    /// multipliers are the perturbation's `δλ`.
    #[allow(clippy::too_many_arguments)]
    pub fn correct_linear(
        &mut self,
        constraints: &[PointConstraint],
        rigid: &[RigidConstraint],
        x: &[f64],
        values: &[f64],
        r: &Matrix3<f64>,
        reduced: &mut [f64],
        multipliers: &mut [f64],
    ) {
        self.correct_towards(constraints, rigid, x, Some(values), r, reduced, multipliers);
    }

    /// [`Self::correct`] with the constraints' values `values` given (linear) or taken at `x`.
    #[allow(clippy::too_many_arguments)]
    fn correct_towards(
        &mut self,
        constraints: &[PointConstraint],
        rigid: &[RigidConstraint],
        x: &[f64],
        values: Option<&[f64]>,
        r: &Matrix3<f64>,
        reduced: &mut [f64],
        multipliers: &mut [f64],
    ) {
        let n = reduced.len();
        let m = self.error.len();
        // e = C (x + Δx_u) − d, rotated into the frame: hR_cᵀ e = Rᵀ (C x − d) − C y.
        let rt = r.transpose();
        for (p, c) in constraints.iter().enumerate() {
            let mut cu = Vector3::zeros();
            for (&row, &w) in c.free_rows.iter().zip(&c.weights) {
                cu += w * Vector3::new(reduced[row], reduced[row + 1], reduced[row + 2]);
            }
            let value = match values {
                Some(v) => Vector3::new(v[3 * p], v[3 * p + 1], v[3 * p + 2]),
                None => c.centroid(x) - c.target,
            };
            let e = rt * value - cu;
            self.error[3 * p..3 * p + 3].copy_from_slice(e.as_slice());
        }
        let mut row = 3 * constraints.len();
        for set in rigid {
            // The linearised error h(x) − Vᵀ hR_sᵀ hR y: y turned from the body's frame into the
            // set's (the matrix's Ā takes the two as one; the error does not need to).
            let k = set.rows();
            let frame = match values {
                Some(v) => {
                    self.error[row..row + k].copy_from_slice(&v[row..row + k]);
                    set.rotation(x)
                }
                None => set.violation(x, &mut self.error[row..row + k]),
            };
            let q = frame.transpose() * r;
            let part = &mut self.set_part[..3 * set.nodes.len()];
            for (local, &fr) in set.free_rows.iter().enumerate() {
                let turned = q * Vector3::new(reduced[fr], reduced[fr + 1], reduced[fr + 2]);
                part[3 * local..3 * local + 3].copy_from_slice(turned.as_slice());
            }
            for j in 0..k {
                self.error[row + j] -= crate::linalg::dot(set.column(j), part);
            }
            row += k;
        }
        for i in 0..m {
            self.mu[i] = (0..m)
                .map(|j| self.schur_inverse[(i, j)] * self.error[j])
                .sum();
        }
        for (col, &mu) in self.mu.iter().enumerate() {
            let column = &self.z[col * n..(col + 1) * n];
            for (u, zc) in reduced.iter_mut().zip(column) {
                *u += zc * mu;
            }
        }
        for p in 0..constraints.len() {
            let dl = r * Vector3::new(self.mu[3 * p], self.mu[3 * p + 1], self.mu[3 * p + 2]);
            for d in 0..3 {
                multipliers[3 * p + d] += dl[d];
            }
        }
        let points = 3 * constraints.len();
        for (l, mu) in multipliers[points..m].iter_mut().zip(&self.mu[points..]) {
            *l += mu;
        }
    }
}

/// Adds the constraint forces `Cᵀλ` of the point constraints and the rigid sets to `f` (flat
/// `3N`) at positions `x`.
pub fn add_constraint_forces(
    constraints: &[PointConstraint],
    rigid: &[RigidConstraint],
    x: &[f64],
    multipliers: &[f64],
    f: &mut [f64],
) {
    let mut row = 3 * constraints.len();
    for set in rigid {
        let k = set.rows();
        set.add_force(x, &multipliers[row..row + k], f);
        row += k;
    }
    for (p, c) in constraints.iter().enumerate() {
        for (&n, &w) in c.nodes.iter().zip(&c.weights) {
            for d in 0..3 {
                f[3 * n + d] += w * multipliers[3 * p + d];
            }
        }
    }
}
