//! Where this shared library lives on disk, so an instantiate call can tell which model a
//! `binaries/<platform>/<Model>.<ext>` file is for and name it in a GUID error. Found from the address
//! of one of the library's own functions: `dladdr` on Unix, `GetModuleHandleExW` + `GetModuleFileNameW`
//! on Windows (declared here rather than through a bindings crate).

use std::ffi::c_void;
#[cfg(unix)]
use std::ffi::CStr;

/// File stem of the shared library this code lives in (`AttitudePlant` for
/// `binaries/linux64/AttitudePlant.so` or `binaries/win64/AttitudePlant.dll`), so a GUID error can
/// name the expected model.
pub(super) fn own_library_stem() -> Option<String> {
    let path = own_library_path()?;
    path.file_stem().map(|s| s.to_string_lossy().into_owned())
}

/// Full path of this shared library, found from the address of one of its functions (Unix: `dladdr`).
#[cfg(unix)]
fn own_library_path() -> Option<std::path::PathBuf> {
    let mut info: libc::Dl_info = unsafe { std::mem::zeroed() };
    // SAFETY: dladdr only reads the address; info is valid storage.
    let ok = unsafe { libc::dladdr(own_library_path as *const c_void, &mut info) };
    if ok == 0 || info.dli_fname.is_null() {
        return None;
    }
    // SAFETY: dladdr returns a NUL-terminated path.
    let path = unsafe { CStr::from_ptr(info.dli_fname) }.to_string_lossy().into_owned();
    Some(std::path::PathBuf::from(path))
}

/// Full path of this DLL (Windows): the module that contains this function, then its file name.
#[cfg(windows)]
fn own_library_path() -> Option<std::path::PathBuf> {
    use std::os::windows::ffi::OsStringExt;
    // The two kernel32 functions, declared here rather than pulling in a bindings crate.
    const GET_MODULE_HANDLE_EX_FLAG_FROM_ADDRESS: u32 = 0x4;
    const GET_MODULE_HANDLE_EX_FLAG_UNCHANGED_REFCOUNT: u32 = 0x2;
    #[link(name = "kernel32")]
    extern "system" {
        fn GetModuleHandleExW(flags: u32, module_name: *const u16, module: *mut *mut c_void) -> i32;
        fn GetModuleFileNameW(module: *mut c_void, file_name: *mut u16, size: u32) -> u32;
    }
    let mut module: *mut c_void = std::ptr::null_mut();
    // SAFETY: with FROM_ADDRESS the "name" is an address inside this DLL; UNCHANGED_REFCOUNT means
    // no handle is taken, so nothing must be freed; module is valid storage.
    let ok = unsafe {
        GetModuleHandleExW(
            GET_MODULE_HANDLE_EX_FLAG_FROM_ADDRESS | GET_MODULE_HANDLE_EX_FLAG_UNCHANGED_REFCOUNT,
            own_library_path as *const u16,
            &mut module,
        )
    };
    if ok == 0 || module.is_null() {
        return None;
    }
    // Long paths: grow the buffer while the name is truncated (the result then equals the size).
    let mut size: u32 = 512;
    loop {
        let mut buf = vec![0u16; size as usize];
        // SAFETY: buf holds `size` u16s; the call writes at most that many.
        let n = unsafe { GetModuleFileNameW(module, buf.as_mut_ptr(), size) };
        if n == 0 {
            return None;
        }
        if n < size {
            buf.truncate(n as usize);
            return Some(std::path::PathBuf::from(std::ffi::OsString::from_wide(&buf)));
        }
        if size >= 1 << 16 {
            return None;
        }
        size *= 2;
    }
}

#[cfg(not(any(unix, windows)))]
fn own_library_path() -> Option<std::path::PathBuf> {
    None
}
