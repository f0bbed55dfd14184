// The texture library's patterns; twin of crates/core/src/texture/*.rs
// (the CPU reference).
// Each is a pure function of a point and its parameters: where the point
// falls (which child, which cell-local point). Each pattern is compiled in
// only when the scene uses it (its PATTERN_* feature).

#import shaders/common.wgsl
#import crates/core/src/noise/fractal.wgsl

// Where a 2D point falls in a board of cells: `select` 0 for the first
// child, 1 for the second, and the point in the cell's own [0, 1)² space.
struct Cell {
    select: f32,
    local: vec2f,
}

// 1 for an odd integer, 0 for an even one (any sign).
fn odd(n: f32) -> f32 {
    return n - 2.0 * floor(n * 0.5);
}

#if PATTERN_CHECKER_2D
fn checker_2d(uv: vec2f, size: vec2f, phase: f32) -> Cell {
    let row = floor(uv.y / size.y);
    let x = uv.x / size.x + phase * odd(row);
    let column = floor(x);
    return Cell(odd(column + row), vec2f(x - column, uv.y / size.y - row));
}
#endif

#if PATTERN_CHECKER
fn checker_3d(p: vec3f, size: vec3f) -> f32 {
    let c = floor(p / size);
    return odd(c.x + c.y + c.z);
}

// The 3D checker box-filtered over p ± half_width (per axis): the XOR of
// three square waves is odd with probability (1 - Π(1 - 2s)) / 2.
fn filtered_checker_3d(p: vec3f, size: vec3f, half_width: vec3f) -> f32 {
    let q = p / size;
    let w = half_width / size;
    let s = vec3f(odd_fraction(q.x, w.x), odd_fraction(q.y, w.y), odd_fraction(q.z, w.z));
    return 0.5 * (1.0 - (1.0 - 2.0 * s.x) * (1.0 - 2.0 * s.y) * (1.0 - 2.0 * s.z));
}
#endif

#if PATTERN_CHECKER_2D || PATTERN_CHECKER
// How much of [0, x] lies in odd unit cells.
fn odd_measure(x: f32) -> f32 {
    let half = floor(x * 0.5);
    return half + 2.0 * max(x * 0.5 - half - 0.5, 0.0);
}

fn odd_fraction(x: f32, w: f32) -> f32 {
    if w <= 0.0 {
        return odd(floor(x));
    }
    return (odd_measure(x + w) - odd_measure(x - w)) / (2.0 * w);
}
#endif

#if PATTERN_CHECKER_2D

// The checker box-filtered over uv ± half_width, in closed form.
fn filtered_checker_2d(uv: vec2f, size: vec2f, phase: f32, half_width: vec2f) -> f32 {
    let row = floor(uv.y / size.y);
    let x = uv.x / size.x + phase * odd(row);
    let sx = odd_fraction(x, half_width.x / size.x);
    let sy = odd_fraction(uv.y / size.y, half_width.y / size.y);
    return sx + sy - 2.0 * sx * sy;
}
#endif

#if PATTERN_BRICK
fn brick(uv: vec2f, size: vec2f, mortar: f32, row_offset: f32) -> Cell {
    let row = floor(uv.y / size.y);
    let x = uv.x / size.x + row_offset * odd(row);
    let local = vec2f(x - floor(x), uv.y / size.y - row);
    let from_edge = min(local, 1.0 - local) * size;
    let on_brick = from_edge.x >= 0.5 * mortar && from_edge.y >= 0.5 * mortar;
    return Cell(select(0.0, 1.0, on_brick), local);
}
#endif

#if PATTERN_TILE
struct TileSample {
    select: f32,
    height_gradient: vec2f,
}

fn tile(uv: vec2f, mortar_half_width: f32, bevel_width: f32, bevel_height: f32) -> TileSample {
    let local = uv - floor(uv);
    let inward = select(vec2f(-1.0), vec2f(1.0), local < vec2f(0.5));
    let from_edge = min(local, 1.0 - local);
    let nearest = min(from_edge.x, from_edge.y);
    let on_tile = nearest >= mortar_half_width;
    let on_bevel = on_tile && nearest < mortar_half_width + bevel_width && bevel_width > 0.0;
    let slope = bevel_height / max(bevel_width, 1e-30);
    let along_u = from_edge.x <= from_edge.y;
    let gradient = select(vec2f(0.0, slope * inward.y), vec2f(slope * inward.x, 0.0), along_u);
    return TileSample(select(0.0, 1.0, on_tile), select(vec2f(0.0), gradient, on_bevel));
}

// The tile's height profile: 0 in the mortar, rising over the bevel to 1.
fn tile_height(uv: vec2f, mortar_half_width: f32, bevel_width: f32) -> f32 {
    let local = uv - floor(uv);
    let from_edge = min(local, 1.0 - local);
    let rise = min(from_edge.x, from_edge.y) - mortar_half_width;
    let ramp = select(1.0, rise / bevel_width, rise < bevel_width);
    return select(ramp, 0.0, rise < 0.0);
}
#endif

#if PATTERN_CUTOUT
fn cutout(uv: vec2f, sides: u32, radius: f32) -> f32 {
    let q = uv - floor(uv) - 0.5;
    let r = length(q);
    if sides < 3u {
        return select(0.0, 1.0, r <= radius);
    }
    let sector = TWO_PI / f32(sides);
    let angle = atan2(q.y, q.x);
    let folded = angle - sector * floor(angle / sector) - 0.5 * sector;
    let apothem = radius * cos(PI / f32(sides));
    return select(0.0, 1.0, r * cos(folded) <= apothem);
}
#endif

#if PATTERN_WOOD
// The report's ring axis: tilted 15° from z towards x (texture::default_axis).
const WOOD_AXIS = vec3f(0.25881904, 0.0, 0.9659258);

fn wood(p: vec3f, axis: vec3f, ring_width: f32, turbulence_amount: f32, n: NoiseParams) -> f32 {
    return wood_rings(p, axis, ring_width, turbulence_amount * turbulence(p, n));
}

// wood() given its radius perturbation, shared as a signal by the renderer.
fn wood_rings(p: vec3f, axis: vec3f, ring_width: f32, perturbation: f32) -> f32 {
    let radius = length(p - dot(p, axis) * axis);
    return odd(floor((radius + perturbation) / ring_width));
}
#endif

#if PATTERN_WAVES
fn waves(uv: vec2f, frequency: f32, direction: vec2f) -> f32 {
    return 0.5 + 0.5 * sin(TWO_PI * frequency * dot(direction, uv));
}
#endif

#if PATTERN_VEINS
fn marble_veins(p: vec3f, axis: vec3f, frequency: f32, turbulence_amount: f32, n: NoiseParams) -> f32 {
    return max(sin(frequency * dot(axis, p) + turbulence_amount * turbulence(p, n)), 0.0);
}
#endif

#if PATTERN_MASSAL_MARBLE
// Massal's marble given the turbulence at p: 0.5 sin((x + y) f + T) + 0.5
// (marble.rs's massal_marble_stripes).
fn massal_marble(p: vec3f, stripe_frequency: f32, turbulence_value: f32) -> f32 {
    return 0.5 * sin((p.x + p.y) * stripe_frequency + turbulence_value) + 0.5;
}
#endif

#if PATTERN_DIAGONAL
// Twin of diagonal.rs: the report's `u < v` example, 0 above the diagonal.
fn diagonal(uv: vec2f) -> f32 {
    return select(1.0, 0.0, uv.x < uv.y);
}
#endif
