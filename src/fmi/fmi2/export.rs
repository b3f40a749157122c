//! The FMI 2.0 half of [`export_fmus!`](crate::export_fmus): `#[no_mangle]` wrappers with the standard
//! `fmi2*` names over this folder's functions, expanded inside `export_fmus!` (so one library serves
//! FMI 2.0 and 3.0 from the same models). Not meant to be used on its own.
//!
//! A `#[no_mangle]` symbol must be spelled out in the crate that links the library (the user's cdylib):
//! one line per C function of `fmi2Functions.h` in a [`__fmi_forward!`](crate::__fmi_forward) table, each
//! only forwarding to the function of the same name in this folder; the few that pass the model list are
//! written out.

/// Expands to the FMI 2.0 entry points for the model list `$models` (a `static [ModelEntry]` slice in
/// scope). Used by [`export_fmus!`](crate::export_fmus) only.
#[doc(hidden)]
#[macro_export]
macro_rules! __export_fmi2 {
    ($models:ident) => {
        const _: () = {
            use ::std::ffi::{c_char, c_int, c_void};
            use $crate::fmi::fmi2::common as c2;
            use $crate::fmi::fmi2::cs as cs2;
            use $crate::fmi::fmi2::me as me2;
            use $crate::fmi::fmi2::state as st2;
            type Component = *mut c_void;
            $crate::__fmi_forward! {
                c2::fmi2GetTypesPlatform() -> *const c_char;
                c2::fmi2GetVersion() -> *const c_char;
            }
            #[no_mangle]
            pub extern "C" fn fmi2Instantiate(
                name: *const c_char,
                fmu_type: c_int,
                guid: *const c_char,
                resources: *const c_char,
                functions: *const c2::CallbackFunctions,
                visible: c_int,
                logging_on: c_int,
            ) -> Component {
                c2::fmi2Instantiate(
                    $models, name, fmu_type, guid, resources, functions, visible, logging_on,
                )
            }
            $crate::__fmi_forward! {
                c2::fmi2FreeInstance(c: Component);
                c2::fmi2SetDebugLogging(c: Component, on: c_int, n: usize, cats: *const *const c_char) -> c_int;
                c2::fmi2SetupExperiment(c: Component, tol_defined: c_int, tol: f64, start: f64, stop_defined: c_int, stop: f64) -> c_int;
                c2::fmi2EnterInitializationMode(c: Component) -> c_int;
                c2::fmi2ExitInitializationMode(c: Component) -> c_int;
                c2::fmi2Terminate(c: Component) -> c_int;
                c2::fmi2Reset(c: Component) -> c_int;
                c2::fmi2GetReal(c: Component, vr: *const u32, n: usize, v: *mut f64) -> c_int;
                c2::fmi2GetInteger(c: Component, vr: *const u32, n: usize, v: *mut c_int) -> c_int;
                c2::fmi2GetBoolean(c: Component, vr: *const u32, n: usize, v: *mut c_int) -> c_int;
                c2::fmi2GetString(c: Component, vr: *const u32, n: usize, v: *mut *const c_char) -> c_int;
                c2::fmi2SetReal(c: Component, vr: *const u32, n: usize, v: *const f64) -> c_int;
                c2::fmi2SetInteger(c: Component, vr: *const u32, n: usize, v: *const c_int) -> c_int;
                c2::fmi2SetBoolean(c: Component, vr: *const u32, n: usize, v: *const c_int) -> c_int;
                c2::fmi2SetString(c: Component, vr: *const u32, n: usize, v: *const *const c_char) -> c_int;
                st2::fmi2GetFMUstate(c: Component, s: *mut *mut c_void) -> c_int;
                st2::fmi2SetFMUstate(c: Component, s: *mut c_void) -> c_int;
                st2::fmi2FreeFMUstate(c: Component, s: *mut *mut c_void) -> c_int;
                st2::fmi2SerializedFMUstateSize(c: Component, s: *mut c_void, size: *mut usize) -> c_int;
                st2::fmi2SerializeFMUstate(c: Component, s: *mut c_void, buf: *mut c_char, size: usize) -> c_int;
                st2::fmi2DeSerializeFMUstate(c: Component, buf: *const c_char, size: usize, s: *mut *mut c_void) -> c_int;
                st2::fmi2GetDirectionalDerivative(c: Component, vu: *const u32, nu: usize, vk: *const u32, nk: usize, dk: *const f64, du: *mut f64) -> c_int;
                cs2::fmi2SetRealInputDerivatives(c: Component, vr: *const u32, n: usize, order: *const c_int, v: *const f64) -> c_int;
                cs2::fmi2GetRealOutputDerivatives(c: Component, vr: *const u32, n: usize, order: *const c_int, v: *mut f64) -> c_int;
                cs2::fmi2DoStep(c: Component, t: f64, h: f64, no_prior: c_int) -> c_int;
                cs2::fmi2CancelStep(c: Component) -> c_int;
                cs2::fmi2GetStatus(c: Component, k: c_int, v: *mut c_int) -> c_int;
                cs2::fmi2GetRealStatus(c: Component, k: c_int, v: *mut f64) -> c_int;
                cs2::fmi2GetIntegerStatus(c: Component, k: c_int, v: *mut c_int) -> c_int;
                cs2::fmi2GetBooleanStatus(c: Component, k: c_int, v: *mut c_int) -> c_int;
                me2::fmi2EnterEventMode(c: Component) -> c_int;
                me2::fmi2NewDiscreteStates(c: Component, info: *mut me2::EventInfo2) -> c_int;
                me2::fmi2EnterContinuousTimeMode(c: Component) -> c_int;
                me2::fmi2CompletedIntegratorStep(c: Component, no_prior: c_int, enter: *mut c_int, term: *mut c_int) -> c_int;
                me2::fmi2SetTime(c: Component, t: f64) -> c_int;
                me2::fmi2SetContinuousStates(c: Component, x: *const f64, n: usize) -> c_int;
                me2::fmi2GetDerivatives(c: Component, dx: *mut f64, n: usize) -> c_int;
                me2::fmi2GetEventIndicators(c: Component, z: *mut f64, n: usize) -> c_int;
                me2::fmi2GetContinuousStates(c: Component, x: *mut f64, n: usize) -> c_int;
                me2::fmi2GetNominalsOfContinuousStates(c: Component, x: *mut f64, n: usize) -> c_int;
                cs2::fmi2GetStringStatus(c: Component, k: c_int, v: *mut *const c_char) -> c_int;
            }
        };
    };
}
