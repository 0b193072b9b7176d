//! One co-simulation instance: parameters and inputs → body → solver → outputs; `do_step`; state
//! save and restore. Knows nothing of C pointers: the FMI glue in `fmi2` calls it after checking
//! arguments and the calling sequence.

use crate::error::Result;
use crate::model::{BodyFile, VariableTable};
use std::path::Path;

/// A snapshot of everything that determines later steps (time, positions, velocities,
/// accelerations, inputs, tunable parameters). Restoring it reproduces later steps bit for bit.
#[derive(Debug, Clone)]
pub struct SlaveState {}

/// One instance of the flexible body.
pub struct Slave {
    body_file: BodyFile,
    variables: VariableTable,
    guid: String,
}

impl Slave {
    /// Loads `body.json` from the resource directory if there is one, else the embedded default body.
    pub fn from_resources(resource_dir: Option<&Path>) -> Result<Slave> {
        let _ = resource_dir;
        todo!()
    }

    /// A fresh instance of `body_file` (parameters at their start values, Instantiated).
    pub fn from_body(body_file: BodyFile) -> Result<Slave> {
        let _ = body_file;
        todo!()
    }

    /// The GUID of this body (fixed variable table, crate version and body file).
    pub fn guid(&self) -> &str {
        &self.guid
    }

    /// The body file this instance was built from.
    pub fn body_file(&self) -> &BodyFile {
        &self.body_file
    }

    /// The variable table (value references, causality, variability).
    pub fn variables(&self) -> &VariableTable {
        &self.variables
    }

    /// `fmi2SetupExperiment`: start time; stop time and tolerance are optional.
    pub fn setup_experiment(&mut self, start_time: f64, stop_time: Option<f64>, tolerance: Option<f64>) -> Result<()> {
        let _ = (start_time, stop_time, tolerance);
        todo!()
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization_mode(&mut self) -> Result<()> {
        todo!()
    }

    /// `fmi2ExitInitializationMode`: validates the parameters, assembles and places the body.
    pub fn exit_initialization_mode(&mut self) -> Result<()> {
        todo!()
    }

    /// Value of a Real variable (the value reference is known to the table).
    pub fn get_real(&mut self, vr: u32) -> Result<f64> {
        let _ = vr;
        todo!()
    }

    /// Sets a Real parameter or input; rejects NaN, infinities and out-of-range values with a
    /// message naming the variable. The caller has checked that the variable may be set now.
    pub fn set_real(&mut self, vr: u32, value: f64) -> Result<()> {
        let _ = (vr, value);
        todo!()
    }

    pub fn get_integer(&mut self, vr: u32) -> Result<i32> {
        let _ = vr;
        todo!()
    }

    pub fn set_integer(&mut self, vr: u32, value: i32) -> Result<()> {
        let _ = (vr, value);
        todo!()
    }

    pub fn get_boolean(&mut self, vr: u32) -> Result<bool> {
        let _ = vr;
        todo!()
    }

    pub fn set_boolean(&mut self, vr: u32, value: bool) -> Result<()> {
        let _ = (vr, value);
        todo!()
    }

    /// `fmi2DoStep`: advances from `current_communication_point` (must match the internal time
    /// within a relative 1e-5 of the step) by `communication_step_size` > 0. On error the state is
    /// unchanged; a step that does not converge is an `ErrorKind::Discard`.
    pub fn do_step(&mut self, current_communication_point: f64, communication_step_size: f64) -> Result<()> {
        let _ = (current_communication_point, communication_step_size);
        todo!()
    }

    /// Current simulation time (s): the last successful communication point.
    pub fn time(&self) -> f64 {
        todo!()
    }

    /// `fmi2Reset`: back to the freshly instantiated state (parameters at their start values).
    pub fn reset(&mut self) {
        todo!()
    }

    /// `fmi2GetFMUstate`.
    pub fn get_state(&self) -> SlaveState {
        todo!()
    }

    /// `fmi2SetFMUstate`.
    pub fn set_state(&mut self, state: &SlaveState) -> Result<()> {
        let _ = state;
        todo!()
    }

    /// The complete `modelDescription.xml` of this body.
    pub fn model_description(&self) -> String {
        todo!()
    }
}
