//! Adapter and device creation, headless or for a window; each device
//! with the handler of its uncaptured errors ([`uncaptured`]).

use anyhow::{Context as _, Result};

pub mod uncaptured;

pub use uncaptured::UncapturedErrors;

/// A device and what the stats panel and the benchmarks report about it.
/// A clone shares the device (wgpu handles are reference counted): the
/// viewer's swatch worker uses one.
#[derive(Clone)]
pub struct GpuContext {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// Whether GPU timestamp queries are enabled (not every adapter has them).
    pub timestamps: bool,
    /// The device's errors that no error scope caught, logged and kept
    /// instead of wgpu's panic.
    pub uncaptured: UncapturedErrors,
}

impl GpuContext {
    /// A device with no surface, for offscreen renders, the noise harness and
    /// tests. `WGPU_BACKEND` and `WGPU_ADAPTER_NAME` select the adapter.
    ///
    /// The primary backends (Vulkan, Metal, DX12) are tried first, and
    /// OpenGL only where none gives an adapter: creating the GL backend
    /// probes for a Wayland display and an EGL driver, and libwayland and
    /// EGL print their failures (`XDG_RUNTIME_DIR is invalid or not set`
    /// where it is unset) on every command with no window. Where GL is the
    /// only way, it is used and says what it says; `WGPU_BACKEND`, when
    /// set, decides alone.
    pub fn headless() -> Result<Self> {
        let primary = Self::from_instance(instance_of(wgpu::Backends::PRIMARY), None);
        match primary {
            Err(_) if wgpu::Backends::from_env().is_none() => {
                Self::from_instance(instance_of(wgpu::Backends::all()), None)
            }
            result => result,
        }
    }

    /// A device able to present to `window`, and the window's surface; the
    /// backends tried as [`GpuContext::headless`] tries them. Where Vulkan
    /// works, the GL backend is never started: EGL and Mesa's GL driver
    /// would otherwise be loaded beside it, with threads and exit handlers
    /// of their own (issue 26 saw a process exit tear EGL down under a
    /// worker still using it).
    pub fn for_window<W>(window: W) -> Result<(Self, wgpu::Surface<'static>)>
    where
        W: Into<wgpu::SurfaceTarget<'static>> + Clone,
    {
        let on = |backends| -> Result<(Self, wgpu::Surface<'static>)> {
            let instance = instance_of(backends);
            let surface = instance
                .create_surface(window.clone())
                .context("creating the window surface")?;
            let ctx = Self::from_instance(instance, Some(&surface))?;
            Ok((ctx, surface))
        };
        match on(wgpu::Backends::PRIMARY) {
            Err(_) if wgpu::Backends::from_env().is_none() => on(wgpu::Backends::all()),
            result => result,
        }
    }

    /// A device able to present to `surface`: a lost device's replacement.
    /// A web page cannot wait for one (as [`GpuContext::sibling`]): there it
    /// is an error that says to reload the page.
    pub fn for_surface(instance: wgpu::Instance, surface: &wgpu::Surface<'_>) -> Result<Self> {
        if cfg!(target_arch = "wasm32") {
            anyhow::bail!(
                "a web page cannot wait for a new GPU device: reload the page (the scene is in \
                 its address if you pressed Share)"
            );
        }
        Self::from_instance(instance, Some(surface))
    }

    /// A device able to present to `window` through the browser's WebGPU,
    /// and the window's surface. A page cannot block on the adapter and
    /// device requests (the browser answers them on its own event loop),
    /// so this one is awaited (issue 34).
    pub async fn for_web_window<W>(window: W) -> Result<(Self, wgpu::Surface<'static>)>
    where
        W: Into<wgpu::SurfaceTarget<'static>>,
    {
        let instance = instance_of(wgpu::Backends::BROWSER_WEBGPU);
        let surface = instance
            .create_surface(window)
            .context("creating the canvas's WebGPU surface")?;
        let ctx = Self::from_instance_async(instance, Some(&surface)).await?;
        Ok((ctx, surface))
    }

    /// A device with no surface from the browser's WebGPU, awaited: for
    /// tests that run inside a page (issue 34).
    pub async fn for_browser() -> Result<Self> {
        Self::from_instance_async(instance_of(wgpu::Backends::BROWSER_WEBGPU), None).await
    }

    fn from_instance(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<Self> {
        pollster::block_on(Self::from_instance_async(instance, surface))
    }

    async fn from_instance_async(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<Self> {
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter: false,
                compatible_surface: surface,
                ..Default::default()
            })
            .await
            .context(
                "no GPU adapter found (install a Vulkan driver, e.g. Debian's mesa-vulkan-drivers)",
            )?;
        let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let required_features = if timestamps {
            wgpu::Features::TIMESTAMP_QUERY
        } else {
            wgpu::Features::empty()
        };
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("marbre"),
                required_features,
                required_limits: adapter.limits(),
                ..Default::default()
            })
            .await
            .context("the adapter refused to create a device")?;
        Ok(Self {
            instance,
            adapter,
            uncaptured: UncapturedErrors::watch(&device),
            device,
            queue,
            timestamps,
        })
    }

    /// A second device on the same adapter, with the same features and
    /// limits: somewhere to compile shaders without holding up this
    /// device's queue (see `gpu::pipeline_build`). A web page cannot wait
    /// for one (its request is answered on the browser's event loop, which
    /// a blocked page never returns to): there it is an error, and each
    /// caller's fallback (no warm-up, no timing, no background render)
    /// applies.
    pub fn sibling(&self) -> Result<Self> {
        self.device_with("a second device", self.device.limits())
    }

    /// A device on the same adapter held to `limits` (lower ones than the
    /// adapter's): how tests check that work sized by its input is split
    /// to a device's limits without inputs as large as real limits.
    pub fn limited(&self, limits: wgpu::Limits) -> Result<Self> {
        self.device_with("a device with these limits", limits)
    }

    /// Another device on this one's adapter and features: `what` it is,
    /// in its errors.
    fn device_with(&self, what: &str, required_limits: wgpu::Limits) -> Result<Self> {
        if cfg!(target_arch = "wasm32") {
            anyhow::bail!("a web page cannot wait for {what} on its GPU");
        }
        let (device, queue) =
            pollster::block_on(self.adapter.request_device(&wgpu::DeviceDescriptor {
                label: Some(what),
                required_features: self.device.features(),
                required_limits,
                ..Default::default()
            }))
            .with_context(|| format!("the adapter refused {what}"))?;
        Ok(Self {
            instance: self.instance.clone(),
            adapter: self.adapter.clone(),
            uncaptured: UncapturedErrors::watch(&device),
            device,
            queue,
            timestamps: self.timestamps,
        })
    }

    /// Whether the adapter is a CPU implementation (lavapipe, WARP), whose
    /// shader compiler runs at the first draw rather than at pipeline
    /// creation.
    pub fn is_cpu(&self) -> bool {
        self.adapter.get_info().device_type == wgpu::DeviceType::Cpu
    }

    /// "name (backend)", as shown in the stats panel and benchmark tables.
    pub fn describe(&self) -> String {
        let info = self.adapter.get_info();
        format!("{} ({:?})", info.name, info.backend)
    }
}

/// An instance on `backends`, unless `WGPU_BACKEND` names others.
fn instance_of(backends: wgpu::Backends) -> wgpu::Instance {
    wgpu::Instance::new(
        wgpu::InstanceDescriptor {
            backends,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        }
        .with_env(),
    )
}
