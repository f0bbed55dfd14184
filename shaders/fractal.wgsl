// Fractal sums; twin of src/noise/fractal.rs.

struct NoiseParams {
    kind: u32,        // 0 gradient, 1 Perlin
    hash: u32,        // 0 pcg3d, 1 sin
    octaves: f32,
    frequency: f32,
    amplitude: f32,
    persistence: f32,
    lacunarity: f32,
    _pad: f32,
}

const MAX_OCTAVES: f32 = 16.0;

fn lattice_noise(p: vec3f, kind: u32, hash: u32) -> f32 {
#if NOISE_PERLIN
    if kind == 1u {
        return perlin_noise(p);
    }
#endif
#if NOISE_GRADIENT
    return gradient_noise(p, hash);
#else
    return 0.0;
#endif
}

fn fractal_sum(p: vec3f, n: NoiseParams, absolute: bool) -> f32 {
    let octaves = clamp(n.octaves, 0.0, MAX_OCTAVES);
    let whole = u32(ceil(octaves));
    var frequency = n.frequency;
    var amplitude = n.amplitude;
    var sum = 0.0;
    for (var i = 0u; i < whole; i++) {
        let weight = min(octaves - f32(i), 1.0);
        var v = lattice_noise(p * frequency, n.kind, n.hash);
        if absolute {
            v = abs(v);
        }
        sum += weight * amplitude * v;
        frequency *= n.lacunarity;
        amplitude *= n.persistence;
    }
    return sum;
}

fn fbm(p: vec3f, n: NoiseParams) -> f32 {
    return fractal_sum(p, n, false);
}

fn turbulence(p: vec3f, n: NoiseParams) -> f32 {
    return fractal_sum(p, n, true);
}

fn marble(p: vec3f, n: NoiseParams, stripe_frequency: f32) -> f32 {
    return sin(p.x * stripe_frequency + fbm(p, n));
}
