//! Every FMI 3.0 function of a feature these FMUs do not declare (adjoint derivatives, Configuration
//! Mode, variable types other than Float64/Int32/Boolean besides Clock). They exist
//! because the standard's importers (fmpy, FMI Library) resolve every `fmi3*` symbol when they load a
//! binary; each one refuses with `fmi3Error` and a logged reason, as the standard prescribes for a call
//! the model description does not allow.
#![allow(
    non_snake_case,
    clippy::missing_safety_doc,
    clippy::not_unsafe_ptr_arg_deref,
    clippy::too_many_arguments
)]

use std::ffi::{c_char, c_int};

use super::common::{call3, mask3, refuse, Instance3};
use crate::fmi::boundary::slice;
use crate::fmi::instance::Fail;

/// Functions of the standard's signature `(instance, vr, n, …)` for a variable type the FMUs have none
/// of: each refuses with `no_such_type` under its own name (`stringify!`), one table line each.
macro_rules! no_such_type {
    ($( $name:ident ( $( $arg:ident : $ty:ty ),* ) => $mask:expr, $what:literal; )*) => {
        $(
            pub extern "C" fn $name(c: Instance3, vr: *const u32, n: usize, $( $arg: $ty ),* ) -> c_int {
                no_such_type(c, stringify!($name), $mask, $what, vr, n)
            }
        )*
    };
}

pub extern "C" fn fmi3GetAdjointDerivative(
    c: Instance3,
    _u: *const u32,
    _nu: usize,
    _k: *const u32,
    _nk: usize,
    _s: *const f64,
    _ns: usize,
    _out: *mut f64,
    _no: usize,
) -> c_int {
    refuse(
        c,
        "fmi3GetAdjointDerivative",
        mask3::DIRECTIONAL_DERIVATIVE,
        "providesAdjointDerivatives = false",
    )
}

pub extern "C" fn fmi3EnterConfigurationMode(c: Instance3) -> c_int {
    refuse(
        c,
        "fmi3EnterConfigurationMode",
        mask3::ANY,
        "this FMU has no structural parameters",
    )
}

pub extern "C" fn fmi3ExitConfigurationMode(c: Instance3) -> c_int {
    refuse(
        c,
        "fmi3ExitConfigurationMode",
        mask3::ANY,
        "this FMU has no structural parameters (Configuration Mode is never entered)",
    )
}

/// Variables of a type this FMU does not have: a call with values is refused (naming the first value
/// reference); an empty call does nothing.
fn no_such_type(c: Instance3, func: &str, allowed: u16, ty: &str, vr: *const u32, n: usize) -> c_int {
    call3(c, func, allowed, |_| {
        let vrs = unsafe { slice(vr, n, "valueReferences[]")? };
        match vrs.first() {
            None => Ok(()),
            Some(v) => Err(Fail::error(format!(
                "unknown {ty} value reference {v}: this FMU has no variables of type {ty}"
            ))),
        }
    })
}

macro_rules! other_types {
    ($($get:ident, $set:ident, $t:ty, $name:literal;)*) => {$(
        pub extern "C" fn $get(c: Instance3, vr: *const u32, n: usize, _v: *mut $t, _nv: usize) -> c_int {
            no_such_type(c, stringify!($get), mask3::GET, $name, vr, n)
        }
        pub extern "C" fn $set(c: Instance3, vr: *const u32, n: usize, _v: *const $t, _nv: usize) -> c_int {
            no_such_type(c, stringify!($set), mask3::SET, $name, vr, n)
        }
    )*};
}

other_types! {
    fmi3GetFloat32, fmi3SetFloat32, f32, "Float32";
    fmi3GetInt8, fmi3SetInt8, i8, "Int8";
    fmi3GetUInt8, fmi3SetUInt8, u8, "UInt8";
    fmi3GetInt16, fmi3SetInt16, i16, "Int16";
    fmi3GetUInt16, fmi3SetUInt16, u16, "UInt16";
    fmi3GetUInt32, fmi3SetUInt32, u32, "UInt32";
    fmi3GetInt64, fmi3SetInt64, i64, "Int64";
    fmi3GetUInt64, fmi3SetUInt64, u64, "UInt64";
    fmi3GetString, fmi3SetString, *const c_char, "String";
}

no_such_type! {
    fmi3GetBinary(_sizes: *mut usize, _v: *mut *const u8, _nv: usize) => mask3::GET, "Binary";
    fmi3SetBinary(_sizes: *const usize, _v: *const *const u8, _nv: usize) => mask3::SET, "Binary";
}
