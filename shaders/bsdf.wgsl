// Lambert + GGX (Smith, separable) with an optional perfect mirror.
// Sampling picks a lobe by its albedo, and weights by the mixture pdf, so the
// estimator stays unbiased whichever lobe dominates.

struct SurfacePoint {
    diffuse: vec3f,
    specular: vec3f,
    alpha: f32,      // GGX α = roughness², kept above 1e-3 so D stays finite
    mirror: f32,
}

fn surface_at(hit: Hit) -> SurfacePoint {
    let m = materials[hit.material];
    var s: SurfacePoint;
    s.diffuse = eval_color(m.diffuse, hit.texture_point);
    s.specular = eval_color(m.specular, hit.texture_point);
    let r = clamp(eval_scalar(m.roughness, hit.texture_point), 0.0, 1.0);
    s.alpha = max(r * r, 1e-3);
    s.mirror = m.mirror;
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

// f(wo, wi)·cos θi for the non-mirror part.
fn eval_bsdf_cos(s: SurfacePoint, n: vec3f, wo: vec3f, wi: vec3f) -> vec3f {
    let n_i = dot(n, wi);
    let n_o = dot(n, wo);
    if n_i <= 0.0 || n_o <= 0.0 {
        return vec3f(0.0);
    }
    let h = normalize(wi + wo);
    let spec = s.specular * ggx_d(max(dot(n, h), 0.0), s.alpha) * smith_g1(n_i, s.alpha) * smith_g1(n_o, s.alpha) / (4.0 * n_o);
    return s.diffuse * INV_PI * n_i + spec;
}

fn specular_probability(s: SurfacePoint) -> f32 {
    let d = luminance(s.diffuse);
    let g = luminance(s.specular);
    if d + g <= 0.0 {
        return 0.5;
    }
    return g / (d + g);
}

fn pdf_bsdf(s: SurfacePoint, n: vec3f, wo: vec3f, wi: vec3f) -> f32 {
    let n_i = dot(n, wi);
    if n_i <= 0.0 {
        return 0.0;
    }
    let h = normalize(wi + wo);
    let n_h = max(dot(n, h), 0.0);
    let p_spec = ggx_d(n_h, s.alpha) * n_h / (4.0 * max(dot(wo, h), 1e-8));
    let ps = specular_probability(s);
    return (1.0 - ps) * n_i * INV_PI + ps * p_spec;
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
}

fn sample_bsdf(s: SurfacePoint, n: vec3f, wo: vec3f) -> BsdfSample {
    var out: BsdfSample;
    out.valid = false;
    if rand() < s.mirror {
        out.wi = reflect(-wo, n);
        out.weight = vec3f(1.0);
        out.valid = true;
        return out;
    }
    let frame_n = basis(n);
    let u1 = rand();
    let u2 = rand();
    var wi: vec3f;
    if rand() < specular_probability(s) {
        // GGX half-vector sampling, pdf D(h) cos θh.
        let a2 = s.alpha * s.alpha;
        let cos_h = sqrt((1.0 - u1) / (1.0 + (a2 - 1.0) * u1));
        let sin_h = sqrt(max(0.0, 1.0 - cos_h * cos_h));
        let phi = TWO_PI * u2;
        let h = frame_n * vec3f(sin_h * cos(phi), sin_h * sin(phi), cos_h);
        wi = reflect(-wo, h);
    } else {
        // Cosine-weighted hemisphere.
        let r = sqrt(u1);
        let phi = TWO_PI * u2;
        wi = frame_n * vec3f(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u1)));
    }
    let pdf = pdf_bsdf(s, n, wo, wi);
    if pdf <= 0.0 {
        return out;
    }
    out.wi = wi;
    out.weight = eval_bsdf_cos(s, n, wo, wi) / pdf;
    out.valid = true;
    return out;
}
