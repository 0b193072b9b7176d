//! `fmi2Get*` and `fmi2Set*` of Real, Integer, Boolean and String variables.
#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::*;

/// `fmi2GetReal`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetReal";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_out(value, nvr)) {
            (Some(vrs), Some(values)) => inst.get_values(F, vrs, values),
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2GetInteger`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    const F: &str = "fmi2GetInteger";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_out(value, nvr)) {
            (Some(vrs), Some(values)) => inst.get_values::<i32>(F, vrs, values),
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2GetBoolean`: writes `fmi2True`/`fmi2False`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2GetBoolean";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_out(value, nvr)) {
            (Some(vrs), Some(values)) => {
                let mut flags = vec![false; nvr];
                let status = inst.get_values::<bool>(F, vrs, &mut flags);
                if status == fmi2Status::fmi2OK {
                    for (out, flag) in values.iter_mut().zip(flags) {
                        *out = if flag { fmi2True } else { fmi2False };
                    }
                }
                status
            }
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2GetString`: the strings stay valid until the next `fmi2GetString` on this instance.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    const F: &str = "fmi2GetString";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_out(value, nvr)) {
            (Some(vrs), Some(out)) => {
                let (status, strings) = inst.get_strings(F, vrs);
                for (o, s) in out.iter_mut().zip(strings) {
                    *o = s.as_ptr();
                }
                status
            }
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2SetReal`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2SetReal";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_in(value, nvr)) {
            (Some(vrs), Some(values)) => inst.set_values(F, vrs, values),
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2SetInteger`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    const F: &str = "fmi2SetInteger";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_in(value, nvr)) {
            (Some(vrs), Some(values)) => inst.set_values::<i32>(F, vrs, values),
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2SetBoolean`: any non-zero value is true.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2SetBoolean";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_in(value, nvr)) {
            (Some(vrs), Some(values)) => {
                let flags: Vec<bool> = values.iter().map(|&b| b != fmi2False).collect();
                inst.set_values::<bool>(F, vrs, &flags)
            }
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2SetString`: the strings are copied (lossy UTF-8).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    const F: &str = "fmi2SetString";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_in(value, nvr)) {
            (Some(vrs), Some(values)) => {
                let copies: Vec<Option<String>> = values.iter().map(|&p| copy_string(p)).collect();
                inst.set_strings(F, vrs, &copies)
            }
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

// ---------------------------------------------------------------------------------------------
// FMU state
