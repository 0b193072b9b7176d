//! The slave's contract with the FMI layer (what the C ABI calls, like the Reference FMUs'
//! `model.h`): [`Slave`] implements it by its inherent methods, one per FMI function, each in
//! the room of its concern; unit tests of the FMI layer use a mock.

use super::{Slave, SlaveState};
use crate::error::Result;
use crate::model::VariableTable;

/// The co-simulation slave as the FMI layer needs it. [`Slave`] implements it; unit tests use a
/// mock so the state machine is tested without the physics.
pub trait CoSimSlave {
    /// A complete snapshot (see [`Slave::get_state`]).
    type State;
    fn guid(&self) -> &str;
    fn variables(&self) -> &VariableTable;
    fn setup_experiment(
        &mut self,
        start_time: f64,
        stop_time: Option<f64>,
        tolerance: Option<f64>,
    ) -> Result<()>;
    fn enter_initialization_mode(&mut self) -> Result<()>;
    fn exit_initialization_mode(&mut self) -> Result<()>;
    fn get_real(&mut self, vr: u32) -> Result<f64>;
    fn set_real(&mut self, vr: u32, value: f64) -> Result<()>;
    fn get_integer(&mut self, vr: u32) -> Result<i32>;
    fn set_integer(&mut self, vr: u32, value: i32) -> Result<()>;
    fn get_boolean(&mut self, vr: u32) -> Result<bool>;
    fn set_boolean(&mut self, vr: u32, value: bool) -> Result<()>;
    /// Value of a String variable (default: there are none).
    fn get_string(&mut self, vr: u32) -> Result<String> {
        Err(crate::Error::new(format!(
            "no String variable has value reference {vr}"
        )))
    }
    /// Sets a String parameter (default: there are none).
    fn set_string(&mut self, vr: u32, value: &str) -> Result<()> {
        let _ = value;
        Err(crate::Error::new(format!(
            "no String variable has value reference {vr}"
        )))
    }
    fn do_step(
        &mut self,
        current_communication_point: f64,
        communication_step_size: f64,
    ) -> Result<()>;
    fn time(&self) -> f64;
    /// `fmi2Terminate`: the slave may leave a summary of the run in its log (default: nothing).
    fn terminate(&mut self) {}
    fn reset(&mut self);
    fn get_state(&self) -> Self::State;
    fn set_state(&mut self, state: &Self::State) -> Result<()>;
    /// Appends the portable byte form of `state` (see `fmi2SerializeFMUstate`).
    fn state_to_bytes(&self, state: &Self::State, out: &mut Vec<u8>);
    /// Reads what [`CoSimSlave::state_to_bytes`] wrote, checked against this slave.
    fn state_from_bytes(&self, bytes: &[u8]) -> Result<Self::State>;
    /// Checks a value for a Real variable without setting it (`Ok` if `set_real` would accept it).
    fn check_real(&self, vr: u32, value: f64) -> Result<()> {
        let _ = (vr, value);
        Ok(())
    }
    /// `fmi2SetRealInputDerivatives` (value references are Real inputs, orders ≥ 1, checked by
    /// the caller): all or nothing.
    fn set_real_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> Result<()>;
    /// `fmi2GetRealOutputDerivatives` for one output.
    fn get_real_output_derivative(&mut self, vr: u32, order: i32) -> Result<f64>;
    /// The step Jacobian of the last step (`flexbody_GetStepJacobian`, see
    /// [`Slave::step_jacobian`]); default: none.
    fn step_jacobian(
        &mut self,
        outputs: &[u32],
        inputs: &[u32],
        jacobian: &mut [f64],
    ) -> Result<()> {
        let _ = (outputs, inputs, jacobian);
        Err(crate::Error::new("this slave has no step Jacobian"))
    }
    /// Hands the slave's pending log messages (category, text) to `sink`.
    fn drain_events(&mut self, sink: &mut dyn FnMut(&'static str, &str)) {
        let _ = sink;
    }
}

impl CoSimSlave for Slave {
    type State = SlaveState;
    fn guid(&self) -> &str {
        Slave::guid(self)
    }
    fn variables(&self) -> &VariableTable {
        Slave::variables(self)
    }
    fn setup_experiment(
        &mut self,
        start_time: f64,
        stop_time: Option<f64>,
        tolerance: Option<f64>,
    ) -> Result<()> {
        Slave::setup_experiment(self, start_time, stop_time, tolerance)
    }
    fn enter_initialization_mode(&mut self) -> Result<()> {
        Slave::enter_initialization_mode(self)
    }
    fn exit_initialization_mode(&mut self) -> Result<()> {
        Slave::exit_initialization_mode(self)
    }
    fn get_real(&mut self, vr: u32) -> Result<f64> {
        Slave::get_real(self, vr)
    }
    fn set_real(&mut self, vr: u32, value: f64) -> Result<()> {
        Slave::set_real(self, vr, value)
    }
    fn get_integer(&mut self, vr: u32) -> Result<i32> {
        Slave::get_integer(self, vr)
    }
    fn set_integer(&mut self, vr: u32, value: i32) -> Result<()> {
        Slave::set_integer(self, vr, value)
    }
    fn get_boolean(&mut self, vr: u32) -> Result<bool> {
        Slave::get_boolean(self, vr)
    }
    fn set_boolean(&mut self, vr: u32, value: bool) -> Result<()> {
        Slave::set_boolean(self, vr, value)
    }
    fn get_string(&mut self, vr: u32) -> Result<String> {
        Slave::get_string(self, vr)
    }
    fn set_string(&mut self, vr: u32, value: &str) -> Result<()> {
        Slave::set_string(self, vr, value)
    }
    fn do_step(&mut self, t: f64, h: f64) -> Result<()> {
        Slave::do_step(self, t, h)
    }
    fn time(&self) -> f64 {
        Slave::time(self)
    }
    fn terminate(&mut self) {
        Slave::terminate(self)
    }
    fn reset(&mut self) {
        Slave::reset(self)
    }
    fn get_state(&self) -> SlaveState {
        Slave::get_state(self)
    }
    fn set_state(&mut self, state: &SlaveState) -> Result<()> {
        Slave::set_state(self, state)
    }
    fn state_to_bytes(&self, state: &SlaveState, out: &mut Vec<u8>) {
        state.write_bytes(out)
    }
    fn state_from_bytes(&self, bytes: &[u8]) -> Result<SlaveState> {
        Slave::state_from_bytes(self, bytes)
    }
    fn check_real(&self, vr: u32, value: f64) -> Result<()> {
        Slave::check_real(self, vr, value)
    }
    fn set_real_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> Result<()> {
        Slave::set_real_input_derivatives(self, vrs, orders, values)
    }
    fn get_real_output_derivative(&mut self, vr: u32, order: i32) -> Result<f64> {
        Slave::get_real_output_derivative(self, vr, order)
    }
    fn step_jacobian(
        &mut self,
        outputs: &[u32],
        inputs: &[u32],
        jacobian: &mut [f64],
    ) -> Result<()> {
        Slave::step_jacobian(self, outputs, inputs, jacobian)
    }
    fn drain_events(&mut self, sink: &mut dyn FnMut(&'static str, &str)) {
        for e in Slave::drain_events(self) {
            sink(e.category, &e.message);
        }
    }
}
