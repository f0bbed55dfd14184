//! Issue 6, case 5 (the environment map's poles and seam) and case 12 (MIS
//! weights at extreme densities), each on the CPU twin and on the shader
//! through the sampling harness; and property tests of the sampling
//! functions (env, GGX, cosine) and the texture mappings.

use crate::sampling_support;

use crate::sampling_support::{Grid, Hemisphere, LatLong};
use glam::{Vec2, Vec3};
use marbre_core::bsdf::{Surface, eval_bsdf, sample_bsdf};
use marbre_core::env_sampling::EnvDistribution;
use marbre_core::envmap::{EnvImage, direction_to_uv, texel_for_direction};
use marbre_core::mis::{bsdf_sample_weight, light_sample_weight, mis_heuristic};
use marbre_core::scene::Strategy as MisStrategy;
use marbre_core::texture::{TextureTransform, cylinder_uv, plane_uv, sphere_uv, triangle_uv};
use marbre_render::gpu::harness::sampling::{BsdfSetup, SamplingHarness};
use marbre_render::gpu::testing::gpu_or_skip;
use proptest::prelude::*;

// ------------------------------------------------ case 5: poles and seam

/// The lab's own atan2 (seed 000, its IBL section), in f64: the mapping
/// the texel must follow, written independently of `direction_to_uv`.
fn lab_atan2(y: f64, x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    if x > 0.0 {
        (y / x).atan()
    } else if y >= 0.0 && x < 0.0 {
        PI + (y / x).atan()
    } else if y < 0.0 && x < 0.0 {
        -PI + (y / x).atan()
    } else if y > 0.0 && x == 0.0 {
        FRAC_PI_2
    } else if y < 0.0 && x == 0.0 {
        -FRAC_PI_2
    } else {
        0.0
    }
}

/// The texel (column, row) the lab's `envMapCoord` reads for `d` in a
/// `w × h` map whose row 0 is the sky: u = (atan2(x, z) + π) / 2π wrapping
/// at 1, v = acos(−y) / π flipped to rows.
fn lab_texel(d: Vec3, (w, h): (u32, u32)) -> (u32, u32) {
    use std::f64::consts::PI;
    let d = d.as_dvec3();
    let u = (lab_atan2(d.x, d.z) + PI) / (2.0 * PI);
    let v = (-d.y).clamp(-1.0, 1.0).acos() / PI;
    let x = ((u * f64::from(w)).floor() as i64).rem_euclid(i64::from(w));
    let y = (((1.0 - v) * f64::from(h)).floor() as i64).clamp(0, i64::from(h) - 1);
    (x as u32, y as u32)
}

/// Exactly the poles, with every sign of zero, and unit directions with
/// x = ±0 or z = ±0 at several heights: the seam (x = 0, z < 0), the
/// map's centre (x = 0, z > 0) and the quarter columns (z = 0).
fn pole_and_seam_directions() -> Vec<Vec3> {
    let mut out = Vec::new();
    for y in [1.0f32, -1.0] {
        for x in [0.0f32, -0.0] {
            for z in [0.0f32, -0.0] {
                out.push(Vec3::new(x, y, z));
            }
        }
    }
    for y in [0.0f32, -0.0, 0.6, -0.8, 0.999_999] {
        let r = (1.0 - y * y).sqrt();
        for zero in [0.0f32, -0.0] {
            for side in [r, -r] {
                out.push(Vec3::new(zero, y, side));
                out.push(Vec3::new(side, y, zero));
            }
        }
    }
    out
}

const MAP_SIZES: [(u32, u32); 4] = [(8, 4), (6, 3), (64, 32), (512, 256)];

#[test]
fn poles_and_seam_read_the_lab_texel_on_the_cpu() {
    for size in MAP_SIZES {
        let image = EnvImage::constant(size.0, size.1, [1.0; 3]);
        for d in pole_and_seam_directions() {
            let uv = direction_to_uv(d);
            assert!(
                uv.is_finite() && (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y),
                "{d:?} -> {uv}"
            );
            assert_eq!(
                texel_for_direction(&image, d, 0.0),
                lab_texel(d, size),
                "{d:?} in {size:?}"
            );
        }
    }
}

/// A map with a sun, whose sampling density is positive everywhere.
fn sunny_map() -> EnvImage {
    let mut image = EnvImage::constant(16, 8, [0.5; 3]);
    image.pixels[3 * 16 + 5] = [1e4; 4];
    image
}

/// The sampler's density at the poles and on the seam is finite, never
/// negative, and exactly 0 at the poles themselves (where sin θ = 0 and
/// the sample is discarded).
#[test]
fn env_pdf_is_finite_at_the_poles_and_seam_on_the_cpu() {
    let distribution = EnvDistribution::new(&sunny_map());
    for d in pole_and_seam_directions() {
        for rotation in [0.0, 90.0, -37.0] {
            let pdf = distribution.pdf_direction(d, rotation);
            assert!(pdf.is_finite() && pdf >= 0.0, "{d:?}: {pdf}");
            if d.x == 0.0 && d.z == 0.0 {
                assert_eq!(pdf, 0.0, "{d:?}");
            }
        }
    }
}

/// A map whose texel (x, y) holds (x, y, 1): exact in half floats, so the
/// GPU's lookup names the texel it read.
fn index_map((w, h): (u32, u32)) -> EnvImage {
    let mut image = EnvImage::constant(w, h, [0.0; 3]);
    for y in 0..h {
        for x in 0..w {
            image.pixels[(y * w + x) as usize] = [x as f32, y as f32, 1.0, 1.0];
        }
    }
    image
}

#[test]
fn poles_and_seam_read_the_lab_texel_on_the_gpu() {
    let Some(ctx) = gpu_or_skip("poles_and_seam_read_the_lab_texel_on_the_gpu") else {
        return;
    };
    let directions = pole_and_seam_directions();
    for size in MAP_SIZES {
        let harness =
            SamplingHarness::new(&ctx, &index_map(size), wgpu::FilterMode::Nearest).unwrap();
        let read = harness.env_radiance(&ctx, 0.0, &directions).unwrap();
        let pdfs = harness.env_pdfs(&ctx, 0.0, &directions).unwrap();
        for ((d, texel), (pdf, uv)) in directions.iter().zip(&read).zip(&pdfs) {
            assert!(texel.is_finite() && uv.is_finite() && pdf.is_finite() && *pdf >= 0.0);
            let got = (texel.x as u32, texel.y as u32);
            assert_eq!(got, lab_texel(*d, size), "{d:?} in {size:?}: uv {uv}");
        }
    }
}

/// A 16 × 8 map whose columns follow one period of a sine, so it is
/// smooth across the seam (column 15 runs on into column 0) but not
/// symmetric about it: clamping instead of wrapping at u = 0/1 shows as
/// a step of 0.5 sin(π/16) ≈ 0.1.
fn seam_map() -> EnvImage {
    let (w, h) = (16u32, 8u32);
    let mut image = EnvImage::constant(w, h, [0.0; 3]);
    for y in 0..h {
        for x in 0..w {
            let v = seam_value(x as i64, y);
            image.pixels[(y * w + x) as usize] = [v as f32, v as f32, v as f32, 1.0];
        }
    }
    image
}

fn seam_value(column: i64, row: u32) -> f64 {
    let x = column.rem_euclid(16) as f64;
    1.0 + 0.5 * (2.0 * std::f64::consts::PI * (x + 0.5) / 16.0).sin() + 0.05 * f64::from(row)
}

/// What a lookup at texel uv `t` of [`seam_map`] returns in exact
/// arithmetic, wrapping in u: bilinear between texel centres, or the
/// texel `t` lies in.
fn seam_expected(t: Vec2, linear: bool) -> f64 {
    let row = ((f64::from(t.y) * 8.0) as u32).min(7);
    let x = f64::from(t.x) * 16.0;
    if !linear {
        return seam_value(x.floor() as i64, row);
    }
    let x = x - 0.5;
    let (i, f) = (x.floor(), x - x.floor());
    (1.0 - f) * seam_value(i as i64, row) + f * seam_value(i as i64 + 1, row)
}

/// Directions whose u runs from two texels before the seam to two past
/// it in steps of 1/128 of a texel, offset by 1/16 of a step (so no u
/// falls on a texel edge, where nearest filtering may go either way), at
/// three row centres (no blending in v); 512 directions a row.
fn seam_crossing() -> Vec<(Vec2, Vec3)> {
    let domain = LatLong {
        rotation_degrees: 0.0,
    };
    let mut out = Vec::new();
    for row in [1u32, 4, 6] {
        let ty = (f64::from(row) + 0.5) / 8.0;
        for k in -256..256 {
            let tx = ((f64::from(k) + 1.0 / 16.0) / 2048.0).rem_euclid(1.0);
            let d = sampling_support::Domain::direction(&domain, glam::DVec2::new(tx, ty));
            out.push((Vec2::new(tx as f32, ty as f32), d.as_vec3()));
        }
    }
    out
}

/// No line at u = 0/1 with either filter: the shader's lookup across the
/// seam matches the wrapped exact lookup, and steps between neighbouring
/// directions stay within the map's own slope.
///
/// Tolerance: the map is stored in half floats (values ≤ 1.85, so a
/// rounding error ≤ 2^-11 × 2 ≈ 1e-3) and lavapipe blends with 8-bit
/// weights (error ≤ the step between texels, 0.5 × 2π/16 ≈ 0.2, over
/// 256 ≈ 8e-4); 3e-3 covers both. The map's steepest slope is 0.2 per
/// texel, so neighbours 1/128 texel apart differ by at most 1.6e-3 with
/// linear filtering, plus twice the tolerance.
#[test]
fn no_line_at_the_seam_with_any_filter_on_the_gpu() {
    let Some(ctx) = gpu_or_skip("no_line_at_the_seam_with_any_filter_on_the_gpu") else {
        return;
    };
    let crossing = seam_crossing();
    let directions: Vec<Vec3> = crossing.iter().map(|(_, d)| *d).collect();
    for (filter, linear) in [
        (wgpu::FilterMode::Linear, true),
        (wgpu::FilterMode::Nearest, false),
    ] {
        let harness = SamplingHarness::new(&ctx, &seam_map(), filter).unwrap();
        let read = harness.env_radiance(&ctx, 0.0, &directions).unwrap();
        for ((t, d), got) in crossing.iter().zip(&read) {
            let expected = seam_expected(*t, linear);
            assert!(
                (f64::from(got.x) - expected).abs() < 3e-3,
                "{filter:?} at t = {t} ({d:?}): {} instead of {expected}",
                got.x
            );
        }
        if linear {
            for row in read.chunks(512) {
                for pair in row.windows(2) {
                    let step = (pair[0].x - pair[1].x).abs();
                    assert!(step < 1.6e-3 + 6e-3, "a step of {step} along a row");
                }
            }
        }
    }
}

/// On the CPU the mapping wraps: directions just either side of the seam
/// read the last and the first column, and the sampling density of a
/// map smooth across the seam is continuous there.
#[test]
fn the_seam_wraps_on_the_cpu() {
    let image = seam_map();
    let distribution = EnvDistribution::new(&image);
    for (t, d) in seam_crossing() {
        let (column, _) = texel_for_direction(&image, d, 0.0);
        let expected = ((t.x * 16.0).floor() as u32) % 16;
        assert_eq!(column, expected, "{t} {d:?}");
        assert!(distribution.pdf_direction(d, 0.0).is_finite());
    }
    let at = |u: f64| {
        let domain = LatLong {
            rotation_degrees: 0.0,
        };
        let d = sampling_support::Domain::direction(&domain, glam::DVec2::new(u, 0.4));
        distribution.pdf_direction(d.as_vec3(), 0.0)
    };
    // Either side of the seam the density is that of the middle of the
    // same column: the seam is no edge of the distribution's own.
    for (edge, middle) in [(1.0 - 1e-5, 15.5 / 16.0), (1e-5, 0.5 / 16.0)] {
        let (a, b) = (at(edge), at(middle));
        assert!(
            (a / b - 1.0).abs() < 1e-5,
            "u = {edge}: {a}, mid-column {b}"
        );
    }
}

// --------------------------------------------------- case 12: MIS weights

/// 0, the smallest subnormal, a subnormal, tiny, ordinary, huge, the
/// largest finite and infinite densities.
const DENSITIES: [f32; 11] = [
    0.0,
    1e-45,
    1e-40,
    1e-30,
    1e-3,
    1.0,
    1e20,
    1e38,
    3.3e38,
    f32::MAX,
    f32::INFINITY,
];

/// The heuristic in f64, where none of these densities overflows or
/// underflows when squared: an infinite density takes the weight (half
/// each if both are), none when both are 0.
fn expected_heuristic(a: f32, b: f32, strategy: MisStrategy) -> f64 {
    let (a, b) = (f64::from(a), f64::from(b));
    match (a.is_infinite(), b.is_infinite()) {
        (true, true) => return 0.5,
        (true, false) => return 1.0,
        (false, true) => return 0.0,
        _ => {}
    }
    if a == 0.0 && b == 0.0 {
        return 0.0;
    }
    if strategy == MisStrategy::MisBalance {
        a / (a + b)
    } else {
        a * a / (a * a + b * b)
    }
}

/// Weights are finite and in [0, 1]; the heuristic matches f64 within
/// `tolerance`; and the weights of the strategies that can draw a
/// direction (density > 0) sum to 1 wherever one can (Bsdf and
/// Hemisphere, direction sampling alone, ignore light sampling's share by
/// design, so there only where the BSDF can).
fn check_weights(
    a: f32,
    b: f32,
    strategy: MisStrategy,
    heuristic: [f32; 2],
    light: f32,
    bsdf: f32,
    tolerance: f64,
) -> Result<(), String> {
    let context = format!("{strategy:?}, light pdf {a:e}, BSDF pdf {b:e}");
    for w in [heuristic[0], heuristic[1], light, bsdf] {
        if !(w.is_finite() && (0.0..=1.0).contains(&w)) {
            return Err(format!("{context}: weight {w}"));
        }
    }
    if matches!(strategy, MisStrategy::MisBalance | MisStrategy::MisPower) {
        for (w, e) in heuristic.iter().zip([
            expected_heuristic(a, b, strategy),
            expected_heuristic(b, a, strategy),
        ]) {
            if (f64::from(*w) - e).abs() > tolerance {
                return Err(format!("{context}: heuristic {w}, f64 says {e}"));
            }
        }
        if a > 0.0 || b > 0.0 {
            let sum = f64::from(heuristic[0]) + f64::from(heuristic[1]);
            if (sum - 1.0).abs() > 2.0 * tolerance {
                return Err(format!("{context}: heuristic pair sums to {sum}"));
            }
        }
    }
    let can_light = a > 0.0 && !strategy.directions_only();
    if can_light || b > 0.0 {
        let sum = if a > 0.0 { f64::from(light) } else { 0.0 }
            + if b > 0.0 { f64::from(bsdf) } else { 0.0 };
        if (sum - 1.0).abs() > 2.0 * tolerance {
            return Err(format!(
                "{context}: light {light} + BSDF {bsdf} weights sum to {sum}"
            ));
        }
    }
    Ok(())
}

/// Tolerance: each weight is a few correctly rounded f32 operations on
/// ratios in [0, 1] (|error| ≤ 3 × 2^-24 ≈ 2e-7); 1e-6 leaves margin.
#[test]
fn mis_weights_are_finite_and_sum_to_one_on_the_cpu() {
    for strategy in MisStrategy::ALL {
        for a in DENSITIES {
            for b in DENSITIES {
                let heuristic = [mis_heuristic(a, b, strategy), mis_heuristic(b, a, strategy)];
                let light = light_sample_weight(a, b, strategy);
                let bsdf = bsdf_sample_weight(b, a, strategy);
                check_weights(a, b, strategy, heuristic, light, bsdf, 1e-6).unwrap();
            }
        }
    }
}

/// The same grid through the shader. A GPU may flush subnormals to zero
/// (WGSL allows it), so a pair holding one is also accepted as computed
/// with it flushed. Tolerance 4e-6: WGSL's division is only accurate to
/// 2.5 ulp, and a weight takes up to three (≤ 1e-6 relative on values
/// ≤ 1), doubled for the pair's sum.
#[test]
fn mis_weights_are_finite_and_sum_to_one_on_the_gpu() {
    let Some(ctx) = gpu_or_skip("mis_weights_are_finite_and_sum_to_one_on_the_gpu") else {
        return;
    };
    let harness = SamplingHarness::without_env(&ctx).unwrap();
    let pairs: Vec<(f32, f32)> = DENSITIES
        .iter()
        .flat_map(|&a| DENSITIES.iter().map(move |&b| (a, b)))
        .collect();
    let flush = |x: f32| if x.is_subnormal() { 0.0 } else { x };
    for strategy in MisStrategy::ALL {
        let weights = harness.mis_weights(&ctx, strategy, &pairs).unwrap();
        for (&(a, b), w) in pairs.iter().zip(&weights) {
            let check = |a, b| check_weights(a, b, strategy, w.heuristic, w.light, w.bsdf, 4e-6);
            if let Err(exact) = check(a, b) {
                check(flush(a), flush(b)).map_err(|_| exact).unwrap();
            }
        }
    }
}

// ------------------------------------------ edges of the unit square, GPU

/// The uniform numbers at and next to the edges of [0, 1): 0, 2^-24 (the
/// shader's smallest step), ½ and 1 − 2^-24 (its largest `rand()`), and
/// 1 − ulp.
const EDGES: [f32; 5] = [
    0.0,
    5.960_464_5e-8,
    0.5,
    0.999_999_94,
    1.0 - f32::EPSILON / 2.0,
];

fn bsdf_setups() -> Vec<BsdfSetup> {
    let n = Vec3::new(0.3, 0.9, 0.2).normalize();
    let t = n.any_orthonormal_vector();
    let mut out = Vec::new();
    for roughness in [0.0, 0.05, 1.0] {
        for cos_o in [1.0f32, 0.5, 1e-4] {
            let wo = (n * cos_o + t * (1.0 - cos_o * cos_o).sqrt()).normalize();
            for (diffuse, specular, mirror) in [(0.0, 1.0, 0.0), (0.5, 0.5, 0.3), (0.0, 0.0, 0.0)] {
                out.push(BsdfSetup {
                    surface: Surface {
                        diffuse: Vec3::splat(diffuse),
                        specular: Vec3::splat(specular),
                        alpha: Surface::alpha_for(roughness),
                        mirror,
                        uniform_diffuse: false,
                        diffuse_transmission: Vec3::ZERO,
                    },
                    n,
                    wo,
                });
            }
        }
    }
    out
}

/// Every combination of edge values, for the BSDF's four numbers.
fn edge_quads() -> Vec<[f32; 4]> {
    let mut out = Vec::new();
    for a in EDGES {
        for b in EDGES {
            for c in EDGES {
                for d in EDGES {
                    out.push([a, b, c, d]);
                }
            }
        }
    }
    out
}

fn assert_unit_and_finite(what: &str, d: Vec3) {
    assert!(
        d.is_finite() && (d.length() - 1.0).abs() < 1e-5,
        "{what}: {d:?}"
    );
}

#[test]
fn samplers_stay_finite_at_the_edges_of_the_unit_square_on_the_gpu() {
    let Some(ctx) = gpu_or_skip("samplers_stay_finite_at_the_edges_of_the_unit_square_on_the_gpu")
    else {
        return;
    };
    let harness = SamplingHarness::new(&ctx, &sunny_map(), wgpu::FilterMode::Linear).unwrap();
    let quads = edge_quads();
    for setup in bsdf_setups() {
        for (u, s) in quads
            .iter()
            .zip(harness.bsdf_samples(&ctx, &setup, &quads).unwrap())
        {
            let what = format!("GPU BSDF sample {u:?} of {setup:?}");
            assert_unit_and_finite(&what, s.wi);
            assert!(s.pdf.is_finite() && s.pdf >= 0.0, "{what}: {s:?}");
            if s.valid {
                assert!(s.weight.is_finite(), "{what}: {s:?}");
            }
        }
    }
    let pairs: Vec<Vec2> = EDGES
        .iter()
        .flat_map(|&a| EDGES.iter().map(move |&b| Vec2::new(a, b)))
        .collect();
    for rotation in [0.0, 123.0] {
        for (u, (d, pdf)) in pairs
            .iter()
            .zip(harness.env_samples(&ctx, rotation, &pairs).unwrap())
        {
            assert_unit_and_finite(&format!("GPU env sample {u}"), d);
            assert!(pdf.is_finite() && pdf >= 0.0, "GPU env sample {u}: {pdf}");
        }
    }
}

// ------------------------------------------------------ property tests, CPU

/// A uniform number in [0, 1), its edges drawn often.
fn unit() -> impl Strategy<Value = f32> {
    prop_oneof![
        1 => Just(0.0f32),
        1 => Just(1.0 - f32::EPSILON / 2.0),
        6 => 0.0f32..1.0,
    ]
}

fn unit_vector() -> impl Strategy<Value = Vec3> {
    (unit(), unit()).prop_map(|(a, b)| {
        let z = 1.0 - 2.0 * a;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * std::f32::consts::PI * b;
        Vec3::new(r * phi.cos(), r * phi.sin(), z).normalize()
    })
}

/// A small map: dark, ordinary and sun-bright texels, black ones too.
fn env_map() -> impl Strategy<Value = EnvImage> {
    (2u32..12, 2u32..8).prop_flat_map(|(w, h)| {
        proptest::collection::vec(
            prop_oneof![3 => 0.0f32..2.0, 1 => Just(0.0f32), 1 => 1e3f32..3e4],
            (w * h) as usize,
        )
        .prop_map(move |values| {
            let mut image = EnvImage::constant(w, h, [0.0; 3]);
            for (p, v) in image.pixels.iter_mut().zip(values) {
                *p = [v, v, v, 1.0];
            }
            image
        })
    })
}

/// A surface seen along `wo`, up to grazing (cos θo ≥ 1e-4), with any
/// roughness, lobe weights (diffuse transmission included) and mirror
/// share.
fn bsdf_setup() -> impl Strategy<Value = BsdfSetup> {
    (
        unit_vector(),
        unit_vector(),
        0.0f32..=1.0,
        0.0f32..=1.0,
        0.0f32..=1.0,
        0.0f32..=1.0,
        0.0f32..=1.0,
    )
        .prop_map(
            |(n, w, roughness, diffuse, specular, mirror, transmission)| {
                let w = if w.dot(n) < 0.0 {
                    w - 2.0 * w.dot(n) * n
                } else {
                    w
                };
                let wo = if w.dot(n) < 1e-4 {
                    (w + 1e-3 * n).normalize()
                } else {
                    w.normalize()
                };
                BsdfSetup {
                    surface: Surface {
                        diffuse: Vec3::splat(diffuse),
                        specular: Vec3::splat(specular),
                        alpha: Surface::alpha_for(roughness),
                        mirror,
                        diffuse_transmission: Vec3::splat(transmission),
                        uniform_diffuse: false,
                    },
                    n,
                    wo,
                }
            },
        )
}

/// ∫ pdf dω over a hemisphere grid (24 × 24 cells, 25 Gauss–Legendre
/// nodes each) crowded around the mirror direction over `width`.
fn hemisphere_integral(setup: &BsdfSetup, width: f64) -> f64 {
    let n = setup.n.as_dvec3();
    let wo = setup.wo.as_dvec3();
    let mirror = 2.0 * n.dot(wo) * n - wo;
    let domain = Hemisphere::new(n, mirror, width, width * n.dot(wo).max(0.05));
    let grid = Grid {
        domain: &domain,
        res: (24, 24),
    };
    let pdf: Vec<f32> = grid
        .nodes()
        .iter()
        .map(|&wi| eval_bsdf(&setup.surface, setup.n, setup.wo, wi).pdf)
        .collect();
    grid.integrate(&pdf).iter().sum()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// The env pdf integrates to 1 over the sphere, for any map and
    /// rotation. Quadrature on the map's own cells (constant density on
    /// each) is exact but for f32 rounding of the CDFs (~1e-7 a cell) and
    /// of sin θ near the poles (~1e-6): 1e-4 bounds both.
    #[test]
    fn env_pdf_integrates_to_one(image in env_map(), rotation in -180.0f32..180.0) {
        let distribution = EnvDistribution::new(&image);
        let domain = LatLong { rotation_degrees: f64::from(rotation) };
        let grid = Grid { domain: &domain, res: (distribution.width as usize, distribution.height as usize) };
        let pdf: Vec<f32> = grid.nodes().iter().map(|&d| distribution.pdf_direction(d, rotation)).collect();
        let total: f64 = grid.integrate(&pdf).iter().sum();
        prop_assert!((total - 1.0).abs() < 1e-4, "∫ pdf dω = {total}");
    }

    /// An env sample is a finite unit direction with a finite density,
    /// and the density `pdf_direction` gives its direction is the one it
    /// came with, unless it lies within rounding of a cell's edge (the
    /// round trip through the direction may then land in the neighbour).
    #[test]
    fn env_samples_are_finite_and_agree_with_their_pdf(
        image in env_map(), u1 in unit(), u2 in unit(), rotation in -180.0f32..180.0,
    ) {
        let distribution = EnvDistribution::new(&image);
        let (t, pdf_t) = distribution.sample(u1, u2);
        prop_assert!(t.is_finite() && pdf_t.is_finite() && pdf_t >= 0.0);
        let (d, pdf) = EnvDistribution::direction(t, pdf_t, rotation);
        prop_assert!(d.is_finite() && (d.length() - 1.0).abs() < 1e-5, "{d:?}");
        prop_assert!(pdf.is_finite() && pdf >= 0.0, "{pdf}");
        let cell = t * Vec2::new(distribution.width as f32, distribution.height as f32);
        let off_edge = (cell - cell.round()).abs().min_element() > 1e-3;
        if pdf > 0.0 && off_edge {
            let again = distribution.pdf_direction(d, rotation);
            prop_assert!((again / pdf - 1.0).abs() < 1e-3, "{pdf} then {again} at {t}");
        }
    }

    /// The cosine lobe alone integrates to 1 over the hemisphere. The
    /// grid is nearly even and the density smooth (cos θ): the quadrature
    /// error is far below the f32 rounding of the density, 1e-6 relative.
    #[test]
    fn cosine_pdf_integrates_to_one(setup in bsdf_setup()) {
        let mut setup = setup;
        setup.surface.diffuse = Vec3::splat(0.7);
        setup.surface.specular = Vec3::ZERO;
        setup.surface.diffuse_transmission = Vec3::ZERO;
        let total = hemisphere_integral(&setup, 10.0);
        prop_assert!((total - 1.0).abs() < 1e-4, "∫ pdf dω = {total}");
    }

    /// GGX seen head-on loses the reflections of half vectors beyond 45°
    /// below the surface: ∫ pdf dω over the hemisphere is
    /// P(cos²θh > ½) = 1 / (1 + α²) in closed form (the sampled
    /// cos²θh = (1 − u) / (1 + (α² − 1) u) exceeds ½ for u < 1 / (1 + α²)).
    /// Tolerance: the grid puts about four cells across the lobe; its
    /// quadrature error, measured below 2e-4 over roughness 0.05–1, with
    /// a margin.
    #[test]
    fn ggx_pdf_at_normal_incidence_integrates_to_the_closed_form(
        n in unit_vector(), roughness in 0.05f32..=1.0,
    ) {
        let alpha = Surface::alpha_for(roughness);
        let setup = BsdfSetup {
            surface: Surface { diffuse: Vec3::ZERO, specular: Vec3::ONE, alpha, mirror: 0.0, diffuse_transmission: Vec3::ZERO, uniform_diffuse: false },
            n,
            wo: n,
        };
        let total = hemisphere_integral(&setup, 6.0 * f64::from(alpha));
        let a2 = f64::from(alpha) * f64::from(alpha);
        let expected = 1.0 / (1.0 + a2);
        prop_assert!((total - expected).abs() < 1e-3, "∫ pdf dω = {total}, not {expected}");
    }

    /// A BSDF sample is a finite unit direction for any numbers in [0, 1)
    /// (edges included), any material and any incidence; a valid one has a
    /// finite weight equal to f·cos / pdf, and its pdf is the one
    /// `eval_bsdf` gives its direction, times the continuous lobes' share.
    #[test]
    fn bsdf_samples_are_finite_and_agree_with_their_pdf(
        setup in bsdf_setup(), u0 in unit(), u1 in unit(), u2 in unit(), u3 in unit(),
    ) {
        let s = sample_bsdf(&setup.surface, setup.n, setup.wo, [u0, u1, u2, u3]);
        prop_assert!(s.wi.is_finite() && (s.wi.length() - 1.0).abs() < 1e-5, "{s:?}");
        prop_assert!(s.pdf.is_finite() && s.pdf >= 0.0, "{s:?}");
        let mirror = u0 < setup.surface.mirror;
        if s.valid && !mirror {
            prop_assert!(s.weight.is_finite(), "{s:?}");
            let e = eval_bsdf(&setup.surface, setup.n, setup.wo, s.wi);
            let pdf = (1.0 - setup.surface.mirror) * e.pdf;
            prop_assert!((s.pdf - pdf).abs() <= 1e-6 * pdf, "{} vs {pdf}", s.pdf);
            prop_assert!((s.weight - e.f_cos / e.pdf).abs().max_element() <= 1e-5 * s.weight.max_element().max(1.0));
        }
    }

    /// Sphere and cylinder u, and sphere v, lie in [0, 1] and are finite
    /// for any finite point: the poles, the axis, ±0 and huge or tiny
    /// coordinates included.
    #[test]
    fn sphere_and_cylinder_uv_are_finite_and_in_range(p in point_anywhere(), height in 1e-3f32..1e3) {
        let uv = sphere_uv(p);
        prop_assert!(uv.is_finite() && (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y), "{p:?} -> {uv}");
        let c = cylinder_uv(p, height);
        prop_assert!((0.0..=1.0).contains(&c.x), "{p:?} -> {c}");
        if p.y.abs() < 1e30 {
            prop_assert!(c.y.is_finite(), "{p:?} -> {c}");
        }
    }

    /// Plane, triangle and 3D-transform coordinates are finite for any
    /// point of a scene (|p| ≤ 1e6), any axes or vertices (degenerate
    /// ones included) and any transform (a zero scale included).
    #[test]
    fn plane_triangle_and_transform_coordinates_are_finite(
        p in scene_point(), o in scene_point(), a in scene_point(), b in scene_point(),
        scale in prop::array::uniform3(prop_oneof![Just(0.0f32), -1e3f32..1e3]),
        rotate in prop::array::uniform3(-1e4f32..1e4),
    ) {
        prop_assert!(plane_uv(p, o, a, b).is_finite());
        let uvs = [Vec2::ZERO, Vec2::X, Vec2::Y];
        prop_assert!(triangle_uv(p, [o, a, b], uvs).is_finite());
        prop_assert!(triangle_uv(p, [o, o, o], uvs).is_finite());
        let transform = TextureTransform {
            translate: o,
            rotate_degrees: Vec3::from_array(rotate),
            scale: Vec3::from_array(scale),
        };
        prop_assert!(transform.to_texture().transform_point3(p).is_finite());
    }
}

/// A coordinate from the special values (±0, tiny, huge, the largest
/// finite) or an ordinary range.
fn coordinate() -> impl Strategy<Value = f32> {
    prop_oneof![
        1 => prop::sample::select(vec![0.0f32, -0.0, 1e-30, -1e-30, 1e-45, 1e30, -1e30, f32::MAX, -f32::MAX]),
        3 => -10.0f32..10.0,
    ]
}

fn point_anywhere() -> impl Strategy<Value = Vec3> {
    (coordinate(), coordinate(), coordinate()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn scene_point() -> impl Strategy<Value = Vec3> {
    prop::array::uniform3(prop_oneof![Just(0.0f32), Just(-0.0f32), -1e6f32..1e6])
        .prop_map(Vec3::from_array)
}

// ------------------------------------------------------ the presets render

/// This part's presets in `presets/hard-cases/`, each with the views
/// worth rendering (the seam preset's poles too).
fn sampling_presets() -> Vec<std::path::PathBuf> {
    let dir = std::path::Path::new(crate::REPO).join("presets/hard-cases");
    let mut out: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("sampling_") && n.ends_with(".ron"))
        })
        .collect();
    out.sort();
    out
}

/// Each preset loads without a clamped value and renders every saved view
/// with no sample dropped as NaN or Inf by the trace pass (its counters)
/// and finite pixels: the seam and both poles of sky.exr through a mirror
/// ball, and a light density near 1e7 against a roughness of 0.05
/// under the power heuristic.
#[test]
fn sampling_presets_render_without_non_finite_samples() {
    let Some(ctx) = gpu_or_skip("sampling_presets_render_without_non_finite_samples") else {
        return;
    };
    let presets = sampling_presets();
    assert_eq!(presets.len(), 2, "{presets:?}");
    for path in presets {
        let loaded = marbre_core::preset::load(&path).unwrap();
        assert!(
            loaded.notes.is_empty(),
            "{}: {:?}",
            path.display(),
            loaded.notes
        );
        let scene = marbre_render::session::load_scene(&path, None).unwrap();
        let mut cameras = vec![scene.scene.camera];
        cameras.extend(scene.scene.views.iter().map(|v| v.camera));
        for camera in cameras {
            let mut view = marbre_render::session::LoadedScene {
                scene: scene.scene.clone(),
                env: scene.env.clone(),
                images: scene.images.clone(),
                notes: Vec::new(),
                substitutes: Vec::new(),
            };
            view.scene.camera = camera;
            let mut renderer = marbre_render::session::renderer_for(&ctx, &view, (32, 32)).unwrap();
            marbre_render::session::accumulate(&ctx, &mut renderer, 8, |_| {}).unwrap();
            let dropped = renderer.count_non_finite(&ctx).unwrap();
            assert!(
                dropped.is_zero(),
                "{} from {camera:?}: dropped {dropped:?}",
                path.display()
            );
            let (_, _, pixels) = renderer.read_radiance(&ctx).unwrap();
            assert!(pixels.iter().flatten().all(|c| c.is_finite()));
        }
    }
}
