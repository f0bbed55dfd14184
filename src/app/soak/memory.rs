//! What the process and the GPU hold, sampled once per soak frame.

use marbre_render::gpu::GpuContext;

/// One frame's memory figures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MemorySample {
    /// Resident set size of the whole process (0 where the platform gives
    /// no `/proc/self/status`: only Linux is measured). On a software
    /// rasteriser (lavapipe) GPU memory is host memory and counts here too.
    pub rss_bytes: u64,
    /// Bytes the device's memory allocator has handed out (Vulkan and D3D12
    /// report it; other backends give None).
    pub gpu_allocated_bytes: Option<u64>,
    /// Live wgpu objects: buffers, textures, views, bind groups, pipelines,
    /// shader modules, query sets and samplers (None where wgpu has no
    /// report, i.e. on WebGPU).
    pub gpu_resources: Option<u64>,
    /// The C heap: bytes held, and bytes free but kept (None where the
    /// allocator does not say). RSS growing while bytes held do not is
    /// memory left resident by the allocator, not a leak.
    pub heap: Option<crate::heap::HeapUsage>,
}

/// The process's and the device's memory now.
pub fn sample_memory(ctx: &GpuContext) -> MemorySample {
    MemorySample {
        rss_bytes: resident_set_bytes().unwrap_or(0),
        gpu_allocated_bytes: ctx
            .device
            .generate_allocator_report()
            .map(|r| r.total_allocated_bytes),
        gpu_resources: live_gpu_resources(ctx),
        heap: crate::heap::usage(),
    }
}

/// The GPU objects alive now, by wgpu-core's count. A web page's WebGPU
/// keeps no such count (wgpu there has no wgpu-core).
#[cfg(target_arch = "wasm32")]
fn live_gpu_resources(_ctx: &GpuContext) -> Option<u64> {
    None
}

#[cfg(not(target_arch = "wasm32"))]
fn live_gpu_resources(ctx: &GpuContext) -> Option<u64> {
    ctx.instance.generate_report().map(|report| {
        let hub = report.hub_report();
        [
            &hub.buffers,
            &hub.textures,
            &hub.texture_views,
            &hub.bind_groups,
            &hub.render_pipelines,
            &hub.compute_pipelines,
            &hub.shader_modules,
            &hub.query_sets,
            &hub.samplers,
        ]
        .iter()
        .map(|r| r.num_allocated as u64)
        .sum()
    })
}

/// The process's resident set, from the `VmRSS` line of
/// `/proc/self/status` (the kernel's count of resident pages, the second
/// field of `/proc/self/statm`, already in kB: no page-size lookup needed);
/// None where there is no such file.
fn resident_set_bytes() -> Option<u64> {
    vm_rss_bytes(&std::fs::read_to_string("/proc/self/status").ok()?)
}

fn vm_rss_bytes(status: &str) -> Option<u64> {
    let line = status.lines().find_map(|l| l.strip_prefix("VmRSS:"))?;
    let mut fields = line.split_whitespace();
    let kib: u64 = fields.next()?.parse().ok()?;
    (fields.next() == Some("kB")).then_some(kib * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vm_rss_is_read_in_bytes() {
        let status = "Name:\tmarbre\nVmPeak:\t  900000 kB\nVmRSS:\t  123456 kB\nThreads:\t4\n";
        assert_eq!(vm_rss_bytes(status), Some(123_456 * 1024));
        assert_eq!(vm_rss_bytes("VmRSS:\t12 MB\n"), None);
        assert_eq!(vm_rss_bytes("Name:\tx\n"), None);
    }

    /// A running test process holds at least its own code and heap.
    #[cfg(target_os = "linux")]
    #[test]
    fn this_process_has_a_resident_set() {
        let rss = resident_set_bytes().expect("/proc/self/status has VmRSS");
        assert!(rss > 1 << 20, "RSS {rss} bytes");
    }

    /// A new 16 MiB buffer is one more live object and at least 16 MiB
    /// more allocated (lavapipe's Vulkan reports its allocator); dropping
    /// it gives both back.
    #[test]
    fn a_buffer_shows_in_the_gpu_figures() {
        let Some(ctx) =
            marbre_render::gpu::testing::gpu_or_skip("a_buffer_shows_in_the_gpu_figures")
        else {
            return;
        };
        let settle = || {
            let _ = ctx.device.poll(wgpu::PollType::wait_indefinitely());
            sample_memory(&ctx)
        };
        let before = settle();
        let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("soak memory probe"),
            size: 16 << 20,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let with = settle();
        let resources = |s: MemorySample| s.gpu_resources.expect("wgpu-core reports its hub");
        assert_eq!(resources(with), resources(before) + 1);
        if let (Some(b), Some(w)) = (before.gpu_allocated_bytes, with.gpu_allocated_bytes) {
            assert!(w >= b + (16 << 20), "allocated {b} → {w} bytes");
        }
        drop(buffer);
        let after = settle();
        assert_eq!(resources(after), resources(before));
        assert_eq!(after.gpu_allocated_bytes, before.gpu_allocated_bytes);
    }
}
