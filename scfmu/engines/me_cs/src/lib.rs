//! A Co-Simulation face for a Model Exchange FMU: this library is copied into the FMU next to the FMU's own
//! binary and named by an added `<CoSimulation modelIdentifier="scfmu_me_cs">` element
//! (`scfmu/engines/me_cs.py`), so that a master which nests Co-Simulation units only (fmpy's container FMU:
//! scfmu's native engine and loop FMUs) can run the unit.
//!
//! It exports the FMI 2.0 Co-Simulation functions ([`fmi2`], for an FMI 2.0 Model Exchange unit) and the
//! FMI 3.0 ones ([`fmi3`], for an FMI 3.0 unit): one thin C-ABI file per version, translating its types and
//! arguments, over one version-neutral body of every entry point ([`face`]). At instantiation it reads
//! `scfmu_me_cs.txt` from the unit's resources folder (the Model Exchange model identifier, the numbers of
//! states and event indicators, the method and its tolerances), opens the unit's own library
//! `binaries/<platform>/<identifier>`, loads its Model Exchange function table and instantiates it as
//! Model Exchange. Getters, setters and the other common functions are forwarded; a communication step
//! `doStep(t, h)` integrates the continuous states with the inputs held, by the engines' Model Exchange
//! stepper (the crate `scfmu_fmi_stepper`, the one the compiled loop uses too):
//!
//! * method `RK4`: the classic Runge–Kutta 4 with a fixed step (the communication step, or `max_step` when
//!   smaller); any other method: Dormand–Prince 5(4) with local extrapolation and adaptive steps under
//!   `rtol`/`atol` (and at most `max_step` when one is set);
//! * after every accepted step `completedIntegratorStep`; a sign change of an event indicator (a state
//!   event) is located by bisection on the step to 1e-12 relative in time (the state inside the step: the
//!   continuous extension of Dormand–Prince, a re-integrated partial step of RK4); at a time event
//!   (`nextEventTime`), a state event or when the unit asks, the event iteration (`enterEventMode`,
//!   `newDiscreteStates` / `updateDiscreteStates` until no update is needed), then continuous-time mode
//!   again with the states re-read.
//!
//! One wrapped unit per copy of this library (a copy lives in each wrapped FMU), so the unit's library
//! handle and its function pointers are process-wide statics of the copy.

#![allow(clippy::missing_safety_doc)]

use std::ffi::{c_char, c_void, CStr};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use scfmu_fmi_stepper::{dynlib, MeUnit, Method, Settings, Stepper, Table};

pub mod face;
pub mod fmi2;
pub mod fmi3;

pub const OK: i32 = 0;
pub const WARNING: i32 = 1;
pub const DISCARD: i32 = 2;
pub const ERROR: i32 = 3;

static LIB: AtomicUsize = AtomicUsize::new(0); // the handle of the unit's own library (dynlib::open)
static LIB_PATH: Mutex<Option<String>> = Mutex::new(None);

/// The wrapped unit's settings (`resources/scfmu_me_cs.txt`, `key=value` lines).
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    pub model_identifier: String,
    pub states: usize,
    pub event_indicators: usize,
    pub rk4: bool,
    pub rtol: f64,
    pub atol: f64,
    pub max_step: f64,
}

impl Config {
    /// The stepper's settings.
    pub fn settings(&self) -> Settings {
        Settings {
            method: if self.rk4 { Method::Rk4 } else { Method::DormandPrince },
            rtol: self.rtol,
            atol: self.atol,
            max_step: self.max_step,
        }
    }

    pub fn parse(text: &str) -> Result<Config, String> {
        let mut c = Config {
            model_identifier: String::new(),
            states: 0,
            event_indicators: 0,
            rk4: false,
            rtol: 1e-10,
            atol: 1e-12,
            max_step: 0.0,
        };
        for line in text
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty() && !l.starts_with('#'))
        {
            let (k, v) = line
                .split_once('=')
                .ok_or_else(|| format!("line {line:?}: not key=value"))?;
            let (k, v) = (k.trim(), v.trim());
            let num = |v: &str| v.parse::<f64>().map_err(|_| format!("{k} = {v:?}: not a number"));
            let int = |v: &str| v.parse::<usize>().map_err(|_| format!("{k} = {v:?}: not a count"));
            match k {
                "model_identifier" => c.model_identifier = v.to_string(),
                "states" => c.states = int(v)?,
                "event_indicators" => c.event_indicators = int(v)?,
                "method" => c.rk4 = v == "RK4",
                "rtol" => c.rtol = num(v)?,
                "atol" => c.atol = num(v)?,
                "max_step" => c.max_step = num(v)?,
                _ => return Err(format!("unknown key {k:?}")),
            }
        }
        if c.model_identifier.is_empty() || c.model_identifier.contains(['/', '\\']) {
            return Err(format!("model_identifier {:?} is not a file name", c.model_identifier));
        }
        if !(c.rtol > 0.0 && c.atol > 0.0 && c.max_step >= 0.0 && c.max_step.is_finite()) {
            return Err("rtol and atol must be > 0, max_step >= 0".into());
        }
        Ok(c)
    }
}

/// The folder of a resource location: an FMI 2.0 `file:` URI or an FMI 3.0 path (percent escapes decoded).
pub fn resource_dir(location: &str) -> String {
    let p = if let Some(rest) = location.strip_prefix("file://") {
        rest.strip_prefix("localhost").unwrap_or(rest).to_string()
    } else if let Some(rest) = location.strip_prefix("file:") {
        rest.to_string()
    } else {
        return location.trim_end_matches('/').to_string();
    };
    let b = p.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    let mut s = String::from_utf8_lossy(&out).into_owned();
    if cfg!(windows) && s.starts_with('/') && s.as_bytes().get(2) == Some(&b':') {
        s.remove(0);
    }
    s.trim_end_matches('/').to_string()
}

/// The unit's binaries folder on this platform: FMI 2.0's `linux64`/`win64`/`darwin64` (no standard name
/// for 64-bit ARM Linux: `aarch64-linux`, as the project's FMUs use), FMI 3.0's `<arch>-<os>` tuples.
pub fn platform_folder(v3: bool) -> &'static str {
    let arm = cfg!(target_arch = "aarch64");
    let (windows, macos) = (cfg!(windows), cfg!(target_os = "macos"));
    match (v3, arm, windows, macos) {
        (false, _, true, _) => "win64",
        (false, _, _, true) => "darwin64", // one universal file for both Mac CPUs
        (false, true, _, _) => "aarch64-linux",
        (false, false, _, _) => "linux64",
        (true, true, true, _) => "aarch64-windows",
        (true, true, _, true) => "aarch64-darwin",
        (true, true, _, _) => "aarch64-linux",
        (true, false, true, _) => "x86_64-windows",
        (true, false, _, true) => "x86_64-darwin",
        (true, false, _, _) => "x86_64-linux",
    }
}

/// Reads the settings and opens the unit's own library (`<resources>/../binaries/<folder>/<identifier>`).
///
/// # Safety
/// `location` is null or a NUL-terminated string.
pub unsafe fn load(location: *const c_char, v3: bool) -> Result<Config, String> {
    if location.is_null() {
        return Err("no resource location".into());
    }
    let res = resource_dir(&CStr::from_ptr(location).to_string_lossy());
    let cfg_path = format!("{res}/scfmu_me_cs.txt");
    let text = std::fs::read_to_string(&cfg_path).map_err(|e| format!("{cfg_path}: {e}"))?;
    let cfg = Config::parse(&text).map_err(|e| format!("{cfg_path}: {e}"))?;
    let folder = platform_folder(v3);
    let ext = if cfg!(windows) {
        "dll"
    } else if cfg!(target_os = "macos") {
        "dylib"
    } else {
        "so"
    };
    let lib = format!("{res}/../binaries/{folder}/{}.{ext}", cfg.model_identifier);
    let mut open = LIB_PATH.lock().unwrap_or_else(|e| e.into_inner());
    match open.as_deref() {
        Some(p) if p != lib => return Err(format!("this wrapper already serves {p}, not {lib}")),
        Some(_) => return Ok(cfg),
        None => {}
    }
    let h = dynlib::open(&lib).map_err(|why| format!("cannot open {lib}: {why}"))?;
    LIB.store(h as usize, Ordering::SeqCst);
    *open = Some(lib);
    Ok(cfg)
}

/// The unit's function `name` (NUL-terminated), cached in `cache`; None when the library lacks it.
pub fn sym(cache: &AtomicUsize, name: &[u8]) -> Option<*const c_void> {
    let p = cache.load(Ordering::Relaxed);
    if p != 0 {
        return Some(p as *const c_void);
    }
    let h = LIB.load(Ordering::SeqCst);
    if h == 0 {
        return None;
    }
    let f = dynlib::symbol(h as *mut c_void, name);
    if f.is_null() {
        return None;
    }
    cache.store(f as usize, Ordering::Relaxed);
    Some(f as *const c_void)
}

/// `me!(fmi2SetTime, unsafe extern "C" fn(...) -> i32)`: the unit's function, or None.
#[macro_export]
macro_rules! me {
    ($name:ident, $ty:ty) => {{
        static P: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        $crate::sym(&P, concat!(stringify!($name), "\0").as_bytes())
            .map(|f| unsafe { std::mem::transmute::<*const std::ffi::c_void, $ty>(f) })
    }};
}

/// The Model Exchange function table of the library [`load`] opened (FMI 3.0 names when `v3`).
pub fn table(v3: bool) -> Result<Table, String> {
    let h = LIB.load(Ordering::SeqCst);
    if h == 0 {
        return Err("the unit's library is not open".into());
    }
    // SAFETY: the handle is the unit's library, opened by `load`; an FMU's functions of the standard's
    // names have the standard's signatures
    unsafe { Table::load(h as *mut c_void, v3) }
}

/// A wrapper instance (both versions): the unit's instance (with its function table), its settings and
/// the stepper.
pub struct Instance {
    pub magic: u64,
    pub inner: *mut c_void,
    pub unit: MeUnit,
    pub cfg: Config,
    pub stepper: Stepper,
    pub start_time: f64,
    pub terminated: bool,
}

pub const MAGIC: u64 = 0x5343_464d_554d_4543; // "SCFMUMEC"

/// The instance behind a pointer handed out by this library, or None.
pub unsafe fn instance<'a>(p: *mut c_void) -> Option<&'a mut Instance> {
    let w = p as *mut Instance;
    if w.is_null() || (*w).magic != MAGIC {
        None
    } else {
        Some(&mut *w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_platform_folder_is_the_standards_name_for_this_build() {
        let want = if cfg!(all(target_arch = "x86_64", target_os = "linux")) {
            ("linux64", "x86_64-linux")
        } else if cfg!(all(target_arch = "aarch64", target_os = "linux")) {
            ("aarch64-linux", "aarch64-linux")
        } else if cfg!(all(target_arch = "aarch64", target_os = "macos")) {
            ("darwin64", "aarch64-darwin")
        } else if cfg!(all(target_arch = "x86_64", target_os = "macos")) {
            ("darwin64", "x86_64-darwin")
        } else {
            ("win64", "x86_64-windows")
        };
        assert_eq!((platform_folder(false), platform_folder(true)), want);
    }

    #[test]
    fn config_parses_and_refuses_bad_values() {
        let c = Config::parse("model_identifier=AttitudePlant\nmethod=RK4\nmax_step=0.005\nstates=13\n").unwrap();
        assert_eq!(
            (c.model_identifier.as_str(), c.rk4, c.max_step, c.states),
            ("AttitudePlant", true, 0.005, 13)
        );
        assert_eq!((c.rtol, c.atol, c.event_indicators), (1e-10, 1e-12, 0));
        assert!(!Config::parse("model_identifier=A\nmethod=DOP853").unwrap().rk4);
        assert!(Config::parse("model_identifier=../x").is_err());
        assert!(Config::parse("model_identifier=A\nrtol=0").is_err());
        assert!(Config::parse("model_identifier=A\nmax_step=-1").is_err());
        assert!(Config::parse("model_identifier=A\nspeed=1").is_err());
        assert!(Config::parse("states=1").is_err());
    }

    #[test]
    fn resource_locations_of_both_versions() {
        assert_eq!(resource_dir("file:///tmp/a%20b/resources/"), "/tmp/a b/resources");
        assert_eq!(resource_dir("file:/tmp/x/resources"), "/tmp/x/resources");
        assert_eq!(resource_dir("file://localhost/tmp/x/resources"), "/tmp/x/resources");
        assert_eq!(resource_dir("/tmp/x/resources/"), "/tmp/x/resources");
    }
}
