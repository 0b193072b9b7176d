//! The co-simulation functions: `fmi3DoStep`, `fmi3EnterStepMode`, `fmi3GetOutputDerivatives`.
#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::*;

/// `fmi3DoStep`: one communication step (synchronous, never early). `eventHandlingNeeded`,
/// `earlyReturn` and `terminateSimulation` are false; after `fmi3Discard` the slave has rolled
/// back to the step's start and the instance stays in Step Mode, so the importer may retry with
/// a shorter step; `lastSuccessfulTime` is the slave's time. The output pointers may be NULL.
#[no_mangle]
pub unsafe extern "C" fn fmi3DoStep(
    instance: fmi3Instance,
    currentCommunicationPoint: fmi3Float64,
    communicationStepSize: fmi3Float64,
    noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    eventHandlingNeeded: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
    earlyReturn: *mut fmi3Boolean,
    lastSuccessfulTime: *mut fmi3Float64,
) -> fmi3Status {
    let _ = noSetFMUStatePriorToCurrentPoint;
    call(instance, "fmi3DoStep", |inst| {
        let (status, terminate) = inst.do_step(currentCommunicationPoint, communicationStepSize);
        let flag = |b: bool| if b { fmi3True } else { fmi3False };
        if let Some(p) = eventHandlingNeeded.as_mut() {
            *p = fmi3False;
        }
        if let Some(p) = terminateSimulation.as_mut() {
            *p = flag(terminate);
        }
        if let Some(p) = earlyReturn.as_mut() {
            *p = fmi3False;
        }
        if let Some(p) = lastSuccessfulTime.as_mut() {
            *p = inst.time();
        }
        status
    })
}

/// `fmi3EnterStepMode`: only after event mode, which this FMU does not have
/// (`hasEventMode="false"`: `fmi3ExitInitializationMode` goes to Step Mode directly).
#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(instance: fmi3Instance) -> fmi3Status {
    const F: &str = "fmi3EnterStepMode";
    call(instance, F, |inst| {
        inst.fail(
            F,
            "not allowed: this FMU has no event mode (hasEventMode=\"false\"); fmi3ExitInitializationMode enters Step Mode",
        )
    })
}

/// `fmi3GetOutputDerivatives` (`maxOutputDerivativeOrder="2"`): `orders[i]` for every element
/// of `valueReferences[i]`; which outputs have derivatives: see
/// [`crate::slave::Slave::get_real_output_derivative`].
#[no_mangle]
pub unsafe extern "C" fn fmi3GetOutputDerivatives(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    orders: *const fmi3Int32,
    values: *mut fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetOutputDerivatives";
    call(instance, F, |inst| {
        match (
            slice_in(valueReferences, nValueReferences),
            slice_in(orders, nValueReferences),
            slice_out(values, nValues),
        ) {
            (Some(vrs), Some(orders), Some(values)) => {
                inst.get_output_derivatives(vrs, orders, values)
            }
            _ => inst.fail(
                F,
                &format!("valueReferences, orders or values is NULL with nValueReferences = {nValueReferences}, nValues = {nValues}"),
            ),
        }
    })
}

/// `flexbody_fmi3GetStepJacobian` (not an FMI function; docs/coupling.md, "Jacobians"): the
/// step Jacobian of the last `fmi3DoStep` for an FMI 3.0 importer, over the elements of the
/// array variables `unknowns` (Float64 outputs, rows) and `knowns` (Float64 inputs, columns),
/// each array's elements in row-major order: `jacobian` (row-major, `nJacobian` = the product
/// of the two element counts). The FMI 2.0 function `flexbody_GetStepJacobian` says why it is
/// not `fmi3GetDirectionalDerivative`.
#[no_mangle]
pub unsafe extern "C" fn flexbody_fmi3GetStepJacobian(
    instance: fmi3Instance,
    unknowns: *const fmi3ValueReference,
    nUnknowns: usize,
    knowns: *const fmi3ValueReference,
    nKnowns: usize,
    jacobian: *mut fmi3Float64,
    nJacobian: usize,
) -> fmi3Status {
    const F: &str = "flexbody_fmi3GetStepJacobian";
    call(instance, F, |inst| {
        match (
            slice_in(unknowns, nUnknowns),
            slice_in(knowns, nKnowns),
            slice_out(jacobian, nJacobian),
        ) {
            (Some(u), Some(k), Some(j)) => inst.step_jacobian(u, k, j),
            _ => inst.fail(
                F,
                &format!("unknowns, knowns or jacobian is NULL with nUnknowns = {nUnknowns}, nKnowns = {nKnowns}, nJacobian = {nJacobian}"),
            ),
        }
    })
}
