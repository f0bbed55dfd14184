// Procedural textures: each pattern gives a blend factor t in [0, 1] between
// the texture's two values. Patterns the scene does not use are compiled out.

fn texture_noise(t: Texture) -> NoiseParams {
    return NoiseParams(t.noise_kind, t.hash, t.octaves, t.frequency, t.amplitude, t.persistence, t.lacunarity, 0.0);
}

fn pattern_t(t: Texture, p: vec3f) -> f32 {
    switch t.kind {
#if PATTERN_CHECKER
        case 1u: {
            let c = floor(p / t.param);
            return f32(i32(c.x + c.y + c.z) & 1);
        }
#endif
#if PATTERN_FBM
        case 2u: {
            return clamp(0.5 + 0.5 * fbm(p, texture_noise(t)), 0.0, 1.0);
        }
#endif
#if PATTERN_TURBULENCE
        case 3u: {
            return clamp(turbulence(p, texture_noise(t)), 0.0, 1.0);
        }
#endif
#if PATTERN_MARBLE
        case 4u: {
            return 0.5 + 0.5 * marble(p, texture_noise(t), t.param);
        }
#endif
        default: {
            return 0.0;
        }
    }
}

fn eval_color(t: Texture, p: vec3f) -> vec3f {
    return mix(t.a.xyz, t.b.xyz, pattern_t(t, p));
}

fn eval_scalar(t: Texture, p: vec3f) -> f32 {
    return mix(t.a.x, t.b.x, pattern_t(t, p));
}
