//! Chi-square tests of the environment and BSDF samplers against their
//! own pdfs, as Mitsuba 3 tests its samplers (`mitsuba.chi2`): N samples
//! are binned over a grid of cells covering the directions, each cell's
//! expected count is N × ∫ pdf dω over it by quadrature, cells expecting
//! fewer than 5 are pooled, and Pearson's statistic is turned into a
//! p-value by the regularised incomplete gamma function. A sampler whose
//! samples do not follow its pdf gives a tiny p-value; the test rejects
//! below 1 % divided by the number of chi² tests in this file (Šidák-Bonferroni
//! correction: the chance that any of them fails by bad luck stays under
//! 1 %). Samples that leave the domain (BSDF samples below the surface,
//! environment samples at a pole) form one more bin, expecting N times
//! the mass the pdf leaves outside.
//!
//! Each sampler runs on the CPU twin and on the shader (through the
//! sampling harness); the GPU's samples are binned against the GPU's own
//! pdf. Negative controls (a pdf of another roughness, of a map with its
//! sun moved by one texel) must be rejected, so the test can fail.

use crate::sampling_support::{Grid, Hemisphere, LatLong, Pcg};
use glam::{DVec3, Vec2, Vec3};
use marbre_core::bsdf::{Surface, eval_bsdf, sample_bsdf};
use marbre_core::env_sampling::EnvDistribution;
use marbre_core::envmap::{EnvImage, load};
use marbre_render::gpu::GpuContext;
use marbre_render::gpu::harness::sampling::{BsdfSetup, SamplingHarness};
use marbre_render::gpu::testing::gpu_or_skip;
use std::path::Path;

/// Samples per test: with ~500 cells most cells expect hundreds, so a
/// pdf wrong by a few % in a region of a few cells is rejected.
const N: usize = 100_000;

/// Chi² tests that can fail by chance in this file: 4 environment maps
/// and 11 BSDF setups, each on the CPU and the GPU.
const TESTS: f64 = 30.0;

/// The rejection threshold for one test (Bonferroni: overall false
/// rejection under 1 %).
const ALPHA: f64 = 0.01 / TESTS;

// ---------------------------------------------------------------- statistics

/// ln Γ(x) for x > 0 (Lanczos, g = 7, 9 terms; ~1e-15 relative).
fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (k, c) in C.iter().enumerate().skip(1) {
        a += c / (x + k as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularised upper incomplete gamma Q(a, x) = Γ(a, x) / Γ(a): the
/// series for P below a + 1, Lentz's continued fraction above (Numerical
/// Recipes, gammq), both to 1e-14.
fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let prefactor = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        1.0 - sum * prefactor
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-15 {
                break;
            }
        }
        prefactor * h
    }
}

/// The outcome of one test.
#[derive(Debug)]
#[allow(dead_code)] // read through Debug in failure messages
struct Chi2 {
    statistic: f64,
    dof: usize,
    p_value: f64,
}

/// Pearson's test of `observed` counts against `expected` ones: cells
/// expecting under 5 are pooled (with the next smallest until the pool
/// expects 5), as the statistic is only χ²-distributed when each bin
/// expects at least about 5. Samples in a cell expecting nothing give a
/// p-value of 0 outright: the sampler drew where its pdf says it cannot.
fn pearson(observed: &[u64], expected: &[f64]) -> Chi2 {
    let total: f64 = expected.iter().sum();
    for (o, e) in observed.iter().zip(expected) {
        if *o > 0 && *e < 1e-9 * total {
            return Chi2 {
                statistic: f64::INFINITY,
                dof: 0,
                p_value: 0.0,
            };
        }
    }
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    let mut bins: Vec<(f64, f64)> = Vec::new();
    for &k in &order {
        if expected[k] < 5.0 || (pool_e > 0.0 && pool_e < 5.0) {
            pool_o += observed[k] as f64;
            pool_e += expected[k];
        } else {
            bins.push((observed[k] as f64, expected[k]));
        }
    }
    if pool_e > 0.0 {
        bins.push((pool_o, pool_e));
    }
    let statistic: f64 = bins.iter().map(|(o, e)| (o - e) * (o - e) / e).sum();
    let dof = bins.len() - 1;
    Chi2 {
        statistic,
        dof,
        p_value: gamma_q(dof as f64 / 2.0, statistic / 2.0),
    }
}

/// Bins `samples` (directions, or `None` for a sample that failed) over
/// `grid`, with one last bin for the samples outside it, and tests them
/// against the density the pdf gives at the grid's quadrature nodes.
fn chi2(grid: &Grid, samples: &[Option<Vec3>], pdf_at_nodes: &[f32]) -> Chi2 {
    let cells = grid.res.0 * grid.res.1;
    let mut observed = vec![0u64; cells + 1];
    for s in samples {
        observed[s.and_then(|d| grid.cell(d)).unwrap_or(cells)] += 1;
    }
    let n = samples.len() as f64;
    let mut expected: Vec<f64> = grid.integrate(pdf_at_nodes).iter().map(|p| p * n).collect();
    let inside: f64 = expected.iter().sum();
    expected.push((n - inside).max(0.0));
    pearson(&observed, &expected)
}

/// Every failing case of a test, reported together.
#[derive(Default)]
struct Failures(Vec<String>);

impl Failures {
    fn check(&mut self, what: &str, result: &Chi2) {
        if result.p_value < ALPHA {
            self.0.push(format!("{what}: {result:?}"));
        }
    }

    fn assert_none(&self) {
        assert!(
            self.0.is_empty(),
            "samples do not follow the pdf (α = {ALPHA:.2e}):\n{}",
            self.0.join("\n")
        );
    }
}

fn assert_rejected(what: &str, result: &Chi2) {
    assert!(
        result.p_value < ALPHA,
        "{what}: a wrong pdf passed: {result:?} (α = {ALPHA:.2e})"
    );
}

/// Known quantiles of the χ² distribution (tables, e.g. NIST/SEMATECH
/// e-Handbook 1.3.6.7.4): Q(k/2, x/2) at the 5 % and 1 % points.
#[test]
fn the_p_value_matches_chi_square_tables() {
    for (dof, x, p) in [
        (1.0, 3.841, 0.05),
        (1.0, 6.635, 0.01),
        (10.0, 18.307, 0.05),
        (10.0, 23.209, 0.01),
        (100.0, 124.342, 0.05),
        (100.0, 135.807, 0.01),
        (500.0, 553.127, 0.05),
    ] {
        let q = gamma_q(dof / 2.0, x / 2.0);
        assert!(
            (q - p).abs() < 1e-3 * p + 1e-5,
            "Q({dof}, {x}) = {q}, not {p}"
        );
    }
    assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-12);
    assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-12);
}

/// The statistic itself: exact counts give p ≈ 1, counts off by 20 % in
/// half the cells give p ≈ 0, and cells expecting little are pooled.
#[test]
fn pearson_pools_small_cells_and_rejects_a_gross_mismatch() {
    let expected = vec![100.0; 50];
    let exact: Vec<u64> = vec![100; 50];
    assert!(pearson(&exact, &expected).p_value > 0.999);
    let off: Vec<u64> = (0..50).map(|k| if k % 2 == 0 { 120 } else { 80 }).collect();
    assert!(pearson(&off, &expected).p_value < 1e-6);
    let small = pearson(&[3, 1, 2, 100], &[2.0, 2.0, 2.0, 100.0]);
    assert_eq!(small.dof, 1, "{small:?}");
    assert_eq!(pearson(&[1, 10], &[0.0, 11.0]).p_value, 0.0);
}

// --------------------------------------------------------------- environment

/// A map with smooth sky light (0.2 to 1) and a one-texel sun 300 to
/// 1,500 times brighter: the sun's 3 × 3 cells draw about 90 % of the
/// samples, and every sky cell still expects a dozen or more, so the
/// test sees the sky's distribution too (with a sun of 2e4 every sky
/// cell expected under 5 and was pooled into one bin).
fn hot_spot_map(sun: (u32, u32)) -> EnvImage {
    let (w, h) = (32, 16);
    let mut image = EnvImage::constant(w, h, [0.0; 3]);
    for y in 0..h {
        for x in 0..w {
            let s = 0.2 + 0.1 * ((x as f32) * 0.7).sin() + 0.05 * (y as f32);
            image.pixels[(y * w + x) as usize] = [s, s * 0.9, s * 1.1, 1.0];
        }
    }
    image.pixels[(sun.1 * w + sun.0) as usize] = [300.0, 270.0, 225.0, 1.0];
    image
}

/// A shipped map (sky.exr: a sun of 22,672 over a sky near 1) box-averaged
/// down to 64 × 32, so each cell of the test holds enough samples.
fn shipped_map() -> EnvImage {
    let root = Path::new(crate::REPO);
    let full = load(&root.join("envmaps/sky.exr"))
        .expect("envmaps/sky.exr is shipped")
        .image;
    let (w, h) = (64, 32);
    let (fx, fy) = (full.width / w, full.height / h);
    let mut image = EnvImage::constant(w, h, [0.0; 3]);
    for y in 0..h {
        for x in 0..w {
            let mut sum = [0.0f32; 3];
            for dy in 0..fy {
                for dx in 0..fx {
                    let p = full.texel(x * fx + dx, y * fy + dy);
                    (0..3).for_each(|c| sum[c] += p[c]);
                }
            }
            let n = (fx * fy) as f32;
            image.pixels[(y * w + x) as usize] = [sum[0] / n, sum[1] / n, sum[2] / n, 1.0];
        }
    }
    image
}

/// The maps the environment sampler is tested on, with a map rotation.
fn env_cases() -> Vec<(&'static str, EnvImage, f32)> {
    vec![
        ("constant", EnvImage::constant(16, 8, [1.0; 3]), 0.0),
        ("hot spot", hot_spot_map((20, 5)), 0.0),
        ("hot spot turned 30°", hot_spot_map((7, 12)), 30.0),
        ("sky.exr at 64x32", shipped_map(), 0.0),
    ]
}

fn env_uniforms(seed: u64) -> Vec<Vec2> {
    let mut rng = Pcg::new(seed);
    (0..N)
        .map(|_| Vec2::new(rng.uniform(), rng.uniform()))
        .collect()
}

/// The grid of the distribution's own cells: the density is constant on
/// each, so the quadrature is exact.
fn env_grid(distribution: &EnvDistribution) -> (usize, usize) {
    (distribution.width as usize, distribution.height as usize)
}

fn cpu_env_samples(distribution: &EnvDistribution, rotation: f32) -> Vec<Option<Vec3>> {
    env_uniforms(7)
        .iter()
        .map(|u| {
            let (t, pdf) = distribution.sample(u.x, u.y);
            let (d, pdf) = EnvDistribution::direction(t, pdf, rotation);
            (pdf > 0.0).then_some(d)
        })
        .collect()
}

#[test]
fn env_sampling_follows_its_pdf_on_the_cpu() {
    let mut failures = Failures::default();
    for (name, image, rotation) in env_cases() {
        let distribution = EnvDistribution::new(&image);
        let domain = LatLong {
            rotation_degrees: f64::from(rotation),
        };
        let grid = Grid {
            domain: &domain,
            res: env_grid(&distribution),
        };
        let pdf: Vec<f32> = grid
            .nodes()
            .iter()
            .map(|&d| distribution.pdf_direction(d, rotation))
            .collect();
        let result = chi2(&grid, &cpu_env_samples(&distribution, rotation), &pdf);
        failures.check(&format!("CPU env sampling, {name}"), &result);
    }
    failures.assert_none();
}

/// Negative control: the samples of a map whose sun is one texel to the
/// left of the pdf's.
#[test]
fn env_chi2_rejects_the_pdf_of_a_shifted_sun() {
    let drawn = EnvDistribution::new(&hot_spot_map((19, 5)));
    let claimed = EnvDistribution::new(&hot_spot_map((20, 5)));
    let domain = LatLong {
        rotation_degrees: 0.0,
    };
    let grid = Grid {
        domain: &domain,
        res: env_grid(&claimed),
    };
    let pdf: Vec<f32> = grid
        .nodes()
        .iter()
        .map(|&d| claimed.pdf_direction(d, 0.0))
        .collect();
    let result = chi2(&grid, &cpu_env_samples(&drawn, 0.0), &pdf);
    assert_rejected("env sampling with a shifted sun's pdf", &result);
}

#[test]
fn env_sampling_follows_its_pdf_on_the_gpu() {
    let Some(ctx) = gpu_or_skip("env_sampling_follows_its_pdf_on_the_gpu") else {
        return;
    };
    let mut failures = Failures::default();
    for (name, image, rotation) in env_cases() {
        let harness = SamplingHarness::new(&ctx, &image, wgpu::FilterMode::Linear).unwrap();
        let distribution = EnvDistribution::new(&image);
        let domain = LatLong {
            rotation_degrees: f64::from(rotation),
        };
        let grid = Grid {
            domain: &domain,
            res: env_grid(&distribution),
        };
        let pdf: Vec<f32> = harness
            .env_pdfs(&ctx, rotation, &grid.nodes())
            .unwrap()
            .iter()
            .map(|(pdf, _)| *pdf)
            .collect();
        let samples: Vec<Option<Vec3>> = harness
            .env_samples(&ctx, rotation, &env_uniforms(7))
            .unwrap()
            .iter()
            .map(|&(d, pdf)| (pdf > 0.0).then_some(d))
            .collect();
        let result = chi2(&grid, &samples, &pdf);
        failures.check(&format!("GPU env sampling, {name}"), &result);
    }
    failures.assert_none();
}

// ---------------------------------------------------------------------- BSDF

/// One BSDF sampling setup: a material seen at `incidence_degrees` from a
/// tilted shading normal.
struct BsdfCase {
    name: String,
    setup: BsdfSetup,
}

fn bsdf_case(diffuse: f32, specular: f32, roughness: f32, incidence_degrees: f64) -> BsdfCase {
    let n = DVec3::new(0.3, 0.9, 0.2).normalize();
    let tangent = n.any_orthonormal_vector();
    let theta = incidence_degrees.to_radians();
    let wo = (n * theta.cos() + tangent * theta.sin()).normalize();
    BsdfCase {
        name: format!(
            "diffuse {diffuse}, specular {specular}, roughness {roughness}, {incidence_degrees}°"
        ),
        setup: BsdfSetup {
            surface: Surface {
                diffuse: Vec3::splat(diffuse),
                specular: Vec3::splat(specular),
                alpha: Surface::alpha_for(roughness),
                mirror: 0.0,
                uniform_diffuse: false,
                diffuse_transmission: Vec3::ZERO,
            },
            n: n.as_vec3(),
            wo: wo.as_vec3(),
        },
    }
}

/// GGX alone at three roughnesses (0.05: a lobe a few mrad wide; 1: the
/// widest) and three incidences (normal, 45°, 89°: near grazing), the
/// lobe mixture, and the cosine lobe alone; the last two again with the
/// diffuse lobe uniform over the hemisphere.
fn bsdf_cases() -> Vec<BsdfCase> {
    let mut cases = Vec::new();
    for roughness in [0.05, 0.3, 1.0] {
        for incidence in [0.0, 45.0, 89.0] {
            cases.push(bsdf_case(0.0, 1.0, roughness, incidence));
        }
    }
    cases.push(bsdf_case(0.5, 0.4, 0.3, 60.0));
    cases.push(bsdf_case(0.8, 0.0, 0.5, 30.0));
    // The diffuse lobe uniform over the hemisphere (Strategy::Hemisphere),
    // alone and in the mixture.
    for mut case in [
        bsdf_case(0.8, 0.0, 0.5, 30.0),
        bsdf_case(0.5, 0.4, 0.3, 60.0),
    ] {
        case.setup.surface.uniform_diffuse = true;
        case.name += ", uniform hemisphere";
        cases.push(case);
    }
    cases
}

/// The hemisphere about the normal, crowded around the mirror direction
/// over a few lobe widths. A half vector δ off the normal reflects wo to
/// 2δ off the mirror direction in the plane of incidence but only
/// 2δ cos θo across it, so at grazing incidence the lobe is a thin arc
/// along the horizon: the grid's azimuthal crowding follows, or a cell
/// holding all of it would be integrated wrongly by its 25 nodes. The
/// diffuse lobe takes the whole hemisphere.
fn bsdf_domain(setup: &BsdfSetup) -> Hemisphere {
    let n = setup.n.as_dvec3();
    let wo = setup.wo.as_dvec3();
    let mirror = 2.0 * n.dot(wo) * n - wo;
    if setup.surface.specular == Vec3::ZERO {
        return Hemisphere::new(n, mirror, 10.0, 10.0);
    }
    let width = 6.0 * f64::from(setup.surface.alpha);
    Hemisphere::new(n, mirror, width, width * n.dot(wo))
}

const BSDF_RES: (usize, usize) = (24, 24);

fn bsdf_uniforms(seed: u64) -> Vec<[f32; 4]> {
    let mut rng = Pcg::new(seed);
    (0..N)
        .map(|_| [rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()])
        .collect()
}

fn cpu_bsdf_samples(setup: &BsdfSetup) -> Vec<Option<Vec3>> {
    bsdf_uniforms(11)
        .iter()
        .map(|&u| {
            let s = sample_bsdf(&setup.surface, setup.n, setup.wo, u);
            (s.valid && s.pdf > 0.0).then_some(s.wi)
        })
        .collect()
}

fn cpu_bsdf_pdfs(setup: &BsdfSetup, directions: &[Vec3]) -> Vec<f32> {
    directions
        .iter()
        .map(|&wi| eval_bsdf(&setup.surface, setup.n, setup.wo, wi).pdf)
        .collect()
}

#[test]
fn bsdf_sampling_follows_its_pdf_on_the_cpu() {
    let mut failures = Failures::default();
    for case in bsdf_cases() {
        let domain = bsdf_domain(&case.setup);
        let grid = Grid {
            domain: &domain,
            res: BSDF_RES,
        };
        let pdf = cpu_bsdf_pdfs(&case.setup, &grid.nodes());
        let result = chi2(&grid, &cpu_bsdf_samples(&case.setup), &pdf);
        failures.check(&format!("CPU BSDF sampling, {}", case.name), &result);
    }
    failures.assert_none();
}

/// Negative control: GGX samples at roughness 0.3 against the pdf of
/// roughness 0.33, and at 0.05 against 0.055 (10 % off).
#[test]
fn bsdf_chi2_rejects_the_pdf_of_another_roughness() {
    for (drawn, claimed, incidence) in [(0.3, 0.33, 45.0), (0.05, 0.055, 0.0)] {
        let case = bsdf_case(0.0, 1.0, drawn, incidence);
        let mut wrong = case.setup;
        wrong.surface.alpha = Surface::alpha_for(claimed);
        let domain = bsdf_domain(&case.setup);
        let grid = Grid {
            domain: &domain,
            res: BSDF_RES,
        };
        let pdf = cpu_bsdf_pdfs(&wrong, &grid.nodes());
        let result = chi2(&grid, &cpu_bsdf_samples(&case.setup), &pdf);
        assert_rejected(
            &format!("roughness {drawn} sampled, {claimed} claimed"),
            &result,
        );
    }
}

/// Negative control: uniform hemisphere samples of a Lambert surface
/// against the cosine lobe's pdf.
#[test]
fn bsdf_chi2_rejects_the_cosine_pdf_for_uniform_samples() {
    let case = bsdf_case(0.8, 0.0, 0.5, 30.0);
    let mut uniform = case.setup;
    uniform.surface.uniform_diffuse = true;
    let domain = bsdf_domain(&case.setup);
    let grid = Grid {
        domain: &domain,
        res: BSDF_RES,
    };
    let pdf = cpu_bsdf_pdfs(&case.setup, &grid.nodes());
    let result = chi2(&grid, &cpu_bsdf_samples(&uniform), &pdf);
    assert_rejected("uniform sampled, cosine claimed", &result);
}

fn gpu_bsdf_chi2(ctx: &GpuContext, harness: &SamplingHarness, case: &BsdfCase) -> Chi2 {
    let domain = bsdf_domain(&case.setup);
    let grid = Grid {
        domain: &domain,
        res: BSDF_RES,
    };
    let pdf: Vec<f32> = harness
        .bsdf_evals(ctx, &case.setup, &grid.nodes())
        .unwrap()
        .iter()
        .map(|e| e.pdf)
        .collect();
    let samples: Vec<Option<Vec3>> = harness
        .bsdf_samples(ctx, &case.setup, &bsdf_uniforms(11))
        .unwrap()
        .iter()
        .map(|s| (s.valid && s.pdf > 0.0).then_some(s.wi))
        .collect();
    chi2(&grid, &samples, &pdf)
}

#[test]
fn bsdf_sampling_follows_its_pdf_on_the_gpu() {
    let Some(ctx) = gpu_or_skip("bsdf_sampling_follows_its_pdf_on_the_gpu") else {
        return;
    };
    let harness = SamplingHarness::without_env(&ctx).unwrap();
    let mut failures = Failures::default();
    for case in bsdf_cases() {
        let result = gpu_bsdf_chi2(&ctx, &harness, &case);
        failures.check(&format!("GPU BSDF sampling, {}", case.name), &result);
    }
    failures.assert_none();
}
