// The texture library's patterns; twin of src/texture/ (the CPU reference).
// Each is a pure function of a point and its parameters: where the point
// falls (which child, which cell-local point) or how the surface tilts.

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

fn checker_2d(uv: vec2f, size: vec2f, phase: f32) -> Cell {
    let row = floor(uv.y / size.y);
    let x = uv.x / size.x + phase * odd(row);
    let column = floor(x);
    return Cell(odd(column + row), vec2f(x - column, uv.y / size.y - row));
}

fn checker_3d(p: vec3f, size: vec3f) -> f32 {
    let c = floor(p / size);
    return odd(c.x + c.y + c.z);
}

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

// The checker box-filtered over uv ± half_width, in closed form.
fn filtered_checker_2d(uv: vec2f, size: vec2f, phase: f32, half_width: vec2f) -> f32 {
    let row = floor(uv.y / size.y);
    let x = uv.x / size.x + phase * odd(row);
    let sx = odd_fraction(x, half_width.x / size.x);
    let sy = odd_fraction(uv.y / size.y, half_width.y / size.y);
    return sx + sy - 2.0 * sx * sy;
}

fn brick(uv: vec2f, size: vec2f, mortar: f32, row_offset: f32) -> Cell {
    let row = floor(uv.y / size.y);
    let x = uv.x / size.x + row_offset * odd(row);
    let local = vec2f(x - floor(x), uv.y / size.y - row);
    let from_edge = min(local, 1.0 - local) * size;
    let on_brick = from_edge.x >= 0.5 * mortar && from_edge.y >= 0.5 * mortar;
    return Cell(select(0.0, 1.0, on_brick), local);
}

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

fn wood(p: vec3f, axis: vec3f, ring_width: f32, turbulence_amount: f32, n: NoiseParams) -> f32 {
    let radius = length(p - dot(p, axis) * axis);
    let perturbed = radius + turbulence_amount * turbulence(p, n);
    return odd(floor(perturbed / ring_width));
}

fn marble_veins(p: vec3f, axis: vec3f, frequency: f32, turbulence_amount: f32, n: NoiseParams) -> f32 {
    return max(sin(frequency * dot(axis, p) + turbulence_amount * turbulence(p, n)), 0.0);
}

fn waves_gradient(uv: vec2f, frequency: f32, amplitude: f32, direction: vec2f) -> vec2f {
    let phase = TWO_PI * frequency * dot(direction, uv);
    return amplitude * TWO_PI * frequency * cos(phase) * direction;
}

fn bump_along(dp: vec3f, dh: f32) -> vec3f {
    let len2 = dot(dp, dp);
    return select(vec3f(0.0), dp * (dh / len2), len2 > 0.0);
}

// Blinn's bump: the normal tilted by the height gradient over uv; a zero or
// non-finite result (tested on the bits) falls back to the normal.
fn bumped_normal(n: vec3f, dp_du: vec3f, dp_dv: vec3f, dh_du: f32, dh_dv: f32) -> vec3f {
    let tilted = n - bump_along(dp_du, dh_du) - bump_along(dp_dv, dh_dv);
    let len = length(tilted);
    let usable = len > 0.0 && !is_non_finite(len);
    return select(n, tilted / len, usable);
}

// A colour ramp of `count` stops (position in w, colour in xyz), sorted.
const MAX_RAMP_STOPS: u32 = 8u;

fn ramp(stops: array<vec4f, 8>, count: u32, t: f32) -> vec3f {
    let n = min(count, MAX_RAMP_STOPS);
    if n == 0u {
        return vec3f(0.0);
    }
    var color = stops[0].xyz;
    for (var i = 1u; i < n; i++) {
        let a = stops[i - 1u];
        let b = stops[i];
        let span = b.w - a.w;
        let w = select(1.0, (t - a.w) / span, span > 0.0);
        color = select(color, mix(a.xyz, b.xyz, clamp(w, 0.0, 1.0)), t > a.w);
    }
    return color;
}
