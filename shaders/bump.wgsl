// Bump mapping: the material's height texture (generated `surface_height`)
// tilts the shading normal. Its gradient over (u, v) comes from central
// differences, one texel-sized step of 1e-3 in uv; the fractal-sum signals
// are taken at the hit itself, so only the non-noise part of a height field
// bumps (noise bumps need the signals at the offset points: issue 3).

const BUMP_STEP: f32 = 1e-3;

fn bumped_shading_normal(hit: Hit, signals: vec4f) -> vec3f {
    let height = materials[hit.material].bump_height;
    let p = hit.texture_point;
    let du = vec2f(BUMP_STEP, 0.0);
    let dv = vec2f(0.0, BUMP_STEP);
    let dh_du = surface_height(hit.material, p, hit.uv + du, signals)
        - surface_height(hit.material, p, hit.uv - du, signals);
    let dh_dv = surface_height(hit.material, p, hit.uv + dv, signals)
        - surface_height(hit.material, p, hit.uv - dv, signals);
    let scale = height / (2.0 * BUMP_STEP);
    return bumped_normal(hit.n, hit.dp_du, hit.dp_dv, scale * dh_du, scale * dh_dv);
}
