//! FMU states: the same snapshots and serialized bytes as FMI 2.0's
//! ([`crate::fmi2::exports`]), under FMI 3.0's names.
#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::*;
use crate::fmi2::exports as fmi2;

/// `fmi3GetFMUState`: a NULL `*FMUState` receives a new state; a non-NULL one is overwritten.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    const F: &str = "fmi3GetFMUState";
    call(instance, F, |inst| {
        fmi2::get_fmu_state(&mut inst.inner, F, FMUState)
    })
}

/// `fmi3SetFMUState`: the state stays valid and can be used again.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
) -> fmi3Status {
    const F: &str = "fmi3SetFMUState";
    call(instance, F, |inst| {
        fmi2::set_fmu_state(&mut inst.inner, F, FMUState)
    })
}

/// `fmi3FreeFMUState`: frees `*FMUState` and sets it to NULL; a NULL state is a no-op.
#[no_mangle]
pub unsafe extern "C" fn fmi3FreeFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    const F: &str = "fmi3FreeFMUState";
    call(instance, F, |inst| {
        fmi2::free_fmu_state(&mut inst.inner, F, FMUState)
    })
}

/// `fmi3SerializedFMUStateSize`.
#[no_mangle]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    const F: &str = "fmi3SerializedFMUStateSize";
    call(instance, F, |inst| {
        fmi2::serialized_fmu_state_size(&mut inst.inner, F, FMUState, size)
    })
}

/// `fmi3SerializeFMUState`: the portable bytes of FMI 2.0's `fmi2SerializeFMUstate`.
#[no_mangle]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    serializedState: *mut fmi3Byte,
    size: usize,
) -> fmi3Status {
    const F: &str = "fmi3SerializeFMUState";
    call(instance, F, |inst| {
        fmi2::serialize_fmu_state(
            &mut inst.inner,
            F,
            FMUState,
            serializedState as *mut crate::fmi2::types::fmi2Byte,
            size,
        )
    })
}

/// `fmi3DeserializeFMUState`: a state from bytes of `fmi3SerializeFMUState`.
#[no_mangle]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    instance: fmi3Instance,
    serializedState: *const fmi3Byte,
    size: usize,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    const F: &str = "fmi3DeserializeFMUState";
    call(instance, F, |inst| {
        fmi2::deserialize_fmu_state(
            &mut inst.inner,
            F,
            serializedState as *const crate::fmi2::types::fmi2Byte,
            size,
            FMUState,
        )
    })
}
