// Radiance arriving from direction d out of the scene.

#if ENV_MAP
#import crates/core/src/envmap.wgsl
#endif

#if ENV_MAP
@group(0) @binding(3) var env_texture: texture_2d<f32>;
@group(0) @binding(4) var env_sampler: sampler;
#endif

fn environment(d: vec3f) -> vec3f {
#if ENV_MAP
    if frame.env_kind == 2u {
        let uv = env_uv(rotate_y(d, frame.env_rotation));
        // The image's first row is the top (v = 1 in the lab's convention).
        let texel = textureSampleLevel(env_texture, env_sampler, vec2f(uv.x, 1.0 - uv.y), 0.0).rgb;
        return texel * frame.env_intensity;
    }
#endif
#if ENV_CONSTANT
    if frame.env_kind == 1u {
        return frame.env_constant * frame.env_intensity;
    }
#endif
    return vec3f(0.0);
}
