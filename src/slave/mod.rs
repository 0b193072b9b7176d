//! One co-simulation instance: parameters and inputs → body → solver → outputs; `do_step`; state
//! save and restore. Knows nothing of C pointers: the FMI glue in `fmi2` calls it after checking
//! arguments and the calling sequence.

use crate::body::interface::DrivingFrame;
use crate::body::Body;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::model::category;
use crate::model::model_description::fmi3::model_description_fmi3;
use crate::model::model_description::{model_description, ModelInfo};
use crate::model::variables::FIXED_TABLE_FINGERPRINT;
use crate::model::{BodyFile, Target, Variable, VariableTable, VariableType};
use crate::output::ResultWriter;
use crate::solver::generalized_alpha::IterationMatrix;
use crate::solver::problem::{DynamicState, FreeNodes};
use assembly::Model;
use interfaces::{default_inputs, interfaces_of, Interface};
use nalgebra::Vector3;
use outputs::{OutputGroup, Outputs};
use results::file_stem;
use std::path::Path;
use step_control::Ladder;
use variables::component_of;

mod assembly;
mod auto_features;
mod cosim;
mod initial_state;
mod interfaces;
mod outputs;
mod parameters;
mod results;
mod state_bytes;
mod step_control;
mod step_jacobian;
mod stepping;
mod variables;
pub use crate::solver::integrator::MATRIX_CACHE_SIZE;
pub use assembly::Features;
pub use cosim::CoSimSlave;
pub use parameters::Parameters;
pub(crate) use state_bytes::Reader as StateReader;
pub use state_bytes::PAYLOAD_FORMAT as STATE_PAYLOAD_FORMAT;
pub use stepping::MAX_STEP_HALVINGS;

/// The input values of one interface, indexed by value-reference slot
/// ([`InterfaceQuantity::slot`]).
type Inputs = [f64; INTERFACE_SLOTS];

/// Value-reference slots of one interface (`1000 + 100 k + slot`): force, torque and the six
/// motion quantities, 30 numbers (see [`InterfaceQuantity::slot`]).
const INTERFACE_SLOTS: usize = 30;

/// The first and second time derivatives of one interface's inputs (`fmi2SetRealInputDerivatives`;
/// only the force and torque slots of force interfaces are ever non-zero).
type InputDerivatives = [Inputs; 2];

/// Highest order of `fmi2SetRealInputDerivatives` (force inputs are extrapolated by their Taylor
/// polynomial of this degree).
pub const MAX_INPUT_DERIVATIVE_ORDER: i32 = 2;

/// `maxOutputDerivativeOrder`: see [`Slave::get_real_output_derivative`].
pub const MAX_OUTPUT_DERIVATIVE_ORDER: i32 = 2;

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
    quiet_since: [f64; 3],
    /// The rung `k` of the internal step `solver.stepSize / 2^k` for the next communication
    /// step, and when the rung above is next probed ([`step_control`]).
    ladder: Ladder,
    /// The deformation scale `D` (m): the largest mass-weighted RMS elastic displacement seen so
    /// far, or quasi-static displacement of the accelerations ([`step_control`]).
    deformation_scale: f64,
    /// `A` (m): the largest seen so far of the bound on the mass-weighted RMS of the elastic
    /// displacement's part above the lowest modes (its energy over `ω₇²`, [`step_control`]).
    high_mode_scale: f64,
    /// The estimate that refining did not reduce (m): the iteration's or the model's own noise
    /// in the estimate, below which the error control does not refine ([`step_control`]).
    estimate_floor: f64,
    /// The slabs' stiffening ratio last measured while it was off (`choose_slab_stiffening`):
    /// near the switch it is measured at every communication step, otherwise once per `T₁/16`.
    slab_stiffening_ratio: f64,
    /// When `model.auto` switched the slabs' own stiffening on (s; `None` where it was forced
    /// on or is off): it comes in over the lowest period from then (`SlabStiffeningSwitch::scale`).
    slab_stiffening_since: Option<f64>,
    /// Whether `D` has settled, so that on a body without supports the iteration's tolerance may
    /// follow the allowance, and the ladder reach its two finest rungs, before the first period
    /// has passed ([`step_control::ScaleSettling`], `step_control::finest_level`).
    scale_settling: step_control::ScaleSettling,
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
    /// The driving frames of the motion interfaces at the start of the last step, against which
    /// the next step tells whether its inputs jump.
    driving: Vec<DrivingFrame>,
    last_step_size: f64,
    start_time: f64,
    stop_time: Option<f64>,
    dynamics: Option<Dynamics>,
    /// Internal steps, fixed-point iterations, retried internal steps, rejected communication
    /// steps.
    counters: [u64; 4],
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
    /// The point masses of the interfaces' lumped bodies, the body's nodes after the mesh's.
    mass_points: Vec<interfaces::MassPoint>,
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
    /// The communication step last taken (0 before the first): a step within ulps of it is
    /// taken as it (see `snapped_step`).
    last_step_size: f64,
    /// The last `fmi2DoStep` as its step Jacobian redoes it (`None` before the first step and
    /// after a reset, an FMU state set or a failed step), and the inputs it was taken with
    /// (copied at every step: the importer may set the next ones before asking).
    jacobian_step: Option<step_jacobian::LastStep>,
    step_inputs: step_jacobian::StepInputs,
    /// The driving frames of motion interfaces at the start of the current step.
    driving: Vec<DrivingFrame>,
    /// `driving` before the current step, put back if the step is rolled back.
    driving_before: Vec<DrivingFrame>,
    start_time: f64,
    /// `fmi2SetupExperiment`'s stop time, when defined: the run over which the time error
    /// control's errors add up (docs/formulation.md, "Time error control": the horizon).
    stop_time: Option<f64>,
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
    /// Communication steps redone with finer internal steps because the error estimate exceeded
    /// the accuracy ([`step_control`]).
    rejected: u64,
    /// Communication steps whose error nothing estimated (one internal step from an input
    /// jump, `step_control::UNESTIMATED_WARN_AFTER`): in all, in a row, and whether the body
    /// has warned of them.
    unestimated: (u64, u32, bool),
    /// Communication steps accepted on the finest rung though an internal step's estimate
    /// exceeded its allowance, and whether the body has warned of them. Like `unestimated`, a
    /// count of the run as it went (an FMU state restored does not take it back).
    beyond_finest: (u64, bool),
    /// Whether the body has warned that a step was accepted on the iteration's floor rather than
    /// on `model.accuracy` (`slave::stepping::internal_steps`).
    floor_warned: bool,
    /// Whether the body has said that the iteration's tolerance follows the allowance of the
    /// internal steps (`slave::stepping::internal_steps`).
    tolerance_followed: bool,
    /// Between `fmi2EnterInitializationMode` and `fmi2ExitInitializationMode`: the outputs read
    /// there are those of the rigidly placed body with the inputs and parameters as they are,
    /// so setting one drops the placement computed for an earlier read.
    initializing: bool,
    /// The error control's scratch over the communication step under way: the largest ratio of
    /// an internal step's error estimate to its allowance (`None`: no step was estimated).
    step_error: Option<f64>,
    /// The largest ratio of the communication step under way against the accuracy alone, the
    /// iteration's floor left out: how far a rejected step must be refined.
    step_error_unfloored: f64,
    /// The largest local error estimate of the current communication step's attempt (m).
    step_estimate: f64,
    /// Whether an input jumped at the start of the communication step under way.
    inputs_jumped: bool,
    /// Internal steps since a motion input last jumped, at the start of the communication step
    /// under way (`step_control::MOTION_RINGING_STEPS`).
    since_motion_jump: u32,
    /// Scratch of `3N`: `K ū` for the deformation scale, `ū` of the state for `model.auto`.
    scale_scratch: Vec<f64>,
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
        let (lo, hi) = mesh.bounding_box();
        let size = (Vector3::from(hi) - Vector3::from(lo)).norm();
        let (interfaces, clamped, mass_points) = interfaces_of(&body_file, &mesh, size)?;
        let variables = VariableTable::new(&body_file.interfaces);
        let defaults = Parameters::from_body_file(&body_file);
        for v in variables.iter() {
            if let (Target::Fixed { key, .. }, VariableType::Real) = (v.target, v.ty) {
                let value = defaults.real(key, component_of(v));
                if let Some(value) = value {
                    Parameters::check_real(&v.name, key, value)
                        .map_err(|e| Error::new(format!("body file: {}", e.message)))?;
                }
            }
        }
        let element_regions = body_file.element_regions(&mesh)?;
        let guid = guid_of(&body_file);
        let n_interfaces = interfaces.len();
        let default_inputs = default_inputs(&interfaces);
        Ok(Slave {
            body_file,
            variables,
            guid,
            mesh,
            interfaces,
            clamped,
            mass_points,
            element_regions,
            size,
            parameters: defaults.clone(),
            defaults,
            inputs: default_inputs.clone(),
            default_inputs,
            input_derivatives: vec![[[0.0; INTERFACE_SLOTS]; 2]; n_interfaces],
            input_times: vec![0.0; n_interfaces],
            input_ages: vec![0.0; n_interfaces],
            last_step_size: 0.0,
            jacobian_step: None,
            step_inputs: step_jacobian::StepInputs::default(),
            driving: vec![DrivingFrame::default(); n_interfaces],
            driving_before: vec![DrivingFrame::default(); n_interfaces],
            start_time: 0.0,
            stop_time: None,
            model: None,
            dynamics: None,
            backup: None,
            retry_backup: None,
            outputs: Outputs::new(n_interfaces),
            statistics: (0, 0),
            retries: 0,
            rejected: 0,
            unestimated: (0, 0, false),
            beyond_finest: (0, false),
            floor_warned: false,
            tolerance_followed: false,
            initializing: false,
            step_error: None,
            step_error_unfloored: 0.0,
            step_estimate: 0.0,
            inputs_jumped: false,
            since_motion_jump: 0,
            scale_scratch: Vec::new(),
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

    /// The current parameter values.
    pub fn parameters(&self) -> &Parameters {
        &self.parameters
    }

    /// `fmi2SetupExperiment`: start time; the stop time, when defined, is the end of the run over
    /// which `model.accuracy` holds (docs/formulation.md, "Time error control": the horizon);
    /// the tolerance is not needed (`solver.tolerance` governs the iteration).
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
        // An infinite stop time is a run without end: no horizon.
        self.stop_time = stop_time.filter(|stop| stop.is_finite());
        // Inputs set before the experiment is set up describe the start.
        self.input_times.fill(start_time);
        Ok(())
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization_mode(&mut self) -> Result<()> {
        self.initializing = true;
        self.dynamics = None;
        self.last_step_size = 0.0;
        self.jacobian_step = None;
        self.input_times.fill(self.start_time);
        self.outputs.invalidate();
        Ok(())
    }

    /// `fmi2ExitInitializationMode`: validates the parameters, assembles and places the body,
    /// factorises the iteration matrix for `solver.stepSize`.
    pub fn exit_initialization_mode(&mut self) -> Result<()> {
        self.ensure_initial_state()?;
        let h = self.parameters.step_size;
        self.prepare_step_size(h)?;
        self.initializing = false;
        self.results = None;
        if !self.parameters.output_directory.is_empty() {
            match ResultWriter::create(
                &self.parameters.output_directory,
                &file_stem(&self.body_file.name),
                self.parameters.output_interval,
            ) {
                Ok(writer) => {
                    self.events.push(LogEvent {
                        category: category::EVENTS,
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
        self.model.as_ref()?.integrator.iteration_matrix(h)
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
            .map_or_else(Vec::new, |m| m.integrator.cached_step_sizes())
    }

    /// Internal steps that did not converge and were retried with halved steps (each retry
    /// counts once per halving).
    pub fn step_retries(&self) -> u64 {
        self.retries
    }

    /// Communication steps redone with finer internal steps because the estimated error
    /// exceeded `model.accuracy`.
    pub fn rejected_steps(&self) -> u64 {
        self.rejected
    }

    /// The internal step the error control has chosen for the next communication step (s): the
    /// rung `solver.stepSize / 2^k` (before the communication step divides it evenly).
    pub fn controlled_step_size(&self) -> f64 {
        let level = self.dynamics.as_ref().map_or(0, |d| d.ladder.level);
        step_control::rung(self.parameters.step_size, level)
    }

    /// `fmi2Terminate`: the run's counters under `logEvents` (internal steps, iterations, retried
    /// and rejected steps, the rung of the internal step).
    pub fn terminate(&mut self) {
        let (steps, iterations) = self.statistics;
        self.events.push(LogEvent {
            category: category::EVENTS,
            message: format!(
                "run summary: {steps} internal steps, {iterations} fixed-point iterations ({:.2} per step), {} internal steps retried with halved steps, {} communication steps redone on a finer rung by the error control (model.accuracy = {:e}), {} not estimated (one internal step from an input jump), {} accepted on the finest rung above their allowance; last internal step at most {:e} s",
                iterations as f64 / steps.max(1) as f64,
                self.retries,
                self.rejected,
                self.parameters.accuracy,
                self.unestimated.0,
                self.beyond_finest.0,
                self.controlled_step_size()
            ),
        });
    }

    /// `fmi2Reset`: back to the freshly instantiated state (parameters at their start values). The
    /// assembled matrices are kept for reuse if the parameters come back the same.
    pub fn reset(&mut self) {
        self.parameters = self.defaults.clone();
        self.inputs.clone_from(&self.default_inputs);
        for d in &mut self.input_derivatives {
            *d = [[0.0; INTERFACE_SLOTS]; 2];
        }
        self.start_time = 0.0;
        self.stop_time = None;
        self.input_times.fill(0.0);
        self.driving.fill(DrivingFrame::default());
        self.last_step_size = 0.0;
        self.jacobian_step = None;
        self.dynamics = None;
        self.backup = None;
        self.statistics = (0, 0);
        self.retries = 0;
        self.rejected = 0;
        self.unestimated = (0, 0, false);
        self.beyond_finest = (0, false);
        self.floor_warned = false;
        self.tolerance_followed = false;
        self.outputs.invalidate();
        self.results = None;
    }

    /// `fmi2GetFMUstate`.
    pub fn get_state(&self) -> SlaveState {
        SlaveState {
            parameters: self.parameters.clone(),
            inputs: self.inputs.clone(),
            input_derivatives: self.input_derivatives.clone(),
            input_times: self.input_times.clone(),
            driving: self.driving.clone(),
            last_step_size: self.last_step_size,
            start_time: self.start_time,
            stop_time: self.stop_time,
            dynamics: self.dynamics.clone(),
            counters: [
                self.statistics.0,
                self.statistics.1,
                self.retries,
                self.rejected,
            ],
        }
    }

    /// `fmi2SetFMUstate`.
    pub fn set_state(&mut self, state: &SlaveState) -> Result<()> {
        if state.inputs.len() != self.inputs.len()
            || state.input_derivatives.len() != self.inputs.len()
            || state.input_times.len() != self.inputs.len()
            || state.driving.len() != self.inputs.len()
        {
            return Err(Error::new("the FMU state belongs to another body"));
        }
        // What follows changes the parameters and inputs, then may fail: no output computed
        // before may be served after it.
        self.outputs.invalidate();
        self.parameters = state.parameters.clone();
        self.inputs.clone_from(&state.inputs);
        self.input_derivatives.clone_from(&state.input_derivatives);
        self.input_times.clone_from(&state.input_times);
        self.driving.copy_from_slice(&state.driving);
        self.last_step_size = state.last_step_size;
        self.jacobian_step = None;
        self.start_time = state.start_time;
        self.stop_time = state.stop_time;
        self.statistics = (state.counters[0], state.counters[1]);
        self.retries = state.counters[2];
        self.rejected = state.counters[3];
        if let Some(d) = &state.dynamics {
            self.ensure_model()?;
            let model = self.model.as_ref().unwrap();
            let expected = 3 * model.body.node_count();
            let multipliers = model.free.multiplier_count();
            if d.state.position.len() != expected || d.state.multipliers.len() != multipliers {
                return Err(Error::new(format!(
                    "the FMU state has {} coordinates and {} constraint multipliers, this body (model.modes = {}) has {expected} and {multipliers}: it belongs to another body",
                    d.state.position.len(),
                    d.state.multipliers.len(),
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
                d.ladder = s.ladder;
                d.deformation_scale = s.deformation_scale;
                d.high_mode_scale = s.high_mode_scale;
                d.estimate_floor = s.estimate_floor;
                d.slab_stiffening_ratio = s.slab_stiffening_ratio;
                d.slab_stiffening_since = s.slab_stiffening_since;
                d.scale_settling = s.scale_settling;
            }
            (d, s) => *d = s.clone(),
        }
        if self.dynamics.is_some() && self.model.as_ref().is_some_and(|m| m.allowed.linear) {
            // The linear body's placement (a rebuilt model has none yet).
            let x0 = self.rigid_placement_positions()?;
            self.model.as_mut().unwrap().place_linear_body(&x0);
        }
        let slab_switch = self.slab_stiffening_switch();
        if let (Some(model), Some(d)) = (self.model.as_mut(), self.dynamics.as_ref()) {
            model.apply_features(d.features);
            let scale = slab_switch.scale(d);
            model.refresh_slab_stiffening(&d.state.position, scale);
        }
        self.outputs.invalidate();
        Ok(())
    }

    /// What the model description says about the model besides its variables.
    fn model_info(&self) -> ModelInfo {
        ModelInfo {
            model_name: self.body_file.name.clone(),
            description: self.body_file.description.clone(),
            guid: self.guid.clone(),
            generation_tool: format!("flexbody {}", env!("CARGO_PKG_VERSION")),
            default_step_size: self.defaults.step_size,
        }
    }

    /// The complete FMI 2.0 `modelDescription.xml` of this body.
    pub fn model_description(&self) -> String {
        model_description(&self.variables, &self.model_info(), &|v: &Variable| {
            self.start_value(v)
        })
    }

    /// The complete FMI 3.0 `modelDescription.xml` of this body (the same variables, see
    /// [`crate::model::model_description::fmi3`]).
    pub fn model_description_fmi3(&self) -> String {
        model_description_fmi3(&self.variables, &self.model_info(), &|v: &Variable| {
            self.start_value(v)
        })
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
