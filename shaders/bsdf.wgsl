// Lambert + GGX (Smith, separable) with an optional perfect mirror.
// Sampling picks a lobe by its albedo, and weights by the mixture pdf, so the
// estimator stays unbiased whichever lobe dominates.

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
}

// The surface at a hit reached by a ray cone `width` wide, along `d`.
fn surface_at(hit: Hit, width: f32, d: vec3f) -> SurfacePoint {
    let p = hit.texture_point;
    let fp = hit_footprint(hit, width, d);
#if NOISE
    let signals = material_signals(hit.material, p, hit.p, fp.p);
#else
    let signals = vec4f(0.0);
#endif
    let textures = surface_textures(hit.material, p, hit.p, hit.uv, fp, signals);
    var s: SurfacePoint;
    // Math steps can leave [0, 1]: reflectances stay within it, so no
    // bounce ever adds energy.
    s.diffuse = clamp(textures.diffuse, vec3f(0.0), vec3f(1.0));
    s.specular = clamp(textures.specular, vec3f(0.0), vec3f(1.0));
    let r = clamp(textures.roughness, 0.0, 1.0);
    s.alpha = max(r * r, 1e-3);
    s.mirror = clamp(textures.mirror, 0.0, 1.0);
    s.opacity = clamp(textures.opacity, 0.0, 1.0);
    s.transmission = clamp(textures.transmission, vec3f(0.0), vec3f(1.0));
    s.emission = max(textures.emission, vec3f(0.0));
#if BUMP
    s.n = bumped_shading_normal(hit, fp, signals, -d);
#else
    s.n = hit.n;
#endif
    return s;
}

fn ggx_d(n_h: f32, a: f32) -> f32 {
    let a2 = a * a;
    let k = n_h * n_h * (a2 - 1.0) + 1.0;
    return a2 / (PI * k * k);
}

fn smith_g1(n_v: f32, a: f32) -> f32 {
    let a2 = a * a;
    return 2.0 * n_v / (n_v + sqrt(a2 + (1.0 - a2) * n_v * n_v));
}

fn specular_probability(s: SurfacePoint) -> f32 {
    let d = luminance(s.diffuse);
    let g = luminance(s.specular);
    if d + g <= 0.0 {
        return 0.5;
    }
    return g / (d + g);
}

struct BsdfEval {
    f_cos: vec3f,    // f(wo, wi)·cos θi for the non-mirror part
    pdf: f32,        // the sampling pdf of wi (solid angle), lobe mixture
}

// The value and the sampling pdf together: they share the half vector and
// D(h), and code is paid for whether used or not on SIMD (see trace.wgsl).
fn eval_bsdf(s: SurfacePoint, n: vec3f, wo: vec3f, wi: vec3f) -> BsdfEval {
    let n_i = dot(n, wi);
    let n_o = dot(n, wo);
    if n_i <= 0.0 || n_o <= 0.0 {
        return BsdfEval(vec3f(0.0), 0.0);
    }
    let h = normalize(wi + wo);
    let n_h = max(dot(n, h), 0.0);
    let d = ggx_d(n_h, s.alpha);
    let spec = s.specular * d * smith_g1(n_i, s.alpha) * smith_g1(n_o, s.alpha) / (4.0 * n_o);
    let ps = specular_probability(s);
    let pdf = (1.0 - ps) * n_i * INV_PI + ps * d * n_h / (4.0 * max(dot(wo, h), 1e-8));
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
    let mirror = rand() < s.mirror;
    let u1 = rand();
    let u2 = rand();
    let specular = rand() < specular_probability(s);
    // GGX half vectors have pdf D(h) cos θh; the diffuse lobe is cosine-weighted.
    let a2 = s.alpha * s.alpha;
    let cos_t = select(sqrt(max(0.0, 1.0 - u1)), sqrt((1.0 - u1) / (1.0 + (a2 - 1.0) * u1)), specular);
    let sin_t = sqrt(max(0.0, 1.0 - cos_t * cos_t));
    let phi = TWO_PI * u2;
    let local = basis(n) * vec3f(sin_t * cos(phi), sin_t * sin(phi), cos_t);
    let wi = select(local, reflect(-wo, local), specular);
    let e = eval_bsdf(s, n, wo, wi);
    var out: BsdfSample;
    out.wi = select(wi, reflect(-wo, n), mirror);
    out.weight = select(e.f_cos / e.pdf, vec3f(1.0), mirror);
    out.valid = mirror || e.pdf > 0.0;
    out.pdf = select((1.0 - s.mirror) * e.pdf, 0.0, mirror);
    return out;
}
