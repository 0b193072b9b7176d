//! The parameters of the body (`Parameters`, set from the body file and by the importer) and
//! their mapping to the fixed variables of the variable table.

use crate::body::ModeCount;
use crate::error::{Error, Result};
use crate::fem::IsotropicMaterial;
use crate::model::body_file::{ModelSpec, MODES_AUTO};
use crate::model::enumerations::{Formulation, Integrator, Stiffening};
use crate::model::variables::{range_violation, FixedKey, FIXED_VARIABLES};
use crate::model::{BodyFile, Target};
use crate::solver::anderson::MAX_DEPTH;

/// The iteration's tolerance per unit of `model.accuracy` ([`Parameters::iteration_tolerance`]):
/// 1e-10 at `ε` 1e-2 and 1e-3 (the default `solver.tolerance`, nothing changes there), 1e-11 at
/// 1e-4, where the floor `ITERATION_NOISE × tolerance × size` of 1e-10 stopped B1's refinement at
/// 1.5e-4 of the peak. `1e-8` trapped B3 stepped in half steps on 78 µs at `ε ≤ 5e-3`
/// (docs/formulation.md, "Time error control": the iteration's tolerance).
pub const TOLERANCE_PER_ACCURACY: f64 = 1e-7;

/// The smallest iteration tolerance the accuracy sets: a few hundred ulps of the positions, above
/// the round-off of a residual in absolute coordinates.
pub const TOLERANCE_FLOOR: f64 = 1e-13;

/// The parameters of the body (docs/fmu.md, "Parameters"; SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct Parameters {
    pub material: IsotropicMaterial,
    pub damping_alpha: f64,
    pub damping_beta: f64,
    pub gravity: [f64; 3],
    pub initial_position: [f64; 3],
    /// Row-major.
    pub initial_rotation: [f64; 9],
    pub initial_velocity: [f64; 3],
    pub initial_angular_velocity: [f64; 3],
    pub step_size: f64,
    pub rho_inf: f64,
    pub tolerance: f64,
    /// `model.accuracy`: the accepted error relative to the deformation scale (0: no time error
    /// control, see `slave::step_control`).
    pub accuracy: f64,
    pub max_iterations: i32,
    pub nonlinear_forces: bool,
    /// `model.linear`: the linear body forced (docs/formulation.md, "The linear body").
    pub linear: bool,
    /// `model.auto`: with it `nonlinear_forces` and `stiffening` are what is allowed and the
    /// slave switches each on per step when its indicator says it matters (see [`Features`]).
    pub auto: bool,
    /// `model.formulation`.
    pub formulation: Formulation,
    /// `model.stiffening`.
    pub stiffening: Stiffening,
    /// `model.frames`: co-moving frames of the reduced-strain body (≥ 1).
    pub frames: i32,
    /// `model.modes`: 0 the full mesh, `n > 0` the reduced body with `n` fixed-interface modes,
    /// `MODES_AUTO` (-1) the reduced body with the modes its accuracy needs.
    pub modes: i32,
    /// `solver.andersonDepth`: history of Anderson's acceleration (0 to 8).
    pub anderson_depth: i32,
    /// `solver.integrator`.
    pub integrator: Integrator,
    /// `output.directory`: where VTK results go; empty: none (see [`crate::output`]).
    pub output_directory: String,
    /// `output.interval` (s): smallest time between saved results; 0: every communication point.
    pub output_interval: f64,
}

impl Parameters {
    /// The reduced body's mode count (`None`: the full mesh). `auto` meets `model.accuracy`,
    /// or its default when that is 0 (docs/formulation.md, "How many modes").
    pub(super) fn mode_count(&self) -> Option<ModeCount> {
        match self.modes {
            0 => None,
            MODES_AUTO => Some(ModeCount::Accuracy(if self.accuracy > 0.0 {
                self.accuracy
            } else {
                ModelSpec::default_accuracy()
            })),
            n => Some(ModeCount::Fixed(n as usize)),
        }
    }

    /// The iteration's relative tolerance (× size): `solver.tolerance`, or with the time error
    /// control on the smaller [`TOLERANCE_PER_ACCURACY`] × `model.accuracy`, not below
    /// [`TOLERANCE_FLOOR`] (docs/formulation.md, "Time error control": the iteration's
    /// tolerance). At the default accuracy 1e-2 both are 1e-10. The internal steps may follow
    /// their allowance below it (`Slave::following_tolerance`).
    pub(super) fn iteration_tolerance(&self) -> f64 {
        if self.accuracy > 0.0 && self.integrator == Integrator::GeneralizedAlpha {
            self.tolerance
                .min((TOLERANCE_PER_ACCURACY * self.accuracy).max(TOLERANCE_FLOOR))
        } else {
            self.tolerance
        }
    }

    /// Whether `model.auto` decides the linear body (it is not forced by `model.linear`).
    pub(super) fn decides_linear(&self) -> bool {
        self.auto && !self.linear
    }

    pub(super) fn from_body_file(b: &BodyFile) -> Parameters {
        Parameters {
            material: IsotropicMaterial {
                youngs_modulus: b.material.youngs_modulus,
                poisson_ratio: b.material.poisson_ratio,
                density: b.material.density,
            },
            damping_alpha: b.damping.alpha,
            damping_beta: b.damping.beta,
            gravity: b.gravity,
            initial_position: [0.0; 3],
            initial_rotation: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            initial_velocity: [0.0; 3],
            initial_angular_velocity: [0.0; 3],
            step_size: b.solver.step_size,
            rho_inf: b.solver.rho_inf,
            tolerance: b.solver.tolerance,
            accuracy: b.model.accuracy,
            max_iterations: b.solver.max_iterations.min(i32::MAX as u32) as i32,
            nonlinear_forces: b.model.nonlinear_forces,
            linear: b.model.linear,
            auto: b.model.auto,
            formulation: Formulation::default(),
            stiffening: Stiffening::default(),
            frames: b.model.frames.clamp(1, i32::MAX as u32) as i32,
            modes: b.model.modes.parameter(),
            anderson_depth: b.solver.anderson_depth.min(MAX_DEPTH as u32) as i32,
            integrator: b.solver.integrator,
            output_directory: String::new(),
            output_interval: 0.0,
        }
    }

    /// The parameters that the assembled model depends on (everything but gravity, the initial
    /// placement, the step size, the iteration settings and the value of a positive
    /// `model.accuracy`).
    pub(super) fn assembly_key(&self) -> AssemblyKey {
        AssemblyKey {
            material: self.material,
            damping: [self.damping_alpha.to_bits(), self.damping_beta.to_bits()],
            rho_inf: self.rho_inf.to_bits(),
            nonlinear_forces: self.nonlinear_forces,
            linear: self.linear,
            auto: self.auto,
            controlled: self.accuracy > 0.0,
            formulation: self.formulation,
            stiffening: self.stiffening,
            frames: self.frames,
            anderson_depth: self.anderson_depth,
            integrator: self.integrator,
            modes: self.modes,
        }
    }

    /// Checks one Real parameter value; the error names the variable, the value and the reason.
    pub(super) fn check_real(name: &str, key: FixedKey, value: f64) -> Result<()> {
        if !value.is_finite() {
            return Err(Error::invalid_value(name, value, "not a finite number"));
        }
        // The range of variables.json; a note on why for the ranges a user may wonder about.
        let reason = FIXED_VARIABLES
            .iter()
            .find(|s| s.key == key)
            .and_then(|s| range_violation(s.min, s.max, s.min_exclusive, s.max_exclusive, value))
            .map(|r| match key {
                FixedKey::PoissonRatio => format!(
                    "{r}: 0.5 is incompressible, which a displacement formulation cannot represent"
                ),
                FixedKey::DampingAlpha | FixedKey::DampingBeta => {
                    format!("{r} (negative damping adds energy)")
                }
                _ => r,
            });
        match reason {
            Some(r) => Err(Error::invalid_value(name, value, &r)),
            None => Ok(()),
        }
    }
}

/// What the assembled model depends on: the parameters of [`Parameters::assembly_key`] (reals
/// by their bits, so that a model is rebuilt exactly when one of them changes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct AssemblyKey {
    material: IsotropicMaterial,
    damping: [u64; 2],
    rho_inf: u64,
    nonlinear_forces: bool,
    linear: bool,
    auto: bool,
    /// `model.accuracy > 0`: the model carries the lowest modes of the error control and
    /// `model.auto`'s slabs and linear body are decided against it.
    controlled: bool,
    formulation: Formulation,
    stiffening: Stiffening,
    frames: i32,
    anderson_depth: i32,
    integrator: Integrator,
    modes: i32,
}

/// Where a parameter lives in [`Parameters`]: one of the four FMI types, borrowed shared (`R =
/// &f64`, ...) or exclusive (`R = &mut f64`, ...).
pub(super) enum Slot<R, I, B, T, C> {
    Real(R),
    Integer(I),
    Boolean(B),
    Text(T),
    /// An Integer that is an enumeration (`variables.json`'s `enumerations`).
    Choice(C),
}

/// An enumeration parameter as an FMI Integer.
pub(super) trait Choice {
    fn item(&self) -> i32;
    /// Sets the item `item`; false (and nothing set) if there is none.
    fn set_item(&mut self, item: i32) -> bool;
}

macro_rules! choice {
    ($($t:ty),*) => {$(
        impl Choice for $t {
            fn item(&self) -> i32 {
                <$t>::item(*self)
            }
            fn set_item(&mut self, item: i32) -> bool {
                match <$t>::from_item(item) {
                    Some(value) => {
                        *self = value;
                        true
                    }
                    None => false,
                }
            }
        }
    )*};
}
choice!(Formulation, Stiffening, Integrator);

/// A parameter read through [`Parameters::slot`].
pub(super) type SlotRef<'a> = Slot<&'a f64, &'a i32, &'a bool, &'a String, &'a dyn Choice>;
/// A parameter written through [`Parameters::slot_mut`].
pub(super) type SlotMut<'a> =
    Slot<&'a mut f64, &'a mut i32, &'a mut bool, &'a mut String, &'a mut dyn Choice>;

/// The one table from a fixed variable (`key`, component `c`) to its field of [`Parameters`],
/// written once for the shared and the exclusive borrow (`$($m)?` is `mut` or nothing).
/// Outputs (the body's) have no slot.
macro_rules! parameter_slot {
    ($p:expr, $key:expr, $c:expr $(, $m:ident)?) => {{
        use FixedKey::*;
        Some(match $key {
            YoungsModulus => Slot::Real(&$($m)? $p.material.youngs_modulus),
            PoissonRatio => Slot::Real(&$($m)? $p.material.poisson_ratio),
            Density => Slot::Real(&$($m)? $p.material.density),
            DampingAlpha => Slot::Real(&$($m)? $p.damping_alpha),
            DampingBeta => Slot::Real(&$($m)? $p.damping_beta),
            Gravity => Slot::Real(&$($m)? $p.gravity[$c]),
            InitialPosition => Slot::Real(&$($m)? $p.initial_position[$c]),
            InitialRotation => Slot::Real(&$($m)? $p.initial_rotation[$c]),
            InitialVelocity => Slot::Real(&$($m)? $p.initial_velocity[$c]),
            InitialAngularVelocity => Slot::Real(&$($m)? $p.initial_angular_velocity[$c]),
            StepSize => Slot::Real(&$($m)? $p.step_size),
            RhoInf => Slot::Real(&$($m)? $p.rho_inf),
            Tolerance => Slot::Real(&$($m)? $p.tolerance),
            Accuracy => Slot::Real(&$($m)? $p.accuracy),
            OutputInterval => Slot::Real(&$($m)? $p.output_interval),
            MaxIterations => Slot::Integer(&$($m)? $p.max_iterations),
            Formulation => Slot::Choice(&$($m)? $p.formulation),
            Stiffening => Slot::Choice(&$($m)? $p.stiffening),
            Frames => Slot::Integer(&$($m)? $p.frames),
            Modes => Slot::Integer(&$($m)? $p.modes),
            AndersonDepth => Slot::Integer(&$($m)? $p.anderson_depth),
            Integrator => Slot::Choice(&$($m)? $p.integrator),
            NonlinearForces => Slot::Boolean(&$($m)? $p.nonlinear_forces),
            Linear => Slot::Boolean(&$($m)? $p.linear),
            Auto => Slot::Boolean(&$($m)? $p.auto),
            OutputDirectory => Slot::Text(&$($m)? $p.output_directory),
            _ => return None,
        })
    }};
}

impl Parameters {
    /// The field of the fixed variable `key` (component `c`), `None` for outputs.
    pub(super) fn slot(&self, key: FixedKey, c: usize) -> Option<SlotRef<'_>> {
        parameter_slot!(self, key, c)
    }

    /// The field of the fixed variable `key` (component `c`) to write, `None` for outputs.
    pub(super) fn slot_mut(&mut self, key: FixedKey, c: usize) -> Option<SlotMut<'_>> {
        parameter_slot!(self, key, c, mut)
    }

    /// The field of a variable's `target` to write: `None` for inputs and outputs.
    pub(super) fn target_mut(&mut self, target: Target) -> Option<SlotMut<'_>> {
        match target {
            Target::Fixed { key, component } => self.slot_mut(key, component),
            Target::Interface { .. } => None,
        }
    }

    /// The Real parameter `key` (component `c`), `None` for outputs and other types.
    pub(super) fn real(&self, key: FixedKey, c: usize) -> Option<f64> {
        match self.slot(key, c)? {
            Slot::Real(x) => Some(*x),
            _ => None,
        }
    }

    /// The Integer parameter `key`.
    pub(super) fn integer(&self, key: FixedKey) -> Option<i32> {
        match self.slot(key, 0)? {
            Slot::Integer(x) => Some(*x),
            Slot::Choice(c) => Some(c.item()),
            _ => None,
        }
    }

    /// The Boolean parameter `key`.
    pub(super) fn boolean(&self, key: FixedKey) -> Option<bool> {
        match self.slot(key, 0)? {
            Slot::Boolean(x) => Some(*x),
            _ => None,
        }
    }
}
