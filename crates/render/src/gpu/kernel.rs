//! Which kernel runs the trace: the fragment shader over a full-screen
//! triangle, a compute dispatch, or the CPU kernel (`crate::cpu_kernel`,
//! the same path in Rust on the machine's cores, its samples folded into
//! the accumulation by the fragment kernel's shader). The GPU kernels call
//! the same WGSL body (`trace_pixel` in shaders/trace.wgsl) and give the
//! same image, the CPU kernel the same image to rounding; which is faster
//! depends on the adapter. An NVIDIA H100 runs pixel shaders on few
//! of its units (the prototype traced the default preset at 1080p in 0.7 ms
//! in compute against 19.5 ms in fragment), while on lavapipe neither wins
//! everywhere (docs/PERFORMANCE.md). So `auto` times both on the scene at
//! hand and keeps the faster (`app/kernel_choice.rs` remembers it per
//! adapter).

use super::context::GpuContext;
use std::fmt;

/// A kernel the renderer can trace with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Kernel {
    /// `fs_trace`: a full-screen triangle, the accumulation targets as
    /// colour attachments.
    #[default]
    Fragment,
    /// `cs_trace`: workgroups of [`WORKGROUP`] pixels, the targets as
    /// storage textures.
    Compute,
    /// `crate::cpu_kernel` on the machine's cores, for the scenes it
    /// traces (`cpu_kernel::support`); another scene is traced by the
    /// fragment kernel meanwhile ([`Kernel::for_scene`]).
    Cpu,
}

impl Kernel {
    pub const ALL: [Kernel; 3] = [Kernel::Fragment, Kernel::Compute, Kernel::Cpu];
    /// The kernels that run on the adapter.
    pub const GPU: [Kernel; 2] = [Kernel::Fragment, Kernel::Compute];

    /// Its name on the command line, in settings and in the panel.
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Fragment => "fragment",
            Kernel::Compute => "compute",
            Kernel::Cpu => "cpu",
        }
    }

    /// The kernel that traces `scene` when this one is asked for: itself,
    /// or the fragment kernel where the CPU kernel cannot trace the scene.
    pub fn for_scene(self, scene: &marbre_core::scene::Scene) -> Kernel {
        match self {
            Kernel::Cpu if crate::cpu_kernel::support(scene).is_err() => Kernel::Fragment,
            k => k,
        }
    }

    /// The kernel named `name` (as [`Kernel::name`] writes it).
    pub fn parse(name: &str) -> Option<Kernel> {
        Kernel::ALL.into_iter().find(|k| k.name() == name)
    }
}

impl fmt::Display for Kernel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What the user asked for: a kernel, or the fastest. Its names
/// parse and print (`--kernel`'s values: the command-line crates hand
/// [`KernelChoice::NAMES`] to clap; this crate has no clap).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum KernelChoice {
    Fragment,
    Compute,
    Cpu,
    /// Time both on the first scene and keep the faster (remembered per
    /// adapter by the viewer).
    #[default]
    Auto,
}

impl KernelChoice {
    pub const ALL: [KernelChoice; 4] = [
        KernelChoice::Fragment,
        KernelChoice::Compute,
        KernelChoice::Cpu,
        KernelChoice::Auto,
    ];
    /// The names [`KernelChoice::name`] gives, in [`KernelChoice::ALL`]'s order.
    pub const NAMES: [&'static str; 4] = ["fragment", "compute", "cpu", "auto"];

    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The kernel this choice names, `None` for `auto`.
    pub fn fixed(self) -> Option<Kernel> {
        match self {
            KernelChoice::Fragment => Some(Kernel::Fragment),
            KernelChoice::Compute => Some(Kernel::Compute),
            KernelChoice::Cpu => Some(Kernel::Cpu),
            KernelChoice::Auto => None,
        }
    }
}

impl fmt::Display for KernelChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for KernelChoice {
    type Err = String;

    fn from_str(name: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|c| c.name() == name)
            .ok_or_else(|| {
                format!(
                    "`{name}` is not a kernel (one of {})",
                    Self::NAMES.join(", ")
                )
            })
    }
}

/// The compute kernel's workgroup, in pixels (shaders/trace.wgsl's
/// `@workgroup_size`, where the measurement that chose it is).
pub const WORKGROUP: (u32, u32) = (16, 8);

/// The storage textures the compute kernel writes (mean, spread,
/// compensation).
const STORAGE_TEXTURES: u32 = 3;

/// Why `ctx`'s adapter cannot run the compute kernel, or `Ok`: it writes
/// three `Rgba32Float` storage textures from workgroups of [`WORKGROUP`].
pub fn compute_support(ctx: &GpuContext) -> Result<(), String> {
    let format = super::accumulation::ACCUMULATION_FORMAT;
    let usages = ctx
        .adapter
        .get_texture_format_features(format)
        .allowed_usages;
    let limits = ctx.device.limits();
    missing_capability(
        usages.contains(wgpu::TextureUsages::STORAGE_BINDING),
        &limits,
    )
    .map_or(Ok(()), Err)
}

/// The first capability the compute kernel needs that is missing, named.
fn missing_capability(storage_format: bool, limits: &wgpu::Limits) -> Option<String> {
    let invocations = WORKGROUP.0 * WORKGROUP.1;
    if !storage_format {
        Some(format!(
            "{:?} textures cannot be storage textures on this adapter",
            super::accumulation::ACCUMULATION_FORMAT
        ))
    } else if limits.max_storage_textures_per_shader_stage < STORAGE_TEXTURES {
        Some(format!(
            "the adapter allows {} storage textures per shader stage, the compute kernel writes {STORAGE_TEXTURES}",
            limits.max_storage_textures_per_shader_stage
        ))
    } else if limits.max_compute_invocations_per_workgroup < invocations
        || limits.max_compute_workgroup_size_x < WORKGROUP.0
        || limits.max_compute_workgroup_size_y < WORKGROUP.1
    {
        Some(format!(
            "the adapter's compute workgroups are smaller than {}x{}",
            WORKGROUP.0, WORKGROUP.1
        ))
    } else {
        None
    }
}

/// The kernel `choice` resolves to on `ctx`'s adapter, before any timing:
/// `auto` starts on the compute kernel where it is supported. `--kernel
/// compute` where it is not is an error naming what is missing.
pub fn resolve(ctx: &GpuContext, choice: KernelChoice) -> anyhow::Result<Kernel> {
    match (choice, compute_support(ctx)) {
        (KernelChoice::Compute, Err(why)) => Err(anyhow::anyhow!(
            "the compute kernel cannot run on {}: {why}",
            ctx.describe()
        )),
        (KernelChoice::Fragment, _) | (KernelChoice::Auto, Err(_)) => Ok(Kernel::Fragment),
        (KernelChoice::Compute, Ok(())) | (KernelChoice::Auto, Ok(())) => Ok(Kernel::Compute),
        (KernelChoice::Cpu, _) => Ok(Kernel::Cpu),
    }
}

/// How much faster the compute kernel must be timed to be chosen: on a
/// busy CPU adapter a short timing cannot tell kernels within a few per
/// cent apart (lavapipe under load picked the one 4 to 15 % slower, on
/// timings of 0.94 to 0.99), while where compute wins it wins by far (an
/// H100: 5 to 25 times).
pub const COMPUTE_MARGIN: f64 = 0.95;

/// The faster kernel from the median milliseconds each took on the same
/// scene and size. A near tie (within [`COMPUTE_MARGIN`]) keeps the
/// fragment kernel, the one every adapter runs.
pub fn faster(fragment_ms: f64, compute_ms: f64) -> Kernel {
    fastest(fragment_ms, &[(Kernel::Compute, compute_ms)])
}

/// The fastest of the fragment kernel and `others` (each timed on the same
/// scene and size): another kernel is chosen only if it beats the
/// fragment kernel by the margin, and the fastest of those wins.
pub fn fastest(fragment_ms: f64, others: &[(Kernel, f64)]) -> Kernel {
    others
        .iter()
        .filter(|(_, ms)| *ms < fragment_ms * COMPUTE_MARGIN)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(Kernel::Fragment, |(k, _)| *k)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_are_refused() {
        for k in Kernel::ALL {
            assert_eq!(Kernel::parse(k.name()), Some(k));
        }
        assert_eq!(Kernel::parse("Compute"), None);
        assert_eq!(Kernel::parse(""), None);
    }

    #[test]
    fn the_faster_kernel_wins_and_a_near_tie_keeps_fragment() {
        assert_eq!(faster(10.0, 4.0), Kernel::Compute);
        assert_eq!(faster(4.0, 10.0), Kernel::Fragment);
        assert_eq!(faster(5.0, 5.0), Kernel::Fragment);
        // Within the margin: a tie.
        assert_eq!(faster(10.0, 9.6), Kernel::Fragment);
        assert_eq!(faster(10.0, 9.4), Kernel::Compute);
    }

    #[test]
    fn the_fastest_of_three_wins_past_the_margin() {
        let others = |compute, cpu| [(Kernel::Compute, compute), (Kernel::Cpu, cpu)];
        assert_eq!(fastest(10.0, &others(4.0, 2.0)), Kernel::Cpu);
        assert_eq!(fastest(10.0, &others(2.0, 4.0)), Kernel::Compute);
        assert_eq!(fastest(10.0, &others(9.8, 9.7)), Kernel::Fragment);
        assert_eq!(fastest(10.0, &others(12.0, 9.0)), Kernel::Cpu);
        assert_eq!(fastest(10.0, &[]), Kernel::Fragment);
    }

    #[test]
    fn each_missing_capability_is_named() {
        let full = wgpu::Limits::default();
        assert_eq!(missing_capability(true, &full), None);
        let format = missing_capability(false, &full).unwrap();
        assert!(format.contains("Rgba32Float"), "{format}");
        let few = wgpu::Limits {
            max_storage_textures_per_shader_stage: 2,
            ..full.clone()
        };
        let textures = missing_capability(true, &few).unwrap();
        assert!(textures.contains("allows 2 storage textures"), "{textures}");
        let small = wgpu::Limits {
            max_compute_invocations_per_workgroup: 32,
            ..full.clone()
        };
        assert!(missing_capability(true, &small).unwrap().contains("16x8"));
        // WebGL2's limits have no storage textures at all.
        assert!(missing_capability(true, &wgpu::Limits::downlevel_webgl2_defaults()).is_some());
    }
}
