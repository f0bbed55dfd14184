//! One OIDN device and its "RT" filters, kept across images of one size:
//! committing a filter loads its network's weights (tens of milliseconds),
//! so the viewer's repeated denoises of the same accumulation pay it once.

use crate::api::{self, Handle};
use crate::library::Library;
use crate::{OidnError, border, sanitise};
use std::ffi::{CStr, c_char, c_void};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Which OIDN device runs the network.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeviceKind {
    Cpu,
    /// NVIDIA GPUs; images go through host memory (OIDN buffers written
    /// and read back), as wgpu cannot share its memory with CUDA.
    Cuda,
}

impl DeviceKind {
    pub fn name(self) -> &'static str {
        match self {
            DeviceKind::Cpu => "CPU",
            DeviceKind::Cuda => "CUDA",
        }
    }
}

/// OIDN's `quality`: its three trained networks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Quality {
    /// For final frames.
    High,
    /// For interactive rendering.
    Balanced,
    /// For real-time previews.
    Fast,
}

impl Quality {
    fn code(self) -> i32 {
        match self {
            Quality::High => api::QUALITY_HIGH,
            Quality::Balanced => api::QUALITY_BALANCED,
            Quality::Fast => api::QUALITY_FAST,
        }
    }
}

/// An image to denoise, row by row, and its guides (both or neither, as
/// OIDN takes a normal only with an albedo).
#[derive(Debug, Clone, Copy)]
pub struct Images<'a> {
    pub size: (u32, u32),
    /// Linear HDR radiance.
    pub colour: &'a [[f32; 3]],
    pub guides: Option<Guides<'a>>,
}

/// The first hit's albedo, and its normal in [−1, 1] (world or camera
/// space, not necessarily normalised), row by row.
#[derive(Debug, Clone, Copy)]
pub struct Guides<'a> {
    pub albedo: &'a [[f32; 3]],
    pub normal: &'a [[f32; 3]],
}

/// An OIDN device and the filters of the last image's size and quality.
pub struct Denoiser {
    library: Arc<Library>,
    device: Handle,
    kind: DeviceKind,
    filters: Option<Filters>,
    /// Set, a running filter stops at its next progress report (OIDN
    /// reports many times a second) and [`Denoiser::denoise`] returns
    /// [`OidnError::cancelled`]: a window closing or an image gone stale
    /// need not wait seconds for a 1080p denoise on a CPU.
    cancel: Arc<AtomicBool>,
}

/// OIDN's progress callback: carry on unless the flag (`user`) is set.
unsafe extern "C" fn carry_on(user: *mut c_void, _done: f64) -> bool {
    // SAFETY: `user` is the `AtomicBool` of the denoiser's `cancel`,
    // which the denoiser keeps alive for as long as its filters.
    !unsafe { &*user.cast::<AtomicBool>() }.load(Ordering::Relaxed)
}

// SAFETY: OIDN's objects may be used from any thread, one at a time; a
// `Denoiser` is only ever used through `&mut self`.
unsafe impl Send for Denoiser {}

/// The three filters of one size and quality (the guides' prefilters and
/// the main one) and their four buffers.
struct Filters {
    size: (u32, u32),
    quality: Quality,
    guided: bool,
    main: Handle,
    prefilters: Vec<Handle>,
    colour: Handle,
    albedo: Handle,
    normal: Handle,
    output: Handle,
}

const FLOAT3: usize = 12;

impl Denoiser {
    /// A committed device of `kind`.
    pub fn new(library: Arc<Library>, kind: DeviceKind) -> Result<Self, OidnError> {
        let code = match kind {
            DeviceKind::Cpu => api::DEVICE_TYPE_CPU,
            DeviceKind::Cuda => api::DEVICE_TYPE_CUDA,
        };
        // SAFETY: OIDN's API; a null device is reported by the check below.
        let device = unsafe { (library.api.new_device)(code) };
        let denoiser = Self {
            library,
            device,
            kind,
            filters: None,
            cancel: Arc::new(AtomicBool::new(false)),
        };
        denoiser.check("oidnNewDevice")?;
        if denoiser.device.is_null() {
            return Err(OidnError::new(
                "oidnNewDevice",
                format!("no {} device", kind.name()),
            ));
        }
        // SAFETY: a device just made.
        unsafe { (denoiser.library.api.commit_device)(denoiser.device) };
        denoiser.check("oidnCommitDevice")?;
        Ok(denoiser)
    }

    /// Whether OIDN can run on the first CUDA GPU (an NVIDIA adapter with
    /// its driver, and the wheel's CUDA device module).
    pub fn cuda_supported(library: &Library) -> bool {
        // SAFETY: OIDN's API, with a device index.
        unsafe { (library.api.is_cuda_device_supported)(0) }
    }

    pub fn kind(&self) -> DeviceKind {
        self.kind
    }

    /// The flag that cancels a running (or the next) denoise when set;
    /// clear it before a denoise that should run.
    pub fn cancel_flag(&self) -> Arc<AtomicBool> {
        self.cancel.clone()
    }

    /// Makes `flag` this denoiser's cancel flag (its filters are made
    /// again, with the new flag).
    pub fn share_cancel_flag(&mut self, flag: Arc<AtomicBool>) {
        self.release_filters();
        self.cancel = flag;
    }

    /// OIDN's version, as "2.5.1".
    pub fn version(&self) -> String {
        // SAFETY: a committed device and a parameter name of oidn.h.
        let v = unsafe { (self.library.api.get_device_int)(self.device, c"version".as_ptr()) };
        format!("{}.{}.{}", v / 10000, (v / 100) % 100, v % 100)
    }

    /// The denoised image, after every input is made finite
    /// ([`sanitise`]), its borders mirrored out ([`border`]) and the guides
    /// filtered themselves.
    pub fn denoise(
        &mut self,
        images: &Images<'_>,
        quality: Quality,
    ) -> Result<Vec<[f32; 3]>, OidnError> {
        let (w, h) = images.size;
        let n = w as usize * h as usize;
        let lengths_agree = images.colour.len() == n
            && images
                .guides
                .is_none_or(|g| g.albedo.len() == n && g.normal.len() == n);
        if n == 0 || !lengths_agree {
            return Err(OidnError::new(
                "denoise",
                format!("a {w}×{h} image needs {n} pixels of colour and of each guide"),
            ));
        }
        let guided = images.guides.is_some();
        let (colour_in, pw, ph) = border::pad(
            &images
                .colour
                .iter()
                .map(|&c| sanitise::colour(c))
                .collect::<Vec<_>>(),
            w as usize,
            h as usize,
        );
        let padded_size = (pw as u32, ph as u32);
        let fits = self
            .filters
            .as_ref()
            .is_some_and(|f| f.size == padded_size && f.quality == quality && f.guided == guided);
        if !fits {
            self.release_filters();
            let filters = self.make_filters(padded_size, quality, guided)?;
            self.filters = Some(filters);
        }
        let f = self.filters.as_ref().expect("made above");
        let (colour, albedo, normal, output, main) =
            (f.colour, f.albedo, f.normal, f.output, f.main);
        let prefilters = f.prefilters.clone();
        self.write(colour, &colour_in);
        if let Some(guides) = images.guides {
            let a: Vec<[f32; 3]> = guides.albedo.iter().map(|&c| sanitise::albedo(c)).collect();
            let nrm: Vec<[f32; 3]> = guides.normal.iter().map(|&c| sanitise::normal(c)).collect();
            self.write(albedo, &border::pad(&a, w as usize, h as usize).0);
            self.write(normal, &border::pad(&nrm, w as usize, h as usize).0);
        }
        for filter in prefilters.into_iter().chain([main]) {
            // SAFETY: a committed filter whose images are this device's
            // buffers of the right size.
            unsafe { (self.library.api.execute_filter)(filter) };
            self.check("oidnExecuteFilter")?;
            if self.cancel.load(Ordering::Relaxed) {
                return Err(OidnError::cancelled());
            }
        }
        let mut padded = vec![[0.0f32; 3]; pw * ph];
        // SAFETY: `padded` holds exactly the output buffer's bytes.
        unsafe {
            (self.library.api.read_buffer)(output, 0, pw * ph * FLOAT3, padded.as_mut_ptr().cast());
        }
        self.check("oidnReadBuffer")?;
        let mut out = border::crop(&padded, w as usize, h as usize);
        // The network's output is finite for finite input; the last guard
        // keeps the promise that nothing non-finite reaches the display.
        for p in &mut out {
            *p = sanitise::colour(*p);
        }
        Ok(out)
    }

    fn write(&self, buffer: Handle, pixels: &[[f32; 3]]) {
        // SAFETY: the buffer was made for this many pixels.
        unsafe {
            (self.library.api.write_buffer)(
                buffer,
                0,
                pixels.len() * FLOAT3,
                pixels.as_ptr().cast(),
            );
        }
    }

    fn make_filters(
        &mut self,
        size: (u32, u32),
        quality: Quality,
        guided: bool,
    ) -> Result<Filters, OidnError> {
        let (w, h) = (size.0 as usize, size.1 as usize);
        let bytes = w * h * FLOAT3;
        let api = &self.library.api;
        // SAFETY: OIDN's API on a committed device; failures are reported
        // by the device's error, checked below.
        let new_buffer = || unsafe { (api.new_buffer)(self.device, bytes) };
        let mut f = Filters {
            size,
            quality,
            guided,
            main: std::ptr::null_mut(),
            prefilters: Vec::new(),
            colour: new_buffer(),
            albedo: if guided {
                new_buffer()
            } else {
                std::ptr::null_mut()
            },
            normal: if guided {
                new_buffer()
            } else {
                std::ptr::null_mut()
            },
            output: new_buffer(),
        };
        if let Err(e) = self.check("oidnNewBuffer") {
            self.release(&f);
            return Err(e);
        }
        let image = |filter: Handle, name: &CStr, buffer: Handle| {
            // SAFETY: a filter and a buffer of `bytes` bytes: w × h FLOAT3
            // pixels, packed.
            unsafe {
                (api.set_filter_image)(
                    filter,
                    name.as_ptr(),
                    buffer,
                    api::FORMAT_FLOAT3,
                    w,
                    h,
                    0,
                    FLOAT3,
                    FLOAT3 * w,
                )
            }
        };
        let user = Arc::as_ptr(&self.cancel).cast_mut().cast::<c_void>();
        let new_filter = || {
            // SAFETY: OIDN's API on a committed device; the monitor's
            // `user` outlives the filter (see `cancel`).
            unsafe {
                let filter = (api.new_filter)(self.device, c"RT".as_ptr());
                (api.set_filter_progress_monitor)(filter, Some(carry_on), user);
                filter
            }
        };
        // SAFETY (below): parameters of oidn.h on filters just made.
        let set_int = |filter: Handle, name: &CStr, v: i32| unsafe {
            (api.set_filter_int)(filter, name.as_ptr() as *const c_char, v)
        };
        let set_bool = |filter: Handle, name: &CStr, v: bool| unsafe {
            (api.set_filter_bool)(filter, name.as_ptr() as *const c_char, v)
        };
        if guided {
            // Prefiltering, as OIDN's documentation recommends for final
            // frames: each guide denoised on its own, in place.
            for (name, buffer) in [(c"albedo", f.albedo), (c"normal", f.normal)] {
                let p = new_filter();
                image(p, name, buffer);
                image(p, c"output", buffer);
                set_int(p, c"quality", quality.code());
                // SAFETY: a filter with its images set.
                unsafe { (api.commit_filter)(p) };
                f.prefilters.push(p);
            }
        }
        f.main = new_filter();
        image(f.main, c"color", f.colour);
        if guided {
            image(f.main, c"albedo", f.albedo);
            image(f.main, c"normal", f.normal);
            set_bool(f.main, c"cleanAux", true);
        }
        image(f.main, c"output", f.output);
        set_bool(f.main, c"hdr", true);
        set_int(f.main, c"quality", quality.code());
        // SAFETY: a filter with its images set.
        unsafe { (api.commit_filter)(f.main) };
        if let Err(e) = self.check("oidnCommitFilter") {
            self.release(&f);
            return Err(e);
        }
        Ok(f)
    }

    /// The device's pending error, if any.
    fn check(&self, call: &'static str) -> Result<(), OidnError> {
        let mut message: *const c_char = std::ptr::null();
        // SAFETY: OIDN's API; a null device asks for the thread's error.
        let code = unsafe { (self.library.api.get_device_error)(self.device, &mut message) };
        if code == api::ERROR_NONE {
            return Ok(());
        }
        if code == api::ERROR_CANCELLED {
            return Err(OidnError::cancelled());
        }
        let message = if message.is_null() {
            format!("error {code}")
        } else {
            // SAFETY: OIDN returns a NUL-terminated string valid until the
            // next call on this device.
            unsafe { CStr::from_ptr(message) }
                .to_string_lossy()
                .into_owned()
        };
        Err(OidnError::new(call, message))
    }

    fn release(&self, f: &Filters) {
        let api = &self.library.api;
        for filter in f.prefilters.iter().chain([&f.main]) {
            if !filter.is_null() {
                // SAFETY: a filter of this device, released once.
                unsafe { (api.release_filter)(*filter) };
            }
        }
        for buffer in [f.colour, f.albedo, f.normal, f.output] {
            if !buffer.is_null() {
                // SAFETY: a buffer of this device, released once.
                unsafe { (api.release_buffer)(buffer) };
            }
        }
    }

    fn release_filters(&mut self) {
        if let Some(f) = self.filters.take() {
            self.release(&f);
        }
    }
}

impl Drop for Denoiser {
    fn drop(&mut self) {
        self.release_filters();
        if !self.device.is_null() {
            // SAFETY: the device, released once, after its objects.
            unsafe { (self.library.api.release_device)(self.device) };
        }
    }
}
