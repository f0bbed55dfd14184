// Fractal sums; twin of fractal.rs.

#import crates/core/src/noise/hash.wgsl
#if NOISE_GRADIENT
#import crates/core/src/noise/gradient.wgsl
#endif
#if NOISE_PERLIN
#import crates/core/src/noise/perlin.wgsl
#endif

struct NoiseParams {
    kind: u32,        // 0 gradient, 1 Perlin
    // Gradient noise: 0 pcg3d, 1 sin, 2 pcg3d tiled every 256 cells.
    // Perlin: 3 for Massal's gradient table, else Perlin's.
    hash: u32,
    octaves: f32,
    frequency: f32,
    amplitude: f32,
    persistence: f32,
    lacunarity: f32,
    // What each octave adds: 0 noise (fBm), 1 |noise| (turbulence),
    // 2 (1 - |noise|)² (ridged).
    shape: u32,
    // Domain warp amount (0: none); compiled in with NOISE_WARP only.
    distortion: f32,
    // Bits (packed so that a material's uniform stays within 64 KiB):
    // NOISE_LINEAR, NOISE_WORLD, NOISE_EVOLVES, and from bit 8 on the w
    // lattice's period in cells while looping (0: none).
    flags: u32,
    // How much the signal's mapping enlarges a footprint.
    footprint_scale: f32,
    // An evolving signal's w at the moment traced (Evolution::w_now).
    w: f32,
}

// 0 geometric progression (lacunarity, persistence), NOISE_LINEAR linear
// (Massal's harmonics: level k = i + 1 at frequency · k, weighted
// amplitude / k).
const NOISE_LINEAR: u32 = 1u;
// The renderer takes the signal at world coordinates, else object ones.
const NOISE_WORLD: u32 = 2u;

fn noise_linear(n: NoiseParams) -> bool {
    return (n.flags & NOISE_LINEAR) != 0u;
}

const MAX_OCTAVES: f32 = 16.0;

#if NOISE_EVOLVE
// The 4D noise at (p, w).
const NOISE_EVOLVES: u32 = 4u;

// The w lattice's period of an evolving signal while looping, 0 without.
fn noise_w_period(n: NoiseParams) -> u32 {
    return n.flags >> 8u;
}

// The w an octave whose frequency is `ratio` times the first's reads:
// w·ratio (Blender's 4D fBm), or while looping w itself, every octave's
// lattice periodic in the loop's cells (fractal.rs's OctaveNoise says why).
fn octave_w(n: NoiseParams, ratio: f32) -> f32 {
    return select(n.w * ratio, n.w, noise_w_period(n) != 0u);
}

// The 4D noise of either kind at (p, w), for the harness.
fn lattice_noise4(p: vec3f, w: f32, kind: u32, hash: u32, period: u32) -> f32 {
#if NOISE_PERLIN
    if kind == 1u {
        return perlin_noise4(p, w, period);
    }
#endif
#if NOISE_GRADIENT
    return gradient_noise4(p, w, hash, period);
#else
    return 0.0;
#endif
}
#endif

// One octave of a signal's noise at q, the octave's frequency `ratio` times
// the first's: 3D, or 4D for an evolving signal.
fn signal_noise(q: vec3f, n: NoiseParams, ratio: f32) -> f32 {
#if NOISE_EVOLVE
    if (n.flags & NOISE_EVOLVES) != 0u {
        return lattice_noise4(q, octave_w(n, ratio), n.kind, n.hash, noise_w_period(n));
    }
#endif
    return lattice_noise(q, n.kind, n.hash);
}

fn lattice_noise(p: vec3f, kind: u32, hash: u32) -> f32 {
#if NOISE_PERLIN
    if kind == 1u {
        return perlin_noise(p, hash == 3u);
    }
#endif
#if NOISE_GRADIENT
    return gradient_noise(p, hash);
#else
    return 0.0;
#endif
}

#if FOOTPRINT
// The octaves a footprint `width` wide resolves; twin of
// noise::footprint_octaves (pbrt's rule, any lacunarity or linear levels).
fn footprint_octaves(n: NoiseParams, width: f32) -> f32 {
    let octaves = clamp(n.octaves, 0.0, MAX_OCTAVES);
    let linear = noise_linear(n);
    if !(width > 0.0 && (n.lacunarity > 1.0 || linear) && n.frequency > 0.0) {
        return octaves;
    }
    var resolved = 0.0;
    if linear {
        resolved = max(0.5 / (n.frequency * width) - 1.0, 0.0);
    } else {
        resolved = max((-1.0 - log2(n.frequency * width)) / log2(n.lacunarity), 0.0);
    }
    let whole = floor(resolved);
    let x = clamp((resolved - whole - 0.3) / 0.4, 0.0, 1.0);
    return min(whole + x * x * (3.0 - 2.0 * x), octaves);
}
#endif

#if FOOTPRINT
// What the octaves past `kept` add on average: for turbulence (shape 1)
// each dropped octave its amplitude times the mean |noise|, so a far
// turbulence fades to its mean rather than to 0 (pbrt's Turbulence); other
// shapes nothing. Twin of noise::dropped_octaves_mean.
fn dropped_octaves_mean(n: NoiseParams, kept: f32) -> f32 {
    if n.shape != 1u {
        return 0.0;
    }
    let octaves = clamp(n.octaves, 0.0, MAX_OCTAVES);
    var frequency = n.frequency;
    var amplitude = n.amplitude;
    var sum = 0.0;
    for (var i = 0u; i < u32(ceil(octaves)); i++) {
        let scales = octave_scales(n, i, frequency, amplitude);
        let full = min(octaves - f32(i), 1.0);
        let shown = clamp(kept - f32(i), 0.0, 1.0);
        sum += (full - shown) * scales.y;
        frequency = scales.x * n.lacunarity;
        amplitude = scales.y * n.persistence;
    }
    // The mean |noise| of the gradient noise and of Perlin's (fractal.rs).
    return sum * select(0.146, 0.220, n.kind == 1u);
}
#endif

// Octave i's frequency and amplitude, given the geometric progression's
// running ones: the linear progression replaces them by frequency · k and
// amplitude / k, k = i + 1.
fn octave_scales(n: NoiseParams, i: u32, frequency: f32, amplitude: f32) -> vec2f {
    let k = f32(i + 1u);
    return select(vec2f(frequency, amplitude), vec2f(n.frequency * k, n.amplitude / k), noise_linear(n));
}

// Octave i's share of the sum, in one place for both kinds' loops: the last,
// fractional octave fades in, and the shape applies.
fn octave_term(v: f32, n: NoiseParams, octaves: f32, i: u32, amplitude: f32) -> f32 {
    let ridge = (1.0 - abs(v)) * (1.0 - abs(v));
    let shaped = select(select(v, abs(v), n.shape == 1u), ridge, n.shape == 2u);
    return min(octaves - f32(i), 1.0) * amplitude * shaped;
}

#if NOISE_WARP
// Offsets that decorrelate the warp's three components (fractal.rs).
const WARP_OFFSET_0 = vec3f(5.2, 1.3, 7.1);
const WARP_OFFSET_1 = vec3f(1.7, 9.2, 3.4);
const WARP_OFFSET_2 = vec3f(8.3, 2.8, 4.9);
#endif

// p moved by the signal's domain warp: three noises at the base frequency.
// Without NOISE_WARP no signal of the scene warps, and p stays.
fn warped(p: vec3f, n: NoiseParams) -> vec3f {
#if NOISE_WARP
    let q = p * n.frequency;
    let w = vec3f(
        signal_noise(q + WARP_OFFSET_0, n, 1.0),
        signal_noise(q + WARP_OFFSET_1, n, 1.0),
        signal_noise(q + WARP_OFFSET_2, n, 1.0),
    );
    return select(p + n.distortion * w, p, n.distortion == 0.0);
#else
    return p;
#endif
}

// One octave loop per noise kind, each calling only its own noise. A loop
// shared by both kinds would hold both noises, and SIMD lanes run both
// whenever either is needed (lavapipe runs every branch): the renderer calls
// each kind's loop only for the signals of that kind.

#if NOISE_GRADIENT
fn fractal_sum_gradient(point: vec3f, n: NoiseParams) -> f32 {
    let p = warped(point, n);
    let octaves = clamp(n.octaves, 0.0, MAX_OCTAVES);
    var frequency = n.frequency;
    var amplitude = n.amplitude;
    var sum = 0.0;
#if NOISE_EVOLVE
    // fᵢ/f₀ beside the frequency, as fractal.rs (not divided: f₀ may be 0).
    var ratio = 1.0;
    let evolves = (n.flags & NOISE_EVOLVES) != 0u;
#endif
    for (var i = 0u; i < u32(ceil(octaves)); i++) {
        let scales = octave_scales(n, i, frequency, amplitude);
#if NOISE_EVOLVE
        ratio = select(ratio, f32(i + 1u), noise_linear(n));
        var v = 0.0;
        if evolves {
            v = gradient_noise4(p * scales.x, octave_w(n, ratio), n.hash, noise_w_period(n));
        } else {
            v = gradient_noise(p * scales.x, n.hash);
        }
        ratio = ratio * n.lacunarity;
#else
        let v = gradient_noise(p * scales.x, n.hash);
#endif
        sum += octave_term(v, n, octaves, i, scales.y);
        frequency = scales.x * n.lacunarity;
        amplitude = scales.y * n.persistence;
    }
    return sum;
}
#endif

#if NOISE_PERLIN
fn fractal_sum_perlin(point: vec3f, n: NoiseParams) -> f32 {
    let p = warped(point, n);
    let octaves = clamp(n.octaves, 0.0, MAX_OCTAVES);
    var frequency = n.frequency;
    var amplitude = n.amplitude;
    var sum = 0.0;
#if NOISE_EVOLVE
    // fᵢ/f₀ beside the frequency, as fractal.rs (not divided: f₀ may be 0).
    var ratio = 1.0;
    let evolves = (n.flags & NOISE_EVOLVES) != 0u;
#endif
    for (var i = 0u; i < u32(ceil(octaves)); i++) {
        let scales = octave_scales(n, i, frequency, amplitude);
#if NOISE_EVOLVE
        ratio = select(ratio, f32(i + 1u), noise_linear(n));
        var v = 0.0;
        if evolves {
            v = perlin_noise4(p * scales.x, octave_w(n, ratio), noise_w_period(n));
        } else {
            v = perlin_noise(p * scales.x, n.hash == 3u);
        }
        ratio = ratio * n.lacunarity;
#else
        let v = perlin_noise(p * scales.x, n.hash == 3u);
#endif
        sum += octave_term(v, n, octaves, i, scales.y);
        frequency = scales.x * n.lacunarity;
        amplitude = scales.y * n.persistence;
    }
    return sum;
}
#endif

// The fractal sum of either kind, for callers that hold one signal.
fn fractal_sum(p: vec3f, n: NoiseParams) -> f32 {
#if NOISE_PERLIN
    if n.kind == 1u {
        return fractal_sum_perlin(p, n);
    }
#endif
#if NOISE_GRADIENT
    return fractal_sum_gradient(p, n);
#else
    return 0.0;
#endif
}

fn fbm(p: vec3f, n: NoiseParams) -> f32 {
    var signed = n;
    signed.shape = 0u;
    return fractal_sum(p, signed);
}

fn turbulence(p: vec3f, n: NoiseParams) -> f32 {
    var absolute = n;
    absolute.shape = 1u;
    return fractal_sum(p, absolute);
}

fn ridged(p: vec3f, n: NoiseParams) -> f32 {
    var ridges = n;
    ridges.shape = 2u;
    return fractal_sum(p, ridges);
}

// The stripes of marble, given the fBm value at the point.
fn marble_stripes(x: f32, fbm_value: f32, stripe_frequency: f32) -> f32 {
    return sin(x * stripe_frequency + fbm_value);
}

fn marble(p: vec3f, n: NoiseParams, stripe_frequency: f32) -> f32 {
    return marble_stripes(p.x, fbm(p, n), stripe_frequency);
}
