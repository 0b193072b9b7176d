//! The ACF-RS body (docs/formulation.md): constant mass `M = Ms ⊗ I3`, constant small-strain
//! stiffness `K`, the co-moving frame, the local deformation `ū`, the internal force with the
//! nonlinear term `f_nl`, Rayleigh damping of the deformation, and the node sets of interfaces.

pub mod driving_frame;
pub mod feature_indicators;
pub mod frame;
pub mod interface;
pub mod lowest_modes;
pub mod lumped_body;
pub mod patches;
pub mod polar;
pub mod reduction;
pub mod slab_stiffening;
pub mod stiffening;
pub mod strain_monitor;

pub use frame::{Frame, FrameWeights};
pub use interface::NodeSet;
pub use lumped_body::LumpedBody;
pub use patches::Patches;
pub use reduction::{InterfaceSets, MeshData, ModeChoice, ModeCount, Reduction, SecondOrderForce};

use crate::fem::nonlinear::SvkSolid;
use crate::linalg::dense::DenseSymmetric;
use crate::linalg::sparse::BlockCsr3;
use crate::linalg::{dot, SymmetricCsr};
use frame::{add_node, node, set_node};
use nalgebra::{Matrix3, Vector3};

/// Switches and coefficients of the internal force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyOptions {
    /// Include `f_nl` (exact gradient of the strain energy; momentum-conserving). Default off:
    /// docs/fmu.md, "Which terms a scene needs", says when a scene needs it.
    pub nonlinear_forces: bool,
    /// Mass-proportional Rayleigh coefficient `α` (1/s).
    pub damping_alpha: f64,
    /// Stiffness-proportional Rayleigh coefficient `β` (s).
    pub damping_beta: f64,
}

impl Default for BodyOptions {
    fn default() -> Self {
        BodyOptions {
            nonlinear_forces: false,
            damping_alpha: 0.0,
            damping_beta: 0.0,
        }
    }
}

/// The constant data of one elastic body.
#[derive(Debug, Clone)]
pub struct Body {
    /// Reference positions `X`, flat `3N` (m).
    pub reference: Vec<f64>,
    /// Consistent scalar mass matrix `Ms` (kg), `N × N`; `M = Ms ⊗ I3`.
    pub mass_matrix: SymmetricCsr,
    /// Small-strain stiffness `K` (N/m), `3N × 3N`.
    pub stiffness_matrix: SymmetricCsr,
    /// The same `K` for the products of the hot path: by 3×3 blocks, or dense for a reduced
    /// body.
    stiffness_product: MatrixProduct,
    /// A reduced body's `Ms` (dense) for [`Body::mass_times`]; `None`: the compressed
    /// `mass_matrix`.
    dense_mass: Option<DenseSymmetric>,
    /// Row sums of `Ms` (kg): `M (1 ⊗ a) = (row sums) ⊗ a`, the exact nodal loads of a uniform
    /// acceleration field and the weights of the centre of mass.
    pub mass_row_sums: Vec<f64>,
    /// Total mass `ρV` (kg).
    pub total_mass: f64,
    /// The co-moving frame over all nodes with HRZ-lumped masses as weights.
    pub frame_weights: FrameWeights,
    pub options: BodyOptions,
    /// The full nonlinear reference formulation (`model.formulation = full`): when present, the
    /// elastic force is the total-Lagrangian St. Venant–Kirchhoff force of `x` instead of
    /// `R K ū` (+ `f_nl`); damping stays the co-rotated one.
    pub full: Option<SvkSolid>,
    /// Several co-moving frames (`model.frames > 1`, [`patches`]): when present, the elastic
    /// force is `Σ_p R_p K_p ū_p` (+ each patch's `f_nl`) instead of the body frame's `R K ū`;
    /// damping and stiffening stay in the body frame.
    pub patches: Option<Patches>,
    /// The reduced body (`model.modes`, [`reduction`]): when present the "nodes" are the
    /// coordinates `q_k` of the basis fields, the matrices are the projected ones and this holds
    /// the basis to expand `q` to the mesh nodes.
    pub reduction: Option<Box<Reduction>>,
    /// Whether `options.nonlinear_forces` may be switched on between steps (`model.auto` with
    /// `model.nonlinearForces` allowed): the iteration matrices then carry the Woodbury
    /// correction of `f_nl` (computed once per step size) even while the term is off, so that
    /// switching it on needs no new factorization.
    pub nonlinear_forces_switchable: bool,
    /// The last `lumped_points` nodes are the mass points of lumped bodies (no stiffness, no
    /// weight in the co-moving frame; docs/formulation.md, "Rigid attachments").
    pub lumped_points: usize,
    /// With rigid sets: `K` with the elements wholly inside them, for the modal analyses (the
    /// lowest period, `model.auto`'s modes), which do not see the sets' constraints;
    /// `stiffness_matrix` leaves those elements out (docs/formulation.md, "Rigid attachments").
    pub modal_stiffness: Option<SymmetricCsr>,
    /// The geometrically linear body (docs/formulation.md, "The linear body"): when present the
    /// co-moving frame is held at this placement instead of fitted to the positions, so the
    /// internal force `R₀ K (R₀ᵀ(x − c₀) − X̄)` is linear in `x` and a step is one linear solve.
    pub linear: Option<LinearPlacement>,
}

/// The placement a linear body's frame is held at: the frame `(c₀, R₀)` of its supports, and
/// the positions of the undeformed body there, `x₀_i = e_i c₀ + R₀ X̄_i` (on which the loads of
/// a linear body act: they do not follow the deformation either).
#[derive(Debug, Clone, PartialEq)]
pub struct LinearPlacement {
    pub frame: Frame,
    /// `x₀` (flat `3N`, m).
    pub positions: Vec<f64>,
}

/// How a constant `3N × 3N` matrix is stored for the products of the hot path.
#[derive(Debug, Clone)]
enum MatrixProduct {
    /// By 3×3 blocks (a mesh: sparse).
    Blocks(BlockCsr3),
    /// Dense (a reduced body: every entry is non-zero).
    Dense(DenseSymmetric),
}

impl MatrixProduct {
    /// `y = A x`, no allocation.
    fn mul_vec(&self, x: &[f64], y: &mut [f64]) {
        match self {
            MatrixProduct::Blocks(a) => a.mul_vec(x, y),
            MatrixProduct::Dense(a) => a.mul_vec(x, y),
        }
    }
}

/// Whether [`Body::internal_force_of`] forms the elastic term `hR K ū`, or leaves it out for the
/// generalized-α iteration to fold into its solve (docs/formulation.md, "The stiffness folded
/// into the solve"; one frame, no `f_nl`): then `ū` is computed, `K ū` is not, and the strain
/// energy is NaN.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ElasticTerm {
    Included,
    LeftOut,
}

/// What [`Body::internal_force`] finds on the way: the frame and the strain energy. (The
/// frame's angular velocity is computed where a force needs it, the damping's rate of the local
/// deformation; [`FrameWeights::angular_velocity_at`] gives it to the outputs.)
#[derive(Debug, Clone, Copy)]
pub struct BodyKinematics {
    pub frame: Frame,
    /// `V = ½ ūᵀ K ū` (J); not computed (NaN) for the full formulation, see
    /// [`Body::strain_energy`].
    pub strain_energy: f64,
}

/// Scratch vectors of [`Body::internal_force`] (allocate once with [`Body::force_scratch`]).
#[derive(Debug, Clone)]
pub struct ForceScratch {
    local_deformation: Vec<f64>,
    elastic_force: Vec<f64>,
    deformation_rate: Vec<f64>,
    damping_force: Vec<f64>,
    mass_times: Vec<f64>,
    stiffening_force: Vec<f64>,
    /// The strain energy of the last [`Body::internal_force`] call (J; NaN for the full
    /// formulation and without the elastic term).
    strain_energy: f64,
    /// Whether the last call left the elastic term out ([`ElasticTerm::LeftOut`]):
    /// `elastic_force` then holds no `K ū`.
    elastic_left_out: bool,
    patch: Option<patches::PatchScratch>,
}

impl ForceScratch {
    /// The local deformation `ū` of the last [`Body::internal_force`] call (flat 3N, m).
    pub fn local_deformation(&self) -> &[f64] {
        &self.local_deformation
    }

    /// `g = K ū` of the last [`Body::internal_force`] call (reduced strain; N). Not after
    /// [`ElasticTerm::LeftOut`] until [`Body::complete_elastic_force`].
    pub fn elastic_force(&self) -> &[f64] {
        debug_assert!(!self.elastic_left_out, "the elastic term was left out");
        &self.elastic_force
    }

    /// The strain energy `V` of the last [`Body::internal_force`] call (J): `½ ūᵀ K ū` with
    /// one frame, `Σ_p ½ ū_pᵀ K_p ū_p` with patches, NaN for the full formulation.
    pub fn strain_energy(&self) -> f64 {
        self.strain_energy
    }

    /// The rotation `R_p` of patch `p` in the last [`Body::internal_force`] call (a body with
    /// patches only).
    pub fn patch_rotation(&self, p: usize) -> Matrix3<f64> {
        self.patch.as_ref().expect("a body with patches").rotations[p]
    }
}

impl Body {
    /// A body from its constant matrices; `lumped_masses` (positive) weight the co-moving frame.
    pub fn new(
        reference: Vec<f64>,
        mass_matrix: SymmetricCsr,
        stiffness_matrix: SymmetricCsr,
        lumped_masses: Vec<f64>,
        options: BodyOptions,
    ) -> Body {
        let n = reference.len() / 3;
        assert_eq!(mass_matrix.n, n);
        assert_eq!(stiffness_matrix.n, 3 * n);
        let ones = vec![1.0; n];
        let mut mass_row_sums = vec![0.0; n];
        mass_matrix.mul_vec(&ones, &mut mass_row_sums);
        let total_mass = mass_row_sums.iter().sum();
        let frame_weights = FrameWeights::new((0..n).collect(), lumped_masses, &reference);
        Body {
            reference,
            mass_matrix,
            stiffness_product: MatrixProduct::Blocks(BlockCsr3::from_csr(&stiffness_matrix)),
            dense_mass: None,
            stiffness_matrix,
            mass_row_sums,
            total_mass,
            frame_weights,
            options,
            full: None,
            patches: None,
            reduction: None,
            nonlinear_forces_switchable: false,
            lumped_points: 0,
            modal_stiffness: None,
            linear: None,
        }
    }

    /// The reduced body of `reduction` ([`reduction`]): coordinates `q_k`, mass `Sᵀ Ms S`,
    /// stiffness `K_r`, the frame of the expanded nodes; `M (e ⊗ a)` for uniform loads.
    pub fn reduced(reduction: Reduction, options: BodyOptions) -> Body {
        let s = reduction.field_count;
        let mut mass_row_sums = vec![0.0; s];
        reduction
            .mass_matrix
            .mul_vec(&reduction.unit, &mut mass_row_sums);
        let total_mass = dot(&mass_row_sums, &reduction.unit);
        Body {
            reference: reduction.reference.clone(),
            mass_matrix: reduction.mass_matrix.clone(),
            stiffness_product: MatrixProduct::Dense(DenseSymmetric::from_csr(
                &reduction.stiffness_matrix,
            )),
            dense_mass: Some(DenseSymmetric::from_csr(&reduction.mass_matrix)),
            stiffness_matrix: reduction.stiffness_matrix.clone(),
            mass_row_sums,
            total_mass,
            frame_weights: reduction.frame_weights.clone(),
            options,
            full: None,
            patches: None,
            reduction: Some(Box::new(reduction)),
            nonlinear_forces_switchable: false,
            lumped_points: 0,
            modal_stiffness: None,
            linear: None,
        }
    }

    /// `e_i`: 1 for a node, the constant field's coefficient for a reduced coordinate.
    #[inline]
    pub fn unit(&self, i: usize) -> f64 {
        self.frame_weights.unit(i)
    }

    /// The rigid placement `x_i = p + Q (X_i − a)`, `ẋ_i = v + ω × Q (X_i − a)` (origin `p`,
    /// rotation `Q`, anchor `a` in reference coordinates, velocity `v`, angular velocity `ω`)
    /// written to `x` and `v` (flat `3N`; for a reduced body its coordinates).
    #[allow(clippy::too_many_arguments)] // a rigid motion is these five quantities
    pub fn place_rigidly(
        &self,
        origin: &Vector3<f64>,
        rotation: &Matrix3<f64>,
        anchor: &Vector3<f64>,
        velocity: &Vector3<f64>,
        angular_velocity: &Vector3<f64>,
        x: &mut [f64],
        v: &mut [f64],
    ) {
        for i in 0..self.node_count() {
            let e = self.unit(i);
            let r = rotation * (node(&self.reference, i) - e * anchor);
            set_node(x, i, &(e * origin + r));
            set_node(v, i, &(e * velocity + angular_velocity.cross(&r)));
        }
    }

    /// The same body with several co-moving frames (see [`patches`]).
    pub fn with_patches(mut self, mut patches: Patches) -> Body {
        if let Some(reduction) = &self.reduction {
            patches.reduce(reduction);
        }
        self.patches = Some(patches);
        self
    }

    /// Whether the elastic force is the body frame's `R K ū` (+ `f_nl`): neither the full
    /// formulation nor patches.
    pub fn single_frame(&self) -> bool {
        self.full.is_none() && self.patches.is_none()
    }

    /// Completes the force scratch of a call that left the elastic term out
    /// ([`ElasticTerm::LeftOut`]): `g = K ū` and the strain energy of its `ū`,
    /// as [`Body::internal_force`] leaves them. Nothing to do otherwise. No allocation.
    pub fn complete_elastic_force(&self, scratch: &mut ForceScratch) {
        if scratch.elastic_left_out {
            self.stiffness_product
                .mul_vec(&scratch.local_deformation, &mut scratch.elastic_force);
            scratch.strain_energy = 0.5 * dot(&scratch.local_deformation, &scratch.elastic_force);
            scratch.elastic_left_out = false;
        }
    }

    /// `K ū` (N, co-moving frame) of the local deformation of the last
    /// [`Body::internal_force`] call: the force scratch's own with one frame (completed,
    /// [`Body::complete_elastic_force`]), else computed into `y` (flat `3N`). No allocation.
    pub fn local_elastic_force<'a>(
        &self,
        scratch: &'a ForceScratch,
        y: &'a mut [f64],
    ) -> &'a [f64] {
        if self.single_frame() {
            scratch.elastic_force()
        } else {
            self.stiffness_product(scratch.local_deformation(), y);
            y
        }
    }

    /// The same body with the full nonlinear formulation of `material` (its `λ`, `μ`).
    pub fn with_full_formulation(mut self, full: SvkSolid) -> Body {
        self.full = Some(full);
        self
    }

    /// The co-moving frame `(c, R)` of positions `x` and the local deformation
    /// `ū_i = Rᵀ(x_i − c) − X̄_i` into `ubar` (flat `3N`, m; docs/formulation.md, "The local
    /// deformation"). No allocation.
    pub fn local_deformation(&self, x: &[f64], ubar: &mut [f64]) -> Frame {
        let fw = &self.frame_weights;
        let frame = match &self.linear {
            Some(placement) => placement.frame,
            None => fw.best_fit(x),
        };
        let rt = frame.rotation.transpose();
        for i in 0..self.node_count() {
            let u = rt * (node(x, i) - fw.unit(i) * frame.origin) - fw.reference_offsets[i];
            set_node(ubar, i, &u);
        }
        frame
    }

    /// The placement of the undeformed body whose best-fit frame is that of positions `x` (a
    /// body placed rigidly: its placement), for [`Body::linear`].
    pub fn linear_placement(&self, x: &[f64]) -> LinearPlacement {
        let fw = &self.frame_weights;
        let frame = fw.best_fit(x);
        let mut positions = vec![0.0; x.len()];
        for i in 0..self.node_count() {
            let p = fw.unit(i) * frame.origin + frame.rotation * fw.reference_offsets[i];
            set_node(&mut positions, i, &p);
        }
        LinearPlacement { frame, positions }
    }

    /// Whether the internal force is linear in the positions and velocities with the iteration
    /// matrix's `K`, `M` and damping as its exact Jacobian (a linear body with one frame,
    /// reduced strain, no `f_nl` and no geometric stiffness `K_G`, which the matrix leaves
    /// out): then the first correction of a step solves it.
    pub fn steps_linearly(&self, geometric_stiffness: bool) -> bool {
        self.linear.is_some()
            && !self.options.nonlinear_forces
            && self.patches.is_none()
            && self.full.is_none()
            && !geometric_stiffness
    }

    /// Number of nodes `N`.
    pub fn node_count(&self) -> usize {
        self.reference.len() / 3
    }

    /// Scratch for [`Self::internal_force`].
    pub fn force_scratch(&self) -> ForceScratch {
        let n3 = self.reference.len();
        ForceScratch {
            local_deformation: vec![0.0; n3],
            elastic_force: vec![0.0; n3],
            deformation_rate: vec![0.0; n3],
            damping_force: vec![0.0; n3],
            mass_times: vec![0.0; n3],
            stiffening_force: vec![0.0; n3],
            strain_energy: 0.0,
            elastic_left_out: false,
            patch: self.patches.as_ref().map(Patches::scratch),
        }
    }

    /// `y = M v = (Ms ⊗ I3) v` for a flat `3N` vector (no allocation: `Ms` acts on the three
    /// directions of each node at once).
    pub fn mass_times(&self, v: &[f64], y: &mut [f64]) {
        if let Some(dense) = &self.dense_mass {
            return dense.mul_nodes(v, y);
        }
        self.mass_matrix.mul_nodes(v, y);
    }

    /// The internal force `f = f_int + f_d` at positions `x` and velocities `v` (flat `3N`, N):
    ///
    /// * local deformation `ū_i = Rᵀ(x_i − c) − X̄_i` (docs/formulation.md, "The local deformation");
    /// * `g = K ū`, elastic force `R g_i` (= `hR K hRᵀ (x − x_r)`, seed paper eq. 9);
    /// * if `nonlinear_forces`: `f_nl,i = −w_i R (X̄_i × z)`, `z = H⁻ᵀ m̄`, `m̄ = Σ ū_i × g_i`,
    ///   `H = Σ w_i [X̄_i]× [X̄_i + ū_i]×`: with it `f_int` is the exact gradient of
    ///   `V = ½ ūᵀ K ū`;
    /// * damping `f_d = hR β K dū/dt + α M (ẋ − v_r)`, `dū_i/dt = Rᵀ(ẋ_i − ċ) − ω̄ × (X̄_i + ū_i)`,
    ///   `v_r` the rigid part of `ẋ` (see [`Body::rigid_velocity`]): zero for any rigid motion.
    ///
    /// `geometric_stiffness`, when given, adds the stiffening force `f_stiff = hR K_G ū`
    /// (docs/formulation.md, "Geometric stiffening") with `K_G` of the current prestress.
    pub fn internal_force(
        &self,
        x: &[f64],
        v: &[f64],
        geometric_stiffness: Option<&SymmetricCsr>,
        scratch: &mut ForceScratch,
        f: &mut [f64],
    ) -> BodyKinematics {
        self.internal_force_of(ElasticTerm::Included, x, v, geometric_stiffness, scratch, f)
    }

    /// [`Body::internal_force`] with its elastic term `hR K ū` included or left out
    /// ([`ElasticTerm`]).
    pub fn internal_force_of(
        &self,
        elastic: ElasticTerm,
        x: &[f64],
        v: &[f64],
        geometric_stiffness: Option<&SymmetricCsr>,
        scratch: &mut ForceScratch,
        f: &mut [f64],
    ) -> BodyKinematics {
        let elastic = elastic == ElasticTerm::Included;
        assert!(
            elastic
                || (self.single_frame() && self.full.is_none() && !self.options.nonlinear_forces),
            "only the one frame's linear elastic term can be left out"
        );
        let fw = &self.frame_weights;
        let frame = self.local_deformation(x, &mut scratch.local_deformation);
        let r = frame.rotation;
        let rt = r.transpose();
        let n = self.node_count();
        let ubar = &mut scratch.local_deformation;
        let g = &mut scratch.elastic_force;
        let strain_energy = if let Some(full) = &self.full {
            full.internal_force(x, g); // global frame
            f64::NAN
        } else if let Some(patches) = &self.patches {
            g.fill(0.0); // global frame
            let patch_scratch = scratch.patch.as_mut().expect("patch scratch");
            // A reduced body's slabs act on its coordinates (docs/formulation.md, "The reduced
            // body": several frames; `Patches::reduce`).
            patches.internal_force(x, self.options.nonlinear_forces, patch_scratch, g)
        } else if elastic {
            self.stiffness_product.mul_vec(ubar, g);
            0.5 * dot(ubar, g)
        } else {
            g.fill(0.0);
            f64::NAN
        };
        if let Some(kg) = geometric_stiffness {
            stiffening::geometric_stiffness_product(kg, ubar, &mut scratch.stiffening_force);
        }

        // A linear body's frame does not move: `ω̄ = 0`, `ċ = 0` and no `f_nl`. `H⁻¹` and `ω̄`
        // only where a term reads them: the damping's rate `dū/dt` and the moment of `f_nl`
        // (an undamped body without `f_nl` takes neither, two passes over the nodes and a
        // 3×3 inverse per residual: 8 % of the reduced B1 body's step).
        let linear = self.linear.is_some();
        let single = self.single_frame();
        let nonlinear_forces = self.options.nonlinear_forces && single && !linear;
        let damped = self.options.damping_alpha != 0.0 || self.options.damping_beta != 0.0;
        let h_inv = if linear || !(damped || nonlinear_forces) {
            Matrix3::zeros()
        } else {
            let h = fw.rotation_sensitivity(&frame, x);
            h.try_inverse().unwrap_or_else(Matrix3::zeros)
        };
        let angular_velocity_body = if linear || !damped {
            Vector3::zeros()
        } else {
            fw.angular_velocity(&frame, &h_inv, v)
        };

        // g ← g + β K dū/dt + α Ms dū/dt, all in the co-moving frame.
        if damped {
            let cdot = if linear {
                Vector3::zeros()
            } else {
                fw.centroid(v)
            };
            let rate = &mut scratch.deformation_rate;
            for i in 0..n {
                let y = fw.reference_offsets[i] + node(ubar, i);
                let d = rt * (node(v, i) - fw.unit(i) * cdot) - angular_velocity_body.cross(&y);
                set_node(rate, i, &d);
            }
            let (alpha, beta) = (self.options.damping_alpha, self.options.damping_beta);
            let fd = &mut scratch.damping_force;
            if beta != 0.0 {
                self.stiffness_product.mul_vec(rate, fd);
                fd.iter_mut().for_each(|v| *v *= beta);
            } else {
                fd.fill(0.0);
            }
            if alpha != 0.0 {
                // α M (ẋ − v_r) with v_r the M-orthogonal projection of ẋ on the rigid motions
                // (consistent-mass centre and inertia): no net force or moment, so rigid motion
                // is not damped, and ẋᵀ f = α (ẋ − v_r)ᵀ M (ẋ − v_r) ≥ 0 always dissipates.
                // (Weighting the relative velocity by the frame's HRZ weights instead leaves a
                // net force that can feed a slow oscillation of a driven body.)
                // (A linear body is held: it has no rigid motion to leave out, and its damping
                // stays linear in `ẋ`.)
                let relative = &mut scratch.deformation_rate;
                if linear {
                    relative.copy_from_slice(v);
                } else {
                    let (centre, velocity, omega) =
                        self.rigid_velocity(x, v, &mut scratch.mass_times);
                    for i in 0..n {
                        let e = fw.unit(i);
                        let vr = e * velocity + omega.cross(&(node(x, i) - e * centre));
                        set_node(relative, i, &(node(v, i) - vr));
                    }
                }
                let mt = &mut scratch.mass_times;
                self.mass_times(relative, mt);
                for i in 0..n {
                    let local = rt * (alpha * node(mt, i));
                    for d in 0..3 {
                        fd[3 * i + d] += local[d];
                    }
                }
            }
        }

        // f_nl: z = H⁻ᵀ m̄, m̄ = Σ ū_i × g_i (elastic g only: f_nl is part of ∂V/∂x).
        let z = if nonlinear_forces {
            let mut mbar = Vector3::zeros();
            for i in 0..n {
                mbar += node(ubar, i).cross(&node(g, i));
            }
            h_inv.transpose() * mbar
        } else {
            Vector3::zeros()
        };

        for i in 0..n {
            // Terms in the co-moving frame, rotated to global at the end.
            let mut fi = Vector3::zeros();
            if single {
                fi += node(g, i);
            }
            if damped {
                fi += node(&scratch.damping_force, i);
            }
            if geometric_stiffness.is_some() {
                fi += node(&scratch.stiffening_force, i);
            }
            if nonlinear_forces {
                fi -= fw.arms[i].cross(&z);
            }
            let mut global = r * fi;
            if !single {
                global += node(g, i);
            }
            set_node(f, i, &global);
        }
        scratch.strain_energy = strain_energy;
        scratch.elastic_left_out = !elastic;
        BodyKinematics {
            frame,
            strain_energy,
        }
    }

    /// Nodal loads of a uniform acceleration field `a` (m/s², e.g. gravity), added to `f`:
    /// `M (1 ⊗ a)` = row sums of `Ms` times `a` (N).
    pub fn add_uniform_acceleration_load(&self, a: &Vector3<f64>, f: &mut [f64]) {
        for (i, &m) in self.mass_row_sums.iter().enumerate() {
            add_node(f, i, &(m * a));
        }
    }

    /// The rigid motion closest to the velocities `v` in the kinetic-energy norm: centre of mass
    /// `x_c`, its velocity `V` and `ω = I⁻¹ L` (consistent mass, current configuration), so that
    /// `v − (V + ω × (x − x_c))` carries no momentum and no angular momentum. `mv` is scratch
    /// (3N). No allocation.
    pub fn rigid_velocity(
        &self,
        x: &[f64],
        v: &[f64],
        mv: &mut [f64],
    ) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let m = self.total_mass;
        let (mut centre, mut velocity) = (Vector3::zeros(), Vector3::zeros());
        for (i, &w) in self.mass_row_sums.iter().enumerate() {
            centre += w * node(x, i);
            velocity += w * node(v, i);
        }
        centre /= m;
        velocity /= m;
        self.mass_times(v, mv);
        let ms = &self.mass_matrix;
        let (mut momentum, mut inertia) = (Vector3::zeros(), Matrix3::zeros());
        for i in 0..ms.n {
            let ri = node(x, i) - self.unit(i) * centre;
            momentum += ri.cross(&node(mv, i));
            for k in ms.row_ptr[i]..ms.row_ptr[i + 1] {
                let j = ms.col_idx[k];
                let rj = node(x, j) - self.unit(j) * centre;
                inertia += ms.values[k] * (Matrix3::identity() * ri.dot(&rj) - ri * rj.transpose());
            }
        }
        let inertia = 0.5 * (inertia + inertia.transpose());
        let omega = inertia.try_inverse().unwrap_or_else(Matrix3::zeros) * momentum;
        (centre, velocity, omega)
    }

    /// `y = K x` (3×3-block product, no allocation).
    pub fn stiffness_product(&self, x: &[f64], y: &mut [f64]) {
        self.stiffness_product.mul_vec(x, y);
    }

    /// `y = K_·H x_H` (flat `3N`): `K`'s columns of the nodes `held` (ascending) times their
    /// entries of `x` (docs/formulation.md, "The stiffness folded into the solve": `K_FH ū_H`).
    /// A reduced body's held coordinates are its first fields, a contiguous block of its dense
    /// `K`: one SIMD product; otherwise `K`'s held rows (it is symmetric). No allocation.
    pub fn held_stiffness_product(&self, held: &[usize], x: &[f64], y: &mut [f64]) {
        if let (MatrixProduct::Dense(k), Some(&first)) = (&self.stiffness_product, held.first()) {
            if held.iter().enumerate().all(|(n, &i)| i == first + n) {
                let columns = 3 * first..3 * (first + held.len());
                return k.mul_columns(columns.clone(), &x[columns], y);
            }
        }
        y.fill(0.0);
        for &i in held {
            for (j, &u) in x.iter().enumerate().skip(3 * i).take(3) {
                let (columns, values) = self.stiffness_matrix.row(j);
                for (&c, &k) in columns.iter().zip(values) {
                    y[c] += k * u;
                }
            }
        }
    }

    /// Strain energy of positions `x` (J): `V = ½ ūᵀ K ū`, or the St. Venant–Kirchhoff energy
    /// of the full formulation; allocates (not for the hot path).
    pub fn strain_energy(&self, x: &[f64]) -> f64 {
        if let Some(full) = &self.full {
            return full.strain_energy(x);
        }
        let mut scratch = self.force_scratch();
        let mut f = vec![0.0; x.len()];
        let zero = vec![0.0; x.len()];
        self.internal_force(x, &zero, None, &mut scratch, &mut f)
            .strain_energy
    }
}
