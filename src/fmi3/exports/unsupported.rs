//! The FMI 3.0 functions this FMU does not support, each an error with a message that says why:
//! model exchange and scheduled execution (co-simulation only), event mode, configuration mode,
//! clocks, directional and adjoint derivatives (`providesDirectionalDerivatives="false"`),
//! variable dependencies (every output depends on every input: none are listed), and the types
//! without variables (Float32, the 8-, 16- and unsigned integers, Binary), whose getters and
//! setters accept an empty request and name the value reference of any other.
#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::*;
use std::ffi::c_int;

/// The instantiation functions of the interface types this FMU does not have: NULL, after a
/// message to the importer's logger.
fn refuse_instantiation(
    function: &str,
    name: fmi3String,
    logMessage: fmi3LogMessageCallback,
    environment: fmi3InstanceEnvironment,
) -> fmi3Instance {
    // SAFETY (caller): `name` is NULL or a NUL-terminated string.
    let name = unsafe { copy_string(name) }.unwrap_or_default();
    let mut logger = Logger::new(super::sink(logMessage, environment), &name, false).for_fmi3();
    logger.error(&format!(
        "{function}: {name}: this FMU supports co-simulation only (fmi3InstantiateCoSimulation)"
    ));
    null_mut()
}

/// `fmi3InstantiateModelExchange`: NULL (co-simulation only).
#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
) -> fmi3Instance {
    let _ = (instantiationToken, resourcePath, visible, loggingOn);
    catch_unwind(|| {
        refuse_instantiation(
            "fmi3InstantiateModelExchange",
            instanceName,
            logMessage,
            instanceEnvironment,
        )
    })
    .unwrap_or(null_mut())
}

/// `fmi3InstantiateScheduledExecution`: NULL (co-simulation only).
#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    clockUpdate: fmi3Callback,
    lockPreemption: fmi3Callback,
    unlockPreemption: fmi3Callback,
) -> fmi3Instance {
    let _ = (
        instantiationToken,
        resourcePath,
        visible,
        loggingOn,
        clockUpdate,
        lockPreemption,
        unlockPreemption,
    );
    catch_unwind(|| {
        refuse_instantiation(
            "fmi3InstantiateScheduledExecution",
            instanceName,
            logMessage,
            instanceEnvironment,
        )
    })
    .unwrap_or(null_mut())
}

/// Functions with an instance that are not supported: `fmi3Error` and a message saying why.
macro_rules! unsupported {
    ($(#[$doc:meta])* $name:ident($($arg:ident: $ty:ty),*), $why:expr) => {
        $(#[$doc])*
        #[no_mangle]
        pub unsafe extern "C" fn $name(instance: fmi3Instance $(, $arg: $ty)*) -> fmi3Status {
            let _ = ($($arg,)*);
            const F: &str = stringify!($name);
            call(instance, F, |inst| inst.inner.unsupported(F, $why))
        }
    };
}

const NO_EVENTS: &str = "this FMU has no event mode (hasEventMode=\"false\"): it has no events";
const NO_CLOCKS: &str = "this FMU has no clocks";
const CO_SIMULATION_ONLY: &str = "this FMU supports co-simulation only";

unsupported!(
    /// `fmi3EnterEventMode`: no event mode.
    fmi3EnterEventMode(), NO_EVENTS);
unsupported!(
    /// `fmi3EnterConfigurationMode`: no structural parameters.
    fmi3EnterConfigurationMode(), "this FMU has no structural parameters");
unsupported!(
    /// `fmi3ExitConfigurationMode`: no structural parameters.
    fmi3ExitConfigurationMode(), "this FMU has no structural parameters");
unsupported!(
    /// `fmi3EvaluateDiscreteStates`: no discrete states.
    fmi3EvaluateDiscreteStates(), "this FMU has no discrete states (no event mode)");
unsupported!(
    /// `fmi3UpdateDiscreteStates`: no event mode.
    fmi3UpdateDiscreteStates(
        discreteStatesNeedUpdate: *mut fmi3Boolean,
        terminateSimulation: *mut fmi3Boolean,
        nominalsOfContinuousStatesChanged: *mut fmi3Boolean,
        valuesOfContinuousStatesChanged: *mut fmi3Boolean,
        nextEventTimeDefined: *mut fmi3Boolean,
        nextEventTime: *mut fmi3Float64
    ),
    NO_EVENTS
);
unsupported!(
    /// `fmi3GetDirectionalDerivative` (`providesDirectionalDerivatives="false"`).
    fmi3GetDirectionalDerivative(
        unknowns: *const fmi3ValueReference,
        nUnknowns: usize,
        knowns: *const fmi3ValueReference,
        nKnowns: usize,
        seed: *const fmi3Float64,
        nSeed: usize,
        sensitivity: *mut fmi3Float64,
        nSensitivity: usize
    ),
    "directional derivatives (providesDirectionalDerivatives=\"false\")"
);
unsupported!(
    /// `fmi3GetAdjointDerivative` (`providesAdjointDerivatives="false"`).
    fmi3GetAdjointDerivative(
        unknowns: *const fmi3ValueReference,
        nUnknowns: usize,
        knowns: *const fmi3ValueReference,
        nKnowns: usize,
        seed: *const fmi3Float64,
        nSeed: usize,
        sensitivity: *mut fmi3Float64,
        nSensitivity: usize
    ),
    "adjoint derivatives (providesAdjointDerivatives=\"false\")"
);
unsupported!(
    /// `fmi3GetNumberOfVariableDependencies`: the model structure lists no dependencies (every
    /// output depends on every input).
    fmi3GetNumberOfVariableDependencies(valueReference: fmi3ValueReference, nDependencies: *mut usize),
    "variable dependencies: the model structure lists none, so every output depends on every input"
);
unsupported!(
    /// `fmi3GetVariableDependencies`: as [`fmi3GetNumberOfVariableDependencies`].
    fmi3GetVariableDependencies(
        dependent: fmi3ValueReference,
        elementIndicesOfDependent: *mut usize,
        independents: *mut fmi3ValueReference,
        elementIndicesOfIndependents: *mut usize,
        dependencyKinds: *mut c_int,
        nDependencies: usize
    ),
    "variable dependencies: the model structure lists none, so every output depends on every input"
);
unsupported!(
    /// `fmi3GetClock`: no clocks.
    fmi3GetClock(valueReferences: *const fmi3ValueReference, nValueReferences: usize, values: *mut fmi3Clock),
    NO_CLOCKS
);
unsupported!(
    /// `fmi3SetClock`: no clocks.
    fmi3SetClock(valueReferences: *const fmi3ValueReference, nValueReferences: usize, values: *const fmi3Clock),
    NO_CLOCKS
);
unsupported!(
    /// `fmi3GetIntervalDecimal`: no clocks.
    fmi3GetIntervalDecimal(
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        intervals: *mut fmi3Float64,
        qualifiers: *mut c_int
    ),
    NO_CLOCKS
);
unsupported!(
    /// `fmi3GetIntervalFraction`: no clocks.
    fmi3GetIntervalFraction(
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        counters: *mut u64,
        resolutions: *mut u64,
        qualifiers: *mut c_int
    ),
    NO_CLOCKS
);
unsupported!(
    /// `fmi3GetShiftDecimal`: no clocks.
    fmi3GetShiftDecimal(valueReferences: *const fmi3ValueReference, nValueReferences: usize, shifts: *mut fmi3Float64),
    NO_CLOCKS
);
unsupported!(
    /// `fmi3GetShiftFraction`: no clocks.
    fmi3GetShiftFraction(
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        counters: *mut u64,
        resolutions: *mut u64
    ),
    NO_CLOCKS
);
unsupported!(
    /// `fmi3SetIntervalDecimal`: no clocks.
    fmi3SetIntervalDecimal(valueReferences: *const fmi3ValueReference, nValueReferences: usize, intervals: *const fmi3Float64),
    NO_CLOCKS
);
unsupported!(
    /// `fmi3SetIntervalFraction`: no clocks.
    fmi3SetIntervalFraction(
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        counters: *const u64,
        resolutions: *const u64
    ),
    NO_CLOCKS
);
unsupported!(
    /// `fmi3SetShiftDecimal`: no clocks.
    fmi3SetShiftDecimal(valueReferences: *const fmi3ValueReference, nValueReferences: usize, shifts: *const fmi3Float64),
    NO_CLOCKS
);
unsupported!(
    /// `fmi3SetShiftFraction`: no clocks.
    fmi3SetShiftFraction(
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        counters: *const u64,
        resolutions: *const u64
    ),
    NO_CLOCKS
);
unsupported!(
    /// `fmi3ActivateModelPartition`: scheduled execution is not supported.
    fmi3ActivateModelPartition(clockReference: fmi3ValueReference, activationTime: fmi3Float64),
    CO_SIMULATION_ONLY
);

// Model exchange.
unsupported!(
    /// `fmi3EnterContinuousTimeMode`: model exchange only.
    fmi3EnterContinuousTimeMode(), CO_SIMULATION_ONLY);
unsupported!(
    /// `fmi3CompletedIntegratorStep`: model exchange only.
    fmi3CompletedIntegratorStep(
        noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
        enterEventMode: *mut fmi3Boolean,
        terminateSimulation: *mut fmi3Boolean
    ),
    CO_SIMULATION_ONLY
);
unsupported!(
    /// `fmi3SetTime`: model exchange only.
    fmi3SetTime(time: fmi3Float64), CO_SIMULATION_ONLY);
unsupported!(
    /// `fmi3SetContinuousStates`: model exchange only.
    fmi3SetContinuousStates(continuousStates: *const fmi3Float64, nContinuousStates: usize),
    CO_SIMULATION_ONLY
);
unsupported!(
    /// `fmi3GetContinuousStateDerivatives`: model exchange only.
    fmi3GetContinuousStateDerivatives(derivatives: *mut fmi3Float64, nContinuousStates: usize),
    CO_SIMULATION_ONLY
);
unsupported!(
    /// `fmi3GetEventIndicators`: model exchange only.
    fmi3GetEventIndicators(eventIndicators: *mut fmi3Float64, nEventIndicators: usize),
    CO_SIMULATION_ONLY
);
unsupported!(
    /// `fmi3GetContinuousStates`: model exchange only.
    fmi3GetContinuousStates(continuousStates: *mut fmi3Float64, nContinuousStates: usize),
    CO_SIMULATION_ONLY
);
unsupported!(
    /// `fmi3GetNominalsOfContinuousStates`: model exchange only.
    fmi3GetNominalsOfContinuousStates(nominals: *mut fmi3Float64, nContinuousStates: usize),
    CO_SIMULATION_ONLY
);
unsupported!(
    /// `fmi3GetNumberOfEventIndicators`: model exchange only.
    fmi3GetNumberOfEventIndicators(nEventIndicators: *mut usize),
    CO_SIMULATION_ONLY
);
unsupported!(
    /// `fmi3GetNumberOfContinuousStates`: model exchange only.
    fmi3GetNumberOfContinuousStates(nContinuousStates: *mut usize),
    CO_SIMULATION_ONLY
);

/// The getters and setters of types without variables: an empty request is fine, any value
/// reference is unknown.
fn no_variables(
    inst: &mut Fmi3Instance,
    function: &str,
    ty: &str,
    vrs: Option<&[fmi3ValueReference]>,
) -> fmi2Status {
    match vrs {
        Some([]) => fmi2Status::fmi2OK,
        Some([vr, ..]) => inst.fail(
            function,
            &format!("unknown {ty} value reference {vr}: this FMU has no {ty} variables"),
        ),
        None => inst.fail(function, "valueReferences is NULL"),
    }
}

macro_rules! no_variables_of_type {
    ($name:ident, $ty:literal, $($arg:ident: $argty:ty),*) => {
        #[doc = concat!("`", stringify!($name), "`: this FMU has no ", $ty, " variables.")]
        #[no_mangle]
        pub unsafe extern "C" fn $name(
            instance: fmi3Instance,
            valueReferences: *const fmi3ValueReference,
            nValueReferences: usize,
            $($arg: $argty),*
        ) -> fmi3Status {
            let _ = ($($arg,)*);
            const F: &str = stringify!($name);
            call(instance, F, |inst| {
                no_variables(inst, F, $ty, slice_in(valueReferences, nValueReferences))
            })
        }
    };
}

no_variables_of_type!(fmi3GetFloat32, "Float32", values: *mut f32, nValues: usize);
no_variables_of_type!(fmi3SetFloat32, "Float32", values: *const f32, nValues: usize);
no_variables_of_type!(fmi3GetInt8, "Int8", values: *mut i8, nValues: usize);
no_variables_of_type!(fmi3SetInt8, "Int8", values: *const i8, nValues: usize);
no_variables_of_type!(fmi3GetUInt8, "UInt8", values: *mut u8, nValues: usize);
no_variables_of_type!(fmi3SetUInt8, "UInt8", values: *const u8, nValues: usize);
no_variables_of_type!(fmi3GetInt16, "Int16", values: *mut i16, nValues: usize);
no_variables_of_type!(fmi3SetInt16, "Int16", values: *const i16, nValues: usize);
no_variables_of_type!(fmi3GetUInt16, "UInt16", values: *mut u16, nValues: usize);
no_variables_of_type!(fmi3SetUInt16, "UInt16", values: *const u16, nValues: usize);
no_variables_of_type!(fmi3GetUInt32, "UInt32", values: *mut u32, nValues: usize);
no_variables_of_type!(fmi3SetUInt32, "UInt32", values: *const u32, nValues: usize);
no_variables_of_type!(fmi3GetUInt64, "UInt64", values: *mut u64, nValues: usize);
no_variables_of_type!(fmi3SetUInt64, "UInt64", values: *const u64, nValues: usize);
no_variables_of_type!(
    fmi3GetBinary,
    "Binary",
    valueSizes: *mut usize,
    values: *mut fmi3Binary,
    nValues: usize
);
no_variables_of_type!(
    fmi3SetBinary,
    "Binary",
    valueSizes: *const usize,
    values: *const fmi3Binary,
    nValues: usize
);
