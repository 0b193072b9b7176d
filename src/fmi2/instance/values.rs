//! Typed access to the slave's variables for `fmi2Get*`/`fmi2Set*`, and which variables may be
//! set in which state.

use super::{CoSimSlave, MachineState, M};
use crate::error::Result;
use crate::model::{Causality, Variability, Variable, VariableType};

/// What a value getter returns for the C side.
pub trait FromSlave<S: CoSimSlave>: Sized {
    const TYPE: VariableType;
    fn get(slave: &mut S, vr: u32) -> Result<Self>;
    /// NaN or an infinity (never passed to the importer).
    fn is_non_finite(&self) -> bool {
        false
    }
}

impl<S: CoSimSlave> FromSlave<S> for f64 {
    const TYPE: VariableType = VariableType::Real;
    fn get(slave: &mut S, vr: u32) -> Result<f64> {
        slave.get_real(vr)
    }
    fn is_non_finite(&self) -> bool {
        !self.is_finite()
    }
}

impl<S: CoSimSlave> FromSlave<S> for i32 {
    const TYPE: VariableType = VariableType::Integer;
    fn get(slave: &mut S, vr: u32) -> Result<i32> {
        slave.get_integer(vr)
    }
}

impl<S: CoSimSlave> FromSlave<S> for bool {
    const TYPE: VariableType = VariableType::Boolean;
    fn get(slave: &mut S, vr: u32) -> Result<bool> {
        slave.get_boolean(vr)
    }
}

/// What a value setter takes from the C side.
pub trait ToSlave<S: CoSimSlave>: Sized + Copy {
    const TYPE: VariableType;
    fn set(slave: &mut S, vr: u32, value: Self) -> Result<()>;
    /// Whether `set` would accept the value (checked for the whole array before setting any).
    fn check(slave: &S, vr: u32, value: Self) -> Result<()> {
        let _ = (slave, vr, value);
        Ok(())
    }
}

impl<S: CoSimSlave> ToSlave<S> for f64 {
    const TYPE: VariableType = VariableType::Real;
    fn set(slave: &mut S, vr: u32, value: f64) -> Result<()> {
        slave.set_real(vr, value)
    }
    fn check(slave: &S, vr: u32, value: f64) -> Result<()> {
        slave.check_real(vr, value)
    }
}

impl<S: CoSimSlave> ToSlave<S> for i32 {
    const TYPE: VariableType = VariableType::Integer;
    fn set(slave: &mut S, vr: u32, value: i32) -> Result<()> {
        slave.set_integer(vr, value)
    }
}

impl<S: CoSimSlave> ToSlave<S> for bool {
    const TYPE: VariableType = VariableType::Boolean;
    fn set(slave: &mut S, vr: u32, value: bool) -> Result<()> {
        slave.set_boolean(vr, value)
    }
}

pub(super) fn type_name(ty: VariableType) -> &'static str {
    match ty {
        VariableType::Real => "Real",
        VariableType::Integer => "Integer",
        VariableType::Boolean => "Boolean",
        VariableType::String => "String",
    }
}

/// Why `v` may not be set in `state` (None: it may). FMI 2.0.4 section 4.2.4, co-simulation.
pub fn settability_violation(state: MachineState, v: &Variable) -> Option<String> {
    match v.causality {
        Causality::Output => Some(format!("{} is an output and cannot be set", v.name)),
        Causality::Input => None,
        Causality::Parameter => match state {
            M::Instantiated | M::InitializationMode => None,
            M::StepComplete if v.variability == Variability::Tunable => None,
            _ => Some(format!(
                "{} is a {} parameter and can only be set before fmi2ExitInitializationMode",
                v.name,
                match v.variability {
                    Variability::Fixed => "fixed",
                    Variability::Tunable => "tunable",
                    Variability::Discrete => "discrete",
                    Variability::Continuous => "continuous",
                }
            )),
        },
    }
}
