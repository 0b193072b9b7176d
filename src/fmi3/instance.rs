//! One FMI 3.0 instance: the FMI 2.0 [`Instance`] (slave, logger, calling-sequence state
//! machine, FMU states) and what FMI 3.0 adds on top: array variables, the independent variable
//! `time`, FMI 3.0's types. No raw pointers here: [`super::exports`] turns C arguments into
//! slices.
//!
//! The calling sequence of FMI 3.0 co-simulation without event mode (FMI 3.0 section 4.2.1) is
//! FMI 2.0's with other names: Instantiated, Initialization Mode, Step Mode (FMI 2.0's
//! StepComplete), Step Discarded (StepFailed), Terminated, and the error states; the FMI 2.0
//! machine checks every call, its messages name FMI 3.0's functions and states
//! ([`crate::fmi2::logger::fmi3_names`]).

use crate::fmi2::exports::Component;
use crate::fmi2::fmi2Status;
use crate::model::arrays::array_variables;
use crate::model::model_description::fmi3::TIME_VALUE_REFERENCE;
use crate::model::{Variable, VariableType};
use std::collections::BTreeMap;

/// The FMI 3.0 types of this FMU's variables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fmi3Type {
    Float64,
    Int32,
    /// An FMI 2.0 Integer with a declared enumeration type: FMI 3.0 reads and writes it as Int64.
    Enumeration,
    Boolean,
    String,
}

impl Fmi3Type {
    fn of(v: &Variable) -> Fmi3Type {
        match v.ty {
            VariableType::Real => Fmi3Type::Float64,
            VariableType::Integer if v.declared_type.is_some() => Fmi3Type::Enumeration,
            VariableType::Integer => Fmi3Type::Int32,
            VariableType::Boolean => Fmi3Type::Boolean,
            VariableType::String => Fmi3Type::String,
        }
    }

    /// The getter and setter of this type.
    fn accessor(self) -> &'static str {
        match self {
            Fmi3Type::Float64 => "Float64",
            Fmi3Type::Int32 => "Int32",
            Fmi3Type::Enumeration => "Int64",
            Fmi3Type::Boolean => "Boolean",
            Fmi3Type::String => "String",
        }
    }
}

/// What a value reference of the FMI 3.0 description stands for.
#[derive(Debug, Clone)]
struct ArrayEntry {
    name: String,
    /// The scalar value reference of element 1; the others follow.
    first: u32,
    len: usize,
    ty: Fmi3Type,
}

/// One FMI 3.0 instance.
pub struct Fmi3Instance {
    /// The FMI 2.0 instance that does the work.
    pub(crate) inner: Component,
    /// The FMI 3.0 variables by value reference ([`crate::model::arrays`]).
    arrays: BTreeMap<u32, ArrayEntry>,
    /// The scalar value references of the current request (grown once, then reused).
    scalars: Vec<u32>,
    /// Per-element derivative orders of the current request.
    orders: Vec<i32>,
    /// Integer and Boolean values of the current request.
    integers: Vec<i32>,
    flags: Vec<bool>,
    /// The scalar value references of the knowns of a step Jacobian request.
    knowns: Vec<u32>,
}

/// The marker for `time` among the scalar value references of a request.
const TIME: u32 = u32::MAX;

impl Fmi3Instance {
    /// Wraps a freshly instantiated FMI 2.0 instance.
    pub fn new(inner: Component) -> Fmi3Instance {
        let table = inner.slave().variables();
        let variables: Vec<&Variable> = table.iter().collect();
        let arrays = array_variables(table)
            .into_iter()
            .map(|a| {
                let entry = ArrayEntry {
                    ty: Fmi3Type::of(variables[a.first]),
                    name: a.name,
                    first: a.value_reference,
                    len: a.len,
                };
                (a.value_reference, entry)
            })
            .collect();
        Fmi3Instance {
            inner,
            arrays,
            scalars: Vec::new(),
            orders: Vec::new(),
            integers: Vec::new(),
            flags: Vec::new(),
            knowns: Vec::new(),
        }
    }

    /// Logs an error of `function` (the state is unchanged).
    pub fn fail(&mut self, function: &str, message: &str) -> fmi2Status {
        self.inner.fail(function, message)
    }

    /// Fills `self.scalars` with the scalar value references of `vrs` of type `ty` (`time` as
    /// [`TIME`]) and checks that they are `n_values` values.
    fn expand(
        &mut self,
        function: &str,
        ty: Fmi3Type,
        vrs: &[u32],
        n_values: usize,
    ) -> Result<(), fmi2Status> {
        self.scalars.clear();
        for &vr in vrs {
            if vr == TIME_VALUE_REFERENCE {
                if ty != Fmi3Type::Float64 {
                    return Err(self.fail(
                        function,
                        &format!(
                            "value reference {vr} is the Float64 variable time: use fmi3GetFloat64"
                        ),
                    ));
                }
                self.scalars.push(TIME);
                continue;
            }
            match self.arrays.get(&vr) {
                Some(a) if a.ty == ty => self.scalars.extend(a.first..a.first + a.len as u32),
                Some(a) => {
                    let message = format!(
                        "value reference {vr} is the {:?} variable {}: use fmi3Get{}/fmi3Set{}",
                        a.ty,
                        a.name,
                        a.ty.accessor(),
                        a.ty.accessor()
                    );
                    return Err(self.fail(function, &message));
                }
                None => {
                    return Err(self.fail(
                        function,
                        &format!("unknown value reference {vr} (an array variable has the value reference of its first element only)"),
                    ))
                }
            }
        }
        if self.scalars.len() != n_values {
            let message = format!(
                "nValues = {n_values} rejected: the {} value references have {} values",
                vrs.len(),
                self.scalars.len()
            );
            return Err(self.fail(function, &message));
        }
        Ok(())
    }

    /// `fmi3GetFloat64`: the elements of every array in row-major order; `time` is the slave's.
    pub fn get_float64(&mut self, function: &str, vrs: &[u32], values: &mut [f64]) -> fmi2Status {
        if let Err(s) = self.expand(function, Fmi3Type::Float64, vrs, values.len()) {
            return s;
        }
        // The state check, also for a request of `time` alone.
        let status = self.inner.get_values::<f64>(function, &[], &mut []);
        if status != fmi2Status::fmi2OK {
            return status;
        }
        let mut start = 0;
        while start < self.scalars.len() {
            if self.scalars[start] == TIME {
                values[start] = self.inner.slave().time();
                start += 1;
                continue;
            }
            let end = self.scalars[start..]
                .iter()
                .position(|&vr| vr == TIME)
                .map_or(self.scalars.len(), |n| start + n);
            let status =
                self.inner
                    .get_values(function, &self.scalars[start..end], &mut values[start..end]);
            if status != fmi2Status::fmi2OK {
                return status;
            }
            start = end;
        }
        fmi2Status::fmi2OK
    }

    /// `fmi3SetFloat64`: all values checked before any is set (`time` cannot be set).
    pub fn set_float64(&mut self, function: &str, vrs: &[u32], values: &[f64]) -> fmi2Status {
        if let Err(s) = self.expand(function, Fmi3Type::Float64, vrs, values.len()) {
            return s;
        }
        if self.scalars.contains(&TIME) {
            return self.fail(
                function,
                "time (value reference 0) is the independent variable and cannot be set",
            );
        }
        self.inner.set_values(function, &self.scalars, values)
    }

    /// `fmi3GetInt32` (Int32 variables) and `fmi3GetInt64` (enumerations): `write(i, value)`
    /// stores element `i`.
    pub fn get_integers(
        &mut self,
        function: &str,
        ty: Fmi3Type,
        vrs: &[u32],
        n_values: usize,
        mut write: impl FnMut(usize, i32),
    ) -> fmi2Status {
        if let Err(s) = self.expand(function, ty, vrs, n_values) {
            return s;
        }
        self.integers.clear();
        self.integers.resize(n_values, 0);
        let status = self
            .inner
            .get_values(function, &self.scalars, &mut self.integers);
        if status == fmi2Status::fmi2OK {
            for (i, &x) in self.integers.iter().enumerate() {
                write(i, x);
            }
        }
        status
    }

    /// `fmi3SetInt32` and `fmi3SetInt64`: `values` as i64; a value outside the 32-bit range of
    /// FMI 2.0's Integer is refused with the variable's name.
    pub fn set_integers(
        &mut self,
        function: &str,
        ty: Fmi3Type,
        vrs: &[u32],
        values: &[i64],
    ) -> fmi2Status {
        if let Err(s) = self.expand(function, ty, vrs, values.len()) {
            return s;
        }
        self.integers.clear();
        for (i, &x) in values.iter().enumerate() {
            match i32::try_from(x) {
                Ok(x) => self.integers.push(x),
                Err(_) => {
                    let vr = self.scalars[i];
                    let name = self
                        .inner
                        .slave()
                        .variables()
                        .get(VariableType::Integer, vr)
                        .map_or(String::new(), |v| v.name.clone());
                    return self.fail(
                        function,
                        &format!(
                            "{name} = {x} rejected: outside the range of the variable's values"
                        ),
                    );
                }
            }
        }
        self.inner
            .set_values(function, &self.scalars, &self.integers)
    }

    /// `fmi3GetBoolean`: `write(i, value)` stores element `i`.
    pub fn get_booleans(
        &mut self,
        function: &str,
        vrs: &[u32],
        n_values: usize,
        mut write: impl FnMut(usize, bool),
    ) -> fmi2Status {
        if let Err(s) = self.expand(function, Fmi3Type::Boolean, vrs, n_values) {
            return s;
        }
        self.flags.clear();
        self.flags.resize(n_values, false);
        let status = self
            .inner
            .get_values(function, &self.scalars, &mut self.flags);
        if status == fmi2Status::fmi2OK {
            for (i, &x) in self.flags.iter().enumerate() {
                write(i, x);
            }
        }
        status
    }

    /// `fmi3SetBoolean`.
    pub fn set_booleans(&mut self, function: &str, vrs: &[u32], values: &[bool]) -> fmi2Status {
        if let Err(s) = self.expand(function, Fmi3Type::Boolean, vrs, values.len()) {
            return s;
        }
        self.inner.set_values(function, &self.scalars, values)
    }

    /// `fmi3GetString`: the strings stay valid until the next `fmi3GetString`.
    pub fn get_strings(
        &mut self,
        function: &str,
        vrs: &[u32],
        n_values: usize,
    ) -> (fmi2Status, &[std::ffi::CString]) {
        if let Err(s) = self.expand(function, Fmi3Type::String, vrs, n_values) {
            return (s, &[]);
        }
        self.inner.get_strings(function, &self.scalars)
    }

    /// `fmi3SetString`: a NULL string (None) is refused with the variable's name.
    pub fn set_strings(
        &mut self,
        function: &str,
        vrs: &[u32],
        values: &[Option<String>],
    ) -> fmi2Status {
        if let Err(s) = self.expand(function, Fmi3Type::String, vrs, values.len()) {
            return s;
        }
        self.inner.set_strings(function, &self.scalars, values)
    }

    /// `fmi3GetOutputDerivatives`: `orders[i]` applies to every element of `vrs[i]`.
    pub fn get_output_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &mut [f64],
    ) -> fmi2Status {
        const F: &str = "fmi3GetOutputDerivatives";
        if let Err(s) = self.expand(F, Fmi3Type::Float64, vrs, values.len()) {
            return s;
        }
        if self.scalars.contains(&TIME) {
            return self.fail(F, "time (value reference 0) is not an output");
        }
        self.orders.clear();
        for (&vr, &order) in vrs.iter().zip(orders) {
            let len = self.arrays.get(&vr).map_or(1, |a| a.len);
            self.orders.extend(std::iter::repeat_n(order, len));
        }
        self.inner
            .get_real_output_derivatives(&self.scalars, &self.orders, values)
    }

    /// `flexbody_fmi3GetStepJacobian`: the step Jacobian of the last `fmi3DoStep`
    /// ([`crate::fmi2::Instance::step_jacobian`]) over the elements of the array variables
    /// `unknowns` (rows) and `knowns` (columns), each array's elements in row-major order;
    /// `jacobian` has one entry per pair of elements.
    pub fn step_jacobian(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        jacobian: &mut [f64],
    ) -> fmi2Status {
        const F: &str = "flexbody_fmi3GetStepJacobian";
        let elements = |vrs: &[u32]| -> usize {
            vrs.iter()
                .map(|vr| self.arrays.get(vr).map_or(1, |a| a.len))
                .sum()
        };
        let (rows, columns) = (elements(unknowns), elements(knowns));
        // The value references first (an unknown one is named), then the size.
        if let Err(s) = self.expand(F, Fmi3Type::Float64, knowns, columns) {
            return s;
        }
        std::mem::swap(&mut self.knowns, &mut self.scalars);
        let status = match self.expand(F, Fmi3Type::Float64, unknowns, rows) {
            Err(s) => s,
            Ok(()) if rows * columns != jacobian.len() => self.fail(
                F,
                &format!(
                    "nJacobian = {} rejected: the unknowns have {rows} elements and the knowns {columns}",
                    jacobian.len()
                ),
            ),
            Ok(()) if self.scalars.contains(&TIME) || self.knowns.contains(&TIME) => {
                self.fail(F, "time (value reference 0) is neither an output nor an input")
            }
            Ok(()) => self
                .inner
                .step_jacobian(F, &self.scalars, &self.knowns, jacobian),
        };
        std::mem::swap(&mut self.knowns, &mut self.scalars);
        status
    }

    /// `fmi3EnterInitializationMode`: FMI 2.0's `fmi2SetupExperiment` and
    /// `fmi2EnterInitializationMode` in one call.
    pub fn enter_initialization_mode(
        &mut self,
        tolerance: Option<f64>,
        start_time: f64,
        stop_time: Option<f64>,
    ) -> fmi2Status {
        match self
            .inner
            .setup_experiment(tolerance, start_time, stop_time)
        {
            fmi2Status::fmi2OK => self.inner.enter_initialization_mode(),
            status => status,
        }
    }

    /// `fmi3DoStep`: the status and whether the importer should end the simulation (never: a
    /// discarded step is rolled back and leaves the instance in Step Mode, ready for a retry
    /// with a shorter step, FMI 3.0 section 2.2.3).
    pub fn do_step(&mut self, t: f64, h: f64) -> (fmi2Status, bool) {
        let status = self.inner.do_step(t, h);
        if status == fmi2Status::fmi2Discard {
            self.inner.continue_after_discard();
        }
        (status, false)
    }

    /// The time of the last successful step.
    pub fn time(&self) -> f64 {
        self.inner.slave().time()
    }
}
