//! Opening the wrapped unit's own library and finding its functions: `dlopen`/`dlsym` on Linux and macOS,
//! `LoadLibraryW`/`GetProcAddress` on Windows (declared here from kernel32, which every Windows process
//! has loaded; no crate needed).

use std::ffi::c_void;

/// Opens the library at `path`; its handle, or the system's reason.
pub fn open(path: &str) -> Result<*mut c_void, String> {
    imp::open(path)
}

/// The address of `name` (NUL-terminated) in the library `handle`, or null.
pub fn symbol(handle: *mut c_void, name: &[u8]) -> *mut c_void {
    debug_assert_eq!(name.last(), Some(&0));
    imp::symbol(handle, name)
}

#[cfg(unix)]
mod imp {
    use std::ffi::{c_char, c_void, CStr, CString};

    pub fn open(path: &str) -> Result<*mut c_void, String> {
        let c = CString::new(path).map_err(|_| "library path with a NUL byte".to_string())?;
        // SAFETY: `c` is a NUL-terminated string; dlerror's result is read before any other dl call
        unsafe {
            let h = libc::dlopen(c.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL);
            if !h.is_null() {
                return Ok(h);
            }
            let why = libc::dlerror();
            Err(if why.is_null() {
                String::new()
            } else {
                CStr::from_ptr(why).to_string_lossy().into()
            })
        }
    }

    pub fn symbol(handle: *mut c_void, name: &[u8]) -> *mut c_void {
        // SAFETY: `name` is NUL-terminated (checked by the caller's debug assertion and the me! macro)
        unsafe { libc::dlsym(handle, name.as_ptr() as *const c_char) }
    }
}

#[cfg(windows)]
mod imp {
    use std::ffi::{c_char, c_void};

    #[link(name = "kernel32")]
    extern "system" {
        fn LoadLibraryW(name: *const u16) -> *mut c_void;
        fn GetProcAddress(module: *mut c_void, name: *const c_char) -> *mut c_void;
        fn GetLastError() -> u32;
    }

    pub fn open(path: &str) -> Result<*mut c_void, String> {
        if path.contains('\0') {
            return Err("library path with a NUL byte".into());
        }
        let wide: Vec<u16> = path
            .replace('/', "\\")
            .encode_utf16()
            .chain(std::iter::once(0))
            .collect();
        // SAFETY: `wide` is a NUL-terminated UTF-16 string
        let h = unsafe { LoadLibraryW(wide.as_ptr()) };
        if h.is_null() {
            // SAFETY: no other system call between LoadLibraryW and this read
            return Err(format!("LoadLibraryW failed with Windows error {}", unsafe {
                GetLastError()
            }));
        }
        Ok(h)
    }

    pub fn symbol(handle: *mut c_void, name: &[u8]) -> *mut c_void {
        // SAFETY: `handle` came from LoadLibraryW; `name` is NUL-terminated
        unsafe { GetProcAddress(handle, name.as_ptr() as *const c_char) }
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    #[test]
    fn a_missing_library_gives_the_reason_and_a_present_one_its_functions() {
        let e = open("/nonexistent/scfmu_no_such_library.so").unwrap_err();
        assert!(e.contains("scfmu_no_such_library"), "{e}");
        let libm = if cfg!(target_os = "macos") {
            "/usr/lib/libSystem.B.dylib"
        } else {
            "libm.so.6"
        };
        let h = open(libm).expect("the C math library");
        let cos = symbol(h, b"cos\0");
        assert!(!cos.is_null());
        // SAFETY: libm's cos has this signature
        let f: extern "C" fn(f64) -> f64 = unsafe { std::mem::transmute(cos) };
        assert_eq!(f(0.0), 1.0);
        assert!(symbol(h, b"scfmu_not_a_function\0").is_null());
    }
}
