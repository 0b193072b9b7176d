//! The body's lowest elastic modes, as the time error control uses them (docs/formulation.md,
//! "Time error control": the deformation scale and the errors that add up).
//!
//! With the mass-normalised modes `φ_j` of the free DOFs (`K φ_j = ω_j² M φ_j`, the elastic ones
//! only on a body without supports) and a field `v` of the body (flat `3N`; turned into the
//! reference orientation by the co-moving frame's `R` when it is global), its coordinates in the
//! lowest modes are `p_j = φ_jᵀ M Rᵀv`, and `√(Σ_j p_j² / m)` is the mass-weighted RMS of its
//! part in them; the rest lies in the modes above (the modes are M-orthogonal).
//!
//! * The **quasi-static displacement** of an acceleration field `a`, the elastic response to
//!   the load `M a` held, is mode by mode `Σ_j φ_j p_j / ω_j²`: its RMS over the lowest modes,
//!   `√(Σ_j p_j² / ω_j⁴ / m)`, is a lower bound of the whole, and close to it where the load
//!   bends the body. (Dividing the whole acceleration field by `ω₁²` instead is an upper bound
//!   that can be far off: a load on a few nodes accelerates them by `F/m_local`, mostly in modes
//!   far above `ω₁`; the connecting rod under its piston load: 6.3e-3 m against 2e-6 m.)
//! * The **elastic displacement** relative to the supports, from the local deformation `ū` and
//!   `g = K ū` ([`LowestModes::deformation`]).
//! * The **errors that last**: a local error in mode `j` persists while the mode's damping
//!   `σ_j = (α + β ω_j²)/2` (1/s, Rayleigh's `α`, `β`) lets it, about `1/σ_j`; over the horizon
//!   `H` (the run, or the period `T₁`) the errors of a step add up with the weight
//!   `w_j = min(1, 1/(σ_j H))` ([`LowestModes::lasting_error`]). The modes above the kept ones
//!   get the weight of the lowest of them, `ω_top` (they decay at least as fast).

use super::frame::node;
use crate::fem::modal::EigenPairs;
use crate::linalg::SymmetricCsr;
use nalgebra::Matrix3;

/// The elastic modes kept: the two lowest bending pairs of a beam and two more (torsion,
/// axial or the next bending mode).
pub const MODES: usize = 6;

/// The lowest elastic modes on the body's free mesh nodes, and the lowest frequency above them.
#[derive(Debug, Clone)]
pub struct LowestModes {
    /// The free mesh nodes (global indices), in the order of the modes' rows.
    nodes: Vec<usize>,
    /// `φ_j` by node, then mode, then component: entry `(k, j, c)` at `3 (MODES k + j) + c`
    /// (kg^-½; modes past `omega_sq.len()` are zero).
    modes: Vec<f64>,
    /// `M φ_j`, stored as `modes` (kg^½).
    mass_modes: Vec<f64>,
    /// `K φ_j` over all of the body's nodes, held ones included (node `i`, mode `j`, component
    /// `c` at `3 (MODES i + j) + c`; N kg^-½ / m), when set ([`Self::with_stiffness_modes`]):
    /// then `φ_jᵀ K ū` needs no product with `K`.
    stiffness_modes: Option<Vec<f64>>,
    /// `ω_j²` (1/s²), ascending, positive; at most [`MODES`].
    omega_sq: Vec<f64>,
    /// `ω_top²` (1/s²): the lowest eigenvalue above the kept ones (the highest kept if none was
    /// computed).
    omega_top_sq: f64,
    /// `σ_j = (α + β ω_j²)/2` (1/s) of the kept modes, then of `ω_top`.
    decay_rates: [f64; MODES + 1],
    /// The body's mass `m` (kg).
    total_mass: f64,
    /// Whether the body has no supports ([`Self::without_supports`]).
    free_body: bool,
}

impl LowestModes {
    /// From the eigenpairs `pairs` of `K φ = ω² M φ` on the free mesh nodes `nodes` (`mass`:
    /// their `M ⊗ I3`), of which the first `rigid` are rigid modes (0, or 6 on a body without
    /// supports) and are left out; [`MODES`] are kept, the next eigenvalue is `ω_top²`.
    /// `damping`: Rayleigh's `(α, β)` (1/s, s).
    pub fn new(
        nodes: &[usize],
        mass: &SymmetricCsr,
        pairs: &EigenPairs,
        rigid: usize,
        total_mass: f64,
        damping: (f64, f64),
    ) -> LowestModes {
        let n = nodes.len();
        let mut modes = vec![0.0; 3 * MODES * n];
        let mut mass_modes = vec![0.0; 3 * MODES * n];
        let mut omega_sq = Vec::with_capacity(MODES);
        let mut omega_top_sq = None;
        let mut m_phi = vec![0.0; 3 * n];
        let elastic = pairs.modes.iter().zip(&pairs.eigenvalues).skip(rigid);
        for (phi, &w2) in elastic.filter(|(_, &w2)| w2 > 0.0) {
            if omega_sq.len() == MODES {
                omega_top_sq = Some(w2);
                break;
            }
            mass.mul_vec(phi, &mut m_phi);
            let j = omega_sq.len();
            for k in 0..n {
                let at = 3 * (MODES * k + j);
                modes[at..at + 3].copy_from_slice(&phi[3 * k..3 * k + 3]);
                mass_modes[at..at + 3].copy_from_slice(&m_phi[3 * k..3 * k + 3]);
            }
            omega_sq.push(w2);
        }
        let omega_top_sq = omega_top_sq.unwrap_or(*omega_sq.last().unwrap_or(&f64::INFINITY));
        let (alpha, beta) = damping;
        let decay_rate = |w2: f64| (alpha + beta * w2) / 2.0;
        let mut decay_rates = [decay_rate(omega_top_sq); MODES + 1];
        for (sigma, &w2) in decay_rates.iter_mut().zip(&omega_sq) {
            *sigma = decay_rate(w2);
        }
        LowestModes {
            nodes: nodes.to_vec(),
            modes,
            mass_modes,
            stiffness_modes: None,
            omega_sq,
            omega_top_sq,
            decay_rates,
            total_mass,
            free_body: false,
        }
    }

    /// The same on a body without supports, whose local deformation `ū` is measured from the
    /// best-fit frame, the nearest rigid motion: its mass-weighted RMS is then the elastic
    /// displacement itself ([`Self::free_body_rms`]).
    pub fn for_body_without_supports(mut self) -> LowestModes {
        self.free_body = true;
        self
    }

    /// Whether the body has no supports ([`Self::for_body_without_supports`]): its deformation
    /// scale is the RMS of `ū` itself.
    pub fn without_supports(&self) -> bool {
        self.free_body
    }

    /// On a body without supports ([`Self::for_body_without_supports`]), the mass-weighted RMS of
    /// the local deformation `ū` (flat `3N`, co-moving frame, m): `√(ūᵀ M ū / m)` over the free
    /// elastic nodes, with `mass` the free DOFs' `M ⊗ I3` (`FreeNodes::mass`, whose first rows
    /// are those nodes', in the order of the modes' nodes; `m`: the body's mass, lumped points
    /// included, as for the lowest modes' part); `None` on a supported body. No allocation.
    pub fn free_body_rms(&self, mass: &SymmetricCsr, ubar: &[f64]) -> Option<f64> {
        if !self.free_body {
            return None;
        }
        let dofs = 3 * self.nodes.len();
        let at = |dof: usize| ubar[3 * self.nodes[dof / 3] + dof % 3];
        let mut squared = 0.0;
        for row in 0..dofs {
            let (cols, values) = mass.row(row);
            let m_u: f64 = (cols.iter().zip(values))
                .filter(|(&c, _)| c < dofs)
                .map(|(&c, v)| v * at(c))
                .sum();
            squared += at(row) * m_u;
        }
        Some((squared.max(0.0) / self.total_mass).sqrt())
    }

    /// The same with `K φ_j` stored (`product(x, K x)` on the body's `size = 3N` coordinates:
    /// the body's own `K`, the one of its `K ū`), so that [`Self::deformation_of`] projects
    /// `K ū` as `φ_jᵀ K ū = (K φ_j)ᵀ ū` (`K` symmetric) without the product. Allocates; set-up
    /// only.
    pub fn with_stiffness_modes(
        mut self,
        product: impl Fn(&[f64], &mut [f64]),
        size: usize,
    ) -> LowestModes {
        let nodes = size / 3;
        let mut stored = vec![0.0; 3 * MODES * nodes];
        let (mut phi, mut k_phi) = (vec![0.0; size], vec![0.0; size]);
        for j in 0..self.omega_sq.len() {
            phi.fill(0.0);
            for (k, &i) in self.nodes.iter().enumerate() {
                let at = 3 * (MODES * k + j);
                phi[3 * i..3 * i + 3].copy_from_slice(&self.modes[at..at + 3]);
            }
            product(&phi, &mut k_phi);
            for i in 0..nodes {
                let at = 3 * (MODES * i + j);
                stored[at..at + 3].copy_from_slice(&k_phi[3 * i..3 * i + 3]);
            }
        }
        self.stiffness_modes = Some(stored);
        self
    }

    /// `G_jl = φ_jᵀ A φ_l` of a symmetric matrix `A` on the body's coordinates (`size` = `3N`),
    /// given by its product `product(x, A x)`, over the kept modes (1/s² for a stiffness; zero
    /// past the computed modes). Allocates; set-up only.
    pub fn project_matrix(
        &self,
        product: impl Fn(&[f64], &mut [f64]),
        size: usize,
    ) -> [[f64; MODES]; MODES] {
        let full: Vec<Vec<f64>> = (0..self.omega_sq.len())
            .map(|j| {
                let mut phi = vec![0.0; size];
                for (k, &i) in self.nodes.iter().enumerate() {
                    let at = 3 * (MODES * k + j);
                    phi[3 * i..3 * i + 3].copy_from_slice(&self.modes[at..at + 3]);
                }
                phi
            })
            .collect();
        let mut g = [[0.0; MODES]; MODES];
        let mut y = vec![0.0; size];
        for (l, phi_l) in full.iter().enumerate() {
            product(phi_l, &mut y);
            for (j, phi_j) in full.iter().enumerate() {
                g[j][l] = crate::linalg::dot(phi_j, &y);
            }
        }
        g
    }

    /// The relative stiffness change `η` of the kept modes under a geometric stiffness whose
    /// projection ([`Self::project_matrix`]) is `g` (docs/formulation.md, "The reduced body": when
    /// the stiffening is taken): the Rayleigh ratio `uᵀ K_G u / uᵀ K u` on their span is
    /// bounded by the largest absolute row sum of `Λ^-½ G Λ^-½` (Gershgorin),
    /// `η = max_j Σ_l |G_jl| / (ω_j ω_l)`. For a beam spun at `Ω` it is about `Ω²/ω₁²`.
    pub fn relative_stiffening(&self, g: &[[f64; MODES]; MODES]) -> f64 {
        let w = &self.omega_sq;
        (0..w.len())
            .map(|j| {
                (0..w.len())
                    .map(|l| g[j][l].abs() / (w[j] * w[l]).sqrt())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// `T₁ = 2π/ω₁` (s), the period of the lowest elastic mode.
    pub fn first_period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.omega_sq[0].sqrt()
    }

    /// `p_j = ψ_jᵀ Rᵀv` for the stored vectors `ψ_j` (`modes` or `mass_modes`): one pass over
    /// the nodes, no allocation.
    fn project(&self, vectors: &[f64], rotation: &Matrix3<f64>, v: &[f64]) -> [f64; MODES] {
        let mut p = [0.0; MODES];
        let rt = rotation.transpose();
        for (k, &i) in self.nodes.iter().enumerate() {
            let local = rt * node(v, i);
            let psi = &vectors[3 * MODES * k..3 * MODES * (k + 1)];
            for (j, p) in p.iter_mut().enumerate() {
                *p += psi[3 * j] * local.x + psi[3 * j + 1] * local.y + psi[3 * j + 2] * local.z;
            }
        }
        p
    }

    /// Takes the part in the lowest modes out of the field `v` (flat `3N`, global, on the free
    /// mesh nodes): `v ← v − R Σ_j φ_j p_j`, `p_j = φ_jᵀ M Rᵀv` (`R`: `rotation`, the co-moving
    /// frame's). No allocation.
    pub fn remove_lowest(&self, rotation: &Matrix3<f64>, v: &mut [f64]) {
        let p = self.project(&self.mass_modes, rotation, v);
        for (k, &i) in self.nodes.iter().enumerate() {
            let phi = &self.modes[3 * MODES * k..3 * MODES * (k + 1)];
            let mut local = nalgebra::Vector3::zeros();
            for (j, p) in p.iter().enumerate() {
                local += *p * nalgebra::Vector3::new(phi[3 * j], phi[3 * j + 1], phi[3 * j + 2]);
            }
            let global = rotation * local;
            for d in 0..3 {
                v[3 * i + d] -= global[d];
            }
        }
    }

    /// The mass-weighted RMS of the quasi-static displacement of the accelerations `a` (flat
    /// `3N`, m/s², global) over the lowest modes (m). No allocation.
    pub fn quasi_static(&self, rotation: &Matrix3<f64>, a: &[f64]) -> f64 {
        let p = self.project(&self.mass_modes, rotation, a);
        let squared: f64 = (p.iter().zip(&self.omega_sq))
            .map(|(p, &w2)| p * p / (w2 * w2))
            .sum();
        (squared / self.total_mass).sqrt()
    }

    /// The errors that last over the horizon `horizon` `H` (s), of a step whose local error is
    /// the field `d` (flat `3N`, global, m) with the filtered estimate `error` (m, mass-weighted
    /// RMS): the weighted RMS of `d`'s part in the lowest modes, `√(Σ_j (w_j p_j)² / m)`, and
    /// of the rest, `w_top √(error² − Σ_j p_j² / m)` (m), with `w_j = min(1, 1/(σ_j H))`. No
    /// allocation.
    pub fn lasting_error(
        &self,
        rotation: &Matrix3<f64>,
        d: &[f64],
        error: f64,
        horizon: f64,
    ) -> (f64, f64) {
        let weight = |sigma: f64| (1.0 / (sigma * horizon)).min(1.0);
        let p = self.project(&self.mass_modes, rotation, d);
        let (mut plain, mut weighted) = (0.0, 0.0);
        for (p, &sigma) in p.iter().zip(&self.decay_rates) {
            plain += p * p;
            weighted += (weight(sigma) * p).powi(2);
        }
        let plain = (plain / self.total_mass).sqrt().min(error);
        let rest = (error * error - plain * plain).max(0.0).sqrt();
        (
            (weighted / self.total_mass).sqrt(),
            weight(self.decay_rates[MODES]) * rest,
        )
    }

    /// The elastic displacement relative to the supports (relative to the nearest rigid motion
    /// on a body without supports) from the elastic force `g = K ū` of the local deformation
    /// `ū` (flat `3N`, co-moving frame) and twice the strain energy, `energy` (J: `ūᵀ g` with one
    /// frame): the mass-weighted RMS of its part in the lowest modes and a bound of the rest's
    /// (m).
    ///
    /// `K` does not see the rigid motion by which `ū` (measured in the best-fit frame) differs
    /// from the displacement `u` relative to the supports, so `g = K u` and the modal
    /// coordinates are `q_j = φ_jᵀ M u = φ_jᵀ g / ω_j²` (on the free nodes `K_FF u_F = g_F`).
    /// The rest carries the energy `ūᵀ g − Σ_j ω_j² q_j²` in modes at or above `ω_top`, so its
    /// mass norm squared is at most that over `ω_top²`. No allocation.
    pub fn deformation(&self, energy: f64, elastic_force: &[f64]) -> (f64, f64) {
        let p = self.project(&self.modes, &Matrix3::identity(), elastic_force);
        self.deformation_from_projection(energy, &p)
    }

    /// [`Self::deformation`] from `ū` itself (flat `3N`, co-moving frame) with the stored
    /// `K φ_j` ([`Self::with_stiffness_modes`]): `φ_jᵀ K ū = Σ_i (K φ_j)_iᵀ ū_i`, the same
    /// projection without a product with `K` (with several frames `K ū` is no part of the
    /// force, and `energy` comes from the slabs). `None` without the stored `K φ_j`. No
    /// allocation.
    pub fn deformation_of(&self, energy: f64, ubar: &[f64]) -> Option<(f64, f64)> {
        let stored = self.stiffness_modes.as_ref()?;
        let mut p = [0.0; MODES];
        for (psi, u) in stored.chunks_exact(3 * MODES).zip(ubar.chunks_exact(3)) {
            for (j, p) in p.iter_mut().enumerate() {
                *p += psi[3 * j] * u[0] + psi[3 * j + 1] * u[1] + psi[3 * j + 2] * u[2];
            }
        }
        Some(self.deformation_from_projection(energy, &p))
    }

    fn deformation_from_projection(&self, energy: f64, p: &[f64; MODES]) -> (f64, f64) {
        let (mut low, mut low_energy) = (0.0, 0.0);
        for (p, &w2) in p.iter().zip(&self.omega_sq) {
            low += p * p / (w2 * w2);
            low_energy += p * p / w2;
        }
        let above = (energy - low_energy).max(0.0) / self.omega_top_sq;
        (
            (low / self.total_mass).sqrt(),
            (above / self.total_mass).sqrt(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two unit masses on springs to ground along x (k = 1 and 4 N/m): modes e₁ and e₂ (x of
    /// node 0 and of node 1), ω² = 1 and 4; body mass 2 kg; Rayleigh `(α, β)`.
    fn two_oscillators(damping: (f64, f64)) -> LowestModes {
        let identity: Vec<_> = (0..6).map(|i| (i, i, 1.0)).collect();
        let mass = SymmetricCsr::from_triplets(6, &identity);
        let mut e1 = vec![0.0; 6];
        e1[0] = 1.0;
        let mut e2 = vec![0.0; 6];
        e2[3] = 1.0;
        let pairs = EigenPairs {
            eigenvalues: vec![1.0, 4.0],
            modes: vec![e1, e2],
            iterations: 1,
        };
        LowestModes::new(&[0, 1], &mass, &pairs, 0, 2.0, damping)
    }

    #[test]
    fn a_body_without_supports_measures_its_deformation_by_the_rms_of_its_local_field() {
        let modes = two_oscillators((0.0, 0.0));
        // Supported: no such measure.
        let identity: Vec<_> = (0..6).map(|i| (i, i, 1.0)).collect();
        let identity = SymmetricCsr::from_triplets(6, &identity);
        assert!(modes.free_body_rms(&identity, &[1.0; 6]).is_none());
        // Unit masses, body mass 2 kg: √((1² + 2² + 3²) / 2) from both nodes' components.
        let free = modes.for_body_without_supports();
        let rms = free
            .free_body_rms(&identity, &[1.0, 0.0, 2.0, 0.0, 3.0, 0.0])
            .unwrap();
        assert!((rms - 7f64.sqrt()).abs() < 1e-15, "{rms}");
        // The free nodes in another order than the body's (nodes 2 and 0 of three, node 1
        // held) and a mass coupling them, [[2, 1], [1, 2]] ⊗ I3: with ū₂ = (1, 0, 3) and
        // ū₀ = (1, 0, 0), ūᵀ M ū = (2 + 2 + 2) + 2 × 9 = 24, over 2 kg.
        let coupled: Vec<_> = (0..3)
            .flat_map(|c| {
                [
                    (c, c, 2.0),
                    (c, c + 3, 1.0),
                    (c + 3, c, 1.0),
                    (c + 3, c + 3, 2.0),
                ]
            })
            .collect();
        let mass = SymmetricCsr::from_triplets(6, &coupled);
        let mut e1 = vec![0.0; 6];
        e1[0] = 1.0;
        let pairs = EigenPairs {
            eigenvalues: vec![1.0],
            modes: vec![e1],
            iterations: 1,
        };
        let reordered = LowestModes::new(&[2, 0], &mass, &pairs, 0, 2.0, (0.0, 0.0))
            .for_body_without_supports();
        let ubar = [1.0, 0.0, 0.0, 100.0, 100.0, 100.0, 1.0, 0.0, 3.0];
        let rms = reordered.free_body_rms(&mass, &ubar).unwrap();
        assert!((rms - 12f64.sqrt()).abs() < 1e-14, "{rms}");
    }

    #[test]
    fn the_quasi_static_displacement_is_the_static_response_mode_by_mode() {
        let modes = two_oscillators((0.0, 0.0));
        // a = (2, 0, 0 | 8, 0, 0): static response u = M a / k = (2, 2): RMS √((4 + 4)/2) = 2.
        let a = [2.0, 0.0, 0.0, 8.0, 0.0, 0.0];
        assert!((modes.quasi_static(&Matrix3::identity(), &a) - 2.0).abs() < 1e-15);
        // Turned by 90° about z, the same field along the global y is the same response.
        let turn = Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        let turned = [0.0, 2.0, 0.0, 0.0, 8.0, 0.0];
        assert!((modes.quasi_static(&turn, &turned) - 2.0).abs() < 1e-15);
        assert!((modes.first_period() - 2.0 * std::f64::consts::PI).abs() < 1e-15);
    }

    #[test]
    fn errors_last_as_long_as_the_damping_lets_them() {
        // β = 0.5 s: σ = β ω² / 2 = 0.25 and 1 /s against T₁ = 2π s: weights 1/(σ T₁).
        let modes = two_oscillators((0.0, 0.5));
        let period = 2.0 * std::f64::consts::PI;
        let (w1, w2) = (1.0 / (0.25 * period), 1.0 / period);
        // d = (3, 0, 0 | 4, 0, 0): p = (3, 4); the estimate has 1 more (RMS²) above the modes,
        // which gets the weight of ω_top² = 4.
        let d = [3.0, 0.0, 0.0, 4.0, 0.0, 0.0];
        let error = (12.5_f64 + 1.0).sqrt();
        let (low, high) = modes.lasting_error(&Matrix3::identity(), &d, error, period);
        let expected = (((w1 * 3.0).powi(2) + (w2 * 4.0).powi(2)) / 2.0).sqrt();
        assert!((low - expected).abs() < 1e-14, "{low} against {expected}");
        assert!((high - w2).abs() < 1e-12, "{high} against {w2}");
        // Over a horizon four times as long the damped errors weigh a quarter as much relative
        // to it (they last 1/σ_j whatever the horizon); the weight never exceeds 1.
        let (low4, high4) = modes.lasting_error(&Matrix3::identity(), &d, error, 4.0 * period);
        assert!((low4 - expected / 4.0).abs() < 1e-14 && (high4 - w2 / 4.0).abs() < 1e-12);
        let (short, _) = modes.lasting_error(&Matrix3::identity(), &d, error, 0.1);
        assert!((short - 12.5_f64.sqrt()).abs() < 1e-14);
        // Undamped, every error lasts the whole horizon.
        let (low, high) =
            two_oscillators((0.0, 0.0)).lasting_error(&Matrix3::identity(), &d, error, period);
        assert!((low - 12.5_f64.sqrt()).abs() < 1e-14 && (high - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_deformation_comes_from_the_elastic_force_and_the_rest_is_bounded() {
        let modes = two_oscillators((0.0, 0.0));
        // u = (0.5, 0.3, 0 | 0.25, 0, 0) with a stiffness 8 N/m along y at node 0 (a mode above
        // the kept ones): g = K u = (0.5, 2.4, 0 | 1, 0, 0).
        let u = [0.5, 0.3, 0.0, 0.25, 0.0, 0.0];
        let g = [0.5, 2.4, 0.0, 1.0, 0.0, 0.0];
        let (low, above) = modes.deformation(crate::linalg::dot(&u, &g), &g);
        // In the modes: q = (0.5, 0.25), RMS √(0.3125 / 2).
        assert!((low - (0.3125_f64 / 2.0).sqrt()).abs() < 1e-15);
        // Above: the energy 0.72 J over ω_top² = 4 bounds the true 0.3² = 0.09 by 0.18.
        assert!((above - (0.18_f64 / 2.0).sqrt()).abs() < 1e-15);
        assert!(above >= (0.09_f64 / 2.0).sqrt());
    }

    #[test]
    fn the_stored_stiffness_modes_project_k_u_without_the_product() {
        // The two oscillators with a third node, held, to which node 1 is tied by its 4 N/m
        // spring along x (K_FF as before), and 8 N/m along y at node 0 (a mode above the kept
        // ones): `(K φ_j)ᵀ ū` must equal `φ_jᵀ (K ū)` with the held node's part of `K ū`.
        let k = |x: &[f64], y: &mut [f64]| {
            y.fill(0.0);
            y[0] = x[0];
            y[1] = 8.0 * x[1];
            y[3] = 4.0 * (x[3] - x[6]);
            y[6] = 4.0 * (x[6] - x[3]);
        };
        let modes = two_oscillators((0.0, 0.0)).with_stiffness_modes(k, 9);
        let u = [0.5, 0.3, 0.0, 0.25, 0.0, 0.0, -0.1, 0.0, 0.0];
        let mut g = [0.0; 9];
        k(&u, &mut g);
        let energy = crate::linalg::dot(&u, &g);
        let from_product = modes.deformation(energy, &g);
        let from_modes = modes.deformation_of(energy, &u).unwrap();
        // Node 1's modal coordinate is g_x1 / 4 = u_x1 − u_x2 = 0.35, not u_x1: the held
        // node counts.
        assert!((from_product.0 - ((0.25_f64 + 0.1225) / 2.0).sqrt()).abs() < 1e-15);
        assert!((from_modes.0 - from_product.0).abs() < 1e-15);
        assert!((from_modes.1 - from_product.1).abs() < 1e-15);
        assert!(two_oscillators((0.0, 0.0))
            .deformation_of(energy, &u)
            .is_none());
    }
}
