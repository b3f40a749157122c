//! The getters and setters of every FMI 3.0 variable type (`fmi3GetFloat64` … `fmi3SetClock`) for
//! [`__export_fmi3!`](crate::__export_fmi3): `#[no_mangle]` wrappers over `values.rs` (the types the
//! FMUs use) and `unsupported.rs` (the others, refused with a message), one line each of the
//! [`__fmi_forward!`](crate::__fmi_forward) table, spelled out in the crate that links the library.

/// Expands to the FMI 3.0 getters and setters. Used by [`__export_fmi3!`](crate::__export_fmi3) only.
#[doc(hidden)]
#[macro_export]
macro_rules! __export_fmi3_values {
    () => {
        const _: () = {
            use ::std::ffi::{c_char, c_int, c_void};
            use $crate::fmi::fmi3::clocks as ck3;
            use $crate::fmi::fmi3::unsupported as un3;
            use $crate::fmi::fmi3::values as va3;
            type Inst3 = *mut c_void;
            $crate::__fmi_forward! {
                va3::fmi3GetFloat64(c: Inst3, vr: *const u32, n: usize, v: *mut f64, nv: usize) -> c_int;
                va3::fmi3SetFloat64(c: Inst3, vr: *const u32, n: usize, v: *const f64, nv: usize) -> c_int;
                va3::fmi3GetInt32(c: Inst3, vr: *const u32, n: usize, v: *mut i32, nv: usize) -> c_int;
                va3::fmi3SetInt32(c: Inst3, vr: *const u32, n: usize, v: *const i32, nv: usize) -> c_int;
                va3::fmi3GetBoolean(c: Inst3, vr: *const u32, n: usize, v: *mut u8, nv: usize) -> c_int;
                va3::fmi3SetBoolean(c: Inst3, vr: *const u32, n: usize, v: *const u8, nv: usize) -> c_int;
                un3::fmi3GetFloat32(c: Inst3, vr: *const u32, n: usize, v: *mut f32, nv: usize) -> c_int;
                un3::fmi3SetFloat32(c: Inst3, vr: *const u32, n: usize, v: *const f32, nv: usize) -> c_int;
                un3::fmi3GetInt8(c: Inst3, vr: *const u32, n: usize, v: *mut i8, nv: usize) -> c_int;
                un3::fmi3SetInt8(c: Inst3, vr: *const u32, n: usize, v: *const i8, nv: usize) -> c_int;
                un3::fmi3GetUInt8(c: Inst3, vr: *const u32, n: usize, v: *mut u8, nv: usize) -> c_int;
                un3::fmi3SetUInt8(c: Inst3, vr: *const u32, n: usize, v: *const u8, nv: usize) -> c_int;
                un3::fmi3GetInt16(c: Inst3, vr: *const u32, n: usize, v: *mut i16, nv: usize) -> c_int;
                un3::fmi3SetInt16(c: Inst3, vr: *const u32, n: usize, v: *const i16, nv: usize) -> c_int;
                un3::fmi3GetUInt16(c: Inst3, vr: *const u32, n: usize, v: *mut u16, nv: usize) -> c_int;
                un3::fmi3SetUInt16(c: Inst3, vr: *const u32, n: usize, v: *const u16, nv: usize) -> c_int;
                un3::fmi3GetUInt32(c: Inst3, vr: *const u32, n: usize, v: *mut u32, nv: usize) -> c_int;
                un3::fmi3SetUInt32(c: Inst3, vr: *const u32, n: usize, v: *const u32, nv: usize) -> c_int;
                un3::fmi3GetInt64(c: Inst3, vr: *const u32, n: usize, v: *mut i64, nv: usize) -> c_int;
                un3::fmi3SetInt64(c: Inst3, vr: *const u32, n: usize, v: *const i64, nv: usize) -> c_int;
                un3::fmi3GetUInt64(c: Inst3, vr: *const u32, n: usize, v: *mut u64, nv: usize) -> c_int;
                un3::fmi3SetUInt64(c: Inst3, vr: *const u32, n: usize, v: *const u64, nv: usize) -> c_int;
                un3::fmi3GetString(c: Inst3, vr: *const u32, n: usize, v: *mut *const c_char, nv: usize) -> c_int;
                un3::fmi3SetString(c: Inst3, vr: *const u32, n: usize, v: *const *const c_char, nv: usize) -> c_int;
                un3::fmi3GetBinary(c: Inst3, vr: *const u32, n: usize, sizes: *mut usize, v: *mut *const u8, nv: usize) -> c_int;
                un3::fmi3SetBinary(c: Inst3, vr: *const u32, n: usize, sizes: *const usize, v: *const *const u8, nv: usize) -> c_int;
                ck3::fmi3GetClock(c: Inst3, vr: *const u32, n: usize, v: *mut u8) -> c_int;
                ck3::fmi3SetClock(c: Inst3, vr: *const u32, n: usize, v: *const u8) -> c_int;
            }
        };
    };
}
