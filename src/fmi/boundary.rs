//! The C boundary both interfaces stand on: the table of live instances (a handle from the master is
//! a token, never an address, mapped to an instance only while that instance lives), the panic guard (a
//! panic inside a call becomes a logged fatal status, never an unwind across `extern "C"`), borrowing of C arrays and
//! out-pointers with the argument named in the error, the model lookup by GUID / instantiation token,
//! and one instantiate for every interface (Co-Simulation and Model Exchange of either version). Nothing
//! here knows an FMI function name beyond what the caller passes in (its name, its [`Dialect`]).

use std::cell::{Cell, RefCell};
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use super::instance::{CallResult, Fail, Instance, Logger};
use super::library_path::own_library_stem;
use super::live::{Handles, KIND_INSTANCE};
use super::state::Snapshot;
use super::types::{Dialect, Status};
use crate::model::guid::guid;
use crate::model::ModelEntry;

/// What the master holds for an instance (the standards' component or instance pointer).
pub type Handle = *mut c_void;

// ----- live instances ----------------------------------------------------------------------------

/// The live instances of this library behind their tokens (`live` says why a handle is a token that is
/// never handed out twice, and how it is checked without a lock).
static LIVE: Handles<Instance> = Handles::new(KIND_INSTANCE);

/// The instance behind a handle if it is a live token of this library and was created through the
/// interface asked for (the room's `dialect`); an instance of one interface is foreign to the other's
/// functions. A null, foreign or freed handle gives None, also
/// after its memory or slot went to a new instance (and the call returns an error status: there is no
/// logger to tell). Nothing is read behind a handle before the table has mapped it to a live instance;
/// on every FMI call, so without a lock.
pub fn instance_of<'a>(c: Handle, dialect: &'static Dialect) -> Option<&'a mut Instance> {
    let p = LIVE.get(c as usize)?;
    // SAFETY: the table maps a live token only to the instance registered under it by `register`,
    // which `free_instance` takes out of the table before freeing it.
    let inst = unsafe { &mut *p };
    std::ptr::eq(inst.dialect, dialect).then_some(inst)
}

/// Registers a new instance under a new token (installing the panic hook with the first one).
fn register(inst: Box<Instance>) -> Result<Handle, String> {
    let p = Box::into_raw(inst);
    LIVE.insert(p, install_panic_hook)
        .map(|t| t as Handle)
        .inspect_err(|_| {
            // SAFETY: not registered: still ours alone
            drop(unsafe { Box::from_raw(p) });
        })
}

/// Frees an instance of the given interface (and its FMU states); anything else is ignored.
pub fn free_instance(c: Handle, dialect: &'static Dialect) {
    if instance_of(c, dialect).is_none() {
        return; // null, not ours, freed or of the other interface: nothing to free, nothing to log to
    }
    let Some(p) = LIVE.remove(c as usize) else {
        return; // freed by another thread in between
    };
    let _ = guarded(|| {
        Snapshot::free_all_of(c as usize);
        // SAFETY: it was registered (so it is a leaked Box<Instance>) and is now unregistered.
        drop(unsafe { Box::from_raw(p) });
    });
    // the last instance: remove the panic hook (not while the calling thread unwinds: take_hook
    // panics then, which would abort inside extern "C")
    LIVE.when_empty(|| {
        if !std::thread::panicking() {
            drop(std::panic::take_hook());
        }
    });
}

// ----- panics ------------------------------------------------------------------------------------

thread_local! {
    static IN_FFI: Cell<bool> = const { Cell::new(false) };
    static PANIC_MESSAGE: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Panics inside an FMI call are reported through the logger, not printed: the hook records the
/// message and location; outside FMI calls (Rust tests) a one-line report goes to stderr. The
/// hook is installed while at least one instance lives (changed only under the live-instance lock)
/// and removed with the last one, so an unloaded library leaves no hook behind.
fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        if IN_FFI.with(Cell::get) {
            let loc = info
                .location()
                .map(|l| format!(" at {}:{}", l.file(), l.line()))
                .unwrap_or_default();
            let msg = info
                .payload()
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| info.payload().downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            PANIC_MESSAGE.with(|m| *m.borrow_mut() = Some(format!("{msg}{loc}")));
        } else {
            let msg = info
                .payload()
                .downcast_ref::<&str>()
                .copied()
                .or_else(|| info.payload().downcast_ref::<String>().map(String::as_str));
            eprintln!(
                "panic: {}{}",
                msg.unwrap_or("unknown panic"),
                info.location().map(|l| format!(" at {l}")).unwrap_or_default()
            );
        }
    }));
}

/// Runs `f` with panics caught: `Err` carries the panic message (and location).
pub fn guarded<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    let was = IN_FFI.with(|x| x.replace(true));
    let r = catch_unwind(AssertUnwindSafe(f));
    IN_FFI.with(|x| x.set(was));
    r.map_err(|_| {
        PANIC_MESSAGE
            .with(|m| m.borrow_mut().take())
            .unwrap_or_else(|| "unknown panic".into())
    })
}

// ----- pointer helpers ---------------------------------------------------------------------------

/// Borrows a C array; `n == 0` needs no pointer. Null with n > 0 is an error naming the argument.
///
/// # Safety
/// A non-null `p` must point to `n` readable elements owned by the master for the duration of the call.
pub unsafe fn slice<'a, T>(p: *const T, n: usize, what: &str) -> CallResult<&'a [T]> {
    if n == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(Fail::error(format!("{what} is NULL but its length is {n}")));
    }
    if n > (isize::MAX as usize) / std::mem::size_of::<T>().max(1) {
        return Err(Fail::error(format!("length {n} of {what} is impossible")));
    }
    // SAFETY: non-null, length checked against the address space; the master owns n elements.
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// [`slice`] for an array the call writes into.
///
/// # Safety
/// A non-null `p` must point to `n` writable elements owned by the master for the duration of the call.
pub unsafe fn slice_mut<'a, T>(p: *mut T, n: usize, what: &str) -> CallResult<&'a mut [T]> {
    if n == 0 {
        return Ok(&mut []);
    }
    if p.is_null() {
        return Err(Fail::error(format!("{what} is NULL but its length is {n}")));
    }
    if n > (isize::MAX as usize) / std::mem::size_of::<T>().max(1) {
        return Err(Fail::error(format!("length {n} of {what} is impossible")));
    }
    // SAFETY: as in `slice`.
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// The storage behind an out-pointer argument; null is an error naming the argument.
pub fn out_ptr<'a, T>(p: *mut T, what: &str) -> CallResult<&'a mut T> {
    if p.is_null() {
        return Err(Fail::error(format!("{what} is NULL")));
    }
    // SAFETY: non-null pointer to storage the master provides for the result.
    Ok(unsafe { &mut *p })
}

/// Reads a C string argument that must be non-null.
pub fn c_str<'a>(p: *const c_char, what: &str) -> Result<&'a CStr, String> {
    if p.is_null() {
        return Err(format!("{what} is NULL"));
    }
    // SAFETY: non-null C string from the master.
    Ok(unsafe { CStr::from_ptr(p) })
}

// ----- instantiation ------------------------------------------------------------------------------

/// The model a library holding `all` instantiates: the one whose name is the library's file name
/// (`binaries/<platform>/<Model>.<ext>`) if there is one, which must then have the requested GUID;
/// else the one with the requested GUID.
/// (`token`: the name of the argument that carries the GUID, for the messages)
fn find_model(all: &'static [ModelEntry], requested: &str, token: &str) -> Result<&'static ModelEntry, String> {
    if let Some(expected) = own_library_stem().and_then(|stem| all.iter().find(|e| e.info.name == stem)) {
        let want = guid(expected);
        return if requested == want.as_str() {
            Ok(expected)
        } else {
            Err(format!("{token} {requested} does not match {}'s GUID {want} (modelDescription.xml and binary are from different builds)", expected.info.name))
        };
    }
    all.iter()
        .find(|e| guid(e).as_str() == requested)
        .ok_or_else(|| format!("{token} {requested} matches no model in this binary"))
}

/// What an instantiate call of a room asks for, in the room's own words.
pub struct Request<'a> {
    /// The C function, for the log.
    pub func: &'static str,
    pub models: &'static [ModelEntry],
    pub instance_name: *const c_char,
    /// The GUID the master expects (under the dialect's `token_argument` name).
    pub token: *const c_char,
    pub logger: Logger,
    pub env: *mut c_void,
    pub logging_on: bool,
    /// The room's interface: the instance serves it alone.
    pub dialect: &'static Dialect,
    pub model_exchange: bool,
    /// The version's own argument checks, run after the instance name is checked.
    pub check_arguments: &'a dyn Fn() -> Result<(), String>,
    /// Refusal of a model that lacks the requested interface (`None`: it has it).
    pub refuse_model: &'a dyn Fn(&ModelEntry) -> Option<String>,
}

/// One instantiate for every interface: checks the arguments, picks the model, creates and registers
/// the instance; a refusal (or a panic) gives NULL and a message through the master's logger.
pub fn instantiate(req: Request) -> Handle {
    let result = guarded(|| -> Result<Handle, String> {
        let name = c_str(req.instance_name, "instanceName")?;
        if name.to_bytes().is_empty() {
            return Err("instanceName is empty".into());
        }
        (req.check_arguments)()?;
        let token = req.dialect.token_argument;
        let requested = c_str(req.token, token)?.to_string_lossy();
        let entry = find_model(req.models, &requested, token)?;
        if let Some(why) = (req.refuse_model)(entry) {
            return Err(why);
        }
        let mut inst = Box::new(Instance::new(
            name.to_owned(),
            entry,
            req.dialect,
            req.logger,
            req.env,
            req.logging_on,
        ));
        inst.model_exchange = req.model_exchange;
        inst.trace(|| {
            format!(
                "{}: {} instance of {}",
                req.func,
                inst.name.to_string_lossy(),
                entry.info.name
            )
        });
        register(inst)
    });
    let msg = match result {
        Ok(Ok(p)) => return p,
        Ok(Err(msg)) => msg,
        Err(panic) => format!("internal error (panic): {panic}"),
    };
    log_without_instance(req.logger, req.env, req.instance_name, req.func, &msg);
    std::ptr::null_mut()
}

/// An error message through the master's logger when there is no instance to log with.
pub fn log_without_instance(logger: Logger, env: *mut c_void, instance_name: *const c_char, func: &str, message: &str) {
    match logger {
        Logger::None => {}
        Logger::Printf(log) => {
            // this logger takes a printf format: escape '%'
            let text =
                CString::new(format!("{func}: {message}").replace('%', "%%").replace('\0', "")).unwrap_or_default();
            let name = if instance_name.is_null() {
                c"?"
            } else {
                unsafe { CStr::from_ptr(instance_name) }
            };
            // SAFETY: master-provided callback with valid NUL-terminated strings.
            unsafe {
                log(
                    env,
                    name.as_ptr(),
                    Status::Error as c_int,
                    c"logStatusError".as_ptr(),
                    text.as_ptr(),
                )
            };
        }
        Logger::Text(log) => {
            let text = CString::new(format!("{func}: {message}").replace('\0', "")).unwrap_or_default();
            // SAFETY: master-provided callback with valid NUL-terminated strings.
            unsafe { log(env, Status::Error as c_int, c"logStatusError".as_ptr(), text.as_ptr()) };
        }
    }
}

/// The `#[no_mangle] extern "C"` wrappers of [`export_fmus!`](crate::export_fmus), one table line per C
/// function (`module::Name(c: Handle, vr: *const u32, n: usize, v: *mut f64) -> c_int;`): each
/// wrapper has the standard name and signature and only forwards its arguments to the function of the
/// same name in the module given, where the code is. Shared by the export macros of both rooms,
/// expanded in the crate that links the library. Not meant to be used on its own.
#[doc(hidden)]
#[macro_export]
macro_rules! __fmi_forward {
    ($( $module:ident :: $name:ident ( $( $arg:ident : $ty:ty ),* $(,)? ) $( -> $ret:ty )? ; )*) => {
        $(
            #[no_mangle]
            pub extern "C" fn $name( $( $arg: $ty ),* ) $( -> $ret )? {
                $module::$name( $( $arg ),* )
            }
        )*
    };
}
