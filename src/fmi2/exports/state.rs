//! FMU states: get, set, free, serialize and deserialize.
#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::*;

/// `fmi2GetFMUstate`: a NULL `*FMUstate` receives a new state; a non-NULL one is overwritten.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    const F: &str = "fmi2GetFMUstate";
    call(c, F, |inst| get_fmu_state(inst, F, FMUstate))
}

/// The body of [`fmi2GetFMUstate`] (also FMI 3.0's).
pub(crate) unsafe fn get_fmu_state(
    inst: &mut Component,
    F: &str,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    if FMUstate.is_null() {
        return inst.fail(F, "FMUstate is NULL");
    }
    let snapshot = match inst.snapshot(F) {
        Ok(s) => s,
        Err(status) => return status,
    };
    store_state(inst, F, FMUstate, snapshot)
}

/// Stores `snapshot` in `*FMUstate` (fmi2GetFMUstate, fmi2DeSerializeFMUstate): a new state when
/// `*FMUstate` is NULL, else it overwrites the live state `*FMUstate` points to.
unsafe fn store_state(
    inst: &mut Component,
    function: &str,
    FMUstate: *mut fmi2FMUstate,
    snapshot: FmuState,
) -> fmi2Status {
    let existing = *FMUstate as *mut FmuState;
    if existing.is_null() {
        *FMUstate = Box::into_raw(Box::new(snapshot)) as fmi2FMUstate;
    } else {
        if !(*existing).is_valid() {
            return inst.fail(
                function,
                "*FMUstate is not a live state of this FMU (freed, or from another FMU)",
            );
        }
        *existing = snapshot;
    }
    fmi2Status::fmi2OK
}

/// `fmi2SetFMUstate`: the state stays valid and can be used again.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    const F: &str = "fmi2SetFMUstate";
    call(c, F, |inst| set_fmu_state(inst, F, FMUstate))
}

/// The body of [`fmi2SetFMUstate`] (also FMI 3.0's).
pub(crate) unsafe fn set_fmu_state(
    inst: &mut Component,
    F: &str,
    FMUstate: fmi2FMUstate,
) -> fmi2Status {
    match (FMUstate as *const FmuState).as_ref() {
        Some(snapshot) => inst.restore(snapshot),
        None => inst.fail(F, "FMUstate is NULL"),
    }
}

/// `fmi2FreeFMUstate`: frees `*FMUstate` and sets it to NULL; a NULL state is a no-op.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    const F: &str = "fmi2FreeFMUstate";
    call(c, F, |inst| free_fmu_state(inst, F, FMUstate))
}

/// The body of [`fmi2FreeFMUstate`] (also FMI 3.0's).
pub(crate) unsafe fn free_fmu_state(
    inst: &mut Component,
    F: &str,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    if let Err(status) = inst.may_free_state() {
        return status;
    }
    if FMUstate.is_null() || (*FMUstate).is_null() {
        return fmi2Status::fmi2OK;
    }
    let ptr = *FMUstate as *mut FmuState;
    if !(*ptr).is_valid() {
        return inst.fail(
            F,
            "*FMUstate is not a live state of this FMU (freed, or from another FMU)",
        );
    }
    drop(Box::from_raw(ptr));
    *FMUstate = null_mut();
    fmi2Status::fmi2OK
}

/// The live state behind `FMUstate`, or an error message.
unsafe fn live_state<'a>(
    inst: &mut Component,
    function: &str,
    FMUstate: fmi2FMUstate,
) -> Result<&'a FmuState, fmi2Status> {
    match (FMUstate as *const FmuState).as_ref() {
        None => Err(inst.fail(function, "FMUstate is NULL")),
        Some(s) if !s.is_valid() => Err(inst.fail(
            function,
            "FMUstate is not a live state of this FMU (freed, or from another FMU)",
        )),
        Some(s) => Ok(s),
    }
}

/// `fmi2SerializedFMUstateSize`: the number of bytes `fmi2SerializeFMUstate` writes.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    const F: &str = "fmi2SerializedFMUstateSize";
    call(c, F, |inst| {
        serialized_fmu_state_size(inst, F, FMUstate, size)
    })
}

/// The body of [`fmi2SerializedFMUstateSize`] (also FMI 3.0's).
pub(crate) unsafe fn serialized_fmu_state_size(
    inst: &mut Component,
    F: &str,
    FMUstate: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    if size.is_null() {
        return inst.fail(F, "size is NULL");
    }
    let state = match live_state(inst, F, FMUstate) {
        Ok(s) => s,
        Err(status) => return status,
    };
    match inst.serialize_snapshot(F, state) {
        Ok(bytes) => {
            *size = bytes.len();
            fmi2Status::fmi2OK
        }
        Err(status) => status,
    }
}

/// `fmi2SerializeFMUstate`: writes the state's portable bytes (layout:
/// [`super::instance::SERIALIZED_MAGIC`]) to `serializedState`, which holds `size` bytes, at
/// least `fmi2SerializedFMUstateSize`; bytes beyond the state are set to zero.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    const F: &str = "fmi2SerializeFMUstate";
    call(c, F, |inst| {
        serialize_fmu_state(inst, F, FMUstate, serializedState, size)
    })
}

/// The body of [`fmi2SerializeFMUstate`] (also FMI 3.0's).
pub(crate) unsafe fn serialize_fmu_state(
    inst: &mut Component,
    F: &str,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    let state = match live_state(inst, F, FMUstate) {
        Ok(s) => s,
        Err(status) => return status,
    };
    let bytes = match inst.serialize_snapshot(F, state) {
        Ok(b) => b,
        Err(status) => return status,
    };
    if size < bytes.len() {
        return inst.fail(
            F,
            &format!(
                "size = {size} rejected: the state needs {} bytes (fmi2SerializedFMUstateSize)",
                bytes.len()
            ),
        );
    }
    let Some(out) = slice_out(serializedState as *mut u8, size) else {
        return inst.fail(F, &format!("serializedState is NULL with size = {size}"));
    };
    out[..bytes.len()].copy_from_slice(&bytes);
    out[bytes.len()..].fill(0);
    fmi2Status::fmi2OK
}

/// `fmi2DeSerializeFMUstate`: a state from bytes of `fmi2SerializeFMUstate` (of an instance of
/// the same FMU, possibly in another process); a NULL `*FMUstate` receives a new state, a
/// non-NULL one is overwritten. Bytes of another body or version are refused with a message.
#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    const F: &str = "fmi2DeSerializeFMUstate";
    call(c, F, |inst| {
        deserialize_fmu_state(inst, F, serializedState, size, FMUstate)
    })
}

/// The body of [`fmi2DeSerializeFMUstate`] (also FMI 3.0's).
pub(crate) unsafe fn deserialize_fmu_state(
    inst: &mut Component,
    F: &str,
    serializedState: *const fmi2Byte,
    size: usize,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    if FMUstate.is_null() {
        return inst.fail(F, "FMUstate is NULL");
    }
    let Some(bytes) = slice_in(serializedState as *const u8, size) else {
        return inst.fail(F, &format!("serializedState is NULL with size = {size}"));
    };
    let snapshot = match inst.deserialize_snapshot(bytes) {
        Ok(s) => s,
        Err(status) => return status,
    };
    store_state(inst, F, FMUstate, snapshot)
}
