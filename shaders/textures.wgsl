// Procedural textures: each pattern gives a blend factor t in [0, 1] between
// the texture's two values. Patterns the scene does not use are compiled out.
//
// The fractal sums, the expensive part, are evaluated once per hit as the
// material's noise signals (deduplicated on the CPU), outside any pattern
// branch. SIMD hardware runs every branch some lane takes under a mask
// (lavapipe runs every branch, taken or not), so a sum written inside each
// pattern's case would be paid for by every pattern in the scene.

#if NOISE
// The material's signals, ordered by kind on the CPU: gradient noise ones
// first, then Perlin ones from `first_perlin` on. Each kind's loop holds only
// its own noise, so a hit pays for Perlin octaves only where some lane reads
// a Perlin signal.
fn material_signals(material: u32, p: vec3f) -> vec3f {
    var values = vec3f(0.0);
    let count = min(materials[material].signal_count, MAX_SIGNALS);
    let first_perlin = min(materials[material].first_perlin, count);
#if NOISE_GRADIENT
    for (var k = 0u; k < first_perlin; k++) {
        values[k] = fractal_sum_gradient(p, materials[material].signals[k]);
    }
#endif
#if NOISE_PERLIN
    for (var k = first_perlin; k < count; k++) {
        values[k] = fractal_sum_perlin(p, materials[material].signals[k]);
    }
#endif
    return values;
}
#endif

fn pattern_t(t: Texture, p: vec3f, signals: vec3f) -> f32 {
    let n = signals[min(t.signal, MAX_SIGNALS - 1u)];
    switch t.kind {
#if PATTERN_CHECKER
        case 1u: {
            let c = floor(p / t.param);
            return f32(i32(c.x + c.y + c.z) & 1);
        }
#endif
#if PATTERN_FBM
        case 2u: {
            return clamp(0.5 + 0.5 * n, 0.0, 1.0);
        }
#endif
#if PATTERN_TURBULENCE
        case 3u: {
            return clamp(n, 0.0, 1.0);
        }
#endif
#if PATTERN_MARBLE
        case 4u: {
            return 0.5 + 0.5 * marble_stripes(p.x, n, t.param);
        }
#endif
        default: {
            return 0.0;
        }
    }
}

fn eval_color(t: Texture, p: vec3f, signals: vec3f) -> vec3f {
    return mix(t.a.xyz, t.b.xyz, pattern_t(t, p, signals));
}

fn eval_scalar(t: Texture, p: vec3f, signals: vec3f) -> f32 {
    return mix(t.a.x, t.b.x, pattern_t(t, p, signals));
}
