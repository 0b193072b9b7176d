//! `fmi3Get*` and `fmi3Set*` of the types this FMU has: Float64, Int32, Int64 (enumerations),
//! Boolean and String. An array variable takes as many values as it has elements, row-major.
#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::*;
use crate::fmi3::instance::Fmi3Type;

/// `fmi3GetFloat64`.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetFloat64";
    call(instance, F, |inst| {
        match (
            slice_in(valueReferences, nValueReferences),
            slice_out(values, nValues),
        ) {
            (Some(vrs), Some(values)) => inst.get_float64(F, vrs, values),
            _ => inst.fail(F, &null_arrays(nValueReferences, nValues)),
        }
    })
}

/// `fmi3SetFloat64`.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    const F: &str = "fmi3SetFloat64";
    call(instance, F, |inst| {
        match (
            slice_in(valueReferences, nValueReferences),
            slice_in(values, nValues),
        ) {
            (Some(vrs), Some(values)) => inst.set_float64(F, vrs, values),
            _ => inst.fail(F, &null_arrays(nValueReferences, nValues)),
        }
    })
}

/// `fmi3GetInt32`: the Int32 variables (counts such as `model.frames`).
#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetInt32";
    call(instance, F, |inst| {
        match (
            slice_in(valueReferences, nValueReferences),
            slice_out(values, nValues),
        ) {
            (Some(vrs), Some(out)) => {
                inst.get_integers(F, Fmi3Type::Int32, vrs, nValues, |i, x| out[i] = x)
            }
            _ => inst.fail(F, &null_arrays(nValueReferences, nValues)),
        }
    })
}

/// `fmi3SetInt32`.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    const F: &str = "fmi3SetInt32";
    call(instance, F, |inst| {
        match (
            slice_in(valueReferences, nValueReferences),
            slice_in(values, nValues),
        ) {
            (Some(vrs), Some(values)) => {
                let wide: Vec<i64> = values.iter().map(|&x| x as i64).collect();
                inst.set_integers(F, Fmi3Type::Int32, vrs, &wide)
            }
            _ => inst.fail(F, &null_arrays(nValueReferences, nValues)),
        }
    })
}

/// `fmi3GetInt64`: the enumerations (FMI 3.0 section 2.4.7.4: enumeration values are Int64).
#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int64,
    nValues: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetInt64";
    call(instance, F, |inst| {
        match (
            slice_in(valueReferences, nValueReferences),
            slice_out(values, nValues),
        ) {
            (Some(vrs), Some(out)) => {
                inst.get_integers(F, Fmi3Type::Enumeration, vrs, nValues, |i, x| {
                    out[i] = x as i64
                })
            }
            _ => inst.fail(F, &null_arrays(nValueReferences, nValues)),
        }
    })
}

/// `fmi3SetInt64`: the enumerations.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int64,
    nValues: usize,
) -> fmi3Status {
    const F: &str = "fmi3SetInt64";
    call(instance, F, |inst| {
        match (
            slice_in(valueReferences, nValueReferences),
            slice_in(values, nValues),
        ) {
            (Some(vrs), Some(values)) => inst.set_integers(F, Fmi3Type::Enumeration, vrs, values),
            _ => inst.fail(F, &null_arrays(nValueReferences, nValues)),
        }
    })
}

/// `fmi3GetBoolean`: writes `true`/`false` (1/0).
#[no_mangle]
pub unsafe extern "C" fn fmi3GetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetBoolean";
    call(instance, F, |inst| {
        match (
            slice_in(valueReferences, nValueReferences),
            slice_out(values, nValues),
        ) {
            (Some(vrs), Some(out)) => inst.get_booleans(F, vrs, nValues, |i, x| {
                out[i] = if x { fmi3True } else { fmi3False }
            }),
            _ => inst.fail(F, &null_arrays(nValueReferences, nValues)),
        }
    })
}

/// `fmi3SetBoolean`: any non-zero byte is true.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    const F: &str = "fmi3SetBoolean";
    call(instance, F, |inst| {
        match (
            slice_in(valueReferences, nValueReferences),
            slice_in(values, nValues),
        ) {
            (Some(vrs), Some(values)) => {
                let flags: Vec<bool> = values.iter().map(|&b| b != fmi3False).collect();
                inst.set_booleans(F, vrs, &flags)
            }
            _ => inst.fail(F, &null_arrays(nValueReferences, nValues)),
        }
    })
}

/// `fmi3GetString`: the strings stay valid until the next `fmi3GetString` on this instance.
#[no_mangle]
pub unsafe extern "C" fn fmi3GetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3String,
    nValues: usize,
) -> fmi3Status {
    const F: &str = "fmi3GetString";
    call(instance, F, |inst| {
        match (
            slice_in(valueReferences, nValueReferences),
            slice_out(values, nValues),
        ) {
            (Some(vrs), Some(out)) => {
                let (status, strings) = inst.get_strings(F, vrs, nValues);
                for (o, s) in out.iter_mut().zip(strings) {
                    *o = s.as_ptr();
                }
                status
            }
            _ => inst.fail(F, &null_arrays(nValueReferences, nValues)),
        }
    })
}

/// `fmi3SetString`: the strings are copied.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3String,
    nValues: usize,
) -> fmi3Status {
    const F: &str = "fmi3SetString";
    call(instance, F, |inst| {
        match (
            slice_in(valueReferences, nValueReferences),
            slice_in(values, nValues),
        ) {
            (Some(vrs), Some(values)) => {
                let copies: Vec<Option<String>> = values.iter().map(|&p| copy_string(p)).collect();
                inst.set_strings(F, vrs, &copies)
            }
            _ => inst.fail(F, &null_arrays(nValueReferences, nValues)),
        }
    })
}
