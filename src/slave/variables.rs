//! Variable access by value reference: typed get and set, start values, input derivatives.

use super::parameters::{Parameters, Slot};
use super::{OutputGroup, Slave, MAX_INPUT_DERIVATIVE_ORDER};
use crate::error::{Error, Result};
use crate::model::model_description::format_real;
use crate::model::variables::{EnumerationSpec, FixedKey, InterfaceQuantity};
use crate::model::{InterfaceKind, Target, Variable, VariableType};

pub(super) fn component_of(v: &Variable) -> usize {
    match v.target {
        Target::Fixed { component, .. } | Target::Interface { component, .. } => component,
    }
}

/// Offset of a body output in [`Outputs::body`].
pub(super) fn body_output_slot(key: FixedKey) -> usize {
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

impl Slave {
    /// Before any variable is set: in initialization mode the rigid placement computed for an
    /// output read before is no longer that of the inputs and parameters, and is dropped (the
    /// next read places the body again).
    fn setting_a_variable(&mut self) {
        if self.initializing {
            self.dynamics = None;
            self.outputs.invalidate();
        }
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

    /// Value of a String variable.
    pub fn get_string(&mut self, vr: u32) -> Result<String> {
        let v = self.lookup(VariableType::String, vr)?;
        match v.target {
            Target::Fixed { key, component } => match self.parameters.slot(key, component) {
                Some(Slot::Text(text)) => Some(text.clone()),
                _ => None,
            },
            Target::Interface { .. } => None,
        }
        .ok_or_else(|| Error::new(format!("no String variable has value reference {vr}")))
    }

    /// Sets a String parameter (`output.directory`: any text; a directory that cannot be created
    /// is reported when the results are first written).
    pub fn set_string(&mut self, vr: u32, value: &str) -> Result<()> {
        self.setting_a_variable();
        let v = self.lookup(VariableType::String, vr)?;
        match self.parameters.target_mut(v.target) {
            Some(Slot::Text(text)) => {
                value.clone_into(text);
                Ok(())
            }
            _ => Err(Error::new(format!("{} cannot be set", v.name))),
        }
    }

    /// Start value of a parameter or input as written in the XML (full precision).
    pub(super) fn start_value(&self, v: &Variable) -> String {
        match (v.ty, v.target) {
            (VariableType::Boolean, Target::Fixed { key, .. }) => {
                self.defaults.boolean(key).unwrap_or(false).to_string()
            }
            (VariableType::Integer, Target::Fixed { key, .. }) => {
                self.defaults.integer(key).unwrap_or(0).to_string()
            }
            (VariableType::Real, Target::Fixed { key, component }) => {
                format_real(self.defaults.real(key, component).unwrap_or(0.0))
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

    pub(super) fn lookup(&self, ty: VariableType, vr: u32) -> Result<Variable> {
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
            Target::Fixed { key, component } => match self.parameters.real(key, component) {
                Some(p) => p,
                None => {
                    self.ensure_outputs(OutputGroup::Body)?;
                    self.outputs.body[body_output_slot(key) + component]
                }
            },
            Target::Interface {
                index,
                quantity,
                component,
            } => {
                if causality == crate::model::Causality::Input {
                    self.inputs[index][quantity.slot() as usize + component]
                } else {
                    self.ensure_outputs(OutputGroup::Interface(index))?;
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
        self.setting_a_variable();
        let v = self
            .variables
            .get(VariableType::Real, vr)
            .ok_or_else(|| Error::new(format!("no Real variable has value reference {vr}")))?;
        match v.target {
            Target::Fixed { key, component } => {
                Parameters::check_real(&v.name, key, value)?;
                match self.parameters.slot_mut(key, component) {
                    Some(Slot::Real(p)) => *p = value,
                    _ => {
                        return Err(Error::new(format!(
                            "{} is an output and cannot be set",
                            v.name
                        )))
                    }
                }
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
            Target::Fixed { key, .. } => self.parameters.integer(key),
            _ => None,
        }
        .ok_or_else(|| Error::new(format!("no Integer variable has value reference {vr}")))
    }

    /// Sets an Integer parameter after [`Slave::check_integer`].
    pub fn set_integer(&mut self, vr: u32, value: i32) -> Result<()> {
        self.setting_a_variable();
        let v = self.lookup(VariableType::Integer, vr)?;
        self.check_integer(&v, value)?;
        match self.parameters.target_mut(v.target) {
            Some(Slot::Integer(x)) => {
                *x = value;
                Ok(())
            }
            // An item: check_integer has checked it against the enumeration.
            Some(Slot::Choice(c)) => match c.set_item(value) {
                true => Ok(()),
                false => Err(Error::invalid_value(&v.name, value, "not an item")),
            },
            _ => Err(Error::new(format!("{} cannot be set", v.name))),
        }
    }

    /// Checks an Integer value for `v`: an enumeration's items, the variable's `min` and `max`
    /// (`modelDescription/variables.json`), and `model.frames` at most the number of elements.
    fn check_integer(&self, v: &Variable, value: i32) -> Result<()> {
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
        let reason = v.range_violation(f64::from(value));
        let elements = self.mesh.element_count();
        let frames = matches!(
            v.target,
            Target::Fixed {
                key: FixedKey::Frames,
                ..
            }
        );
        let reason = reason.or_else(|| {
            (frames && value as usize > elements)
                .then(|| format!("must lie in [1, {elements}] (the number of elements)"))
        });
        match reason {
            Some(r) => Err(Error::invalid_value(&v.name, value, &r)),
            None => Ok(()),
        }
    }

    pub fn get_boolean(&mut self, vr: u32) -> Result<bool> {
        let v = self.lookup(VariableType::Boolean, vr)?;
        match v.target {
            Target::Fixed { key, .. } => self.parameters.boolean(key),
            _ => None,
        }
        .ok_or_else(|| Error::new(format!("no Boolean variable has value reference {vr}")))
    }

    pub fn set_boolean(&mut self, vr: u32, value: bool) -> Result<()> {
        self.setting_a_variable();
        let v = self.lookup(VariableType::Boolean, vr)?;
        match self.parameters.target_mut(v.target) {
            Some(Slot::Boolean(x)) => {
                *x = value;
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
    pub(super) fn input_derivative_slot(
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
}
