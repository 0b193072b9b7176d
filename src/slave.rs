//! One co-simulation instance: parameters and inputs → body → solver → outputs; `do_step`; state
//! save and restore. Knows nothing of C pointers: the FMI glue in `fmi2` calls it after checking
//! arguments and the calling sequence.

use crate::body::feature_indicators::{self, FeatureIndicators};
use crate::body::frame::{nearest_rotation, node};
use crate::body::interface::{DrivingFrame, InterfaceMotion};
use crate::body::stiffening::Stiffening;
use crate::body::strain_monitor::{StrainMonitor, DEFAULT_THRESHOLD};
use crate::body::{Body, BodyOptions, NodeSet, Patches, Reduction};
use crate::error::{Error, ErrorKind, Result};
use crate::fem::nonlinear::SvkSolid;
use crate::fem::{self, IsotropicMaterial};
use crate::mesh::Mesh;
use crate::model::body_file::Integrator;
use crate::model::model_description::{format_real, model_description, ModelInfo};
use crate::model::variables::{
    EnumerationSpec, FixedKey, InterfaceQuantity, FIXED_TABLE_FINGERPRINT,
};
use crate::model::{BodyFile, InterfaceKind, Target, Variable, VariableTable, VariableType};
use crate::output::ResultWriter;
use crate::solver::anderson::MAX_DEPTH;
use crate::solver::central_difference::CentralDifference;
use crate::solver::consistent_acceleration::ConsistentAcceleration;
use crate::solver::generalized_alpha::{
    self, DynamicState, FreeNodes, GeneralizedAlpha, IterationMatrix, IterationSettings,
    StepWorkspace,
};
use crate::solver::radau::{self, RadauIIA, RadauMatrix, RadauProblem, RadauWorkspace};
use nalgebra::{Matrix3, Vector3};
use std::path::Path;

mod state_bytes;
pub use state_bytes::PAYLOAD_FORMAT as STATE_PAYLOAD_FORMAT;

/// The input values of one interface, indexed by value-reference slot
/// ([`InterfaceQuantity::slot`]).
type Inputs = [f64; 30];

/// The first and second time derivatives of one interface's inputs (`fmi2SetRealInputDerivatives`;
/// only the force and torque slots of force interfaces are ever non-zero).
type InputDerivatives = [Inputs; 2];

/// `model.formulation` item of the full nonlinear reference.
const FORMULATION_FULL: i32 = 2;
/// `model.stiffening` items.
const STIFFENING_NONE: i32 = 1;
const STIFFENING_INERTIAL: i32 = 2;
const STIFFENING_STRESS: i32 = 3;
/// `Dynamics::quiet_since` of a term whose indicator is not below its switch-off threshold (a
/// finite number: the state's byte form holds finite numbers only).
const NOT_QUIET: f64 = f64::MAX;
/// `solver.integrator` items.
const INTEGRATOR_GENERALIZED_ALPHA: i32 = 1;
const INTEGRATOR_CENTRAL_DIFFERENCE: i32 = 2;
const INTEGRATOR_RADAU: i32 = 3;

/// Most factorizations kept, one per internal step size in use, least recently used evicted.
///
/// Memory: each entry holds the sparse Cholesky factor of the free DOFs' iteration matrix plus
/// its solve workspace (and, with pins or hinges, the small dense Schur complement). For the
/// default body (621 nodes, 1 800 free DOF) the factor holds 223 083 values (1.8 MB, about 3 MB
/// with its indices); the cache is bounded by four of them whatever sequence of communication
/// step sizes the importer sends (`tests/fmi2_capabilities.rs` checks the bound). With
/// `radauIIA` an entry holds that Cholesky factor and a complex (`c64`) LU factor of the same
/// matrix size besides (pivoting, COLAMD ordering: it is larger; factorization measured 3–6 ×
/// the Cholesky's time), so a Radau entry costs several times a generalized-α one.
/// Four covers a steady step size, a last partial step and the three step sizes of the retries
/// of a failed internal step ([`MAX_STEP_HALVINGS`]); a fifth size evicts the least recently used
/// one, which is factorised again when it comes back.
pub const MATRIX_CACHE_SIZE: usize = 4;

/// How often an internal step that did not converge is retried with halved internal steps
/// (2, 4, ..., 2^MAX_STEP_HALVINGS steps in its place) before the communication step is
/// discarded. Smaller steps help the fixed-point iteration: the mass term `M/(βh²)` of the
/// constant iteration matrix grows like `1/h²` and the neglected nonlinear terms do not.
pub const MAX_STEP_HALVINGS: u32 = 3;

/// Highest order of `fmi2SetRealInputDerivatives` (force inputs are extrapolated by their Taylor
/// polynomial of this degree).
pub const MAX_INPUT_DERIVATIVE_ORDER: i32 = 2;

/// `maxOutputDerivativeOrder`: see [`Slave::get_real_output_derivative`].
pub const MAX_OUTPUT_DERIVATIVE_ORDER: i32 = 2;

/// The parameters of DESIGN.md section 4 (SI units).
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
    pub max_iterations: i32,
    pub nonlinear_forces: bool,
    /// `model.auto`: with it `nonlinear_forces` and `stiffening` are what is allowed and the
    /// slave switches each on per step when its indicator says it matters (see [`Features`]).
    pub auto: bool,
    /// `model.formulation`: 1 reducedStrain, 2 full.
    pub formulation: i32,
    /// `model.stiffening`: 1 none, 2 inertial, 3 stress.
    pub stiffening: i32,
    /// `model.frames`: co-moving frames of the reduced-strain body (≥ 1).
    pub frames: i32,
    /// `model.modes`: 0 the full mesh, `n > 0` the reduced body with `n` fixed-interface modes.
    pub modes: i32,
    /// `solver.andersonDepth`: history of Anderson's acceleration (0 to 8).
    pub anderson_depth: i32,
    /// `solver.integrator`: 1 generalized-α, 2 central difference, 3 Radau IIA.
    pub integrator: i32,
    /// `output.directory`: where VTK results go; empty: none (see [`crate::output`]).
    pub output_directory: String,
    /// `output.interval` (s): smallest time between saved results; 0: every communication point.
    pub output_interval: f64,
}

impl Parameters {
    fn from_body_file(b: &BodyFile) -> Parameters {
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
            max_iterations: b.solver.max_iterations.min(i32::MAX as u32) as i32,
            nonlinear_forces: b.model.nonlinear_forces,
            auto: b.model.auto,
            formulation: 1,
            stiffening: 1,
            frames: b.model.frames.clamp(1, i32::MAX as u32) as i32,
            modes: b.model.modes.min(i32::MAX as u32) as i32,
            anderson_depth: b.solver.anderson_depth.min(MAX_DEPTH as u32) as i32,
            integrator: match b.solver.integrator {
                Integrator::GeneralizedAlpha => INTEGRATOR_GENERALIZED_ALPHA,
                Integrator::CentralDifference => INTEGRATOR_CENTRAL_DIFFERENCE,
                Integrator::RadauIIA => INTEGRATOR_RADAU,
            },
            output_directory: String::new(),
            output_interval: 0.0,
        }
    }

    /// The parameters that the assembled model depends on (everything but gravity, the initial
    /// placement, the step size and the iteration settings).
    fn model_key(&self) -> ModelKey {
        (
            self.material,
            [
                self.damping_alpha.to_bits(),
                self.damping_beta.to_bits(),
                self.rho_inf.to_bits(),
            ],
            [self.nonlinear_forces, self.auto],
            [
                self.formulation * 16 + self.stiffening,
                self.frames,
                self.anderson_depth,
                self.integrator,
                self.modes,
            ],
        )
    }

    /// Checks one Real parameter value; the error names the variable, the value and the reason.
    fn check_real(name: &str, key: FixedKey, value: f64) -> Result<()> {
        if !value.is_finite() {
            return Err(Error::invalid_value(name, value, "not a finite number"));
        }
        let reason = match key {
            FixedKey::YoungsModulus if value <= 0.0 => Some("must be positive"),
            FixedKey::Density if value <= 0.0 => Some("must be positive"),
            FixedKey::PoissonRatio if !(value > -1.0 && value < 0.5) => {
                Some("must lie in (-1, 0.5): 0.5 is incompressible, which a displacement formulation cannot represent")
            }
            FixedKey::DampingAlpha | FixedKey::DampingBeta if value < 0.0 => {
                Some("must not be negative (negative damping adds energy)")
            }
            FixedKey::StepSize if value <= 0.0 => Some("must be positive"),
            FixedKey::RhoInf if !(0.0..=1.0).contains(&value) => Some("must lie in [0, 1]"),
            FixedKey::Tolerance if !(value > 0.0 && value < 1.0) => Some("must lie in (0, 1)"),
            FixedKey::OutputInterval if value < 0.0 => Some("must not be negative"),
            _ => None,
        };
        match reason {
            Some(r) => Err(Error::invalid_value(name, value, r)),
            None => Ok(()),
        }
    }
}

/// An interface at run time: its kind and node set.
#[derive(Debug, Clone)]
struct Interface {
    kind: InterfaceKind,
    set: NodeSet,
    /// Point constraints of a pin (one: the whole set) or a hinge (two: the halves of the set
    /// on either side of the plane through its centroid normal to the axis): node lists and
    /// weights.
    point_constraints: Vec<(Vec<usize>, Vec<f64>)>,
    /// Index of the first of them in the solver's constraint list.
    first_constraint: usize,
}

/// What the assembled model depends on (see [`Parameters::model_key`]).
type ModelKey = (IsotropicMaterial, [u64; 3], [bool; 2], [i32; 5]);

/// The terms in force during a step: with `model.auto` chosen per communication step by
/// [`FeatureIndicators`] among the allowed ones, otherwise the forced switches. Part of the
/// state (saved and restored with it), since the choice has hysteresis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Features {
    pub nonlinear_forces: bool,
    pub stiffening: bool,
}

/// The assembled model for one set of parameters.
struct Model {
    key: ModelKey,
    body: Body,
    free: FreeNodes,
    scheme: GeneralizedAlpha,
    matrices: Vec<IterationMatrix>,
    workspace: StepWorkspace,
    /// Geometric stiffening (`model.stiffening` inertial or stress); its `K_G` lives in
    /// `workspace.geometric_stiffness`.
    stiffening: Option<Stiffening>,
    /// The constant-mass solve for consistent accelerations (initialization, load jumps).
    mass: ConsistentAcceleration,
    /// The explicit scheme (`solver.integrator = centralDifference`), if chosen.
    explicit: Option<CentralDifference>,
    /// Radau IIA (`solver.integrator = radauIIA`), if chosen: its factorization cache (used in
    /// place of `matrices`) and workspace. Its residual shares `workspace`'s force scratch and
    /// geometric stiffness.
    radau: Option<RadauModel>,
    /// The watch on `‖∇ū‖` (one co-moving frame only) and whether it is above the threshold.
    strain_monitor: Option<(StrainMonitor, bool)>,
    /// `model.auto`'s indicators (one co-moving frame, reduced strain, some term allowed).
    indicators: Option<FeatureIndicators>,
    /// The allowed terms: upper bounds of [`Features`].
    allowed: Features,
    /// `K_G` while stiffening is switched off (it moves to `workspace.geometric_stiffness` and
    /// back: no allocation).
    parked_geometric_stiffness: Option<crate::fem::SymmetricCsr>,
}

impl Model {
    /// Puts `features` into force: the body's `f_nl` switch and where `K_G` lives. The iteration
    /// matrices are not touched: they carry the Woodbury correction of `f_nl` whenever it is
    /// allowed (unused while it is off), and stiffening is on the right-hand side, absorbed by
    /// the fixed-point/Anderson iteration; so a switch never refactorises.
    fn apply_features(&mut self, features: Features) {
        self.body.options.nonlinear_forces = features.nonlinear_forces;
        let active = self.workspace.geometric_stiffness.is_some();
        if features.stiffening != active {
            std::mem::swap(
                &mut self.workspace.geometric_stiffness,
                &mut self.parked_geometric_stiffness,
            );
        }
    }
}

/// Radau IIA's part of the model.
struct RadauModel {
    tableau: RadauIIA,
    matrices: Vec<RadauMatrix>,
    workspace: RadauWorkspace,
}

/// The motion state and the loads it is in equilibrium with.
#[derive(Debug, Clone, PartialEq)]
struct Dynamics {
    state: DynamicState,
    /// Inputs per interface that `state`'s accelerations belong to.
    loads: Vec<Inputs>,
    gravity: [f64; 3],
    /// The terms in force.
    features: Features,
    /// Per term (f_nl, stiffening): since when its estimate has stayed below the switch-off
    /// threshold while it is on ([`NOT_QUIET`]: it has not), see [`choose_features`].
    quiet_since: [f64; 2],
}

/// A snapshot of everything that determines later steps (time, positions, velocities,
/// accelerations, inputs and their derivatives, parameters) and the step counters. Restoring it
/// reproduces later steps bit for bit. [`SlaveState::to_bytes`] / [`Slave::state_from_bytes`]
/// give it a portable byte form (module `state_bytes`).
#[derive(Debug, Clone, PartialEq)]
pub struct SlaveState {
    parameters: Parameters,
    inputs: Vec<Inputs>,
    input_derivatives: Vec<InputDerivatives>,
    input_times: Vec<f64>,
    start_time: f64,
    dynamics: Option<Dynamics>,
    /// Internal steps, fixed-point iterations, retried internal steps.
    counters: [u64; 3],
}

/// Outputs computed once per state, on the first read.
#[derive(Debug, Clone, Default)]
struct Outputs {
    valid: bool,
    body: [f64; 26],
    /// Acceleration of the centre of mass (for output derivatives).
    body_acceleration: [f64; 3],
    /// Per interface: force[3], torque[3], then motion (position, rotation, velocity, angular
    /// velocity, acceleration, angular acceleration) in value-reference slot order.
    interfaces: Vec<[f64; 30]>,
    /// Scratch `M ẋ` (flat, the body's size; resized only when the model changes).
    momentum: Vec<f64>,
}

/// A message for the importer's logger that is not an error: `category` is one of the declared
/// log categories (`logEvents`, `logSolver`).
#[derive(Debug, Clone, PartialEq)]
pub struct LogEvent {
    pub category: &'static str,
    pub message: String,
}

/// One instance of the flexible body.
pub struct Slave {
    body_file: BodyFile,
    variables: VariableTable,
    guid: String,
    mesh: Mesh,
    /// Node sets, and `clamped[i]` for nodes held by a `fixed` support.
    interfaces: Vec<Interface>,
    clamped: Vec<bool>,
    /// The material region of each element (`BodyFile::regions`), `None`: `material.*`.
    element_regions: Vec<Option<usize>>,
    /// Characteristic size of the body (m): the diagonal of its bounding box.
    size: f64,
    defaults: Parameters,
    parameters: Parameters,
    inputs: Vec<Inputs>,
    default_inputs: Vec<Inputs>,
    /// Input derivatives (`fmi2SetRealInputDerivatives`), with respect to the sample time of
    /// their interface: the force inputs are `u(t) = u + u'·τ + u''·τ²/2`, `τ = t − t_s`.
    input_derivatives: Vec<InputDerivatives>,
    /// Per interface, the sample time `t_s` of its inputs: the FMU time at which they were last
    /// set (the start time before initialization). The inputs describe the interface at `t_s`
    /// and are extrapolated from there, however many steps the importer takes before it sets
    /// them again (see [`Slave::resample_inputs`]).
    input_times: Vec<f64>,
    /// Per interface, `t_0 − t_s` for the step under way (`t_0` its start): how far the
    /// inputs' extrapolation has run when the step begins. Scratch, sized once.
    input_ages: Vec<f64>,
    /// The driving frames of motion interfaces at the start of the current step.
    driving: Vec<DrivingFrame>,
    start_time: f64,
    model: Option<Model>,
    dynamics: Option<Dynamics>,
    /// Backup of the dynamics at the start of a communication step (rollback on failure).
    backup: Option<DynamicState>,
    /// Backup at the start of an internal step being retried with smaller steps.
    retry_backup: Option<DynamicState>,
    outputs: Outputs,
    /// Internal steps and fixed-point iterations since initialization.
    statistics: (u64, u64),
    /// Internal steps that did not converge and were retried with halved steps.
    retries: u64,
    /// Messages for the logger, drained by the FMI layer after each call.
    events: Vec<LogEvent>,
    /// The VTK results of this run, if `output.directory` is set.
    results: Option<ResultWriter>,
}

impl Slave {
    /// Loads `body.json` from the resource directory if there is one, else the embedded default body.
    pub fn from_resources(resource_dir: Option<&Path>) -> Result<Slave> {
        let body = match resource_dir.map(|d| d.join("body.json")) {
            Some(path) if path.exists() => {
                let text = std::fs::read_to_string(&path).map_err(|e| {
                    Error::new(format!("cannot read the body file {}: {e}", path.display()))
                })?;
                BodyFile::from_json(&text)
                    .map_err(|e| Error::new(format!("{}: {}", path.display(), e.message)))?
            }
            _ => BodyFile::default_body(),
        };
        Slave::from_body_in(body, resource_dir)
    }

    /// Reads the body file at `path` (a mesh file it names is looked up beside it).
    pub fn from_body_path(path: &Path) -> Result<Slave> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            Error::new(format!("cannot read the body file {}: {e}", path.display()))
        })?;
        let body = BodyFile::from_json(&text)
            .map_err(|e| Error::new(format!("{}: {}", path.display(), e.message)))?;
        Slave::from_body_in(body, path.parent())
    }

    /// A fresh instance of `body_file` (parameters at their start values, Instantiated); a mesh
    /// file it names is looked up relative to the current directory.
    pub fn from_body(body_file: BodyFile) -> Result<Slave> {
        Slave::from_body_in(body_file, None)
    }

    /// [`Slave::from_body`] with mesh files looked up in `base_dir` (the body file's directory).
    pub fn from_body_in(body_file: BodyFile, base_dir: Option<&Path>) -> Result<Slave> {
        body_file.check()?;
        let mesh = body_file.mesh.build(base_dir)?;
        let reference: Vec<f64> = mesh.nodes().iter().flatten().copied().collect();
        let lumped = fem::lumped_masses(&mesh, 1.0);
        let mut interfaces = Vec::new();
        let mut clamped = vec![false; mesh.node_count()];
        let (lo, hi) = mesh.bounding_box();
        let size = (Vector3::from(hi) - Vector3::from(lo)).norm();
        for spec in &body_file.interfaces {
            let nodes = spec
                .nodes
                .select(&mesh)
                .map_err(|e| Error::new(format!("interface '{}': {}", spec.name, e.message)))?;
            let weights: Vec<f64> = nodes.iter().map(|&i| lumped[i]).collect();
            if matches!(spec.kind, InterfaceKind::Fixed | InterfaceKind::Motion) {
                for &i in &nodes {
                    clamped[i] = true;
                }
            }
            let point_constraints = point_constraints(spec, &nodes, &weights, &reference, size)?;
            let set = NodeSet::new(
                &spec.name,
                nodes,
                weights,
                &reference,
                spec.reference_point.map(Vector3::from),
            )?;
            interfaces.push(Interface {
                kind: spec.kind,
                set,
                point_constraints,
                first_constraint: 0,
            });
        }
        if clamped.iter().all(|&c| c) {
            return Err(Error::new(
                "body file: fixed supports hold every node: nothing can move",
            ));
        }
        let variables = VariableTable::new(&body_file.interfaces);
        let defaults = Parameters::from_body_file(&body_file);
        for v in variables.iter() {
            if let (Target::Fixed { key, .. }, VariableType::Real) = (v.target, v.ty) {
                let value = read_parameter(&defaults, key, component_of(v));
                if let Some(value) = value {
                    Parameters::check_real(&v.name, key, value)
                        .map_err(|e| Error::new(format!("body file: {}", e.message)))?;
                }
            }
        }
        let element_regions = body_file.element_regions(&mesh)?;
        let guid = guid_of(&body_file);
        let n_interfaces = interfaces.len();
        // Motion interfaces start at their place in the body file, at rest.
        let default_inputs: Vec<Inputs> = interfaces
            .iter()
            .map(|i| {
                let mut values = [0.0; 30];
                if i.kind == InterfaceKind::Motion {
                    let p = InterfaceQuantity::Position.slot() as usize;
                    values[p..p + 3].copy_from_slice(i.set.reference_point.as_slice());
                    let r = InterfaceQuantity::Rotation.slot() as usize;
                    values[r..r + 9]
                        .copy_from_slice(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
                }
                values
            })
            .collect();
        Ok(Slave {
            body_file,
            variables,
            guid,
            mesh,
            interfaces,
            clamped,
            element_regions,
            size,
            parameters: defaults.clone(),
            defaults,
            inputs: default_inputs.clone(),
            default_inputs,
            input_derivatives: vec![[[0.0; 30]; 2]; n_interfaces],
            input_times: vec![0.0; n_interfaces],
            input_ages: vec![0.0; n_interfaces],
            driving: vec![DrivingFrame::default(); n_interfaces],
            start_time: 0.0,
            model: None,
            dynamics: None,
            backup: None,
            retry_backup: None,
            outputs: Outputs {
                interfaces: vec![[0.0; 30]; n_interfaces],
                ..Outputs::default()
            },
            statistics: (0, 0),
            retries: 0,
            events: Vec::new(),
            results: None,
        })
    }

    /// The GUID of this body (fixed variable table, crate version and body file).
    pub fn guid(&self) -> &str {
        &self.guid
    }

    /// The body file this instance was built from.
    pub fn body_file(&self) -> &BodyFile {
        &self.body_file
    }

    /// The mesh of the body.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The variable table (value references, causality, variability).
    pub fn variables(&self) -> &VariableTable {
        &self.variables
    }

    /// Sets a Real, Integer or Boolean variable by name (for scripts and measurements: an
    /// Integer takes `value` when it is integral, a Boolean `value != 0`); the same checks as
    /// the typed setters.
    pub fn set_by_name(&mut self, name: &str, value: f64) -> Result<()> {
        let v = self
            .variables
            .by_name(name)
            .ok_or_else(|| Error::new(format!("no variable is named {name}")))?;
        let (vr, ty) = (v.value_reference, v.ty);
        match ty {
            VariableType::Real => self.set_real(vr, value),
            VariableType::Integer if value.fract() == 0.0 && value.abs() <= i32::MAX as f64 => {
                self.set_integer(vr, value as i32)
            }
            VariableType::Integer => Err(Error::invalid_value(name, value, "not an integer")),
            VariableType::Boolean => self.set_boolean(vr, value != 0.0),
            VariableType::String => Err(Error::new(format!(
                "{name} is a String variable: use set_string"
            ))),
        }
    }

    /// A Real variable by name.
    pub fn get_by_name(&mut self, name: &str) -> Result<f64> {
        let vr = self
            .variables
            .by_name(name)
            .ok_or_else(|| Error::new(format!("no variable is named {name}")))?
            .value_reference;
        self.get_real(vr)
    }

    /// The current parameter values.
    pub fn parameters(&self) -> &Parameters {
        &self.parameters
    }

    /// `fmi2SetupExperiment`: start time; stop time and tolerance are optional (and not needed).
    pub fn setup_experiment(
        &mut self,
        start_time: f64,
        stop_time: Option<f64>,
        tolerance: Option<f64>,
    ) -> Result<()> {
        if !start_time.is_finite() {
            return Err(Error::invalid_value(
                "startTime",
                start_time,
                "not a finite number",
            ));
        }
        if let Some(stop) = stop_time {
            if stop.is_nan() || stop < start_time {
                return Err(Error::invalid_value(
                    "stopTime",
                    stop,
                    "must not be before startTime",
                ));
            }
        }
        let _ = tolerance; // the body's own solver.tolerance governs the iteration
        self.start_time = start_time;
        // Inputs set before the experiment is set up describe the start.
        self.input_times.fill(start_time);
        Ok(())
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization_mode(&mut self) -> Result<()> {
        self.dynamics = None;
        self.input_times.fill(self.start_time);
        self.outputs.valid = false;
        Ok(())
    }

    /// `fmi2ExitInitializationMode`: validates the parameters, assembles and places the body,
    /// factorises the iteration matrix for `solver.stepSize`.
    pub fn exit_initialization_mode(&mut self) -> Result<()> {
        self.ensure_initial_state()?;
        let h = self.parameters.step_size;
        self.matrix_index(h)?;
        self.results = None;
        if !self.parameters.output_directory.is_empty() {
            match ResultWriter::create(
                &self.parameters.output_directory,
                &file_stem(&self.body_file.name),
                self.parameters.output_interval,
            ) {
                Ok(writer) => {
                    self.events.push(LogEvent {
                        category: "logEvents",
                        message: format!(
                            "output.directory: writing VTK results to {}",
                            writer.collection_path().display()
                        ),
                    });
                    self.results = Some(writer);
                    self.write_results();
                }
                Err(e) => self.output_failed(&e),
            }
        }
        Ok(())
    }

    /// Writes the current state to the results if they are on and a state is due. A file error
    /// is logged and switches the results off: it never fails the simulation.
    fn write_results(&mut self) {
        let (Some(writer), Some(model), Some(dynamics)) = (
            self.results.as_mut(),
            self.model.as_ref(),
            self.dynamics.as_ref(),
        ) else {
            return;
        };
        let s = &dynamics.state;
        if !writer.is_due(s.time) {
            return;
        }
        if let Err(e) = writer.write(
            s.time,
            &self.mesh,
            &self.parameters.material,
            &model.body,
            &s.position,
            &s.velocity,
        ) {
            self.output_failed(&e);
        }
    }

    /// Logs a failure to write results (an error message; the call itself succeeds) and stops
    /// writing.
    fn output_failed(&mut self, reason: &str) {
        self.results = None;
        self.events.push(LogEvent {
            category: "logStatusError",
            message: format!(
                "error: output.directory = '{}': {reason}; no further results are written (the simulation goes on)",
                self.parameters.output_directory
            ),
        });
    }

    /// Value of a String variable.
    pub fn get_string(&mut self, vr: u32) -> Result<String> {
        let v = self.lookup(VariableType::String, vr)?;
        match v.target {
            Target::Fixed {
                key: FixedKey::OutputDirectory,
                ..
            } => Ok(self.parameters.output_directory.clone()),
            _ => Err(Error::new(format!(
                "no String variable has value reference {vr}"
            ))),
        }
    }

    /// Sets a String parameter (`output.directory`: any text; a directory that cannot be created
    /// is reported when the results are first written).
    pub fn set_string(&mut self, vr: u32, value: &str) -> Result<()> {
        let v = self.lookup(VariableType::String, vr)?;
        match v.target {
            Target::Fixed {
                key: FixedKey::OutputDirectory,
                ..
            } => {
                self.parameters.output_directory = value.to_string();
                Ok(())
            }
            _ => Err(Error::new(format!("{} cannot be set", v.name))),
        }
    }

    /// Current simulation time (s): the last successful communication point.
    pub fn time(&self) -> f64 {
        self.dynamics
            .as_ref()
            .map_or(self.start_time, |d| d.state.time)
    }

    /// Positions, velocities and accelerations (flat `3N`) once initialized.
    pub fn dynamic_state(&self) -> Option<&DynamicState> {
        self.dynamics.as_ref().map(|d| &d.state)
    }

    /// The free nodes, their reduced matrices and constraints once initialized.
    pub fn free_nodes(&self) -> Option<&FreeNodes> {
        self.model.as_ref().map(|m| &m.free)
    }

    /// The cached factorization of the iteration matrix for internal step `h`, if a step of that
    /// size has been taken (for measurements: the floor of a step is one solve with it).
    pub fn iteration_matrix(&self, h: f64) -> Option<&IterationMatrix> {
        self.model
            .as_ref()?
            .matrices
            .iter()
            .find(|m| (m.step_size - h).abs() <= 1e-9 * h)
    }

    /// The assembled body once initialized.
    pub fn body(&self) -> Option<&Body> {
        self.model.as_ref().map(|m| &m.body)
    }

    /// Takes the log messages produced since the last call (none on the hot path).
    pub fn drain_events(&mut self) -> std::vec::Drain<'_, LogEvent> {
        self.events.drain(..)
    }

    /// Internal steps taken and fixed-point iterations done since instantiation.
    pub fn solver_statistics(&self) -> (u64, u64) {
        self.statistics
    }

    /// Step sizes with a factorization in the cache (at most [`MATRIX_CACHE_SIZE`]), most
    /// recently used last.
    pub fn cached_step_sizes(&self) -> Vec<f64> {
        self.model
            .as_ref()
            .map_or_else(Vec::new, |m| match &m.radau {
                Some(radau) => radau.matrices.iter().map(|x| x.step_size).collect(),
                None => m.matrices.iter().map(|x| x.step_size).collect(),
            })
    }

    /// Internal steps that did not converge and were retried with halved steps (each retry
    /// counts once per halving).
    pub fn step_retries(&self) -> u64 {
        self.retries
    }

    /// `fmi2Reset`: back to the freshly instantiated state (parameters at their start values). The
    /// assembled matrices are kept for reuse if the parameters come back the same.
    pub fn reset(&mut self) {
        self.parameters = self.defaults.clone();
        self.inputs.clone_from(&self.default_inputs);
        for d in &mut self.input_derivatives {
            *d = [[0.0; 30]; 2];
        }
        self.start_time = 0.0;
        self.input_times.fill(0.0);
        self.dynamics = None;
        self.backup = None;
        self.statistics = (0, 0);
        self.retries = 0;
        self.outputs.valid = false;
        self.results = None;
    }

    /// `fmi2GetFMUstate`.
    pub fn get_state(&self) -> SlaveState {
        SlaveState {
            parameters: self.parameters.clone(),
            inputs: self.inputs.clone(),
            input_derivatives: self.input_derivatives.clone(),
            input_times: self.input_times.clone(),
            start_time: self.start_time,
            dynamics: self.dynamics.clone(),
            counters: [self.statistics.0, self.statistics.1, self.retries],
        }
    }

    /// `fmi2SetFMUstate`.
    pub fn set_state(&mut self, state: &SlaveState) -> Result<()> {
        if state.inputs.len() != self.inputs.len()
            || state.input_derivatives.len() != self.inputs.len()
            || state.input_times.len() != self.inputs.len()
        {
            return Err(Error::new("the FMU state belongs to another body"));
        }
        self.parameters = state.parameters.clone();
        self.inputs.clone_from(&state.inputs);
        self.input_derivatives.clone_from(&state.input_derivatives);
        self.input_times.clone_from(&state.input_times);
        self.start_time = state.start_time;
        self.statistics = (state.counters[0], state.counters[1]);
        self.retries = state.counters[2];
        if let Some(d) = &state.dynamics {
            self.ensure_model()?;
            let expected = 3 * self.model.as_ref().unwrap().body.node_count();
            if d.state.position.len() != expected {
                return Err(Error::new(format!(
                    "the FMU state has {} coordinates, this body (model.modes = {}) has {expected}: it belongs to another body",
                    d.state.position.len(),
                    self.parameters.modes
                )));
            }
        }
        match (&mut self.dynamics, &state.dynamics) {
            (Some(d), Some(s)) if d.state.position.len() == s.state.position.len() => {
                d.state.copy_from(&s.state);
                d.loads.clone_from(&s.loads);
                d.gravity = s.gravity;
                d.features = s.features;
                d.quiet_since = s.quiet_since;
            }
            (d, s) => *d = s.clone(),
        }
        if let (Some(model), Some(d)) = (self.model.as_mut(), self.dynamics.as_ref()) {
            model.apply_features(d.features);
        }
        self.outputs.valid = false;
        Ok(())
    }

    /// The complete `modelDescription.xml` of this body.
    pub fn model_description(&self) -> String {
        let info = ModelInfo {
            model_name: self.body_file.name.clone(),
            description: self.body_file.description.clone(),
            guid: self.guid.clone(),
            generation_tool: format!("flexbody {}", env!("CARGO_PKG_VERSION")),
            default_step_size: self.defaults.step_size,
        };
        model_description(&self.variables, &info, &|v: &Variable| self.start_value(v))
    }

    /// Start value of a parameter or input as written in the XML (full precision).
    fn start_value(&self, v: &Variable) -> String {
        match (v.ty, v.target) {
            (VariableType::Boolean, Target::Fixed { key, .. }) => read_boolean(&self.defaults, key)
                .unwrap_or(false)
                .to_string(),
            (VariableType::Integer, Target::Fixed { key, .. }) => {
                read_integer(&self.defaults, key).unwrap_or(0).to_string()
            }
            (VariableType::Real, Target::Fixed { key, component }) => {
                format_real(read_parameter(&self.defaults, key, component).unwrap_or(0.0))
            }
            (VariableType::String, Target::Fixed { .. }) => self.defaults.output_directory.clone(),
            (
                VariableType::Real,
                Target::Interface {
                    index,
                    quantity,
                    component,
                },
            ) => format_real(self.default_inputs[index][quantity.slot() as usize + component]),
            _ => "0".to_string(),
        }
    }

    fn lookup(&self, ty: VariableType, vr: u32) -> Result<Variable> {
        self.variables
            .get(ty, vr)
            .cloned()
            .ok_or_else(|| Error::new(format!("no {ty:?} variable has value reference {vr}")))
    }

    /// Value of a Real variable.
    pub fn get_real(&mut self, vr: u32) -> Result<f64> {
        let (target, causality) = match self.variables.get(VariableType::Real, vr) {
            Some(v) => (v.target, v.causality),
            None => {
                return Err(Error::new(format!(
                    "no Real variable has value reference {vr}"
                )))
            }
        };
        let value = match target {
            Target::Fixed { key, component } => {
                match read_parameter(&self.parameters, key, component) {
                    Some(p) => p,
                    None => {
                        self.ensure_outputs()?;
                        self.outputs.body[body_output_slot(key) + component]
                    }
                }
            }
            Target::Interface {
                index,
                quantity,
                component,
            } => {
                if causality == crate::model::Causality::Input {
                    self.inputs[index][quantity.slot() as usize + component]
                } else {
                    self.ensure_outputs()?;
                    self.outputs.interfaces[index][quantity.slot() as usize + component]
                }
            }
        };
        // Never hand out a NaN: the state is checked after every step, so this is a guard.
        if value.is_finite() {
            Ok(value)
        } else {
            Err(Error::new(format!(
                "value reference {vr} evaluated to {value}: the state is not finite"
            )))
        }
    }

    /// Sets a Real parameter or input; rejects NaN, infinities and out-of-range values with a
    /// message naming the variable; a rejected value changes nothing. Allocation-free unless it
    /// fails.
    pub fn set_real(&mut self, vr: u32, value: f64) -> Result<()> {
        let v = self
            .variables
            .get(VariableType::Real, vr)
            .ok_or_else(|| Error::new(format!("no Real variable has value reference {vr}")))?;
        match v.target {
            Target::Fixed { key, component } => {
                Parameters::check_real(&v.name, key, value)?;
                let p = write_parameter(&mut self.parameters, key, component).ok_or_else(|| {
                    Error::new(format!("{} is an output and cannot be set", v.name))
                })?;
                *p = value;
            }
            Target::Interface {
                index,
                quantity,
                component,
            } => {
                if !value.is_finite() {
                    return Err(Error::invalid_value(&v.name, value, "not a finite number"));
                }
                if v.causality != crate::model::Causality::Input {
                    return Err(Error::new(format!(
                        "{} is an output and cannot be set",
                        v.name
                    )));
                }
                self.resample_inputs(index);
                self.inputs[index][quantity.slot() as usize + component] = value;
            }
        }
        Ok(())
    }

    pub fn get_integer(&mut self, vr: u32) -> Result<i32> {
        let v = self.lookup(VariableType::Integer, vr)?;
        match v.target {
            Target::Fixed { key, .. } => read_integer(&self.parameters, key),
            _ => None,
        }
        .ok_or_else(|| Error::new(format!("no Integer variable has value reference {vr}")))
    }

    pub fn set_integer(&mut self, vr: u32, value: i32) -> Result<()> {
        let v = self.lookup(VariableType::Integer, vr)?;
        if let Some(e) = v.declared_type.and_then(EnumerationSpec::by_name) {
            if value < 1 || value as usize > e.items.len() {
                let names: Vec<String> = e
                    .items
                    .iter()
                    .enumerate()
                    .map(|(k, (name, _))| format!("{} = {name}", k + 1))
                    .collect();
                return Err(Error::invalid_value(
                    &v.name,
                    value,
                    &format!("not an item of {} ({})", e.name, names.join(", ")),
                ));
            }
        }
        match v.target {
            Target::Fixed {
                key: FixedKey::MaxIterations,
                ..
            } => {
                if value < 1 {
                    return Err(Error::invalid_value(&v.name, value, "must be at least 1"));
                }
                self.parameters.max_iterations = value;
                Ok(())
            }
            Target::Fixed {
                key: FixedKey::Integrator,
                ..
            } => {
                self.parameters.integrator = value;
                Ok(())
            }
            Target::Fixed {
                key: FixedKey::AndersonDepth,
                ..
            } => {
                if !(0..=MAX_DEPTH as i32).contains(&value) {
                    return Err(Error::invalid_value(
                        &v.name,
                        value,
                        &format!("must lie in [0, {MAX_DEPTH}]"),
                    ));
                }
                self.parameters.anderson_depth = value;
                Ok(())
            }
            Target::Fixed {
                key: FixedKey::Formulation,
                ..
            } => {
                self.parameters.formulation = value;
                Ok(())
            }
            Target::Fixed {
                key: FixedKey::Stiffening,
                ..
            } => {
                self.parameters.stiffening = value;
                Ok(())
            }
            Target::Fixed {
                key: FixedKey::Frames,
                ..
            } => {
                if value < 1 || value as usize > self.mesh.element_count() {
                    return Err(Error::invalid_value(
                        &v.name,
                        value,
                        &format!(
                            "must lie in [1, {}] (the number of elements)",
                            self.mesh.element_count()
                        ),
                    ));
                }
                self.parameters.frames = value;
                Ok(())
            }
            Target::Fixed {
                key: FixedKey::Modes,
                ..
            } => {
                if value < 0 {
                    return Err(Error::invalid_value(
                        &v.name,
                        value,
                        "must not be negative (0: the full mesh)",
                    ));
                }
                self.parameters.modes = value;
                Ok(())
            }
            _ => Err(Error::new(format!("{} cannot be set", v.name))),
        }
    }

    pub fn get_boolean(&mut self, vr: u32) -> Result<bool> {
        let v = self.lookup(VariableType::Boolean, vr)?;
        match v.target {
            Target::Fixed { key, .. } => read_boolean(&self.parameters, key),
            _ => None,
        }
        .ok_or_else(|| Error::new(format!("no Boolean variable has value reference {vr}")))
    }

    pub fn set_boolean(&mut self, vr: u32, value: bool) -> Result<()> {
        let v = self.lookup(VariableType::Boolean, vr)?;
        match v.target {
            Target::Fixed {
                key: FixedKey::NonlinearForces,
                ..
            } => {
                self.parameters.nonlinear_forces = value;
                Ok(())
            }
            Target::Fixed {
                key: FixedKey::Auto,
                ..
            } => {
                self.parameters.auto = value;
                Ok(())
            }
            _ => Err(Error::new(format!("{} cannot be set", v.name))),
        }
    }

    /// Checks a value for a Real variable as [`Slave::set_real`] would, without setting it (so
    /// that an `fmi2SetReal` call with one bad value sets none). Allocation-free unless it fails.
    pub fn check_real(&self, vr: u32, value: f64) -> Result<()> {
        let v = self
            .variables
            .get(VariableType::Real, vr)
            .ok_or_else(|| Error::new(format!("no Real variable has value reference {vr}")))?;
        match v.target {
            Target::Fixed { key, .. } => Parameters::check_real(&v.name, key, value),
            Target::Interface { .. } if !value.is_finite() => {
                Err(Error::invalid_value(&v.name, value, "not a finite number"))
            }
            Target::Interface { .. } => Ok(()),
        }
    }

    /// `fmi2SetRealInputDerivatives`: `values[k]` is the `orders[k]`-th time derivative (1 or 2)
    /// of the force or torque input `vrs[k]` of a force interface, with respect to the
    /// communication point. Over the following `fmi2DoStep` the input is extrapolated as
    /// `u(t) = u + u'·(t − t_c) + u''·(t − t_c)²/2` and applied at the end of every internal
    /// step (see [`Slave::do_step`]); a derivative stays in force until it is set again (0
    /// switches it off) and `fmi2Reset` clears it. Motion interfaces already extrapolate their
    /// pose with their velocity inputs: derivatives of their inputs are refused. All or nothing:
    /// one rejected entry sets none. Allocation-free unless it fails.
    pub fn set_real_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> Result<()> {
        for ((&vr, &order), &value) in vrs.iter().zip(orders).zip(values) {
            self.input_derivative_slot(vr, order, value)?;
        }
        for ((&vr, &order), &value) in vrs.iter().zip(orders).zip(values) {
            let (index, order, slot) = self.input_derivative_slot(vr, order, value)?;
            self.resample_inputs(index);
            self.input_derivatives[index][order][slot] = value;
        }
        Ok(())
    }

    /// Where derivative `order` of input `vr` is kept (interface, order − 1, slot), after
    /// checking the request.
    fn input_derivative_slot(
        &self,
        vr: u32,
        order: i32,
        value: f64,
    ) -> Result<(usize, usize, usize)> {
        let v = self
            .variables
            .get(VariableType::Real, vr)
            .ok_or_else(|| Error::new(format!("no Real variable has value reference {vr}")))?;
        if v.causality != crate::model::Causality::Input {
            return Err(Error::new(format!(
                "{} (value reference {vr}) is not an input: only inputs have derivatives to set",
                v.name
            )));
        }
        if !(1..=MAX_INPUT_DERIVATIVE_ORDER).contains(&order) {
            return Err(Error::invalid_value(
                &format!("the order of the derivative of {}", v.name),
                order,
                &format!("must be 1 or {MAX_INPUT_DERIVATIVE_ORDER}"),
            ));
        }
        if !value.is_finite() {
            return Err(Error::invalid_value(
                &format!("derivative of order {order} of {}", v.name),
                value,
                "not a finite number",
            ));
        }
        match v.target {
            Target::Interface {
                index,
                quantity: q @ (InterfaceQuantity::Force | InterfaceQuantity::Torque),
                component,
            } if self.interfaces[index].kind == InterfaceKind::Force => {
                Ok((index, order as usize - 1, q.slot() as usize + component))
            }
            _ => Err(Error::new(format!(
                "{} (value reference {vr}): input derivatives are supported for the force and torque inputs of force interfaces; a motion interface's pose is extrapolated with its velocity inputs",
                v.name
            ))),
        }
    }

    /// `fmi2GetRealOutputDerivatives`: the `order`-th time derivative (1 or 2) of an output at the
    /// current time. Available:
    ///
    /// | output | order 1 | order 2 |
    /// | --- | --- | --- |
    /// | `<i>.position` (force interface) | `<i>.velocity` | `<i>.acceleration` |
    /// | `<i>.rotation` | `[ω]× R` | `([α]× + [ω]×[ω]×) R` |
    /// | `<i>.velocity`, `<i>.angularVelocity` | `<i>.acceleration`, `<i>.angularAcceleration` | — |
    /// | `body.position` | `body.velocity` | centre-of-mass acceleration |
    /// | `body.velocity` | centre-of-mass acceleration | — |
    /// | `body.linearMomentum` | total mass × centre-of-mass acceleration | — |
    /// | `body.rotation` | `[ω]× R` (`ω` = `body.angularVelocity`) | — |
    ///
    /// An interface's rates are those of the least-squares rigid motion of its node set (the
    /// velocity and acceleration outputs): the exact time derivatives of its pose for a rigid
    /// motion of the set, and within the set's deformation rate otherwise. Other outputs
    /// (reactions, energies, momenta' rates other than the above) have no derivative: an error.
    pub fn get_real_output_derivative(&mut self, vr: u32, order: i32) -> Result<f64> {
        let v = self
            .variables
            .get(VariableType::Real, vr)
            .ok_or_else(|| Error::new(format!("no Real variable has value reference {vr}")))?;
        let (target, causality) = (v.target, v.causality);
        // The name only for messages (no allocation on the way to a value).
        let name = |s: &Slave| {
            s.variables
                .get(VariableType::Real, vr)
                .map_or(String::new(), |v| v.name.clone())
        };
        if causality != crate::model::Causality::Output {
            return Err(Error::new(format!(
                "{} (value reference {vr}) is not an output: only outputs have derivatives to get",
                name(self)
            )));
        }
        if !(1..=MAX_OUTPUT_DERIVATIVE_ORDER).contains(&order) {
            return Err(Error::invalid_value(
                &format!("the order of the derivative of {}", name(self)),
                order,
                &format!("must be 1 or {MAX_OUTPUT_DERIVATIVE_ORDER} (maxOutputDerivativeOrder)"),
            ));
        }
        self.ensure_outputs()?;
        let rotation_rate = |r: &[f64], w: &[f64], a: Option<&[f64]>, c: usize| {
            let r = Matrix3::from_row_slice(r);
            let w = Vector3::from_column_slice(w).cross_matrix();
            let rate = match a {
                None => w * r,
                Some(a) => (Vector3::from_column_slice(a).cross_matrix() + w * w) * r,
            };
            rate[(c / 3, c % 3)]
        };
        use InterfaceQuantity as Q;
        let slot = |q: Q| q.slot() as usize;
        let value = match target {
            Target::Interface {
                index,
                quantity,
                component: c,
            } if self.interfaces[index].kind == InterfaceKind::Force => {
                let out = &self.outputs.interfaces[index];
                let three = |q: Q| &out[slot(q)..slot(q) + 3];
                match (quantity, order) {
                    (Q::Position, 1) => Some(out[slot(Q::Velocity) + c]),
                    (Q::Position, 2) | (Q::Velocity, 1) => Some(out[slot(Q::Acceleration) + c]),
                    (Q::AngularVelocity, 1) => Some(out[slot(Q::AngularAcceleration) + c]),
                    (Q::Rotation, 1) => Some(rotation_rate(
                        &out[slot(Q::Rotation)..slot(Q::Rotation) + 9],
                        three(Q::AngularVelocity),
                        None,
                        c,
                    )),
                    (Q::Rotation, 2) => Some(rotation_rate(
                        &out[slot(Q::Rotation)..slot(Q::Rotation) + 9],
                        three(Q::AngularVelocity),
                        Some(three(Q::AngularAcceleration)),
                        c,
                    )),
                    _ => None,
                }
            }
            Target::Fixed { key, component: c } => {
                let body = &self.outputs.body;
                let acom = &self.outputs.body_acceleration;
                let mass = self.model.as_ref().map_or(0.0, |m| m.body.total_mass);
                match (key, order) {
                    (FixedKey::BodyPosition, 1) => Some(body[12 + c]),
                    (FixedKey::BodyPosition, 2) | (FixedKey::BodyVelocity, 1) => Some(acom[c]),
                    (FixedKey::BodyLinearMomentum, 1) => Some(mass * acom[c]),
                    (FixedKey::BodyRotation, 1) => {
                        Some(rotation_rate(&body[3..12], &body[15..18], None, c))
                    }
                    _ => None,
                }
            }
            _ => None,
        };
        match value {
            Some(x) if x.is_finite() => Ok(x),
            Some(x) => Err(Error::new(format!(
                "the derivative of order {order} of {} evaluated to {x}: the state is not finite",
                name(self)
            ))),
            None => Err(Error::new(format!(
                "{} (value reference {vr}) has no derivative of order {order} (available: interface position and rotation up to order 2, velocity and angularVelocity order 1; body.position up to order 2, body.velocity, body.linearMomentum and body.rotation order 1)",
                name(self)
            ))),
        }
    }

    /// `fmi2DoStep`: advances from `current_communication_point` (must match the internal time
    /// within a relative 1e-5 of the step) by `communication_step_size` > 0, in equal internal
    /// steps no longer than `solver.stepSize`. On error the state is unchanged; a step that does
    /// not converge is an [`ErrorKind::Discard`].
    pub fn do_step(
        &mut self,
        current_communication_point: f64,
        communication_step_size: f64,
    ) -> Result<()> {
        let big_h = communication_step_size;
        if !(big_h.is_finite() && big_h > 0.0) {
            return Err(Error::invalid_value(
                "communicationStepSize",
                big_h,
                "must be positive and finite",
            ));
        }
        let t = self.time();
        if self.dynamics.is_none() {
            return Err(Error::new("doStep before the body was initialized"));
        }
        let slack = 1e-5 * big_h + 4.0 * f64::EPSILON * t.abs();
        if !current_communication_point.is_finite()
            || (current_communication_point - t).abs() > slack
        {
            return Err(Error::invalid_value(
                "currentCommunicationPoint",
                current_communication_point,
                &format!("does not match the FMU's time {t} (restore a state with fmi2SetFMUstate to go back)"),
            ));
        }
        // The explicit scheme's internal step is limited to its stable step.
        let largest_step = match self.model.as_ref().and_then(|m| m.explicit.as_ref()) {
            Some(explicit) => self.parameters.step_size.min(explicit.stable_step()),
            None => self.parameters.step_size,
        };
        let substeps = ((big_h / largest_step) * (1.0 - 1e-9)).ceil().max(1.0);
        if substeps > 1e9 {
            return Err(Error::invalid_value(
                "communicationStepSize",
                big_h,
                "needs more than 1e9 internal steps of solver.stepSize",
            ));
        }
        let h = big_h / substeps;
        let n = substeps as usize;
        self.update_driving_frames()?;
        // Factorise (on a cache miss) before anything changes: an error here leaves the state.
        self.matrix_index(h)?;
        let model = self.model.as_mut().expect("matrix_index built the model");
        let dynamics = self.dynamics.as_mut().unwrap();
        choose_features(
            model,
            dynamics,
            self.parameters.tolerance * self.size,
            &mut self.events,
        );
        if let (Some(stiffening), Some(k_g)) = (
            model.stiffening.as_mut(),
            model.workspace.geometric_stiffness.as_mut(),
        ) {
            let s = &dynamics.state;
            stiffening.update(
                &self.mesh,
                &self.parameters.material,
                &model.body,
                &s.position,
                &s.velocity,
                &s.acceleration,
                k_g,
            );
        }
        let backup = self.backup.get_or_insert_with(|| dynamics.state.clone());
        backup.copy_from(&dynamics.state);
        dynamics.state.time = current_communication_point;
        // Held inputs that jump at a communication point are not restarted from consistent
        // accelerations (`generalized_alpha::restart_for_load_change`): that makes one FMU's
        // ZOH response second order in h, but it destabilised the iterated coupling of two FMUs
        // (tests/python/test_coupling.py: the work on A grew from 2.3e-4 J to 1.1 J at
        // H = 2e-4 s). Input derivatives give continuous loads instead.
        let mut result = Ok(());
        for i in 0..n {
            result = self.internal_step(current_communication_point, big_h, i, n, h);
            if result.is_err() {
                break;
            }
        }
        let dynamics = self.dynamics.as_mut().unwrap();
        if result.is_ok() && !dynamics.state.position.iter().all(|x| x.is_finite()) {
            result = Err(Error::discard("the step produced non-finite positions"));
        }
        match result {
            Ok(()) => {
                dynamics.state.time = current_communication_point + big_h;
                // The end state's accelerations belong to the inputs extrapolated to t_c + H.
                dynamics.loads.clone_from(&self.inputs);
                for ((load, d), age) in dynamics
                    .loads
                    .iter_mut()
                    .zip(&self.input_derivatives)
                    .zip(&self.input_ages)
                {
                    extrapolate(load, d, age + big_h);
                }
                dynamics.gravity = self.parameters.gravity;
                self.outputs.valid = false;
                // The small-strain watch: a message when ‖∇ū‖ crosses the threshold (once per
                // crossing; again after it fell below half of it).
                let model = self.model.as_mut().expect("the model exists after a step");
                if let Some((monitor, above)) = &mut model.strain_monitor {
                    let g = monitor
                        .largest_gradient(model.workspace.force_scratch().local_deformation());
                    if g > DEFAULT_THRESHOLD && !*above {
                        *above = true;
                        self.events.push(LogEvent {
                            category: "logEvents",
                            message: format!(
                                "warning: at t = {} the deformation gradient in the co-moving frame reached ‖∇ū‖ ≈ {g:.3} (> {DEFAULT_THRESHOLD}): beyond the small-strain range of the reduced strain the results lose accuracy without other signs; use model.frames > 1 for large bending or model.formulation = full",
                                current_communication_point + big_h
                            ),
                        });
                    } else if g < 0.5 * DEFAULT_THRESHOLD && *above {
                        *above = false;
                        self.events.push(LogEvent {
                            category: "logEvents",
                            message: format!(
                                "at t = {} ‖∇ū‖ ≈ {g:.3} is back within the small-strain range",
                                current_communication_point + big_h
                            ),
                        });
                    }
                }
                if self.results.is_some() {
                    self.write_results();
                }
                Ok(())
            }
            Err(e) => {
                dynamics.state.copy_from(self.backup.as_ref().unwrap());
                self.outputs.valid = false;
                let kind = e.kind;
                let message = format!(
                    "doStep from t = {current_communication_point} by communicationStepSize = {big_h}: {}; the state was rolled back to t = {current_communication_point}{}",
                    e.message,
                    if kind == ErrorKind::Discard {
                        "; retry with a smaller communication step (fmi2SetFMUstate to a saved state, or fmi2Reset)"
                    } else {
                        ""
                    }
                );
                Err(Error { kind, message })
            }
        }
    }

    /// Internal step `i` of `n` (of length `h`) of the communication step from `t_c` by `big_h`.
    /// If it does not converge it is redone as 2, 4, ... 2^[`MAX_STEP_HALVINGS`] steps (each
    /// halving logged under `logEvents`); the error of the last attempt is returned if none
    /// converges, with the state back at the start of this internal step. No allocation unless
    /// a step fails.
    fn internal_step(&mut self, t_c: f64, big_h: f64, i: usize, n: usize, h: f64) -> Result<()> {
        let tau0 = i as f64 * h;
        let mut depth = 0;
        loop {
            let m = 1usize << depth;
            let hs = h / m as f64;
            let index = self.matrix_index(hs)?;
            if depth > 0 {
                let state = &self.dynamics.as_ref().unwrap().state;
                self.retry_backup
                    .get_or_insert_with(|| state.clone())
                    .copy_from(state);
            }
            let result = self.advance(index, t_c, big_h, tau0, hs, m, i + 1 == n);
            let e = match result {
                Ok(()) => return Ok(()),
                Err(e) => e,
            };
            if depth > 0 {
                let state = &mut self.dynamics.as_mut().unwrap().state;
                state.copy_from(self.retry_backup.as_ref().unwrap());
            }
            if e.kind != ErrorKind::Discard {
                return Err(e);
            }
            if depth == MAX_STEP_HALVINGS {
                return Err(Error::discard(format!(
                    "the internal step from t = {} (h = {h:e}) did not converge, nor when retried with {m} steps of h/{m} = {hs:e}: {}",
                    t_c + tau0,
                    e.message
                )));
            }
            depth += 1;
            self.retries += 1;
            self.events.push(LogEvent {
                category: "logEvents",
                message: format!(
                    "internal step from t = {} (h = {hs:e}) did not converge ({}); retrying it as {} steps of {:e} s",
                    t_c + tau0,
                    e.message,
                    1usize << depth,
                    h / (1usize << depth) as f64
                ),
            });
        }
    }

    /// `m` internal steps of `hs` with iteration matrix `index`, from `tau0` after the
    /// communication point `t_c`. Force inputs are taken at each internal step's end,
    /// `u(t_c + τ) = u + u'·τ + u''·τ²/2` (the generalized-α scheme here satisfies the equations
    /// of motion at the end of each internal step, so this is where the load enters); the last
    /// internal step of the communication step uses `τ = big_h` exactly.
    #[allow(clippy::too_many_arguments)]
    fn advance(
        &mut self,
        index: usize,
        t_c: f64,
        big_h: f64,
        tau0: f64,
        hs: f64,
        m: usize,
        last_of_step: bool,
    ) -> Result<()> {
        let settings = IterationSettings {
            absolute_tolerance: self.parameters.tolerance * self.size,
            max_iterations: self.parameters.max_iterations.max(1) as usize,
        };
        let model = self.model.as_mut().expect("the model exists during a step");
        let dynamics = self.dynamics.as_mut().unwrap();
        let gravity = Vector3::from(self.parameters.gravity);
        let interfaces = &self.interfaces;
        let inputs = &self.inputs;
        let derivatives = &self.input_derivatives;
        let ages = &self.input_ages;
        let tau = std::cell::Cell::new(tau0);
        let body = &model.body;
        let loads = |x: &[f64], f: &mut [f64]| {
            apply_loads(
                body,
                interfaces,
                inputs,
                Some((derivatives, ages, tau.get())),
                &gravity,
                x,
                f,
            )
        };
        let driving = &self.driving;
        let prescribe = |t: f64, state: &mut DynamicState| {
            prescribe_motion(body, interfaces, driving, t - t_c, state)
        };
        let problem = generalized_alpha::StepProblem {
            body,
            free: &model.free,
            loads: &loads,
            prescribe: &prescribe,
        };
        // Radau's stages sit inside the step: its loads take the time.
        let timed_loads = |t: f64, x: &[f64], f: &mut [f64]| {
            tau.set(t - t_c);
            loads(x, f)
        };
        let radau_problem = RadauProblem {
            body,
            free: &model.free,
            loads: &timed_loads,
            prescribe: &prescribe,
        };
        for j in 0..m {
            tau.set(if last_of_step && j + 1 == m {
                big_h
            } else {
                tau0 + (j + 1) as f64 * hs
            });
            let report = match (&model.explicit, &mut model.radau) {
                (Some(explicit), _) => {
                    explicit.step(&problem, hs, &mut dynamics.state, &mut model.workspace)?
                }
                (None, Some(radau)) => radau::step(
                    &radau_problem,
                    &mut radau.matrices[index],
                    &settings,
                    hs,
                    &mut dynamics.state,
                    &mut radau.workspace,
                    &mut model.workspace,
                )?,
                (None, None) => generalized_alpha::step(
                    &problem,
                    &mut model.matrices[index],
                    &settings,
                    hs,
                    &mut dynamics.state,
                    &mut model.workspace,
                )?,
            };
            self.statistics.0 += 1;
            self.statistics.1 += report.iterations as u64;
        }
        Ok(())
    }

    /// The inputs' ages at the current time `t_0` (`t_0 − t_s` per interface) and the driving
    /// frames of the motion interfaces there: the frame of the inputs, extrapolated from their
    /// sample time `t_s` to `t_0` (no allocation unless an input is rejected).
    fn update_driving_frames(&mut self) -> Result<()> {
        let t = self.time();
        for (k, interface) in self.interfaces.iter().enumerate() {
            let age = t - self.input_times[k];
            self.input_ages[k] = age;
            if interface.kind == InterfaceKind::Motion {
                let mut frame = driving_frame(&self.body_file.interfaces[k].name, &self.inputs[k])?;
                if age != 0.0 {
                    (frame.position, frame.rotation) = frame.at(age);
                }
                self.driving[k] = frame;
            }
        }
        Ok(())
    }

    /// Makes the current time the sample time of interface `k`'s inputs, before one of them (or
    /// a derivative) is set. Inputs set at time `t_s` describe the interface at `t_s`; those
    /// not set again continue along their extrapolation, so they are moved to the current time
    /// `t` (`τ = t − t_s`): a motion interface's pose with its velocities (`p + v τ`,
    /// `exp([ω]× τ) Q`), a force interface's force and torque with their derivatives
    /// (`u + u'τ + u''τ²/2`, `u' + u''τ`). Before initialization the inputs describe the start
    /// time. Allocation-free.
    fn resample_inputs(&mut self, k: usize) {
        let t = self.time();
        let tau = t - self.input_times[k];
        self.input_times[k] = t;
        if self.dynamics.is_none() || tau == 0.0 {
            return;
        }
        let input = &mut self.inputs[k];
        match self.interfaces[k].kind {
            InterfaceKind::Motion => {
                let slot = |q: InterfaceQuantity| q.slot() as usize;
                let vector = |input: &Inputs, q: InterfaceQuantity| {
                    Vector3::from_column_slice(&input[slot(q)..slot(q) + 3])
                };
                let r = slot(InterfaceQuantity::Rotation);
                let frame = DrivingFrame {
                    position: vector(input, InterfaceQuantity::Position),
                    rotation: Matrix3::from_row_slice(&input[r..r + 9]),
                    velocity: vector(input, InterfaceQuantity::Velocity),
                    angular_velocity: vector(input, InterfaceQuantity::AngularVelocity),
                };
                let (p, q) = frame.at(tau);
                let at = slot(InterfaceQuantity::Position);
                input[at..at + 3].copy_from_slice(p.as_slice());
                for (j, value) in input[r..r + 9].iter_mut().enumerate() {
                    *value = q[(j / 3, j % 3)];
                }
            }
            InterfaceKind::Force => {
                let d = &mut self.input_derivatives[k];
                extrapolate(input, d, tau);
                for s in 0..6 {
                    d[0][s] += d[1][s] * tau;
                }
            }
            InterfaceKind::Fixed | InterfaceKind::Pin | InterfaceKind::Hinge => {}
        }
    }

    /// Builds the model if the parameters it depends on changed (assembly and frames).
    fn ensure_model(&mut self) -> Result<()> {
        let key = self.parameters.model_key();
        if self.model.as_ref().is_some_and(|m| m.key == key) {
            return Ok(());
        }
        let p = &self.parameters;
        p.material.validate()?;
        let reference: Vec<f64> = self.mesh.nodes().iter().flatten().copied().collect();
        // HRZ-lumped masses: the frame weights, the patches' weights, the explicit scheme's mass.
        // Material regions: each element's material (the body's outside every region).
        let regions = &self.body_file.regions;
        if !regions.is_empty() {
            let unsupported = if p.formulation == FORMULATION_FULL {
                Some("model.formulation = full")
            } else if p.stiffening != 1 {
                Some("model.stiffening other than none")
            } else if p.frames > 1 {
                Some("model.frames > 1")
            } else if !p.output_directory.is_empty() {
                Some("output.directory (the stress output uses one material)")
            } else {
                None
            };
            if let Some(what) = unsupported {
                return Err(Error::new(format!(
                    "material regions ('{}'{}) are supported by the reduced-strain body with one frame and no stiffening only, not with {what}",
                    regions[0].name,
                    if regions.len() > 1 { ", ..." } else { "" }
                )));
            }
        }
        let element_material = |e: usize| match self.element_regions[e] {
            Some(k) => IsotropicMaterial {
                youngs_modulus: regions[k].youngs_modulus,
                poisson_ratio: p.material.poisson_ratio,
                density: regions[k].density.unwrap_or(p.material.density),
            },
            None => p.material,
        };
        let density = |e: usize| element_material(e).density;
        let lumped = fem::lumped_masses_of(&self.mesh, &density);
        let options = BodyOptions {
            nonlinear_forces: p.nonlinear_forces,
            damping_alpha: p.damping_alpha,
            damping_beta: p.damping_beta,
        };
        let mass_matrix = fem::scalar_mass_matrix_of(&self.mesh, &density);
        let stiffness_matrix = fem::stiffness_matrix_of(&self.mesh, &element_material);
        if p.modes > 0 {
            self.check_reducible()?;
            let p = &self.parameters;
            let started = std::time::Instant::now();
            let (boundary, loaded): (Vec<&NodeSet>, Vec<&NodeSet>) = {
                let sets = |kinds: &[InterfaceKind]| {
                    self.interfaces
                        .iter()
                        .filter(|i| kinds.contains(&i.kind))
                        .map(|i| &i.set)
                        .collect::<Vec<_>>()
                };
                (
                    sets(&[InterfaceKind::Fixed, InterfaceKind::Motion]),
                    sets(&[InterfaceKind::Force]),
                )
            };
            let reduction = Reduction::new(
                &reference,
                &mass_matrix,
                &stiffness_matrix,
                &lumped,
                &boundary,
                &loaded,
                p.modes as usize,
            )?;
            let frequencies: Vec<String> = reduction
                .mode_eigenvalues
                .iter()
                .map(|l| format!("{:.4}", l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)))
                .collect();
            self.events.push(LogEvent {
                category: "logEvents",
                message: format!(
                    "reduced the body (model.modes = {}): {} nodes → {} fields ({} coordinates); fixed-interface mode frequencies [{}] Hz ({:.3} s)",
                    p.modes,
                    reduction.node_count,
                    reduction.field_count,
                    3 * reduction.field_count,
                    frequencies.join(", "),
                    started.elapsed().as_secs_f64()
                ),
            });
            let mut held = reduction.held.iter();
            for interface in &mut self.interfaces {
                let holds = matches!(interface.kind, InterfaceKind::Fixed | InterfaceKind::Motion);
                let coordinates = if holds {
                    held.next().cloned().unwrap_or_default()
                } else {
                    Vec::new()
                };
                interface.set.set_reduction(Some((&reduction, coordinates)));
            }
            let mut clamped = vec![false; reduction.field_count];
            for interface in &self.interfaces {
                if matches!(interface.kind, InterfaceKind::Fixed | InterfaceKind::Motion) {
                    for k in interface.set.held_indices() {
                        clamped[k] = true;
                    }
                }
            }
            let body = Body::reduced(reduction, options);
            return self.finish_model(key, body, clamped, &lumped);
        }
        for interface in &mut self.interfaces {
            interface.set.set_reduction(None);
        }
        let p = &self.parameters;
        let body = Body::new(
            reference,
            mass_matrix,
            stiffness_matrix,
            lumped.clone(),
            options,
        );
        let body = if p.formulation == FORMULATION_FULL {
            body.with_full_formulation(SvkSolid::new(&self.mesh, &p.material))
        } else if p.frames > 1 {
            body.with_patches(Patches::along_principal_axis(
                &self.mesh,
                &p.material,
                &lumped,
                p.frames as usize,
            )?)
        } else {
            body
        };
        let clamped = self.clamped.clone();
        self.finish_model(key, body, clamped, &lumped)
    }

    /// `model.modes > 0` supports one generalized-α, single-frame, reduced-strain body without
    /// stiffening, pins or hinges; anything else is an error naming the parameter.
    fn check_reducible(&self) -> Result<()> {
        let p = &self.parameters;
        let reason = if p.formulation == FORMULATION_FULL {
            Some(
                "model.formulation = full is the nonlinear reference on the whole mesh".to_string(),
            )
        } else if p.frames > 1 {
            Some(format!(
                "model.frames = {}: a reduced body has one co-moving frame",
                p.frames
            ))
        } else if p.stiffening != STIFFENING_NONE {
            Some(format!(
                "model.stiffening = {}: geometric stiffening is not projected on the modes",
                if p.stiffening == STIFFENING_INERTIAL {
                    "inertial"
                } else {
                    "stress"
                }
            ))
        } else if p.integrator == INTEGRATOR_CENTRAL_DIFFERENCE {
            Some("solver.integrator = centralDifference needs a lumped (diagonal) mass; the reduced mass is dense".to_string())
        } else {
            self.interfaces
                .iter()
                .zip(&self.body_file.interfaces)
                .find(|(i, _)| matches!(i.kind, InterfaceKind::Pin | InterfaceKind::Hinge))
                .map(|(i, spec)| {
                    format!(
                        "interface '{}' is a {:?} support: pins and hinges are not available on a reduced body (use a fixed support or a motion interface)",
                        spec.name, i.kind
                    )
                })
        };
        match reason {
            Some(r) => Err(Error::invalid_value(
                "model.modes",
                self.parameters.modes,
                &r,
            )),
            None => Ok(()),
        }
    }

    /// The solver's side of a model build: free nodes, constraints, stiffening, the explicit
    /// scheme, the logs.
    fn finish_model(
        &mut self,
        key: ModelKey,
        body: Body,
        clamped: Vec<bool>,
        lumped: &[f64],
    ) -> Result<()> {
        let p = &self.parameters;
        let started = std::time::Instant::now();
        let mut free = FreeNodes::new(&body, &clamped);
        for (k, interface) in self.interfaces.iter_mut().enumerate() {
            interface.first_constraint = free.constraints.len();
            for (nodes, weights) in &interface.point_constraints {
                // The target is set where the body is placed (ensure_initial_state).
                free.add_point_constraint(
                    &self.body_file.interfaces[k].name,
                    nodes,
                    weights,
                    Vector3::zeros(),
                )?;
            }
        }
        let mut workspace =
            StepWorkspace::with_anderson_depth(&body, &free, p.anderson_depth as usize);
        let stiffening = match p.stiffening {
            STIFFENING_INERTIAL => Some(Stiffening::inertial(
                &self.mesh,
                &p.material,
                &body,
                &self.clamped,
            )?),
            STIFFENING_STRESS => Some(Stiffening::stress(&self.mesh, &body)),
            _ => None,
        };
        if stiffening.is_some() {
            workspace.geometric_stiffness = Some(Stiffening::pattern(&self.mesh));
        }
        // model.auto: indicators for the allowed terms of the one-frame reduced-strain body
        // (patches and the full formulation have no switchable terms: forced as given).
        let allowed = Features {
            nonlinear_forces: p.nonlinear_forces,
            stiffening: stiffening.is_some(),
        };
        // The reduced body is forced as given too (its indicators would need the expanded mesh).
        let single = p.formulation != FORMULATION_FULL && p.frames == 1 && body.reduction.is_none();
        let indicators = (p.auto && single && (allowed.nonlinear_forces || allowed.stiffening))
            .then(|| {
                FeatureIndicators::new(
                    &self.mesh,
                    &body,
                    &free.nodes,
                    &free.stiffness,
                    &free.mass,
                    !free.clamped.is_empty(),
                    stiffening.as_ref(),
                )
            });
        let mut body = body;
        body.nonlinear_forces_switchable = indicators.is_some() && allowed.nonlinear_forces;
        if let Some(ind) = &indicators {
            let verdict = |allowed: bool, estimated: bool, why: &str| {
                if !allowed {
                    "not allowed (off)".to_string()
                } else if estimated {
                    "allowed, switched per communication step by its indicator".to_string()
                } else {
                    format!("allowed, always on ({why})")
                }
            };
            self.events.push(LogEvent {
                category: "logEvents",
                message: format!(
                    "model.auto: f_nl {}; stiffening {}; lowest natural frequency {}; a term is switched on when {} × its estimated effect exceeds solver.tolerance × size = {:.3e} m, off when it stayed below {} of that for one period 2π/ω₁",
                    verdict(
                        allowed.nonlinear_forces,
                        ind.estimates_nonlinear_forces(),
                        "no estimate for a body without fixed supports or motion interfaces: its spurious moment accumulates"
                    ),
                    verdict(allowed.stiffening, ind.estimates_stiffening(), "no estimate"),
                    ind.first_frequency()
                        .map_or("not computed".to_string(), |w| format!("{w:.4e} rad/s")),
                    feature_indicators::SAFETY,
                    p.tolerance * self.size,
                    feature_indicators::HYSTERESIS
                ),
            });
        }
        self.events.push(LogEvent {
            category: "logEvents",
            message: format!(
                "assembled the body: {} {}, {} elements, {} DOF ({} free), nnz(K) = {}, mass {:.6e} kg ({:.3} s)",
                body.node_count(),
                if body.reduction.is_some() { "fields" } else { "nodes" },
                self.mesh.element_count(),
                body.reference.len(),
                free.dof_count(),
                body.stiffness_matrix.nnz(),
                body.total_mass,
                started.elapsed().as_secs_f64()
            ),
        });
        let explicit = if p.integrator == INTEGRATOR_CENTRAL_DIFFERENCE {
            let scheme = CentralDifference::new(&body, lumped, &free)?;
            self.events.push(LogEvent {
                category: "logEvents",
                message: format!(
                    "central difference: highest frequency {:.4e} rad/s, stable step {:.4e} s ({} × 2/ω_max){}",
                    scheme.highest_frequency,
                    scheme.stable_step(),
                    crate::solver::central_difference::STABILITY_MARGIN,
                    if p.step_size > scheme.stable_step() {
                        format!(
                            "; solver.stepSize = {} exceeds it: internal steps are limited to the stable step",
                            p.step_size
                        )
                    } else {
                        String::new()
                    }
                ),
            });
            Some(scheme)
        } else {
            None
        };
        let monitored =
            p.formulation != FORMULATION_FULL && p.frames == 1 && body.reduction.is_none();
        let radau = if p.integrator == INTEGRATOR_RADAU {
            // Radau's constant matrices hold the rotated small-strain stiffness: no tangent for
            // the full formulation.
            if p.formulation == FORMULATION_FULL {
                return Err(Error::new(
                    "solver.integrator = radauIIA supports model.formulation = reducedStrain only (its constant iteration matrices hold the rotated small-strain stiffness); use generalizedAlpha for the full formulation",
                ));
            }
            Some(RadauModel {
                tableau: RadauIIA::new(),
                matrices: Vec::new(),
                workspace: RadauWorkspace::with_anderson_depth(
                    &body,
                    &free,
                    p.anderson_depth as usize,
                ),
            })
        } else {
            None
        };
        self.model = Some(Model {
            key,
            radau,
            body,
            scheme: GeneralizedAlpha::new(p.rho_inf),
            matrices: Vec::new(),
            mass: ConsistentAcceleration::new(&free)?,
            explicit,
            strain_monitor: monitored.then(|| (StrainMonitor::new(&self.mesh), false)),
            free,
            workspace,
            stiffening,
            indicators,
            allowed,
            parked_geometric_stiffness: None,
        });
        self.dynamics = None;
        // The backups have the old model's size (a changed model.modes changes it).
        self.backup = None;
        self.retry_backup = None;
        let size = self.model.as_ref().map_or(0, |m| m.body.reference.len());
        self.outputs.momentum = vec![0.0; size];
        Ok(())
    }

    /// Index of the factorization for internal step `h` in the cache (factorising on a miss and
    /// evicting the least recently used entry when [`MATRIX_CACHE_SIZE`] are kept).
    fn matrix_index(&mut self, h: f64) -> Result<usize> {
        self.ensure_model()?;
        let p = &self.parameters;
        let model = self.model.as_mut().unwrap();
        if model.explicit.is_some() {
            return Ok(usize::MAX); // the explicit scheme factorises nothing
        }
        let events = &mut self.events;
        if let Some(radau) = &mut model.radau {
            return cached_factorization(
                &mut radau.matrices,
                h,
                |m| m.step_size,
                || {
                    RadauMatrix::new(
                        &model.body,
                        &model.free,
                        &radau.tableau,
                        h,
                        p.damping_alpha,
                        p.damping_beta,
                    )
                },
                |matrix, seconds| {
                    format!(
                    "factorised the Radau IIA matrices for internal step h = {h:e} s: real Cholesky nnz(L) = {} and complex LU ({seconds:.3} s); they serve every step of this size",
                    matrix.real_factor_nnz()
                )
                },
                events,
            );
        }
        cached_factorization(
            &mut model.matrices,
            h,
            |m| m.step_size,
            || {
                IterationMatrix::new(
                    &model.body,
                    &model.free,
                    &model.scheme,
                    h,
                    p.damping_alpha,
                    p.damping_beta,
                )
            },
            |matrix, seconds| {
                format!(
                "factorised the iteration matrix for internal step h = {h:e} s: nnz(L) = {} ({seconds:.3} s); it serves every step of this size",
                matrix.factor.factor_nnz()
            )
            },
            events,
        )
    }

    /// Places the body rigidly and computes the consistent initial acceleration (DESIGN.md
    /// section 4): with motion interfaces, so that the first one's constraint holds at t0 with its
    /// input velocities (the others must agree with that rigid placement); without, at
    /// `initial.position`/`initial.rotation` with `initial.velocity`/`initial.angularVelocity`.
    fn ensure_initial_state(&mut self) -> Result<()> {
        self.ensure_model()?;
        self.update_driving_frames()?;
        let p = &self.parameters;
        // The placement x_i = origin + Q (X_i − anchor), ẋ_i = v + ω × Q (X_i − anchor).
        let first_motion = self
            .interfaces
            .iter()
            .position(|i| i.kind == InterfaceKind::Motion);
        let (origin, q, anchor, v0, w0, source) = match first_motion {
            Some(k) => {
                let f = &self.driving[k];
                let name = &self.body_file.interfaces[k].name;
                (
                    f.position,
                    f.rotation,
                    self.interfaces[k].set.reference_point,
                    f.velocity,
                    f.angular_velocity,
                    format!("the inputs of motion interface '{name}'"),
                )
            }
            None => {
                let q = Matrix3::from_row_slice(&p.initial_rotation);
                let deviation = (q.transpose() * q - Matrix3::identity()).amax();
                if deviation > 1e-6 || q.determinant() <= 0.0 {
                    return Err(Error::new(format!(
                        "initial.rotation = {:?} rejected: not a rotation matrix (|QᵀQ − I| = {deviation:.2e}, det = {:.6})",
                        p.initial_rotation,
                        q.determinant()
                    )));
                }
                (
                    Vector3::from(p.initial_position),
                    nearest_rotation(&q),
                    Vector3::zeros(),
                    Vector3::from(p.initial_velocity),
                    Vector3::from(p.initial_angular_velocity),
                    "initial.velocity and initial.angularVelocity".to_string(),
                )
            }
        };
        let has_fixed = self
            .interfaces
            .iter()
            .any(|i| i.kind == InterfaceKind::Fixed);
        if has_fixed && (v0.norm() > 0.0 || w0.norm() > 0.0) {
            return Err(Error::new(format!(
                "{source} rejected: velocity {:?}, angular velocity {:?}, but a body held by a fixed support must start at rest",
                v0.as_slice(),
                w0.as_slice()
            )));
        }
        let model = self.model.as_mut().unwrap();
        // model.auto starts with the terms that have an estimate off (the body is placed
        // rigidly: ū = 0, where both vanish); without it the switches are forced.
        let features = match &model.indicators {
            Some(ind) => Features {
                nonlinear_forces: model.allowed.nonlinear_forces
                    && !ind.estimates_nonlinear_forces(),
                stiffening: model.allowed.stiffening && !ind.estimates_stiffening(),
            },
            None => model.allowed,
        };
        model.apply_features(features);
        let body = &model.body;
        let n = body.node_count();
        let mut state = DynamicState {
            time: self.start_time,
            position: vec![0.0; 3 * n],
            velocity: vec![0.0; 3 * n],
            acceleration: vec![0.0; 3 * n],
            pseudo_acceleration: vec![0.0; 3 * n],
            multipliers: vec![0.0; model.free.multiplier_count()],
        };
        body.place_rigidly(
            &origin,
            &q,
            &anchor,
            &v0,
            &w0,
            &mut state.position,
            &mut state.velocity,
        );
        // Every other motion interface must hold in this rigid placement.
        let tolerance = 1e-6 * self.size;
        for (k, interface) in self.interfaces.iter().enumerate() {
            if interface.kind != InterfaceKind::Motion || Some(k) == first_motion {
                continue;
            }
            let mut placed = state.clone();
            interface.set.prescribe(
                &body.reference,
                &self.driving[k],
                0.0,
                &mut placed.position,
                &mut placed.velocity,
                &mut placed.acceleration,
            );
            let gap = placed
                .position
                .iter()
                .zip(&state.position)
                .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            if gap > tolerance {
                return Err(Error::new(format!(
                    "motion interfaces '{}' and '{}' disagree at t0: no rigid placement of the body satisfies both (their inputs differ by {gap:.3e} m at the nodes; tolerance {tolerance:.1e} m)",
                    self.body_file.interfaces[first_motion.unwrap()].name,
                    self.body_file.interfaces[k].name
                )));
            }
        }
        for interface in &self.interfaces {
            if interface.kind == InterfaceKind::Fixed {
                for i in interface.set.held_indices() {
                    state.velocity[3 * i..3 * i + 3].fill(0.0);
                }
            }
        }
        prescribe_motion(body, &self.interfaces, &self.driving, 0.0, &mut state);
        // Pins and hinges hold their centroids where the body was placed; the placement's
        // velocity must not move them.
        for (k, interface) in self.interfaces.iter().enumerate() {
            let first = interface.first_constraint;
            for constraint in
                &mut model.free.constraints[first..first + interface.point_constraints.len()]
            {
                constraint.target = constraint.centroid(&state.position);
                let speed = constraint.centroid(&state.velocity).norm();
                if speed > 1e-9 * (1.0 + v0.norm() + w0.norm() * self.size) {
                    return Err(Error::new(format!(
                        "{source} rejected: the initial velocity moves the {:?} support '{}' at {speed:.3e} m/s; the body may only turn about it",
                        interface.kind,
                        self.body_file.interfaces[k].name
                    )));
                }
            }
        }
        let body = &model.body;
        let gravity = Vector3::from(p.gravity);
        let interfaces = &self.interfaces;
        let inputs = &self.inputs;
        let loads =
            |x: &[f64], f: &mut [f64]| apply_loads(body, interfaces, inputs, None, &gravity, x, f);
        generalized_alpha::initial_acceleration(
            body,
            &model.free,
            &loads,
            &mut state,
            &mut model.workspace,
            &mut model.mass,
        )?;
        if let Some(explicit) = &model.explicit {
            // The explicit scheme's accelerations belong to the lumped mass.
            explicit.accelerations(body, &model.free, &loads, &mut state, &mut model.workspace);
        }
        self.dynamics = Some(Dynamics {
            state,
            loads: self.inputs.clone(),
            gravity: p.gravity,
            features,
            quiet_since: [NOT_QUIET; 2],
        });
        self.outputs.valid = false;
        Ok(())
    }

    /// Computes the outputs of the current state (once per state).
    fn ensure_outputs(&mut self) -> Result<()> {
        if self.outputs.valid {
            return Ok(());
        }
        if self.dynamics.is_none() {
            // Initialization mode: outputs of the rigidly placed body with the current inputs.
            self.ensure_initial_state()?;
        }
        let model = self.model.as_mut().unwrap();
        let dynamics = self.dynamics.as_ref().unwrap();
        let state = &dynamics.state;
        let body = &model.body;
        let gravity = Vector3::from(dynamics.gravity);
        let interfaces = &self.interfaces;
        let loads_in = &dynamics.loads;
        let loads = |x: &[f64], f: &mut [f64]| {
            apply_loads(body, interfaces, loads_in, None, &gravity, x, f)
        };
        let kin =
            generalized_alpha::residual(body, &model.free, state, &loads, &mut model.workspace);
        let residual = generalized_alpha::last_residual(&model.workspace);

        // Body outputs (DESIGN.md section 4).
        let m = body.total_mass;
        let (mut com, mut vcom, mut acom) = (Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
        for (i, &mi) in body.mass_row_sums.iter().enumerate() {
            com += mi * node(&state.position, i);
            vcom += mi * node(&state.velocity, i);
            acom += mi * node(&state.acceleration, i);
        }
        com /= m;
        vcom /= m;
        acom /= m;
        self.outputs.body_acceleration = acom.into();
        let (mut angular, mut kinetic) = (Vector3::zeros(), 0.0);
        let momentum = &mut self.outputs.momentum;
        momentum.resize(state.velocity.len(), 0.0); // sized by `finish_model`: no allocation
        body.mass_times(&state.velocity, momentum);
        for i in 0..body.node_count() {
            let mv = node(momentum, i);
            angular += (node(&state.position, i) - body.unit(i) * com).cross(&mv);
            kinetic += 0.5 * node(&state.velocity, i).dot(&mv);
        }
        let r = kin.frame.rotation;
        let omega = r * kin.angular_velocity_body;
        let out = &mut self.outputs.body;
        out[0..3].copy_from_slice(com.as_slice());
        for (k, value) in out[3..12].iter_mut().enumerate() {
            *value = r[(k / 3, k % 3)];
        }
        out[12..15].copy_from_slice(vcom.as_slice());
        out[15..18].copy_from_slice(omega.as_slice());
        out[18..21].copy_from_slice((m * vcom).as_slice());
        out[21..24].copy_from_slice(angular.as_slice());
        out[24] = kinetic;
        out[25] = match &body.full {
            Some(full) => full.strain_energy(&state.position),
            None => kin.strain_energy,
        };

        for (k, interface) in self.interfaces.iter().enumerate() {
            let out = &mut self.outputs.interfaces[k];
            match interface.kind {
                InterfaceKind::Pin | InterfaceKind::Hinge => {
                    // The constraint load on the body is −Cᵀλ: per point constraint a force −λ_k
                    // at its centroid c_k; the torque is taken about the reference point.
                    let p = interface
                        .set
                        .motion(&state.position, &state.velocity, &state.acceleration)
                        .position;
                    let (mut force, mut torque) = (Vector3::zeros(), Vector3::zeros());
                    let first = interface.first_constraint;
                    for (j, constraint) in model.free.constraints
                        [first..first + interface.point_constraints.len()]
                        .iter()
                        .enumerate()
                    {
                        let m = &state.multipliers[3 * (first + j)..3 * (first + j) + 3];
                        let f = -Vector3::new(m[0], m[1], m[2]);
                        force += f;
                        torque += (constraint.centroid(&state.position) - p).cross(&f);
                    }
                    out[0..3].copy_from_slice(force.as_slice());
                    out[3..6].copy_from_slice(torque.as_slice());
                }
                InterfaceKind::Fixed | InterfaceKind::Motion => {
                    // Reaction of the support on the body: λ_C = (M ẍ + f − f_ext)_C.
                    let (f, t) = interface.set.resultant(&state.position, residual);
                    out[0..3].copy_from_slice(f.as_slice());
                    out[3..6].copy_from_slice(t.as_slice());
                }
                InterfaceKind::Force => {
                    out[0..6].copy_from_slice(&dynamics.loads[k][0..6]);
                    let m: InterfaceMotion =
                        interface
                            .set
                            .motion(&state.position, &state.velocity, &state.acceleration);
                    out[6..9].copy_from_slice(m.position.as_slice());
                    for (j, value) in out[9..18].iter_mut().enumerate() {
                        *value = m.rotation[(j / 3, j % 3)];
                    }
                    out[18..21].copy_from_slice(m.velocity.as_slice());
                    out[21..24].copy_from_slice(m.angular_velocity.as_slice());
                    out[24..27].copy_from_slice(m.acceleration.as_slice());
                    out[27..30].copy_from_slice(m.angular_acceleration.as_slice());
                }
            }
        }
        let finite = self.outputs.body.iter().all(|x| x.is_finite())
            && self.outputs.body_acceleration.iter().all(|x| x.is_finite())
            && self
                .outputs
                .interfaces
                .iter()
                .flatten()
                .all(|x| x.is_finite());
        if !finite {
            return Err(Error::new(
                "the outputs of the current state are not finite",
            ));
        }
        self.outputs.valid = true;
        Ok(())
    }
}

/// The point constraints of a pin (the whole set) or a hinge (the two halves of the set on either
/// side of the plane through its centroid normal to `axis`; both halves' centroids must lie on
/// the axis, so that turning about it moves neither: a hole or a face with the axis through its
/// centre). Holding both half-centroids leaves exactly the rotation about the axis free.
fn point_constraints(
    spec: &crate::model::InterfaceSpec,
    nodes: &[usize],
    weights: &[f64],
    reference: &[f64],
    size: f64,
) -> Result<Vec<(Vec<usize>, Vec<f64>)>> {
    let total: f64 = weights.iter().sum();
    let centroid = nodes
        .iter()
        .zip(weights)
        .fold(Vector3::zeros(), |c, (&i, w)| {
            c + *w / total * node(reference, i)
        });
    let tolerance = 1e-9 * size;
    if matches!(spec.kind, InterfaceKind::Pin | InterfaceKind::Hinge) {
        if let Some(p) = spec.reference_point {
            if (Vector3::from(p) - centroid).norm() > tolerance {
                return Err(Error::new(format!(
                    "interface '{}': a {:?} acts at the weighted centroid {:?} of its node set; referencePoint {:?} must be omitted or equal to it",
                    spec.name,
                    spec.kind,
                    centroid.as_slice(),
                    p
                )));
            }
        }
    }
    match spec.kind {
        InterfaceKind::Pin => Ok(vec![(nodes.to_vec(), weights.to_vec())]),
        InterfaceKind::Hinge => {
            let axis = spec.axis.map(Vector3::from).unwrap_or_default();
            if axis.norm().is_nan() || axis.norm() <= 0.0 {
                return Err(Error::new(format!(
                    "interface '{}': a hinge needs a nonzero \"axis\"",
                    spec.name
                )));
            }
            let axis = axis.normalize();
            let mut halves = [(Vec::new(), Vec::new()), (Vec::new(), Vec::new())];
            for (&i, &w) in nodes.iter().zip(weights) {
                let s = (node(reference, i) - centroid).dot(&axis);
                if s.abs() > tolerance {
                    let half = &mut halves[usize::from(s > 0.0)];
                    half.0.push(i);
                    half.1.push(w);
                }
            }
            for (nodes, weights) in &halves {
                let total: f64 = weights.iter().sum();
                if nodes.is_empty() {
                    return Err(Error::new(format!(
                        "interface '{}': the node set does not extend along the hinge axis {:?}",
                        spec.name,
                        axis.as_slice()
                    )));
                }
                let c = nodes
                    .iter()
                    .zip(weights)
                    .fold(Vector3::zeros(), |c, (&i, w)| {
                        c + *w / total * node(reference, i)
                    });
                let off_axis = (c - centroid).cross(&axis).norm();
                if off_axis > 1e-6 * size {
                    return Err(Error::new(format!(
                        "interface '{}': the hinge axis {:?} through the centroid {:?} misses the centroid of one half of the node set by {off_axis:.3e} m; choose a set symmetric about the axis (a hole, or a face with the axis through its centre)",
                        spec.name,
                        axis.as_slice(),
                        centroid.as_slice()
                    )));
                }
            }
            Ok(halves.into_iter().collect())
        }
        _ => Ok(Vec::new()),
    }
}

/// `model.auto`: decides from the state at the communication point which allowed terms are in
/// force over the next communication step (held over its internal steps, like `K_G`), logs each
/// change once under `logEvents` with the estimate and the threshold, and puts the terms into
/// force. A term goes on when `SAFETY × estimate > target`; it goes off when that has stayed
/// below `HYSTERESIS × target` for one period `2π/ω₁` of the lowest mode (a vibrating body's
/// indicators peak twice per period: the dwell keeps a term from switching with the vibration). `target` is the iteration's absolute tolerance `solver.tolerance × size` (m). No
/// allocation unless a decision changes.
fn choose_features(
    model: &mut Model,
    dynamics: &mut Dynamics,
    target: f64,
    events: &mut Vec<LogEvent>,
) {
    if let Some(indicators) = model.indicators.as_mut() {
        let s = &dynamics.state;
        let e = indicators.estimate(&model.body, &s.position, &s.velocity, &s.acceleration);
        let dwell = indicators
            .first_frequency()
            .map_or(0.0, |w| 2.0 * std::f64::consts::PI / w);
        let mut f = dynamics.features;
        let mut decide = |active: &mut bool,
                          quiet_since: &mut f64,
                          allowed: bool,
                          estimate: Option<f64>,
                          name: &str| {
            let Some(e) = estimate.filter(|_| allowed) else {
                *active = allowed;
                *quiet_since = NOT_QUIET;
                return;
            };
            let scaled = feature_indicators::SAFETY * e;
            let next = if *active {
                if scaled >= feature_indicators::HYSTERESIS * target {
                    *quiet_since = NOT_QUIET;
                    true
                } else {
                    if *quiet_since == NOT_QUIET {
                        *quiet_since = s.time;
                    }
                    s.time - *quiet_since < dwell
                }
            } else {
                scaled > target
            };
            if next != *active {
                *active = next;
                events.push(LogEvent {
                    category: "logEvents",
                    message: if next {
                        format!(
                            "model.auto: at t = {} {name} switched on: estimated effect {e:.3e} m, × {} = {scaled:.3e} m > solver.tolerance × size = {target:.3e} m",
                            s.time,
                            feature_indicators::SAFETY
                        )
                    } else {
                        format!(
                            "model.auto: at t = {} {name} switched off: estimated effect {e:.3e} m, × {} = {scaled:.3e} m < {} × solver.tolerance × size = {:.3e} m since t = {} (at least one period 2π/ω₁ = {dwell:.3e} s)",
                            s.time,
                            feature_indicators::SAFETY,
                            feature_indicators::HYSTERESIS,
                            feature_indicators::HYSTERESIS * target,
                            *quiet_since
                        )
                    },
                });
            }
        };
        let [quiet_nl, quiet_stiffening] = &mut dynamics.quiet_since;
        decide(
            &mut f.nonlinear_forces,
            quiet_nl,
            model.allowed.nonlinear_forces,
            e.nonlinear_forces,
            "the nonlinear force f_nl",
        );
        decide(
            &mut f.stiffening,
            quiet_stiffening,
            model.allowed.stiffening,
            e.stiffening,
            "geometric stiffening",
        );
        dynamics.features = f;
    }
    model.apply_features(dynamics.features);
}

/// Clamps the nodes of every motion interface to its driving frame `tau` seconds into the step.
fn prescribe_motion(
    body: &Body,
    interfaces: &[Interface],
    driving: &[DrivingFrame],
    tau: f64,
    state: &mut DynamicState,
) {
    for (interface, frame) in interfaces.iter().zip(driving) {
        if interface.kind == InterfaceKind::Motion {
            interface.set.prescribe(
                &body.reference,
                frame,
                tau,
                &mut state.position,
                &mut state.velocity,
                &mut state.acceleration,
            );
        }
    }
}

/// Index of the factorization for step `h` in `cache`, most recently used last (a rotation of
/// at most [`MATRIX_CACHE_SIZE`] entries: no allocation on a hit). On a miss `factorise()` builds
/// it, the least recently used (the first) is evicted when the cache is full, and
/// `describe(matrix, seconds)` is logged under `logEvents`.
fn cached_factorization<T>(
    cache: &mut Vec<T>,
    h: f64,
    step_size: impl Fn(&T) -> f64,
    factorise: impl FnOnce() -> Result<T>,
    describe: impl Fn(&T, f64) -> String,
    events: &mut Vec<LogEvent>,
) -> Result<usize> {
    if let Some(i) = cache
        .iter()
        .position(|m| (step_size(m) - h).abs() <= 1e-9 * h)
    {
        cache[i..].rotate_left(1);
        return Ok(cache.len() - 1);
    }
    let started = std::time::Instant::now();
    let matrix = factorise()?;
    events.push(LogEvent {
        category: "logEvents",
        message: describe(&matrix, started.elapsed().as_secs_f64()),
    });
    if cache.len() >= MATRIX_CACHE_SIZE {
        cache.remove(0);
    }
    cache.push(matrix);
    Ok(cache.len() - 1)
}

/// The driving frame of motion interface `name` from its inputs: a rotation input within 1e-3 of
/// orthonormal is orthonormalised (nearest rotation), one further off is an error.
fn driving_frame(name: &str, values: &Inputs) -> Result<DrivingFrame> {
    let slot = |q: InterfaceQuantity| q.slot() as usize;
    let vector = |q: InterfaceQuantity| Vector3::from_column_slice(&values[slot(q)..slot(q) + 3]);
    let r = slot(InterfaceQuantity::Rotation);
    let q = Matrix3::from_row_slice(&values[r..r + 9]);
    let deviation = (q.transpose() * q - Matrix3::identity()).amax();
    if deviation > 1e-3 || q.determinant() <= 0.0 {
        return Err(Error::new(format!(
            "{name}.rotation = {:?} rejected: not a rotation matrix (|QᵀQ − I| = {deviation:.2e}, det = {:.6}); inputs within 1e-3 of orthonormal are orthonormalised",
            &values[r..r + 9],
            q.determinant()
        )));
    }
    Ok(DrivingFrame {
        position: vector(InterfaceQuantity::Position),
        rotation: nearest_rotation(&q),
        velocity: vector(InterfaceQuantity::Velocity),
        angular_velocity: vector(InterfaceQuantity::AngularVelocity),
    })
}

/// External loads at positions `x`: gravity `M (1 ⊗ g)` and each force interface's force and
/// torque distributed over its node set; added to `f`. With `extrapolation = (derivatives,
/// ages, τ)` the force inputs are taken `τ` seconds after the start of the step, which is
/// `ages[k]` after interface `k`'s inputs were sampled (see [`extrapolate`]).
fn apply_loads(
    body: &Body,
    interfaces: &[Interface],
    inputs: &[Inputs],
    extrapolation: Option<(&[InputDerivatives], &[f64], f64)>,
    gravity: &Vector3<f64>,
    x: &[f64],
    f: &mut [f64],
) {
    if gravity.norm_squared() > 0.0 {
        body.add_uniform_acceleration_load(gravity, f);
    }
    for (k, (interface, input)) in interfaces.iter().zip(inputs).enumerate() {
        if interface.kind != InterfaceKind::Force {
            continue;
        }
        let mut load = [0.0; 6];
        load.copy_from_slice(&input[..6]);
        if let Some((derivatives, ages, tau)) = extrapolation {
            let d = &derivatives[k];
            let tau = ages[k] + tau;
            for (s, value) in load.iter_mut().enumerate() {
                if d[0][s] != 0.0 || d[1][s] != 0.0 {
                    *value += d[0][s] * tau + 0.5 * d[1][s] * tau * tau;
                }
            }
        }
        if load.iter().any(|&v| v != 0.0) {
            let force = Vector3::new(load[0], load[1], load[2]);
            let torque = Vector3::new(load[3], load[4], load[5]);
            interface.set.distribute(x, &force, &torque, f);
        }
    }
}

/// A force interface's inputs `τ` seconds after their sample time: `u + u'·τ + u''·τ²/2`
/// in the force and torque slots (the only ones with derivatives); the same arithmetic as
/// [`apply_loads`], so the end-of-step loads match those the last internal step used.
fn extrapolate(input: &mut Inputs, d: &InputDerivatives, tau: f64) {
    for s in 0..6 {
        if d[0][s] != 0.0 || d[1][s] != 0.0 {
            input[s] += d[0][s] * tau + 0.5 * d[1][s] * tau * tau;
        }
    }
}

fn component_of(v: &Variable) -> usize {
    match v.target {
        Target::Fixed { component, .. } | Target::Interface { component, .. } => component,
    }
}

/// Offset of a body output in [`Outputs::body`].
fn body_output_slot(key: FixedKey) -> usize {
    match key {
        FixedKey::BodyPosition => 0,
        FixedKey::BodyRotation => 3,
        FixedKey::BodyVelocity => 12,
        FixedKey::BodyAngularVelocity => 15,
        FixedKey::BodyLinearMomentum => 18,
        FixedKey::BodyAngularMomentum => 21,
        FixedKey::BodyKineticEnergy => 24,
        FixedKey::BodyStrainEnergy => 25,
        _ => unreachable!("{key:?} is not a body output"),
    }
}

/// Value of a Real parameter (`None` for outputs and non-Real keys). Allocation-free.
fn read_parameter(p: &Parameters, key: FixedKey, c: usize) -> Option<f64> {
    use FixedKey::*;
    Some(match key {
        YoungsModulus => p.material.youngs_modulus,
        PoissonRatio => p.material.poisson_ratio,
        Density => p.material.density,
        DampingAlpha => p.damping_alpha,
        DampingBeta => p.damping_beta,
        Gravity => p.gravity[c],
        InitialPosition => p.initial_position[c],
        InitialRotation => p.initial_rotation[c],
        InitialVelocity => p.initial_velocity[c],
        InitialAngularVelocity => p.initial_angular_velocity[c],
        StepSize => p.step_size,
        RhoInf => p.rho_inf,
        Tolerance => p.tolerance,
        OutputInterval => p.output_interval,
        _ => return None,
    })
}

/// A file name made from a model name: characters other than letters, digits, `-`, `_` and `.`
/// become `_`.
fn file_stem(name: &str) -> String {
    let stem: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if stem.is_empty() || stem.chars().all(|c| c == '.') {
        "body".into()
    } else {
        stem
    }
}

/// The storage of a Real parameter (`None` for outputs and non-Real keys).
fn write_parameter(p: &mut Parameters, key: FixedKey, c: usize) -> Option<&mut f64> {
    use FixedKey::*;
    Some(match key {
        YoungsModulus => &mut p.material.youngs_modulus,
        PoissonRatio => &mut p.material.poisson_ratio,
        Density => &mut p.material.density,
        DampingAlpha => &mut p.damping_alpha,
        DampingBeta => &mut p.damping_beta,
        Gravity => &mut p.gravity[c],
        InitialPosition => &mut p.initial_position[c],
        InitialRotation => &mut p.initial_rotation[c],
        InitialVelocity => &mut p.initial_velocity[c],
        InitialAngularVelocity => &mut p.initial_angular_velocity[c],
        StepSize => &mut p.step_size,
        RhoInf => &mut p.rho_inf,
        Tolerance => &mut p.tolerance,
        OutputInterval => &mut p.output_interval,
        _ => return None,
    })
}

fn read_integer(p: &Parameters, key: FixedKey) -> Option<i32> {
    match key {
        FixedKey::MaxIterations => Some(p.max_iterations),
        FixedKey::Formulation => Some(p.formulation),
        FixedKey::Stiffening => Some(p.stiffening),
        FixedKey::Frames => Some(p.frames),
        FixedKey::Modes => Some(p.modes),
        FixedKey::AndersonDepth => Some(p.anderson_depth),
        FixedKey::Integrator => Some(p.integrator),
        _ => None,
    }
}

fn read_boolean(p: &Parameters, key: FixedKey) -> Option<bool> {
    match key {
        FixedKey::NonlinearForces => Some(p.nonlinear_forces),
        FixedKey::Auto => Some(p.auto),
        _ => None,
    }
}

/// GUID of a body: FNV-1a (two seeds) of the fixed table's fingerprint, the crate version and the
/// canonical body file, formatted as a UUID.
pub fn guid_of(body_file: &BodyFile) -> String {
    let text = format!(
        "{FIXED_TABLE_FINGERPRINT:x}|{}|{}",
        env!("CARGO_PKG_VERSION"),
        body_file.to_canonical_json()
    );
    let fnv = |seed: u64| {
        let mut h = seed;
        for b in text.bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x100000001b3);
        }
        h
    };
    let (a, b) = (fnv(0xcbf29ce484222325), fnv(0x84222325cbf29ce4));
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    )
}
