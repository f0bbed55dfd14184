//! The part of OIDN 2's C API that marbre calls, as function pointers read
//! from the opened library (the declarations of `oidn.h`).

use std::ffi::{c_char, c_int, c_void};

/// `OIDNDevice`, `OIDNFilter`, `OIDNBuffer`: opaque handles.
pub type Handle = *mut c_void;

pub const DEVICE_TYPE_CPU: c_int = 1;
pub const DEVICE_TYPE_CUDA: c_int = 3;
pub const FORMAT_FLOAT3: c_int = 3;
pub const ERROR_NONE: c_int = 0;
pub const ERROR_CANCELLED: c_int = 6;
pub const QUALITY_FAST: c_int = 4;
pub const QUALITY_BALANCED: c_int = 5;
pub const QUALITY_HIGH: c_int = 6;

/// The functions, each `unsafe extern "C"` as `oidn.h` declares it.
pub struct Api {
    pub new_device: unsafe extern "C" fn(c_int) -> Handle,
    pub commit_device: unsafe extern "C" fn(Handle),
    pub release_device: unsafe extern "C" fn(Handle),
    pub get_device_error: unsafe extern "C" fn(Handle, *mut *const c_char) -> c_int,
    pub get_device_int: unsafe extern "C" fn(Handle, *const c_char) -> c_int,
    pub is_cuda_device_supported: unsafe extern "C" fn(c_int) -> bool,
    pub new_buffer: unsafe extern "C" fn(Handle, usize) -> Handle,
    pub write_buffer: unsafe extern "C" fn(Handle, usize, usize, *const c_void),
    pub read_buffer: unsafe extern "C" fn(Handle, usize, usize, *mut c_void),
    pub release_buffer: unsafe extern "C" fn(Handle),
    pub new_filter: unsafe extern "C" fn(Handle, *const c_char) -> Handle,
    #[allow(clippy::type_complexity)]
    pub set_filter_image: unsafe extern "C" fn(
        Handle,
        *const c_char,
        Handle,
        c_int,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    pub set_filter_bool: unsafe extern "C" fn(Handle, *const c_char, bool),
    pub set_filter_int: unsafe extern "C" fn(Handle, *const c_char, c_int),
    pub commit_filter: unsafe extern "C" fn(Handle),
    pub execute_filter: unsafe extern "C" fn(Handle),
    pub release_filter: unsafe extern "C" fn(Handle),
    pub set_filter_progress_monitor:
        unsafe extern "C" fn(Handle, Option<ProgressMonitor>, *mut c_void),
}

/// `OIDNProgressMonitorFunction`: called as a filter runs; returning false
/// cancels it.
pub type ProgressMonitor = unsafe extern "C" fn(*mut c_void, f64) -> bool;

impl Api {
    /// Reads every function from `lib`; the name of the first one missing
    /// otherwise (an OIDN 1 library, or not OIDN at all).
    ///
    /// # Safety
    /// `lib` must be OIDN 2's library, whose functions have the signatures
    /// above.
    #[cfg(not(target_arch = "wasm32"))]
    pub unsafe fn read(lib: &libloading::Library) -> Result<Self, String> {
        macro_rules! symbol {
            ($name:literal) => {
                // SAFETY: the caller vouches for the library; the field's
                // type is the declaration in oidn.h.
                *unsafe { lib.get(concat!($name, "\0").as_bytes()) }
                    .map_err(|e| format!("{} is missing: {e}", $name))?
            };
        }
        Ok(Self {
            new_device: symbol!("oidnNewDevice"),
            commit_device: symbol!("oidnCommitDevice"),
            release_device: symbol!("oidnReleaseDevice"),
            get_device_error: symbol!("oidnGetDeviceError"),
            get_device_int: symbol!("oidnGetDeviceInt"),
            is_cuda_device_supported: symbol!("oidnIsCUDADeviceSupported"),
            new_buffer: symbol!("oidnNewBuffer"),
            write_buffer: symbol!("oidnWriteBuffer"),
            read_buffer: symbol!("oidnReadBuffer"),
            release_buffer: symbol!("oidnReleaseBuffer"),
            new_filter: symbol!("oidnNewFilter"),
            set_filter_image: symbol!("oidnSetFilterImage"),
            set_filter_bool: symbol!("oidnSetFilterBool"),
            set_filter_int: symbol!("oidnSetFilterInt"),
            commit_filter: symbol!("oidnCommitFilter"),
            execute_filter: symbol!("oidnExecuteFilter"),
            release_filter: symbol!("oidnReleaseFilter"),
            set_filter_progress_monitor: symbol!("oidnSetFilterProgressMonitorFunction"),
        })
    }
}
