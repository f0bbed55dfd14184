//! `marbre bench-bvh`: builds the BVH of a heavy procedural mesh and times
//! the GPU's traversal of it (`crates/core/src/accel/traverse.wgsl` through the compute
//! harness), with the CPU's traversal on one thread for scale.

use anyhow::{Result, ensure};
use clap::Args;
use glam::Vec3;
use marbre_core::accel::shapes::bumpy_sphere;
use marbre_core::accel::{Bvh, TriangleVerts};
use marbre_render::gpu::GpuContext;
use marbre_render::gpu::harness::bvh::{BvhHarness, Query, Ray};
use std::time::{Duration, Instant};

#[derive(Args, Debug)]
pub struct BvhBenchArgs {
    /// Triangles in the generated mesh (a sphere displaced by fBm).
    #[arg(long, default_value_t = 1_000_000)]
    pub triangles: usize,
    /// Rays per timed dispatch, for each ray set.
    #[arg(long, default_value_t = 1 << 20)]
    pub rays: usize,
    /// Timed dispatches per measurement (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub repeats: u32,
    /// Only build the BVH; no GPU.
    #[arg(long)]
    pub build_only: bool,
}

/// Primary rays of a pinhole camera 3 units from the mesh, one per pixel of
/// a square image, row by row: neighbouring invocations trace neighbouring
/// rays, as in the trace pass.
fn camera_rays(n: usize) -> Vec<Ray> {
    let side = (n as f64).sqrt().ceil() as usize;
    let eye = Vec3::new(0.4, 0.9, 2.8);
    let forward = (Vec3::ZERO - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let half = (20f32).to_radians().tan();
    (0..n)
        .map(|k| {
            let (x, y) = ((k % side) as f32, (k / side) as f32);
            let u = ((x + 0.5) / side as f32 * 2.0 - 1.0) * half;
            let v = (1.0 - (y + 0.5) / side as f32 * 2.0) * half;
            Ray {
                origin: eye,
                direction: (forward + u * right + v * up).normalize(),
                t_max: f32::MAX,
            }
        })
        .collect()
}

/// Incoherent rays, like diffuse bounces: from random points on a shell
/// around the mesh's surface, in random directions; neighbouring
/// invocations share nothing.
fn scattered_rays(n: usize) -> Vec<Ray> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut unit = move || loop {
        let v = Vec3::new(next(), next(), next()) * 2.0 - 1.0;
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            break v / l.sqrt();
        }
    };
    (0..n)
        .map(|k| {
            let radius = 0.9 + 0.3 * (k % 7) as f32 / 6.0;
            Ray {
                origin: unit() * radius,
                direction: unit(),
                t_max: f32::MAX,
            }
        })
        .collect()
}

fn rate(rays: usize, time: Duration) -> String {
    format!(
        "{:7.3} Mrays/s ({:.0} ms)",
        rays as f64 / time.as_secs_f64() / 1e6,
        time.as_secs_f64() * 1e3,
    )
}

/// CPU time this process has used so far, all threads (lavapipe's
/// workers are threads of this process), from /proc on Linux. On a shared
/// machine, rays per CPU-second compare variants better than wall clock.
fn process_cpu_time() -> Option<Duration> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) in parentheses:
    // utime and stime are the 12th and 13th, in clock ticks (100 per s).
    let rest = &stat[stat.rfind(')')? + 2..];
    let fields: Vec<&str> = rest.split(' ').collect();
    let ticks: u64 = fields.get(11)?.parse::<u64>().ok()? + fields.get(12)?.parse::<u64>().ok()?;
    Some(Duration::from_millis(ticks * 10))
}

/// Times `query` (wall clock per dispatch, sorted) and the CPU time per
/// dispatch, where /proc tells.
fn measure(
    ctx: &GpuContext,
    harness: &BvhHarness,
    rays: &[Ray],
    query: Query,
    repeats: u32,
) -> Result<(Vec<Duration>, Option<Duration>)> {
    harness.time(ctx, rays, query, 1)?;
    let before = process_cpu_time();
    let times = harness.time(ctx, rays, query, repeats)?;
    // `time` runs one more dispatch, untimed, first.
    let cpu = before
        .zip(process_cpu_time())
        .map(|(a, b)| (b - a) / (repeats.max(1) + 1));
    Ok((times, cpu))
}

/// The median and best of sorted times, as rates, and the rate per
/// CPU-second.
fn rates(rays: usize, (sorted, cpu): &(Vec<Duration>, Option<Duration>)) -> String {
    let per_cpu = cpu.map_or(String::new(), |cpu| {
        format!(
            ", {:.3} Mrays per CPU-second",
            rays as f64 / cpu.as_secs_f64() / 1e6
        )
    });
    format!(
        "{}, best {}{per_cpu}",
        rate(rays, sorted[sorted.len() / 2]),
        rate(rays, sorted[0])
    )
}

pub fn run(args: &BvhBenchArgs) -> Result<()> {
    ensure!(args.triangles > 0, "--triangles must be at least 1");
    let start = Instant::now();
    let mesh = bumpy_sphere(args.triangles);
    let triangles = mesh.triangles();
    println!(
        "mesh: bumpy sphere, {} triangles, {} vertices (generated in {:.0} ms)",
        triangles.len(),
        mesh.positions.len(),
        start.elapsed().as_secs_f64() * 1e3
    );
    let bvh = Bvh::build(&triangles);
    let s = &bvh.stats;
    println!(
        "bvh: {} triangles, {} nodes, {} leaves, max depth {}, SAH cost {:.2}, built in {:.0} ms (1 thread)",
        s.triangles,
        s.nodes,
        s.leaves,
        s.max_depth,
        s.sah_cost,
        s.build_time.as_secs_f64() * 1e3
    );
    if args.build_only {
        return Ok(());
    }
    let ordered = bvh.reorder(&triangles);
    let ctx = GpuContext::headless()?;
    println!("adapter: {}", ctx.describe());
    let verts: Vec<TriangleVerts> = ordered.iter().map(TriangleVerts::new).collect();
    let harness = BvhHarness::new(&ctx, &bvh.nodes, &verts)?;
    println!(
        "{} rays per dispatch; median and best of {} dispatches, wall clock (dispatch + wait)",
        args.rays, args.repeats
    );
    for (name, rays) in [
        ("camera", camera_rays(args.rays)),
        ("scattered", scattered_rays(args.rays)),
    ] {
        let hits = harness.closest(&ctx, &rays)?;
        let hit_count = hits.iter().filter(|h| h.is_some()).count();
        let closest = measure(&ctx, &harness, &rays, Query::Closest, args.repeats)?;
        let occluded = measure(&ctx, &harness, &rays, Query::Occluded, args.repeats)?;
        // The CPU on one thread, on every k-th ray, for scale.
        let stride = rays.len().div_ceil(100_000);
        let sample: Vec<(usize, &Ray)> = rays.iter().enumerate().step_by(stride).collect();
        let start = Instant::now();
        let cpu_hits = sample
            .iter()
            .filter(|(_, r)| {
                bvh.intersect(&ordered, r.origin, r.direction, r.t_max)
                    .is_some()
            })
            .count();
        let cpu = start.elapsed();
        println!(
            "{name} rays ({:.1} % hit):\n  GPU closest   {}\n  GPU occluded  {}\n  CPU closest, 1 thread, {} rays: {}",
            100.0 * hit_count as f64 / rays.len() as f64,
            rates(rays.len(), &closest),
            rates(rays.len(), &occluded),
            sample.len(),
            rate(sample.len(), cpu),
        );
        let gpu_sample_hits = sample.iter().filter(|(i, _)| hits[*i].is_some()).count();
        if gpu_sample_hits != cpu_hits {
            println!(
                "  warning: of the CPU's sample the GPU hit {gpu_sample_hits}, the CPU {cpu_hits}"
            );
        }
    }
    Ok(())
}
