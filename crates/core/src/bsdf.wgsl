// Lambert + GGX (Smith, separable) with an optional perfect mirror and a
// diffuse transmission lobe (N3D's TD: Lambert on the other side).
// Sampling picks a lobe by its albedo, and weights by the mixture pdf, so the
// estimator stays unbiased whichever lobe dominates. Twin of bsdf.rs;
// the surface these functions read is built by surface_at (surface.wgsl),
// so this file needs nothing of the scene and the sampling harness runs it.

#import shaders/common.wgsl
#import shaders/random.wgsl

struct SurfacePoint {
    // The shading normal: the geometric one, tilted by the bump texture.
    n: vec3f,
    diffuse: vec3f,
    specular: vec3f,
    alpha: f32,      // GGX α = roughness², kept above 1e-3 so D stays finite
    mirror: f32,
    // The chance that a ray meets the surface rather than passing through.
    opacity: f32,
    // The colour of the light that passes through (where opacity < 1).
    transmission: vec3f,
    emission: vec3f,
    // Sample the diffuse lobe uniformly over the hemisphere (pdf 1 / 2π)
    // instead of by cosine (Rust: Strategy::Hemisphere); same value.
    uniform_diffuse: bool,
    // The diffuse transmission TD: f = TD/π between directions on opposite
    // sides of the surface.
    diffuse_transmission: vec3f,
}

// GGX D(h) from cos²θh and sin²θh given apart. The textbook denominator
// cos²θh (α² − 1) + 1 is 1 − cos²θh + α² cos²θh: near the peak cos θh
// rounds to 1 in steps of 6e-8, so 1 − cos²θh keeps few digits where a
// lobe of roughness 0.05 has sin²θh ~ 1e-5 (the chi² test rejected that
// D against its own samples); sin²θh comes from a cross product instead.
fn ggx_d(cos2: f32, sin2: f32, a: f32) -> f32 {
    let a2 = a * a;
    let k = sin2 + cos2 * a2;
    return a2 / (PI * k * k);
}

fn smith_g1(n_v: f32, a: f32) -> f32 {
    let a2 = a * a;
    return 2.0 * n_v / (n_v + sqrt(a2 + (1.0 - a2) * n_v * n_v));
}

// The chances of sampling each continuous lobe, by albedo: (GGX,
// transmission); the diffuse lobe takes the rest. A black surface splits
// evenly between GGX and diffuse, so an opaque surface keeps its samples.
fn lobe_probabilities(s: SurfacePoint) -> vec2f {
    let d = luminance(s.diffuse);
    let g = luminance(s.specular);
    let t = luminance(s.diffuse_transmission);
    let sum = d + g + t;
    if sum <= 0.0 {
        return vec2f(0.5, 0.0);
    }
    return vec2f(g, t) / sum;
}

const UNIFORM_HEMISPHERE_PDF: f32 = 0.15915494;

// The diffuse lobe's sampling density at cos θi = n_i > 0.
fn diffuse_pdf(n_i: f32, uniform: bool) -> f32 {
    return select(n_i * INV_PI, UNIFORM_HEMISPHERE_PDF, uniform);
}

struct BsdfEval {
    f_cos: vec3f,    // f(wo, wi)·cos θi for the non-mirror part
    pdf: f32,        // the sampling pdf of wi (solid angle), lobe mixture
}

// The value and the sampling pdf together: they share the half vector and
// D(h), and code is paid for whether used or not on SIMD (see trace.wgsl).
// `n` faces `wo`; `wi` on its side meets the reflecting lobes, `wi` across
// it the transmission lobe alone.
fn eval_bsdf(s: SurfacePoint, n: vec3f, wo: vec3f, wi: vec3f) -> BsdfEval {
    let n_i = dot(n, wi);
    let n_o = dot(n, wo);
    if n_i == 0.0 || n_o <= 0.0 {
        return BsdfEval(vec3f(0.0), 0.0);
    }
    let p = lobe_probabilities(s);
    let ps = p.x;
    let pt = p.y;
    if n_i < 0.0 {
        return BsdfEval(s.diffuse_transmission * INV_PI * -n_i, pt * diffuse_pdf(-n_i, s.uniform_diffuse));
    }
    let h = normalize(wi + wo);
    let n_h = max(dot(n, h), 0.0);
    let n_x_h = cross(n, h);
    let d = ggx_d(n_h * n_h, dot(n_x_h, n_x_h), s.alpha);
    let spec = s.specular * d * smith_g1(n_i, s.alpha) * smith_g1(n_o, s.alpha) / (4.0 * n_o);
    let pdf = (1.0 - ps - pt) * diffuse_pdf(n_i, s.uniform_diffuse) + ps * d * n_h / (4.0 * max(dot(wo, h), 1e-8));
    return BsdfEval(s.diffuse * INV_PI * n_i + spec, pdf);
}

// An orthonormal basis around n (Duff et al. 2017), free of singularities.
fn basis(n: vec3f) -> mat3x3f {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t = vec3f(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let bt = vec3f(b, sign + n.y * n.y * a, -n.y);
    return mat3x3f(t, bt, n);
}

struct BsdfSample {
    wi: vec3f,
    weight: vec3f,   // f·cos / pdf, or the mirror's 1
    valid: bool,
    // The density of wi under the continuous lobes, (1 - mirror)·pdf, for
    // multiple importance sampling; 0 when the mirror was chosen (a delta).
    pdf: f32,
}

// One code path for both lobes, chosen by selects: the lobes differ only in
// how cos θ is drawn and whether the direction is a half vector.
fn sample_bsdf(s: SurfacePoint, n: vec3f, wo: vec3f) -> BsdfSample {
    let u0 = rand();
    let u1 = rand();
    let u2 = rand();
    let u3 = rand();
    return sample_bsdf_with(s, n, wo, vec4f(u0, u1, u2, u3));
}

// sample_bsdf with its four uniform numbers given (the sampling harness
// passes them): mirror or not, cos θ, φ, which lobe (GGX below its chance,
// then transmission, then diffuse).
fn sample_bsdf_with(s: SurfacePoint, n: vec3f, wo: vec3f, u: vec4f) -> BsdfSample {
    let mirror = u.x < s.mirror;
    let u1 = u.y;
    let u2 = u.z;
    let p = lobe_probabilities(s);
    let specular = u.w < p.x;
    // The transmission lobe is the diffuse one mirrored through the plane.
    let transmit = !specular && u.w < p.x + p.y;
    // GGX half vectors have pdf D(h) cos θh; the diffuse lobe is cosine-weighted.
    // GGX's cos²θ = (1 − u) / (1 + (α² − 1) u) and sin²θ = α² u / (same),
    // the denominator summed as (1 − u) + α² u: both numerators then add
    // up to it and h stays unit length (1 + (α² − 1) u cancels for u near
    // 1). sin θ in closed form, not sqrt(1 − cos²θ), which loses its
    // digits where cos θ is near 1 (a narrow lobe).
    let a2 = s.alpha * s.alpha;
    let ggx = (1.0 - u1) + a2 * u1;
    // The uniform hemisphere's cos θ = 1 − u, sin²θ = u (2 − u).
    let cos_diffuse = select(sqrt(max(0.0, 1.0 - u1)), 1.0 - u1, s.uniform_diffuse);
    let sin_diffuse = select(sqrt(u1), sqrt(max(0.0, u1 * (2.0 - u1))), s.uniform_diffuse);
    let cos_t = select(cos_diffuse, sqrt((1.0 - u1) / ggx), specular);
    let sin_t = select(sin_diffuse, sqrt(a2 * u1 / ggx), specular);
    let phi = TWO_PI * u2;
    let side = select(1.0, -1.0, transmit);
    let local = basis(n) * vec3f(sin_t * cos(phi), sin_t * sin(phi), side * cos_t);
    let wi = select(local, reflect(-wo, local), specular);
    let e = eval_bsdf(s, n, wo, wi);
    var out: BsdfSample;
    out.wi = select(wi, reflect(-wo, n), mirror);
    out.weight = select(e.f_cos / e.pdf, vec3f(1.0), mirror);
    out.valid = mirror || e.pdf > 0.0;
    out.pdf = select((1.0 - s.mirror) * e.pdf, 0.0, mirror);
    return out;
}
