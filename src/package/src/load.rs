//! Reads the catalogue of a built shared library: loads it (`dlopen`), calls the
//! `spacecraft_fmus_catalogue` function that `export_fmus!` generates, and copies the bytes. Unix hosts
//! (the library of the host platform); a Windows build of the same crate is packaged next to it.

use std::path::Path;

#[cfg(unix)]
use std::ffi::{c_void, CStr, CString};

#[cfg(unix)]
const SYMBOL: &CStr = c"spacecraft_fmus_catalogue";

#[cfg(unix)]
pub(crate) fn catalogue_bytes(lib: &Path) -> Result<Vec<u8>, String> {
    let path = lib.canonicalize().map_err(|e| format!("{}: {e}", lib.display()))?;
    let c_path =
        CString::new(path.to_string_lossy().as_bytes()).map_err(|_| format!("{}: path contains NUL", lib.display()))?;
    // SAFETY: a NUL-terminated path; RTLD_LOCAL keeps the library's symbols out of this process's
    // namespace. The handle is never closed: the tool is short-lived and Rust libraries do not
    // promise to survive dlclose.
    let handle = unsafe { libc::dlopen(c_path.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
    if handle.is_null() {
        // SAFETY: dlerror returns a NUL-terminated message or NULL.
        let why = unsafe { libc::dlerror() };
        let why = if why.is_null() {
            "unknown error".into()
        } else {
            unsafe { CStr::from_ptr(why) }.to_string_lossy().into_owned()
        };
        return Err(format!("cannot load {}: {why}", path.display()));
    }
    // SAFETY: valid handle and symbol name.
    let sym = unsafe { libc::dlsym(handle, SYMBOL.as_ptr()) };
    if sym.is_null() {
        return Err(format!(
            "{} has no spacecraft_fmus_catalogue: is it a cdylib whose crate calls spacecraft_fmus::export_fmus!(...)?",
            path.display()
        ));
    }
    // SAFETY: the symbol is the function export_fmus! generates, with this signature.
    let f: extern "C" fn(*mut usize) -> *const u8 =
        unsafe { std::mem::transmute::<*mut c_void, extern "C" fn(*mut usize) -> *const u8>(sym) };
    let mut size = 0usize;
    let p = f(&mut size);
    if p.is_null() {
        return Err(format!(
            "{}: building the catalogue failed inside the library (a panic in a model declaration?)",
            path.display()
        ));
    }
    // SAFETY: the library owns `size` bytes at `p` while it is loaded (it is never unloaded here).
    Ok(unsafe { std::slice::from_raw_parts(p, size) }.to_vec())
}

#[cfg(not(unix))]
pub(crate) fn catalogue_bytes(lib: &Path) -> Result<Vec<u8>, String> {
    Err(format!(
        "{}: fmu-package reads catalogues on Unix hosts only (cross-build Windows binaries from Linux)",
        lib.display()
    ))
}
