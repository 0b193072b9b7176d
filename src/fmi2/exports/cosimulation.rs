//! The co-simulation functions: directional and input/output derivatives, `fmi2DoStep`,
//! `fmi2CancelStep` and the status queries.
#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::*;

/// `fmi2GetDirectionalDerivative`: not supported (`providesDirectionalDerivative="false"`).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    vUnknown_ref: *const fmi2ValueReference,
    nUnknown: usize,
    vKnown_ref: *const fmi2ValueReference,
    nKnown: usize,
    dvKnown: *const fmi2Real,
    dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    let _ = (
        vUnknown_ref,
        nUnknown,
        vKnown_ref,
        nKnown,
        dvKnown,
        dvUnknown,
    );
    const F: &str = "fmi2GetDirectionalDerivative";
    call(c, F, |inst| {
        inst.unsupported(
            F,
            "directional derivatives (providesDirectionalDerivative=\"false\")",
        )
    })
}

/// `flexbody_GetStepJacobian` (not an FMI function; docs/coupling.md, "Jacobians"): the step
/// Jacobian of the last `fmi2DoStep`, `jacobian[i * nKnown + j] = ∂ vUnknown_ref[i] (t₁) / ∂
/// vKnown_ref[j] (t₀)` (row-major), the derivative of outputs at the step's end with respect to
/// inputs held over it, the state at its start fixed. FMI 2.0's `fmi2GetDirectionalDerivative`
/// in co-simulation is the derivative at one instant, which this body's outputs do not have with
/// respect to its inputs; the step Jacobian is what an implicit coupling needs, so it comes as a
/// function of its own, exported beside the FMI 2.0 functions (`ctypes` or `dlsym` reach it).
#[no_mangle]
pub unsafe extern "C" fn flexbody_GetStepJacobian(
    c: fmi2Component,
    vUnknown_ref: *const fmi2ValueReference,
    nUnknown: usize,
    vKnown_ref: *const fmi2ValueReference,
    nKnown: usize,
    jacobian: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "flexbody_GetStepJacobian";
    call(c, F, |inst| {
        let size = nUnknown.checked_mul(nKnown);
        match (
            slice_in(vUnknown_ref, nUnknown),
            slice_in(vKnown_ref, nKnown),
            size.and_then(|n| slice_out(jacobian, n)),
        ) {
            (Some(unknowns), Some(knowns), Some(values)) => {
                inst.step_jacobian(F, unknowns, knowns, values)
            }
            _ => inst.fail(
                F,
                &format!(
                    "vUnknown_ref, vKnown_ref or jacobian is NULL (or too large) with nUnknown = {nUnknown}, nKnown = {nKnown}"
                ),
            ),
        }
    })
}

// ---------------------------------------------------------------------------------------------
// Co-simulation

/// `fmi2SetRealInputDerivatives` (`canInterpolateInputs="true"`): derivatives of force inputs,
/// see [`crate::slave::Slave::set_real_input_derivatives`].
#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2SetRealInputDerivatives";
    call(c, F, |inst| {
        match (
            slice_in(vr, nvr),
            slice_in(order, nvr),
            slice_in(value, nvr),
        ) {
            (Some(vrs), Some(orders), Some(values)) => {
                inst.set_real_input_derivatives(vrs, orders, values)
            }
            _ => inst.fail(F, &format!("vr, order or value is NULL with nvr = {nvr}")),
        }
    })
}

/// `fmi2GetRealOutputDerivatives` (`maxOutputDerivativeOrder="2"`): see
/// [`crate::slave::Slave::get_real_output_derivative`] for which outputs have derivatives.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetRealOutputDerivatives";
    call(c, F, |inst| {
        match (
            slice_in(vr, nvr),
            slice_in(order, nvr),
            slice_out(value, nvr),
        ) {
            (Some(vrs), Some(orders), Some(values)) => {
                inst.get_real_output_derivatives(vrs, orders, values)
            }
            _ => inst.fail(F, &format!("vr, order or value is NULL with nvr = {nvr}")),
        }
    })
}

/// `fmi2DoStep`: `noSetFMUStatePriorToCurrentPoint` is ignored (states are kept by the importer).
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    let _ = noSetFMUStatePriorToCurrentPoint;
    call(c, "fmi2DoStep", |inst| {
        inst.do_step(currentCommunicationPoint, communicationStepSize)
    })
}

/// `fmi2CancelStep`: FMI 2.0 allows it only in the state StepInProgress, after `fmi2DoStep`
/// returned `fmi2Pending`. Steps here are synchronous (`canRunAsynchronuously="false"`), so that
/// state never occurs and every call is a calling-sequence error (`fmi2Error`, as the Reference
/// FMUs do); the instance is unchanged.
#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    const F: &str = "fmi2CancelStep";
    call(c, F, |inst| inst.cancel_step())
}

/// Writes `result` to `value` (checked for NULL) or returns its error status.
unsafe fn write_status<T>(
    inst: &mut Component,
    function: &str,
    value: *mut T,
    result: impl FnOnce(&mut Component) -> Result<T, fmi2Status>,
) -> fmi2Status {
    if value.is_null() {
        return inst.fail(function, "value is NULL");
    }
    match result(inst) {
        Ok(x) => {
            *value = x;
            fmi2Status::fmi2OK
        }
        Err(status) => status,
    }
}

/// `fmi2GetStatus`: always an error (see [`Instance::get_status`]).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    s: c_int,
    value: *mut fmi2Status,
) -> fmi2Status {
    const F: &str = "fmi2GetStatus";
    call(c, F, |inst| {
        write_status(inst, F, value, |i| i.get_status(s))
    })
}

/// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    s: c_int,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetRealStatus";
    call(c, F, |inst| {
        write_status(inst, F, value, |i| i.get_real_status(s))
    })
}

/// `fmi2GetIntegerStatus`: no Integer status exists.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    s: c_int,
    value: *mut fmi2Integer,
) -> fmi2Status {
    const F: &str = "fmi2GetIntegerStatus";
    call(c, F, |inst| {
        write_status(inst, F, value, |i| i.get_integer_status(s))
    })
}

/// `fmi2GetBooleanStatus`: `fmi2Terminated` (true after a discarded step).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: c_int,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2GetBooleanStatus";
    call(c, F, |inst| {
        write_status(inst, F, value, |i| {
            i.get_boolean_status(s)
                .map(|b| if b { fmi2True } else { fmi2False })
        })
    })
}

/// `fmi2GetStringStatus`: `fmi2PendingStatus` needs a pending step, which never happens.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    s: c_int,
    value: *mut fmi2String,
) -> fmi2Status {
    const F: &str = "fmi2GetStringStatus";
    call(c, F, |inst| {
        if value.is_null() {
            return inst.fail(F, "value is NULL");
        }
        inst.get_string_status(s)
    })
}
