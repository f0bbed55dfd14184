// Sampling the light table (Rust: lights::LightTable): choose a light,
// uniformly or by power, then a point on it: the point light itself, a
// sphere by the solid angle it subtends, a triangle uniformly by area.
// Triangles emit on one side, the one their counter-clockwise winding faces
// (as OBJ scenes and Mitsuba expect); spheres, like every analytic
// primitive, on both, so a closed emissive sphere lights its inside.

#import shaders/common.wgsl
#import crates/core/src/noise/hash.wgsl
#import shaders/random.wgsl
#if AREA_LIGHT
#import crates/core/src/bsdf.wgsl
#import crates/core/src/geometry/sphere.wgsl
#import crates/core/src/texture/mapping.wgsl
#import shaders/intersect.wgsl
#endif

// The chance of choosing light `index` (Rust: LightTable::pmf).
fn light_pmf(index: u32) -> f32 {
    if frame.light_selection == 0u {
        return 1.0 / f32(frame.light_count);
    }
    return lights[index].power / frame.light_total_power;
}

// The light `u` in [0, 1) picks (Rust: LightTable::choose): by power, the
// first whose cumulative distribution exceeds u, found by bisection.
fn choose_light(u: f32) -> u32 {
    let n = frame.light_count;
    if frame.light_selection == 0u {
        return min(u32(u * f32(n)), n - 1u);
    }
    var lo = 0u;
    var hi = n - 1u;
    loop {
        if lo >= hi {
            break;
        }
        let mid = (lo + hi) / 2u;
        if lights[mid].cdf <= u {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

struct LightSample {
    // From the shading point towards the sampled point.
    wi: vec3f,
    // To the sampled point: the shadow ray's length.
    distance: f32,
    // The emitted radiance towards the shading point (a point light: its
    // intensity over the squared distance).
    radiance: vec3f,
    // The solid-angle density of wi, times the chance of the light's
    // choice; 0 when there is no sample.
    pdf: f32,
    // A point light: no other strategy can reach it, so it takes no MIS.
    delta: bool,
}

// 1 - cos θmax of the cone a sphere of squared radius r2 subtends at
// squared distance d2 (> r2), as sin² / (1 + cos): no cancellation for
// small, far spheres.
fn sphere_cone(r2: f32, d2: f32) -> f32 {
    let sin2 = r2 / d2;
    return sin2 / (1.0 + sqrt(max(0.0, 1.0 - sin2)));
}

#if AREA_LIGHT
// The solid-angle density with which sampling sphere `index` from `x`
// gives the point `y` on it: uniform over its cone from outside, uniform
// by area from inside.
fn sphere_light_pdf(index: u32, x: vec3f, y: vec3f) -> f32 {
    let s = spheres[index];
    let to_c = s.center - x;
    let d2 = dot(to_c, to_c);
    let r2 = s.radius * s.radius;
    if d2 > r2 {
        return 1.0 / (TWO_PI * sphere_cone(r2, d2));
    }
    let to_y = y - x;
    let cos_l = abs(dot(normalize(y - s.center), normalize(to_y)));
    return select(0.0, dot(to_y, to_y) / (4.0 * PI * r2 * cos_l), cos_l > 0.0);
}
#endif

// Where light samples lie on their light (Rust: scene::LightPoints).
const LIGHT_POINTS_CENTROID: u32 = 1u;
const LIGHT_POINTS_FIXED_SET: u32 = 2u;
// The fixed set's seed: any constant, the same for every pixel and frame.
const FIXED_SET_SEED: u32 = 0x51ED270Bu;

// The three numbers of light sample `k` of a shading point: the light's
// choice, then two for the point on it. Always drawn from the pixel's
// sequence, so every mode leaves the rest of the path's numbers as they
// were; the fixed set then replaces them by numbers of k alone.
fn light_numbers(k: u32) -> vec3f {
    let u = vec3f(rand(), rand(), rand());
    if frame.light_points == LIGHT_POINTS_FIXED_SET {
        return vec3f(pcg3d(vec3u(k, FIXED_SET_SEED, 0u)) >> vec3u(8u)) * (1.0 / 16777216.0);
    }
    return u;
}

// Light sample `k` of the shading point `x`.
fn sample_light(x: vec3f, k: u32) -> LightSample {
    var out: LightSample;
    out.pdf = 0.0;
    out.delta = false;
    let u = light_numbers(k);
#if AREA_LIGHT
    let index = choose_light(u.x);
    let pmf = light_pmf(index);
    let light = lights[index];
#else
    // The point light is the only light: no table to read.
    let pmf = 1.0;
    let light = Light(0u, 0u, 1.0, 1.0);
#endif
    // The centroid mode's fixed point: the middle of the sphere's cone (the
    // point facing x) or the triangle's barycentre (1/3, 1/3, 1/3), which
    // √u1 = 2/3, u2 = 1/2 give below.
    let centroid = frame.light_points == LIGHT_POINTS_CENTROID;
    let u1 = select(u.y, select(0.0, 4.0 / 9.0, light.kind == 2u), centroid);
    let u2 = select(u.z, 0.5, centroid);
#if POINT_LIGHT
    if light.kind == 0u {
        let to_light = frame.light_pos - x;
        let d2 = dot(to_light, to_light);
        out.distance = sqrt(d2);
        out.wi = to_light / out.distance;
        out.radiance = frame.light_power / d2;
        out.pdf = pmf;
        out.delta = true;
    }
#endif
#if AREA_LIGHT
    if light.kind == 1u {
        let s = spheres[light.primitive];
        let to_c = s.center - x;
        let d2 = dot(to_c, to_c);
        let r2 = s.radius * s.radius;
        let cone = sphere_cone(r2, d2);
        // cos θ = 1 - u1 (1 - cos θmax); sin² θ from the same product.
        let k = u1 * cone;
        let cos_t = 1.0 - k;
        let sin_t = sqrt(max(0.0, k * (2.0 - k)));
        let phi = TWO_PI * u2;
        let wi = basis(to_c * inverseSqrt(d2)) * vec3f(sin_t * cos(phi), sin_t * sin(phi), cos_t);
        let t = intersect_sphere(x, wi, s);
        if d2 > r2 && t < NO_HIT {
            let dir = normalize(x + t * wi - s.center);
            let y = s.center + dir * s.radius;
            out.wi = wi;
            out.distance = t;
            out.radiance = surface_emission(light.primitive, y - s.center, y, sphere_uv(dir));
            out.pdf = pmf / (TWO_PI * cone);
        }
        if d2 <= r2 {
            // From inside, the whole sphere is in view: a point uniform by area.
            let z = 1.0 - 2.0 * u1;
            let ring = sqrt(max(0.0, 1.0 - z * z));
            let dir = vec3f(ring * cos(phi), ring * sin(phi), z);
            let y = s.center + dir * s.radius;
            let to_y = y - x;
            let distance = length(to_y);
            let wi_inside = to_y / distance;
            let cos_l = abs(dot(dir, wi_inside));
            if distance > 0.0 && cos_l > 0.0 {
                out.wi = wi_inside;
                out.distance = distance;
                out.radiance = surface_emission(light.primitive, y - s.center, y, sphere_uv(dir));
                out.pdf = pmf * distance * distance / (4.0 * PI * r2 * cos_l);
            }
        }
    }
#if MESH
    if light.kind == 2u {
        let tri = mesh_triangles[light.primitive];
        let e1 = tri.v1.xyz - tri.v0.xyz;
        let e2 = tri.v2.xyz - tri.v0.xyz;
        let c = cross(e1, e2);
        let twice_area = length(c);
        // Uniform by area: barycentrics (1 - √u1, √u1 (1 - u2), √u1 u2).
        let su = sqrt(u1);
        let w1 = su * (1.0 - u2);
        let w2 = su * u2;
        let y = tri.v0.xyz + w1 * e1 + w2 * e2;
        let to_y = y - x;
        let d2 = dot(to_y, to_y);
        let distance = sqrt(d2);
        let wi = to_y / distance;
        let cos_l = -dot(c, wi) / twice_area;
        if cos_l > 0.0 && twice_area > 0.0 {
            let a = mesh_attributes[light.primitive];
            let uv = (1.0 - w1 - w2) * a.uv01.xy + w1 * a.uv01.zw + w2 * a.uv2;
            out.wi = wi;
            out.distance = distance;
            out.radiance = surface_emission(a.material, y, y, uv);
            out.pdf = pmf * d2 / (0.5 * twice_area * cos_l);
        }
    }
#endif
#endif
    return out;
}

#if AREA_LIGHT
// The density with which light sampling from `x` would have produced the
// point `hit` reached by a BSDF ray: the choice of its light times the
// solid-angle density on it; 0 for surfaces that are not in the table.
fn emitter_pdf(hit: Hit, x: vec3f) -> f32 {
    let emitted = materials[hit.material].emitted_luminance;
    if emitted <= 0.0 || frame.light_count == 0u {
        return 0.0;
    }
    var power_area = 0.0;
    var solid_angle_pdf = 0.0;
    if hit.shape == SHAPE_SPHERE {
        let r = spheres[hit.index].radius;
        power_area = 4.0 * PI * r * r;
        solid_angle_pdf = sphere_light_pdf(hit.index, x, hit.p);
    }
#if MESH
    if hit.shape == SHAPE_TRIANGLE {
        let tri = mesh_triangles[hit.index];
        let c = cross(tri.v1.xyz - tri.v0.xyz, tri.v2.xyz - tri.v0.xyz);
        let area = 0.5 * length(c);
        let to_hit = hit.p - x;
        let cos_l = abs(dot(c, to_hit)) / (2.0 * area * length(to_hit));
        power_area = area;
        solid_angle_pdf = select(0.0, dot(to_hit, to_hit) / (area * cos_l), area > 0.0 && cos_l > 0.0);
    }
#endif
    var pmf = 1.0 / f32(frame.light_count);
    if frame.light_selection != 0u {
        pmf = PI * emitted * power_area / frame.light_total_power;
    }
    return pmf * solid_angle_pdf;
}
#endif
