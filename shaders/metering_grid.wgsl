// The grid of texels a metering pass reads: at most GRID × GRID texels
// spread evenly over the traced region, reduced by one workgroup of
// WORKGROUP invocations. Shared by auto_exposure.wgsl and
// error_meter.wgsl; the CPU twin is metering_grid.rs.

const GRID: u32 = 256u;
const WORKGROUP: u32 = 256u;

// The traced region of the accumulation texture, in texels, and how many
// texels are read along each axis: min(region, GRID).
struct MeteringGrid {
    region: vec2u,
    grid: vec2u,
}

// The texel under the centre of grid cell `i` of `grid` cells spanning
// `size` texels: floor((i + 0.5) * size / grid), in integers. With
// grid == size it is i: every texel.
fn grid_texel(i: u32, grid: u32, size: u32) -> u32 {
    return ((2u * i + 1u) * size) / (2u * grid);
}

// The texel of the k-th grid cell, row by row.
fn grid_cell_texel(k: u32, g: MeteringGrid) -> vec2u {
    let cell = vec2u(k % g.grid.x, k / g.grid.x);
    return vec2u(grid_texel(cell.x, g.grid.x, g.region.x), grid_texel(cell.y, g.grid.y, g.region.y));
}
