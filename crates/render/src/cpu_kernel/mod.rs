//! The CPU kernel (issue 33): the trace of shaders/trace.wgsl in Rust, on
//! the machine's cores (rayon), for machines whose only adapter is a CPU
//! emulating a GPU (lavapipe, CI runners, render-farm nodes). On lavapipe
//! the WGSL kernels run 8 lanes in lock step, every branch under a mask,
//! and every storage read whose index differs between lanes as a loop of
//! scalar loads (accel/traverse.wgsl): a path tracer's divergent lanes pay
//! for all of that. Native code pays for none of it.
//!
//! It traces a band's samples into a buffer, which the renderer uploads
//! and the trace module built with `CPU_SAMPLES` folds into the
//! accumulation exactly as the GPU kernels fold their own (the same
//! running mean, spread, non-finite counts and guides), so everything
//! after the trace (meters, display, denoisers, read-backs, the viewer) is
//! the same code whichever kernel traced.
//!
//! What it traces: [`support`] says (the scenes of OBJ files with their
//! lights and a sky, and procedural textures at points); `auto` offers it
//! only where it does.

mod path;
mod rng;
mod scene;

pub use scene::{CpuScene, support};

use crate::gpu::scene_gpu::{Frame, SAMPLE_SEED_STEP};
use glam::{Vec2, Vec3};
use path::Tracer;
use rayon::prelude::*;
use rng::Rng;

/// What a band of samples leaves for the GPU: three blocks of the band's
/// rows, one `[f32; 4]` per pixel each: the mean of the pixel's finite
/// samples and its NaN count, the albedo guide and its infinite count,
/// the normal guide (`cpu_samples` in shaders/trace.wgsl).
pub const BLOCKS: u32 = 3;

/// Traces rows `frame.band_start .. frame.band_end` of a target
/// `frame.render_size[0]` wide: `frame.samples_per_frame` samples a pixel,
/// seeded as the GPU kernels seed them. Returns [`BLOCKS`] blocks of
/// `width × rows` texels.
pub fn trace_band(scene: &CpuScene, frame: &Frame) -> Vec<[f32; 4]> {
    let width = frame.render_size[0] as usize;
    let rows = frame.band_end.saturating_sub(frame.band_start) as usize;
    let block = width * rows;
    let mut out = vec![[0.0f32; 4]; BLOCKS as usize * block];
    let (radiance, guides) = out.split_at_mut(block);
    let (albedo, normal) = guides.split_at_mut(block);
    let tracer = Tracer { scene, frame };
    radiance
        .par_chunks_mut(width)
        .zip(albedo.par_chunks_mut(width))
        .zip(normal.par_chunks_mut(width))
        .enumerate()
        .for_each(|(row, ((radiance, albedo), normal))| {
            let y = frame.band_start + row as u32;
            for x in 0..width {
                let texels = trace_pixel(&tracer, (x as u32, y));
                radiance[x] = texels[0];
                albedo[x] = texels[1];
                normal[x] = texels[2];
            }
        });
    out
}

/// `trace_pixel`'s samples: their mean (non-finite ones dropped and
/// counted), the firefly clamp, and the guides' means.
fn trace_pixel(tracer: &Tracer, pixel: (u32, u32)) -> [[f32; 4]; 3] {
    let frame = tracer.frame;
    let spp = frame.samples_per_frame.max(1);
    let image_pixel = (
        pixel.0 + frame.crop_origin[0],
        pixel.1 + frame.crop_origin[1],
    );
    let (mut sum, mut albedo, mut normal) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    let (mut nan, mut infinite) = (0u32, 0u32);
    for k in 0..spp {
        let seed = frame
            .accumulated
            .wrapping_add(k)
            .wrapping_mul(SAMPLE_SEED_STEP)
            .wrapping_add(frame.frame_index);
        let mut rng = Rng::seeded(image_pixel, seed);
        let jitter = Vec2::new(rng.next(), rng.next());
        let position = Vec2::new(image_pixel.0 as f32, image_pixel.1 as f32) + jitter;
        let sample = tracer.trace_path(position, &mut rng);
        albedo += sample.albedo / spp as f32;
        normal += sample.normal / spp as f32;
        let mut l = sample.radiance;
        let brightest = l.max_element();
        if frame.sample_clamp > 0.0 && brightest > frame.sample_clamp {
            l *= frame.sample_clamp / brightest;
        }
        if !l.is_finite() {
            if l.is_nan() {
                nan += 1;
            } else {
                infinite += 1;
            }
        } else {
            sum += l / spp as f32;
        }
    }
    [
        sum.extend(nan as f32).to_array(),
        albedo.extend(infinite as f32).to_array(),
        normal.extend(0.0).to_array(),
    ]
}
