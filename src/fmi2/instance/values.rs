//! Typed access to the slave's variables for `fmi2Get*`/`fmi2Set*`, and which variables may be
//! set in which state.

use super::{CoSimSlave, Instance, MachineState, DO_STEP, GET, M, OUTPUT_DERIVATIVES, SET};
use crate::error::Result;
use crate::fmi2::types::fmi2Status;
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

impl<S: CoSimSlave> Instance<S> {
    /// Looks up `vr` of type `ty`; the error names the value reference and, when it exists with
    /// another type, that type.
    fn lookup(&self, ty: VariableType, vr: u32) -> std::result::Result<&Variable, String> {
        let table = self.slave.variables();
        table.get(ty, vr).ok_or_else(|| {
            let other = [
                VariableType::Real,
                VariableType::Integer,
                VariableType::Boolean,
                VariableType::String,
            ]
            .into_iter()
            .find_map(|t| table.get(t, vr));
            match other {
                Some(v) => format!(
                    "value reference {vr} is the {} variable {}, not a {} variable",
                    type_name(v.ty),
                    v.name,
                    type_name(ty)
                ),
                None => format!("unknown {} value reference {vr}", type_name(ty)),
            }
        })
    }

    /// The calling-sequence check of the getters: the states of `GET`; with
    /// [`Instance::reading_start_values`] (FMI 3.0) also Instantiated for the variables that
    /// have a start value (parameters and inputs), not for outputs.
    fn check_get(
        &mut self,
        function: &str,
        ty: VariableType,
        vrs: &[u32],
    ) -> std::result::Result<(), fmi2Status> {
        if !(self.start_values_readable && self.state == MachineState::Instantiated) {
            return self.check_state(function, GET);
        }
        for &vr in vrs {
            let reason = match self.lookup(ty, vr) {
                Ok(v) if v.causality == Causality::Output => format!(
                    "{} (value reference {vr}) is an output: it has no start value and is computed from fmi2EnterInitializationMode on",
                    v.name
                ),
                Ok(_) => continue,
                Err(e) => e,
            };
            return Err(self.fail(function, &reason));
        }
        Ok(())
    }

    /// `fmi2Get{Real,Integer,Boolean}`: `values[i]` of `vrs[i]` (same length, checked by the
    /// caller). Non-finite Reals are refused rather than passed on.
    pub fn get_values<T: FromSlave<S> + Copy + std::fmt::Debug>(
        &mut self,
        function: &str,
        vrs: &[u32],
        values: &mut [T],
    ) -> fmi2Status {
        debug_assert_eq!(vrs.len(), values.len());
        if let Err(s) = self.check_get(function, T::TYPE, vrs) {
            return s;
        }
        for (&vr, out) in vrs.iter().zip(values.iter_mut()) {
            let name = match self.lookup(T::TYPE, vr) {
                Ok(v) => v.name.clone(),
                Err(e) => return self.fail(function, &e),
            };
            match T::get(&mut self.slave, vr) {
                Ok(x) if x.is_non_finite() => {
                    return self.fail(function, &format!("{name} (value reference {vr}) is {x:?}"));
                }
                Ok(x) => *out = x,
                Err(e) => return self.report(function, &e),
            }
        }
        fmi2Status::fmi2OK
    }

    /// `fmi2Set{Real,Integer,Boolean}`: checks every value reference, its settability in the
    /// current state and (Reals) its value before setting any value; then sets them in order
    /// (the slave rejects bad values with a message naming the variable).
    pub fn set_values<T: ToSlave<S>>(
        &mut self,
        function: &str,
        vrs: &[u32],
        values: &[T],
    ) -> fmi2Status {
        debug_assert_eq!(vrs.len(), values.len());
        if let Err(s) = self.check_state(function, SET) {
            return s;
        }
        for &vr in vrs {
            let reason = match self.lookup(T::TYPE, vr) {
                Ok(v) => settability_violation(self.state, v)
                    .map(|r| format!("{r} (value reference {vr}, state {:?})", self.state)),
                Err(e) => Some(e),
            };
            if let Some(reason) = reason {
                return self.fail(function, &reason);
            }
        }
        for (&vr, &x) in vrs.iter().zip(values) {
            if let Err(e) = T::check(&self.slave, vr, x) {
                return self.report(function, &e);
            }
        }
        for (&vr, &x) in vrs.iter().zip(values) {
            if let Err(e) = T::set(&mut self.slave, vr, x) {
                return self.report(function, &e);
            }
        }
        fmi2Status::fmi2OK
    }

    /// `fmi2GetString`: the values of `vrs`, kept in the instance until its next
    /// `fmi2GetString` (the caller hands out pointers into them). A value with a NUL byte is
    /// refused.
    pub fn get_strings(
        &mut self,
        function: &str,
        vrs: &[u32],
    ) -> (fmi2Status, &[std::ffi::CString]) {
        if let Err(s) = self.check_get(function, VariableType::String, vrs) {
            return (s, &[]);
        }
        let mut values = Vec::with_capacity(vrs.len());
        for &vr in vrs {
            if let Err(e) = self.lookup(VariableType::String, vr) {
                return (self.fail(function, &e), &[]);
            }
            match self.slave.get_string(vr) {
                Ok(text) => match std::ffi::CString::new(text) {
                    Ok(c) => values.push(c),
                    Err(_) => {
                        let status = self.fail(
                            function,
                            &format!("String value reference {vr} holds a NUL character"),
                        );
                        return (status, &[]);
                    }
                },
                Err(e) => return (self.report(function, &e), &[]),
            }
        }
        self.strings = values;
        (fmi2Status::fmi2OK, &self.strings)
    }

    /// `fmi2SetString`: like [`Self::set_values`]; a NULL string (None) is an error naming the
    /// variable.
    pub fn set_strings(
        &mut self,
        function: &str,
        vrs: &[u32],
        values: &[Option<String>],
    ) -> fmi2Status {
        debug_assert_eq!(vrs.len(), values.len());
        if let Err(s) = self.check_state(function, SET) {
            return s;
        }
        for (&vr, value) in vrs.iter().zip(values) {
            let reason = match self.lookup(VariableType::String, vr) {
                Ok(v) => settability_violation(self.state, v)
                    .map(|r| format!("{r} (value reference {vr}, state {:?})", self.state))
                    .or_else(|| {
                        value
                            .is_none()
                            .then(|| format!("{} = NULL rejected: not a string", v.name))
                    }),
                Err(e) => Some(e),
            };
            if let Some(reason) = reason {
                return self.fail(function, &reason);
            }
        }
        for (&vr, value) in vrs.iter().zip(values) {
            if let Err(e) = self
                .slave
                .set_string(vr, value.as_deref().unwrap_or_default())
            {
                return self.report(function, &e);
            }
        }
        fmi2Status::fmi2OK
    }

    /// `fmi2SetRealInputDerivatives` (`canInterpolateInputs="true"`): allowed where inputs may be
    /// set; every value reference must be a Real input and every order 1 or 2 (what the slave
    /// can use); all or nothing.
    pub fn set_real_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> fmi2Status {
        const F: &str = "fmi2SetRealInputDerivatives";
        if let Err(s) = self.check_state(F, SET) {
            return s;
        }
        for (&vr, &order) in vrs.iter().zip(orders) {
            let reason = match self.lookup(VariableType::Real, vr) {
                Ok(v) if v.causality != Causality::Input => {
                    Some(format!("{} (value reference {vr}) is not an input", v.name))
                }
                Ok(v) if order < 1 => Some(format!(
                    "order = {order} rejected for {} (value reference {vr}): must be at least 1",
                    v.name
                )),
                Ok(_) => None,
                Err(e) => Some(e),
            };
            if let Some(reason) = reason {
                return self.fail(F, &reason);
            }
        }
        match self.slave.set_real_input_derivatives(vrs, orders, values) {
            Ok(()) => fmi2Status::fmi2OK,
            Err(e) => self.report(F, &e),
        }
    }

    /// `fmi2GetRealOutputDerivatives` (`maxOutputDerivativeOrder="2"`): every value reference
    /// must be a Real output; the slave says which derivatives exist.
    pub fn get_real_output_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &mut [f64],
    ) -> fmi2Status {
        const F: &str = "fmi2GetRealOutputDerivatives";
        if let Err(s) = self.check_state(F, OUTPUT_DERIVATIVES) {
            return s;
        }
        for ((&vr, &order), out) in vrs.iter().zip(orders).zip(values.iter_mut()) {
            if let Err(e) = self.lookup(VariableType::Real, vr) {
                return self.fail(F, &e);
            }
            match self.slave.get_real_output_derivative(vr, order) {
                Ok(x) if x.is_finite() => *out = x,
                Ok(x) => {
                    return self.fail(F, &format!("the derivative of value reference {vr} is {x}"))
                }
                Err(e) => return self.report(F, &e),
            }
        }
        fmi2Status::fmi2OK
    }

    /// `flexbody_GetStepJacobian`: the step Jacobian of the last `fmi2DoStep` (see
    /// [`crate::slave::Slave::step_jacobian`]), row-major, in StepComplete. The value
    /// references are checked here (Real outputs, Real inputs); the slave checks what its
    /// Jacobian covers. On error the instance is as it was (`jacobian`'s entries unspecified).
    pub fn step_jacobian(
        &mut self,
        function: &str,
        unknowns: &[u32],
        knowns: &[u32],
        jacobian: &mut [f64],
    ) -> fmi2Status {
        let f = function;
        if let Err(s) = self.check_state(f, DO_STEP) {
            return s;
        }
        for (&vr, causality, role) in unknowns
            .iter()
            .map(|vr| (vr, Causality::Output, "an output (unknown)"))
            .chain(
                knowns
                    .iter()
                    .map(|vr| (vr, Causality::Input, "an input (known)")),
            )
        {
            let reason = match self.lookup(VariableType::Real, vr) {
                Ok(v) if v.causality != causality => {
                    Some(format!("{} (value reference {vr}) is not {role}", v.name))
                }
                Ok(_) => None,
                Err(e) => Some(e),
            };
            if let Some(reason) = reason {
                return self.fail(f, &reason);
            }
        }
        let result = self.slave.step_jacobian(unknowns, knowns, jacobian);
        self.flush_events();
        match result {
            Ok(()) if jacobian.iter().all(|x| x.is_finite()) => fmi2Status::fmi2OK,
            Ok(()) => self.fail(f, "the step Jacobian is not finite"),
            Err(e) => self.report(f, &e),
        }
    }
}
