//! Cheap indicators of `model.auto`: does the nonlinear force `f_nl` or the geometric stiffening
//! change the result by more than the solver's tolerance at the current state?
//!
//! Both are estimates of the **displacement** the neglected term would cause (m), to be compared
//! with the iteration's absolute tolerance `solver.tolerance × size` (the slave switches a term on
//! when `SAFETY × estimate` exceeds it and off again once it stayed below `HYSTERESIS` of it for
//! one period `2π/ω₁` of the lowest mode). Each costs O(N) plus one product with `K` per
//! communication step, against one product with `K`, one solve and O(N) per iteration of every
//! internal step (measured: 61 µs against a 1.5 ms step on B3, 91 µs against 2.6 ms on B1);
//! nothing allocates.
//!
//! **`f_nl`.** `f_nl,i = w_i R (z × X̄_i)` (see [`super::Body::internal_force`]) is the inertial
//! load of a rigid angular acceleration `z = H⁻ᵀ m̄` (1/s²) of the HRZ-lumped masses `w_i`
//! about the frame's centroid: it cancels the spurious moment `m̄ = Σ ū_i × g_i` of the
//! co-rotated elastic forces. Leaving it out applies the body force field `a_i = z × X̄_i` (of
//! size at most `|z| r_max`, `r_max = max |X̄_i|`) to the body. On a supported body the
//! quasi-static response `δu = K⁻¹ M a` obeys `‖δu‖_M ≤ ‖a‖_M / ω₁²` (the M-norm of `K⁻¹ M`
//! is `1/ω₁²`, `ω₁` the lowest natural frequency of the supported body), hence the
//! mass-weighted RMS displacement error is at most
//!
//! ```text
//! e_nl = |z| r_max / ω₁²                                                        (m)
//! ```
//!
//! A body without supports gets no estimate: there the spurious moment accelerates the whole
//! body and the error grows with time (the momentum drift of B2), so `f_nl` stays on when it is
//! allowed.
//!
//! **Stiffening.** `f_stiff = K_G ū` changes the stiffness of a shape `u` by the Rayleigh ratio
//! `η = uᵀ K_G u / uᵀ K u`, and so the quasi-static deformation by the relative amount `η`; with
//! `|ū|_max` the largest nodal local deformation the estimate is `e_s = η |ū|_max` (m).
//!
//! * `inertial`: `K_G = Σ_k c_k K_G,k` (12 unit cases, `c` the rigid acceleration coefficients
//!   of [`super::stiffening::inertial_coefficients`]). On the span of the `MODES` lowest modes
//!   `Φ` (mass-normalised, `Λ = diag ω_j²`) the ratio is bounded by the spectral radius of
//!   `Λ^-½ (Σ_k c_k Φᵀ K_G,k Φ) Λ^-½`, itself bounded by its largest absolute row sum
//!   (Gershgorin): `η = max_j Σ_l |G_jl| / (ω_j ω_l)`, `G = Σ_k c_k G_k`, `G_k = Φᵀ K_G,k Φ`
//!   precomputed (12 × `MODES`² numbers). For Kane's beam spun at Ω this is `≈ Ω² / ω₁²`, the
//!   textbook measure of centrifugal stiffening; a quasi-static deformation lies in the span
//!   of the lowest modes, which is why they suffice.
//! * `stress`: the prestress of the current deformation, `|S0| ≈ E ε` with `ε` the largest
//!   deformation gradient of [`super::strain_monitor::StrainMonitor`]. For a slender body the
//!   geometric stiffness of an axial stress `σ` against the bending stiffness is
//!   `σ A L² / (E I) = 12 (σ / E) (L / t)²` (`L`, `t` the largest and the smallest extent of the
//!   bounding box): `η = 12 ε (L / t)²`, conservative for stocky bodies and for stresses that are
//!   not axial.

use super::frame::{node, set_node};
use super::stiffening::{inertial_coefficients, GeometricStiffening};
use super::strain_monitor::StrainMonitor;
use super::Body;
use crate::fem::modal::lowest_eigenpairs;
use crate::linalg::SymmetricCsr;
use crate::mesh::Mesh;
use nalgebra::{Matrix3, Vector3};

/// Modes spanned by the stiffening indicator (two bending planes, twice).
pub const MODES: usize = 4;
/// A term is switched on when `SAFETY × estimate > tolerance × size`: the estimates are bounds of
/// an RMS (not a maximum) and of the quasi-static response (not its dynamic amplification).
pub const SAFETY: f64 = 10.0;
/// ... and off again when `SAFETY × estimate < HYSTERESIS × tolerance × size` has held for one
/// period `2π/ω₁`, so that an indicator near the threshold, or one that oscillates with a
/// vibration, does not make the term chatter.
pub const HYSTERESIS: f64 = 0.5;

/// The modal data of a supported body.
#[derive(Debug, Clone)]
struct Modal {
    /// `ω_j²` (1/s²), ascending.
    omega_sq: [f64; MODES],
    /// `G_k = Φᵀ K_G,k Φ` of the 12 `inertial` unit cases (N/m per unit coefficient, with
    /// mass-normalised modes: 1/s² per unit coefficient).
    unit_projections: Option<[[[f64; MODES]; MODES]; 12]>,
}

/// Which kind of stiffening the indicator estimates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StiffeningKind {
    Inertial,
    Stress,
}

/// The estimates at one state (m); `None`: no estimate (the term stays on when allowed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimates {
    pub nonlinear_forces: Option<f64>,
    pub stiffening: Option<f64>,
}

/// Precomputed data and scratch of the indicators (built with the model).
#[derive(Debug, Clone)]
pub struct FeatureIndicators {
    modal: Option<Modal>,
    /// `r_max = max |X̄_i|` (m).
    reach: f64,
    /// `12 (L / t)²` of the bounding box.
    slenderness: f64,
    stiffening: Option<StiffeningKind>,
    strain: StrainMonitor,
    local_deformation: Vec<f64>,
    elastic_force: Vec<f64>,
}

impl FeatureIndicators {
    /// Indicators for `body` with free nodes `free_nodes` (their `K_FF`, `M_FF` given; `supported`
    /// if some nodes are clamped, which makes `K_FF` positive definite) and the allowed
    /// `stiffening`. The lowest `MODES` modes are computed here (subspace iteration, once).
    pub fn new(
        mesh: &Mesh,
        body: &Body,
        free_nodes: &[usize],
        free_stiffness: &SymmetricCsr,
        free_mass: &SymmetricCsr,
        supported: bool,
        stiffening: Option<&GeometricStiffening>,
    ) -> FeatureIndicators {
        let n3 = body.reference.len();
        let kind = stiffening.map(|s| match s {
            GeometricStiffening::Inertial { .. } => StiffeningKind::Inertial,
            GeometricStiffening::Stress { .. } => StiffeningKind::Stress,
        });
        let modal = if supported && free_stiffness.n >= MODES {
            lowest_eigenpairs(free_stiffness, free_mass, MODES, 1e-8, 200)
                .ok()
                .map(|pairs| {
                    let omega_sq: [f64; MODES] = std::array::from_fn(|j| pairs.eigenvalues[j]);
                    let modes: Vec<Vec<f64>> = pairs
                        .modes
                        .iter()
                        .map(|phi| {
                            let mut full = vec![0.0; n3];
                            for (k, &i) in free_nodes.iter().enumerate() {
                                full[3 * i..3 * i + 3].copy_from_slice(&phi[3 * k..3 * k + 3]);
                            }
                            full
                        })
                        .collect();
                    let unit_projections = stiffening
                        .and_then(GeometricStiffening::unit_cases)
                        .map(|cases| {
                            let mut y = vec![0.0; n3];
                            let mut g = [[[0.0; MODES]; MODES]; 12];
                            for (k, case) in cases.iter().enumerate() {
                                for l in 0..MODES {
                                    case.mul_vec(&modes[l], &mut y);
                                    for j in 0..MODES {
                                        g[k][j][l] = crate::linalg::dot(&modes[j], &y);
                                    }
                                }
                            }
                            g
                        });
                    Modal {
                        omega_sq,
                        unit_projections,
                    }
                })
                .filter(|m| m.omega_sq.iter().all(|&w| w.is_finite() && w > 0.0))
        } else {
            None
        };
        let reach = body
            .frame_weights
            .reference_offsets
            .iter()
            .fold(0.0_f64, |r, x| r.max(x.norm()));
        let (lo, hi) = mesh.bounding_box();
        let mut extents: [f64; 3] = std::array::from_fn(|c| hi[c] - lo[c]);
        extents.sort_by(f64::total_cmp);
        let slenderness = if extents[0] > 0.0 {
            12.0 * (extents[2] / extents[0]).powi(2)
        } else {
            f64::INFINITY
        };
        FeatureIndicators {
            modal,
            reach,
            slenderness,
            stiffening: kind,
            strain: StrainMonitor::new(mesh),
            local_deformation: vec![0.0; n3],
            elastic_force: vec![0.0; n3],
        }
    }

    /// The lowest natural frequency `ω₁` of the supported body (rad/s), if computed.
    pub fn first_frequency(&self) -> Option<f64> {
        self.modal.as_ref().map(|m| m.omega_sq[0].sqrt())
    }

    /// Whether `f_nl` gets an estimate (a supported body with its modes).
    pub fn estimates_nonlinear_forces(&self) -> bool {
        self.modal.is_some()
    }

    /// Whether the allowed stiffening gets an estimate.
    pub fn estimates_stiffening(&self) -> bool {
        match self.stiffening {
            Some(StiffeningKind::Inertial) => self
                .modal
                .as_ref()
                .is_some_and(|m| m.unit_projections.is_some()),
            Some(StiffeningKind::Stress) => self.slenderness.is_finite(),
            None => false,
        }
    }

    /// The estimates at positions, velocities and accelerations `(x, v, a)` (flat 3N). No
    /// allocation.
    pub fn estimate(&mut self, body: &Body, x: &[f64], v: &[f64], a: &[f64]) -> Estimates {
        let fw = &body.frame_weights;
        let frame = fw.best_fit(x);
        let rt = frame.rotation.transpose();
        let mut largest: f64 = 0.0;
        for i in 0..body.node_count() {
            let u = rt * (node(x, i) - frame.origin) - fw.reference_offsets[i];
            largest = largest.max(u.norm());
            set_node(&mut self.local_deformation, i, &u);
        }
        let nonlinear_forces = self.modal.as_ref().map(|m| {
            body.stiffness_product(&self.local_deformation, &mut self.elastic_force);
            let mut mbar = Vector3::zeros();
            for i in 0..body.node_count() {
                mbar += node(&self.local_deformation, i).cross(&node(&self.elastic_force, i));
            }
            let h_inv = fw
                .rotation_sensitivity(&frame, x)
                .try_inverse()
                .unwrap_or_else(Matrix3::zeros);
            let z = h_inv.transpose() * mbar;
            z.norm() * self.reach / m.omega_sq[0]
        });
        let ratio = match self.stiffening {
            Some(StiffeningKind::Inertial) => self.modal.as_ref().and_then(|m| {
                let projections = m.unit_projections.as_ref()?;
                let c = inertial_coefficients(body, x, v, a);
                // G = Σ_k c_k G_k, then the largest row sum of |Λ^-½ G Λ^-½|.
                let mut g = [[0.0; MODES]; MODES];
                for (ck, gk) in c.iter().zip(projections) {
                    for (row, row_k) in g.iter_mut().zip(gk) {
                        for (x, xk) in row.iter_mut().zip(row_k) {
                            *x += ck * xk;
                        }
                    }
                }
                let eta = g
                    .iter()
                    .zip(&m.omega_sq)
                    .map(|(row, wj)| {
                        row.iter()
                            .zip(&m.omega_sq)
                            .map(|(x, wl)| x.abs() / (wj * wl).sqrt())
                            .sum::<f64>()
                    })
                    .fold(0.0, f64::max);
                Some(eta)
            }),
            Some(StiffeningKind::Stress) if self.slenderness.is_finite() => {
                Some(self.strain.largest_gradient(&self.local_deformation) * self.slenderness)
            }
            _ => None,
        };
        Estimates {
            nonlinear_forces,
            stiffening: ratio.map(|eta| eta * largest),
        }
    }
}
