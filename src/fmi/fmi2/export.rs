//! The FMI 2.0 half of [`export_fmus!`](crate::export_fmus): `#[no_mangle]` wrappers with the standard
//! `fmi2*` names over this folder's functions, expanded inside `export_fmus!` (so one library serves
//! FMI 2.0 and 3.0 from the same models). Not meant to be used on its own.
//!
//! Size: `__export_fmi2!` is longer than 80 lines because a `#[no_mangle]` symbol must be spelled out in
//! the crate that links the library (the user's cdylib), one short wrapper per C function of
//! `fmi2Functions.h`; each only forwards to the function of the same name in this folder.

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
            #[no_mangle]
            pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
                c2::fmi2GetTypesPlatform()
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetVersion() -> *const c_char {
                c2::fmi2GetVersion()
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
            #[no_mangle]
            pub extern "C" fn fmi2FreeInstance(c: Component) {
                c2::fmi2FreeInstance(c)
            }
            #[no_mangle]
            pub extern "C" fn fmi2SetDebugLogging(
                c: Component,
                on: c_int,
                n: usize,
                cats: *const *const c_char,
            ) -> c_int {
                c2::fmi2SetDebugLogging(c, on, n, cats)
            }
            #[no_mangle]
            pub extern "C" fn fmi2SetupExperiment(
                c: Component,
                tol_defined: c_int,
                tol: f64,
                start: f64,
                stop_defined: c_int,
                stop: f64,
            ) -> c_int {
                c2::fmi2SetupExperiment(c, tol_defined, tol, start, stop_defined, stop)
            }
            #[no_mangle]
            pub extern "C" fn fmi2EnterInitializationMode(c: Component) -> c_int {
                c2::fmi2EnterInitializationMode(c)
            }
            #[no_mangle]
            pub extern "C" fn fmi2ExitInitializationMode(c: Component) -> c_int {
                c2::fmi2ExitInitializationMode(c)
            }
            #[no_mangle]
            pub extern "C" fn fmi2Terminate(c: Component) -> c_int {
                c2::fmi2Terminate(c)
            }
            #[no_mangle]
            pub extern "C" fn fmi2Reset(c: Component) -> c_int {
                c2::fmi2Reset(c)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetReal(c: Component, vr: *const u32, n: usize, v: *mut f64) -> c_int {
                c2::fmi2GetReal(c, vr, n, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetInteger(c: Component, vr: *const u32, n: usize, v: *mut c_int) -> c_int {
                c2::fmi2GetInteger(c, vr, n, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetBoolean(c: Component, vr: *const u32, n: usize, v: *mut c_int) -> c_int {
                c2::fmi2GetBoolean(c, vr, n, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetString(c: Component, vr: *const u32, n: usize, v: *mut *const c_char) -> c_int {
                c2::fmi2GetString(c, vr, n, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2SetReal(c: Component, vr: *const u32, n: usize, v: *const f64) -> c_int {
                c2::fmi2SetReal(c, vr, n, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2SetInteger(c: Component, vr: *const u32, n: usize, v: *const c_int) -> c_int {
                c2::fmi2SetInteger(c, vr, n, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2SetBoolean(c: Component, vr: *const u32, n: usize, v: *const c_int) -> c_int {
                c2::fmi2SetBoolean(c, vr, n, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2SetString(c: Component, vr: *const u32, n: usize, v: *const *const c_char) -> c_int {
                c2::fmi2SetString(c, vr, n, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetFMUstate(c: Component, s: *mut *mut c_void) -> c_int {
                st2::fmi2GetFMUstate(c, s)
            }
            #[no_mangle]
            pub extern "C" fn fmi2SetFMUstate(c: Component, s: *mut c_void) -> c_int {
                st2::fmi2SetFMUstate(c, s)
            }
            #[no_mangle]
            pub extern "C" fn fmi2FreeFMUstate(c: Component, s: *mut *mut c_void) -> c_int {
                st2::fmi2FreeFMUstate(c, s)
            }
            #[no_mangle]
            pub extern "C" fn fmi2SerializedFMUstateSize(c: Component, s: *mut c_void, size: *mut usize) -> c_int {
                st2::fmi2SerializedFMUstateSize(c, s, size)
            }
            #[no_mangle]
            pub extern "C" fn fmi2SerializeFMUstate(
                c: Component,
                s: *mut c_void,
                buf: *mut c_char,
                size: usize,
            ) -> c_int {
                st2::fmi2SerializeFMUstate(c, s, buf, size)
            }
            #[no_mangle]
            pub extern "C" fn fmi2DeSerializeFMUstate(
                c: Component,
                buf: *const c_char,
                size: usize,
                s: *mut *mut c_void,
            ) -> c_int {
                st2::fmi2DeSerializeFMUstate(c, buf, size, s)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetDirectionalDerivative(
                c: Component,
                vu: *const u32,
                nu: usize,
                vk: *const u32,
                nk: usize,
                dk: *const f64,
                du: *mut f64,
            ) -> c_int {
                st2::fmi2GetDirectionalDerivative(c, vu, nu, vk, nk, dk, du)
            }
            #[no_mangle]
            pub extern "C" fn fmi2SetRealInputDerivatives(
                c: Component,
                vr: *const u32,
                n: usize,
                order: *const c_int,
                v: *const f64,
            ) -> c_int {
                cs2::fmi2SetRealInputDerivatives(c, vr, n, order, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetRealOutputDerivatives(
                c: Component,
                vr: *const u32,
                n: usize,
                order: *const c_int,
                v: *mut f64,
            ) -> c_int {
                cs2::fmi2GetRealOutputDerivatives(c, vr, n, order, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2DoStep(c: Component, t: f64, h: f64, no_prior: c_int) -> c_int {
                cs2::fmi2DoStep(c, t, h, no_prior)
            }
            #[no_mangle]
            pub extern "C" fn fmi2CancelStep(c: Component) -> c_int {
                cs2::fmi2CancelStep(c)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetStatus(c: Component, k: c_int, v: *mut c_int) -> c_int {
                cs2::fmi2GetStatus(c, k, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetRealStatus(c: Component, k: c_int, v: *mut f64) -> c_int {
                cs2::fmi2GetRealStatus(c, k, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetIntegerStatus(c: Component, k: c_int, v: *mut c_int) -> c_int {
                cs2::fmi2GetIntegerStatus(c, k, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetBooleanStatus(c: Component, k: c_int, v: *mut c_int) -> c_int {
                cs2::fmi2GetBooleanStatus(c, k, v)
            }
            #[no_mangle]
            pub extern "C" fn fmi2EnterEventMode(c: Component) -> c_int {
                me2::fmi2EnterEventMode(c)
            }
            #[no_mangle]
            pub extern "C" fn fmi2NewDiscreteStates(c: Component, info: *mut me2::EventInfo2) -> c_int {
                me2::fmi2NewDiscreteStates(c, info)
            }
            #[no_mangle]
            pub extern "C" fn fmi2EnterContinuousTimeMode(c: Component) -> c_int {
                me2::fmi2EnterContinuousTimeMode(c)
            }
            #[no_mangle]
            pub extern "C" fn fmi2CompletedIntegratorStep(
                c: Component,
                no_prior: c_int,
                enter: *mut c_int,
                term: *mut c_int,
            ) -> c_int {
                me2::fmi2CompletedIntegratorStep(c, no_prior, enter, term)
            }
            #[no_mangle]
            pub extern "C" fn fmi2SetTime(c: Component, t: f64) -> c_int {
                me2::fmi2SetTime(c, t)
            }
            #[no_mangle]
            pub extern "C" fn fmi2SetContinuousStates(c: Component, x: *const f64, n: usize) -> c_int {
                me2::fmi2SetContinuousStates(c, x, n)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetDerivatives(c: Component, dx: *mut f64, n: usize) -> c_int {
                me2::fmi2GetDerivatives(c, dx, n)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetEventIndicators(c: Component, z: *mut f64, n: usize) -> c_int {
                me2::fmi2GetEventIndicators(c, z, n)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetContinuousStates(c: Component, x: *mut f64, n: usize) -> c_int {
                me2::fmi2GetContinuousStates(c, x, n)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetNominalsOfContinuousStates(c: Component, x: *mut f64, n: usize) -> c_int {
                me2::fmi2GetNominalsOfContinuousStates(c, x, n)
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetStringStatus(c: Component, k: c_int, v: *mut *const c_char) -> c_int {
                cs2::fmi2GetStringStatus(c, k, v)
            }
        };
    };
}
