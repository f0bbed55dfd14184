//! The grid of texels the metering passes read (auto exposure, the error
//! meter): every texel of the traced region up to [`GRID`] per axis, a
//! centred strided grid beyond, so one workgroup meters any image size in
//! bounded time. The CPU twin of `shaders/metering_grid.wgsl`.

use bytemuck::{Pod, Zeroable};

/// At most this many texels are metered along each axis.
pub const GRID: u32 = 256;

/// `MeteringGrid` in `shaders/metering_grid.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct MeteringGrid {
    pub region: [u32; 2],
    pub grid: [u32; 2],
}

impl MeteringGrid {
    /// The grid over a traced `region` (texels from the origin).
    pub fn over(region: (u32, u32)) -> Self {
        let region = (region.0.max(1), region.1.max(1));
        let (gw, gh) = grid_size(region);
        Self {
            region: [region.0, region.1],
            grid: [gw, gh],
        }
    }
}

/// How many texels are metered along each axis of a `region`.
pub fn grid_size(region: (u32, u32)) -> (u32, u32) {
    (region.0.clamp(1, GRID), region.1.clamp(1, GRID))
}

/// The texel under the centre of cell `i` of `grid` cells spanning `size`
/// texels (`grid_texel` in the shader).
fn grid_texel(i: u32, grid: u32, size: u32) -> u32 {
    ((2 * i + 1) * size) / (2 * grid)
}

/// The pixels of a `size` image (row-major) that the GPU meters.
pub fn grid_pixels(pixels: &[[f32; 4]], size: (u32, u32)) -> Vec<[f32; 4]> {
    let (gw, gh) = grid_size(size);
    let mut out = Vec::with_capacity((gw * gh) as usize);
    for gy in 0..gh {
        let y = grid_texel(gy, gh, size.1);
        for gx in 0..gw {
            let x = grid_texel(gx, gw, size.0);
            out.push(pixels[(y * size.0 + x) as usize]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_is_every_pixel_up_to_its_size_and_strided_beyond() {
        let pixels: Vec<[f32; 4]> = (0..200 * 3).map(|i| [i as f32; 4]).collect();
        assert_eq!(grid_pixels(&pixels, (200, 3)), pixels);
        let (w, h) = (1000, 300);
        let pixels: Vec<[f32; 4]> = (0..w * h)
            .map(|i| [(i % w) as f32, (i / w) as f32, 0.0, 0.0])
            .collect();
        let grid = grid_pixels(&pixels, (w, h));
        assert_eq!(grid.len(), (GRID * GRID) as usize);
        let xs: Vec<f32> = grid[..GRID as usize].iter().map(|p| p[0]).collect();
        // Centred cells: the first and last texels sit half a cell in.
        assert_eq!(xs[0], 1.0);
        assert_eq!(xs[GRID as usize - 1], 998.0);
        assert!(xs.windows(2).all(|p| p[1] > p[0]));
        let ys: Vec<f32> = grid.iter().step_by(GRID as usize).map(|p| p[1]).collect();
        assert_eq!((ys[0], ys[GRID as usize - 1]), (0.0, 299.0));
        assert!(ys.windows(2).all(|p| p[1] > p[0]));
    }

    #[test]
    fn the_shader_grid_is_the_cpu_twin() {
        let source = crate::gpu::shader_source::renderer_files::METERING_GRID.text;
        assert!(source.contains(&format!("const GRID: u32 = {GRID}u;")));
    }
}
