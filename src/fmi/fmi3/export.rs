//! The FMI 3.0 half of [`export_fmus!`](crate::export_fmus): `#[no_mangle]` wrappers with the standard
//! `fmi3*` names over this folder's functions, expanded inside `export_fmus!` (so one
//! library serves FMI 2.0 and 3.0 from the same models). All 75 functions of `fmi3Functions.h` are
//! exported, those of interfaces and features the FMUs do not declare included: importers (fmpy, FMI
//! Library) resolve every one. Not meant to be used on its own. The getters and setters of every
//! variable type are in `export_values.rs`.
//!
//! Size: `__export_fmi3!` is longer than 80 lines because a `#[no_mangle]` symbol must be spelled out in
//! the crate that links the library (the user's cdylib): one line per C function in a
//! [`__fmi_forward!`](crate::__fmi_forward) table, each only forwarding to the function of the same name
//! in this folder, where the code is; the instantiate functions, which pass the model list, are written out.

/// Expands to the FMI 3.0 entry points for the model list `$models` (a `static [ModelEntry]` slice in
/// scope). Used by [`export_fmus!`](crate::export_fmus) only.
#[doc(hidden)]
#[macro_export]
macro_rules! __export_fmi3 {
    ($models:ident) => {
        const _: () = {
            use ::std::ffi::{c_char, c_int, c_void};
            use $crate::fmi::fmi3::clocks as ck3;
            use $crate::fmi::fmi3::common as co3;
            use $crate::fmi::fmi3::cs as cs3;
            use $crate::fmi::fmi3::me as me3;
            use $crate::fmi::fmi3::state as st3;
            use $crate::fmi::fmi3::unsupported as un3;
            use $crate::fmi::fmi3::values as va3;
            type Inst3 = *mut c_void;
            type Log3 = Option<$crate::fmi::fmi3::common::Log3Fn>;
            $crate::__fmi_forward! {
                co3::fmi3GetVersion() -> *const c_char;
                co3::fmi3SetDebugLogging(c: Inst3, on: u8, n: usize, cats: *const *const c_char) -> c_int;
            }
            #[no_mangle]
            pub extern "C" fn fmi3InstantiateCoSimulation(
                name: *const c_char,
                token: *const c_char,
                resources: *const c_char,
                visible: u8,
                logging_on: u8,
                event_mode_used: u8,
                early_return_allowed: u8,
                required: *const u32,
                n_required: usize,
                env: *mut c_void,
                log: Log3,
                update: *const c_void,
            ) -> Inst3 {
                cs3::fmi3InstantiateCoSimulation(
                    $models,
                    name,
                    token,
                    resources,
                    visible,
                    logging_on,
                    event_mode_used,
                    early_return_allowed,
                    required,
                    n_required,
                    env,
                    log,
                    update,
                )
            }
            #[no_mangle]
            pub extern "C" fn fmi3InstantiateModelExchange(
                name: *const c_char,
                token: *const c_char,
                resources: *const c_char,
                visible: u8,
                logging_on: u8,
                env: *mut c_void,
                log: Log3,
            ) -> Inst3 {
                me3::fmi3InstantiateModelExchange($models, name, token, resources, visible, logging_on, env, log)
            }
            #[no_mangle]
            pub extern "C" fn fmi3InstantiateScheduledExecution(
                name: *const c_char,
                token: *const c_char,
                resources: *const c_char,
                visible: u8,
                logging_on: u8,
                env: *mut c_void,
                log: Log3,
                clock_update: *const c_void,
                lock: Option<$crate::fmi::fmi3::clocks::PreemptionFn>,
                unlock: Option<$crate::fmi::fmi3::clocks::PreemptionFn>,
            ) -> Inst3 {
                ck3::fmi3InstantiateScheduledExecution($models, name, token, resources, visible, logging_on, env, log, clock_update, lock, unlock)
            }
            $crate::__fmi_forward! {
                co3::fmi3FreeInstance(c: Inst3);
                co3::fmi3EnterInitializationMode(c: Inst3, tol_defined: u8, tol: f64, start: f64, stop_defined: u8, stop: f64) -> c_int;
                co3::fmi3ExitInitializationMode(c: Inst3) -> c_int;
                me3::fmi3EnterEventMode(c: Inst3) -> c_int;
                co3::fmi3Terminate(c: Inst3) -> c_int;
                co3::fmi3Reset(c: Inst3) -> c_int;
            }
            $crate::__export_fmi3_values!();
            $crate::__fmi_forward! {
                st3::fmi3GetNumberOfVariableDependencies(c: Inst3, vr: u32, n: *mut usize) -> c_int;
                st3::fmi3GetVariableDependencies(c: Inst3, dep: u32, e1: *mut usize, ind: *mut u32, e2: *mut usize, kinds: *mut c_int, n: usize) -> c_int;
                st3::fmi3GetFMUState(c: Inst3, s: *mut *mut c_void) -> c_int;
                st3::fmi3SetFMUState(c: Inst3, s: *mut c_void) -> c_int;
                st3::fmi3FreeFMUState(c: Inst3, s: *mut *mut c_void) -> c_int;
                st3::fmi3SerializedFMUStateSize(c: Inst3, s: *mut c_void, size: *mut usize) -> c_int;
                st3::fmi3SerializeFMUState(c: Inst3, s: *mut c_void, buf: *mut u8, size: usize) -> c_int;
                st3::fmi3DeserializeFMUState(c: Inst3, buf: *const u8, size: usize, s: *mut *mut c_void) -> c_int;
                st3::fmi3GetDirectionalDerivative(c: Inst3, u: *const u32, nu: usize, k: *const u32, nk: usize, seed: *const f64, ns: usize, out: *mut f64, no: usize) -> c_int;
                un3::fmi3GetAdjointDerivative(c: Inst3, u: *const u32, nu: usize, k: *const u32, nk: usize, seed: *const f64, ns: usize, out: *mut f64, no: usize) -> c_int;
                un3::fmi3EnterConfigurationMode(c: Inst3) -> c_int;
                un3::fmi3ExitConfigurationMode(c: Inst3) -> c_int;
                ck3::fmi3GetIntervalDecimal(c: Inst3, vr: *const u32, n: usize, i: *mut f64, q: *mut c_int) -> c_int;
                ck3::fmi3GetIntervalFraction(c: Inst3, vr: *const u32, n: usize, k: *mut u64, r: *mut u64, q: *mut c_int) -> c_int;
                ck3::fmi3GetShiftDecimal(c: Inst3, vr: *const u32, n: usize, s: *mut f64) -> c_int;
                ck3::fmi3GetShiftFraction(c: Inst3, vr: *const u32, n: usize, k: *mut u64, r: *mut u64) -> c_int;
                ck3::fmi3SetIntervalDecimal(c: Inst3, vr: *const u32, n: usize, i: *const f64) -> c_int;
                ck3::fmi3SetIntervalFraction(c: Inst3, vr: *const u32, n: usize, k: *const u64, r: *const u64) -> c_int;
                ck3::fmi3SetShiftDecimal(c: Inst3, vr: *const u32, n: usize, s: *const f64) -> c_int;
                ck3::fmi3SetShiftFraction(c: Inst3, vr: *const u32, n: usize, k: *const u64, r: *const u64) -> c_int;
                me3::fmi3EvaluateDiscreteStates(c: Inst3) -> c_int;
                me3::fmi3UpdateDiscreteStates(c: Inst3, a: *mut u8, b: *mut u8, d: *mut u8, e: *mut u8, f: *mut u8, t: *mut f64) -> c_int;
                me3::fmi3EnterContinuousTimeMode(c: Inst3) -> c_int;
                me3::fmi3CompletedIntegratorStep(c: Inst3, p: u8, e: *mut u8, t: *mut u8) -> c_int;
                me3::fmi3SetTime(c: Inst3, t: f64) -> c_int;
                me3::fmi3SetContinuousStates(c: Inst3, x: *const f64, n: usize) -> c_int;
                me3::fmi3GetContinuousStateDerivatives(c: Inst3, x: *mut f64, n: usize) -> c_int;
                me3::fmi3GetEventIndicators(c: Inst3, x: *mut f64, n: usize) -> c_int;
                me3::fmi3GetContinuousStates(c: Inst3, x: *mut f64, n: usize) -> c_int;
                me3::fmi3GetNominalsOfContinuousStates(c: Inst3, x: *mut f64, n: usize) -> c_int;
                me3::fmi3GetNumberOfEventIndicators(c: Inst3, n: *mut usize) -> c_int;
                me3::fmi3GetNumberOfContinuousStates(c: Inst3, n: *mut usize) -> c_int;
                ck3::fmi3EnterStepMode(c: Inst3) -> c_int;
                cs3::fmi3GetOutputDerivatives(c: Inst3, vr: *const u32, n: usize, order: *const i32, v: *mut f64, nv: usize) -> c_int;
                cs3::fmi3DoStep(c: Inst3, t: f64, h: f64, no_prior: u8, event: *mut u8, terminate: *mut u8, early: *mut u8, last: *mut f64) -> c_int;
                ck3::fmi3ActivateModelPartition(c: Inst3, clock: u32, t: f64) -> c_int;
            }
        };
    };
}
