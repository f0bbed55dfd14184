//! The texture library's WGSL (`crates/core/src/texture/patterns.wgsl`), run on the
//! GPU through the compute harness, against the CPU reference in
//! `marbre_core::texture`, at 10,000 points per pattern and per mapping.
//!
//! Patterns that switch at an edge (a cell, the mortar, a ring) may differ
//! where the GPU's rounding puts a point on the other side of it: such a
//! point is exempt only if it lies within a hair of that edge on the CPU, and
//! the exemptions must stay rare, so the test cannot pass by exempting.

use glam::{Vec2, Vec3};
use marbre_core::noise::{FractalParams, HashKind, NoiseKind, NoiseSettings, turbulence};
use marbre_core::scene::Pattern;
use marbre_core::texture::{self, RampStop};
use marbre_render::gpu::harness::texture::{PatternQuery, evaluate};
use marbre_render::gpu::testing::gpu_or_skip;

const N: usize = 10_000;

/// Deterministic points spread over [-extent, extent]³ (an R3 sequence).
fn points(extent: f32) -> Vec<Vec3> {
    let a = [0.819_172_5_f64, 0.671_043_5, 0.549_700_5];
    (0..N)
        .map(|k| {
            let c = a.map(|ai| ((ai * (k as f64 + 0.5)).fract() * 2.0 - 1.0) as f32 * extent);
            Vec3::from_array(c)
        })
        .collect()
}

/// Distance from x to the nearest integer.
fn off_integer(x: f32) -> f32 {
    (x - x.round()).abs()
}

/// Compares the GPU's results with `cpu` component by component; a point
/// beyond `tolerance` must satisfy `near_edge`, and fewer than 1 % may.
fn assert_parity(
    name: &str,
    gpu: &[[f32; 4]],
    points: &[Vec3],
    tolerance: f32,
    cpu: impl Fn(Vec3) -> [f32; 4],
    near_edge: impl Fn(Vec3) -> bool,
) {
    let mut exempt = 0;
    for (g, &p) in gpu.iter().zip(points) {
        let c = cpu(p);
        let error = (0..4).map(|i| (g[i] - c[i]).abs()).fold(0.0, f32::max);
        if error > tolerance {
            assert!(
                near_edge(p),
                "{name}: at {p} the GPU gives {g:?}, the CPU {c:?}"
            );
            exempt += 1;
        }
    }
    assert!(
        exempt < N / 100,
        "{name}: {exempt} points differ at an edge"
    );
}

fn turbulent() -> NoiseSettings {
    NoiseSettings {
        kind: NoiseKind::Gradient,
        hash: HashKind::Pcg,
        fractal: FractalParams {
            octaves: 4.0,
            frequency: 3.0,
            ..FractalParams::default()
        },
        evolution: None,
    }
}

#[test]
fn boards_match_the_cpu() {
    let Some(ctx) = gpu_or_skip("boards_match_the_cpu") else {
        return;
    };
    let pts = points(3.0);
    let (size, phase) = (Vec2::new(0.25, 0.4), 0.5);
    let gpu = evaluate(&ctx, &PatternQuery::Checker2d { size, phase }, &pts).unwrap();
    let near_cell_edge = |p: Vec3| {
        let row = (p.y / size.y).floor();
        off_integer(p.y / size.y) < 1e-4
            || off_integer(p.x / size.x + phase * texture::checker::odd(row)) < 1e-4
    };
    assert_parity(
        "checker 2D",
        &gpu,
        &pts,
        1e-5,
        |p| {
            let c = texture::checker_2d(p.truncate(), size, phase);
            [c.select, c.local.x, c.local.y, 0.0]
        },
        near_cell_edge,
    );

    let size3 = Vec3::new(0.3, 0.5, 0.7);
    let gpu = evaluate(&ctx, &PatternQuery::Checker3d { size: size3 }, &pts).unwrap();
    assert_parity(
        "checker 3D",
        &gpu,
        &pts,
        0.0,
        |p| [texture::checker_3d(p, size3), 0.0, 0.0, 0.0],
        |p| {
            (p / size3)
                .to_array()
                .iter()
                .any(|&c| off_integer(c) < 1e-4)
        },
    );

    let half_width = Vec2::new(0.05, 0.13);
    let gpu = evaluate(
        &ctx,
        &PatternQuery::FilteredChecker2d {
            size,
            phase,
            half_width,
        },
        &pts,
    )
    .unwrap();
    assert_parity(
        "filtered checker",
        &gpu,
        &pts,
        1e-4,
        |p| {
            [
                texture::filtered_checker_2d(p.truncate(), size, phase, half_width),
                0.0,
                0.0,
                0.0,
            ]
        },
        |p| off_integer(p.y / size.y) < 1e-4,
    );

    let (size3, w3) = (Vec3::new(0.5, 0.7, 0.3), Vec3::new(0.11, 0.02, 0.3));
    let gpu = evaluate(
        &ctx,
        &PatternQuery::FilteredChecker3d {
            size: size3,
            half_width: w3,
        },
        &pts,
    )
    .unwrap();
    assert_parity(
        "filtered 3D checker",
        &gpu,
        &pts,
        1e-4,
        |p| [texture::filtered_checker_3d(p, size3, w3), 0.0, 0.0, 0.0],
        |_| false,
    );
}

#[test]
fn masonry_and_cutouts_match_the_cpu() {
    let Some(ctx) = gpu_or_skip("masonry_and_cutouts_match_the_cpu") else {
        return;
    };
    let pts = points(2.0);
    let (size, mortar, row_offset) = (Vec2::new(0.3, 0.1), 0.02, 0.5);
    let gpu = evaluate(
        &ctx,
        &PatternQuery::Brick {
            size,
            mortar,
            row_offset,
        },
        &pts,
    )
    .unwrap();
    let near_brick_edge = |p: Vec3| {
        let c = texture::brick(p.truncate(), size, mortar, row_offset);
        let from_edge = c.local.min(Vec2::ONE - c.local) * size;
        (from_edge - Vec2::splat(0.5 * mortar)).abs().min_element() < 1e-4
            || from_edge.min_element() < 1e-4
    };
    assert_parity(
        "brick",
        &gpu,
        &pts,
        1e-4,
        |p| {
            let c = texture::brick(p.truncate(), size, mortar, row_offset);
            [c.select, c.local.x, c.local.y, 0.0]
        },
        near_brick_edge,
    );

    let (m, w, h) = (0.04, 0.06, 0.5);
    let query = PatternQuery::Tile {
        mortar_half_width: m,
        bevel_width: w,
        bevel_height: h,
    };
    let gpu = evaluate(&ctx, &query, &pts).unwrap();
    assert_parity(
        "tile",
        &gpu,
        &pts,
        1e-5,
        |p| {
            let t = texture::tile(p.truncate(), m, w, h);
            let height = texture::tile_height(p.truncate(), m, w);
            [t.select, t.height_gradient.x, t.height_gradient.y, height]
        },
        |p| {
            let l = p.truncate() - p.truncate().floor();
            let d = l.min(Vec2::ONE - l);
            let nearest = d.min_element();
            (nearest - m).abs() < 1e-4
                || (nearest - m - w).abs() < 1e-4
                || (d.x - d.y).abs() < 1e-4
                || (l - Vec2::splat(0.5)).abs().min_element() < 1e-4
        },
    );

    for (sides, radius) in [(0, 0.4), (5, 0.35), (6, 0.45)] {
        let gpu = evaluate(&ctx, &PatternQuery::Cutout { sides, radius }, &pts).unwrap();
        assert_parity(
            "cutout",
            &gpu,
            &pts,
            0.0,
            |p| [texture::cutout(p.truncate(), sides, radius), 0.0, 0.0, 0.0],
            |p| {
                // Near the boundary: one side of it within a hair.
                let d = Vec2::new(1e-4, 0.0);
                let uv = p.truncate();
                [d, -d, d.perp(), -d.perp()].iter().any(|&e| {
                    texture::cutout(uv + e, sides, radius) != texture::cutout(uv, sides, radius)
                })
            },
        );
    }
}

#[test]
fn wood_and_marble_match_the_cpu() {
    let Some(ctx) = gpu_or_skip("wood_and_marble_match_the_cpu") else {
        return;
    };
    let pts = points(2.0);
    let noise = turbulent();
    let axis = texture::default_axis();
    let (ring_width, amount) = (0.12, 0.3);
    let query = PatternQuery::Wood {
        axis,
        ring_width,
        turbulence_amount: amount,
        noise,
    };
    let gpu = evaluate(&ctx, &query, &pts).unwrap();
    assert_parity(
        "wood",
        &gpu,
        &pts,
        0.0,
        |p| {
            [
                texture::wood(p, axis, ring_width, amount, &noise),
                0.0,
                0.0,
                0.0,
            ]
        },
        |p| {
            let radius = (p - p.dot(axis) * axis).length();
            off_integer((radius + amount * turbulence(p, &noise)) / ring_width) < 1e-3
        },
    );

    let marble_axis = Vec3::new(1.0, 0.0, 0.0);
    let (frequency, amount) = (10.0, 25.0);
    let query = PatternQuery::MarbleVeins {
        axis: marble_axis,
        frequency,
        turbulence_amount: amount,
        noise,
    };
    let gpu = evaluate(&ctx, &query, &pts).unwrap();
    // The turbulence is amplified 25 times: its 1e-5 agreement becomes ~3e-4.
    assert_parity(
        "marble veins",
        &gpu,
        &pts,
        2e-3,
        |p| {
            [
                texture::marble_veins(p, marble_axis, frequency, amount, &noise),
                0.0,
                0.0,
                0.0,
            ]
        },
        |_| false,
    );

    // Massal's marble with his recipe, at the viewer's default frequency
    // and at his own 0.05 over his pixel-sized scene.
    for (frequency, extent) in [(Pattern::MASSAL_MARBLE_FREQUENCY, 2.0), (0.05, 320.0)] {
        let noise = NoiseSettings::massal(frequency);
        let query = PatternQuery::MassalMarble {
            stripe_frequency: frequency,
            noise,
        };
        let pts = points(extent);
        let gpu = evaluate(&ctx, &query, &pts).unwrap();
        assert_parity(
            "Massal's marble",
            &gpu,
            &pts,
            1e-4,
            |p| [texture::massal_marble(p, frequency, &noise), 0.0, 0.0, 0.0],
            |_| false,
        );
    }
}

#[test]
fn waves_bump_and_ramp_match_the_cpu() {
    let Some(ctx) = gpu_or_skip("waves_bump_and_ramp_match_the_cpu") else {
        return;
    };
    let pts = points(2.0);
    let (frequency, amplitude, direction) = (4.0, 0.05, Vec2::new(0.6, 0.8));
    let query = PatternQuery::WavesGradient {
        frequency,
        amplitude,
        direction,
    };
    let gpu = evaluate(&ctx, &query, &pts).unwrap();
    assert_parity(
        "waves",
        &gpu,
        &pts,
        1e-3 * amplitude * frequency * std::f32::consts::TAU,
        |p| {
            let g = texture::waves_gradient(p.truncate(), frequency, amplitude, direction);
            let height = texture::waves(p.truncate(), frequency, direction);
            [g.x, g.y, height, 0.0]
        },
        |_| false,
    );

    // Random unit normals, tilted by a fixed frame and gradient.
    let normals: Vec<Vec3> = pts.iter().map(|p| p.normalize_or(Vec3::Y)).collect();
    let (dp_du, dp_dv, dh_du, dh_dv) = (
        Vec3::new(0.5, 0.1, 0.0),
        Vec3::new(0.0, 0.2, 1.5),
        0.7,
        -0.3,
    );
    let query = PatternQuery::Bump {
        dp_du,
        dp_dv,
        dh_du,
        dh_dv,
    };
    let gpu = evaluate(&ctx, &query, &normals).unwrap();
    assert_parity(
        "bump",
        &gpu,
        &normals,
        1e-5,
        |n| {
            texture::bumped_normal(n, dp_du, dp_dv, dh_du, dh_dv)
                .extend(0.0)
                .to_array()
        },
        |_| false,
    );
    // A degenerate frame falls back to the normal on the GPU too.
    let query = PatternQuery::Bump {
        dp_du: Vec3::ZERO,
        dp_dv: Vec3::ZERO,
        dh_du: 1.0,
        dh_dv: f32::INFINITY,
    };
    let gpu = evaluate(&ctx, &query, &normals).unwrap();
    for (g, n) in gpu.iter().zip(&normals) {
        assert!(
            (Vec3::new(g[0], g[1], g[2]) - *n).length() < 1e-6,
            "{g:?} vs {n}"
        );
    }

    let stops = vec![
        RampStop {
            position: -0.5,
            color: Vec3::new(0.1, 0.2, 0.3),
        },
        RampStop {
            position: 0.0,
            color: Vec3::new(0.9, 0.1, 0.0),
        },
        RampStop {
            position: 0.0,
            color: Vec3::new(0.0, 0.5, 0.5),
        },
        RampStop {
            position: 1.2,
            color: Vec3::new(1.0, 1.0, 1.0),
        },
    ];
    let gpu = evaluate(
        &ctx,
        &PatternQuery::Ramp {
            stops: stops.clone(),
        },
        &pts,
    )
    .unwrap();
    assert_parity(
        "ramp",
        &gpu,
        &pts,
        1e-5,
        |p| texture::ramp(&stops, p.x).extend(0.0).to_array(),
        |p| p.x.abs() < 1e-5,
    );
}

#[test]
fn mappings_match_the_cpu() {
    let Some(ctx) = gpu_or_skip("mappings_match_the_cpu") else {
        return;
    };
    let pts = points(2.0);
    // Where u wraps (towards -z) the two sides differ by 1: only a point
    // within a hair of the seam may.
    let near_seam = |p: Vec3| p.z < 0.0 && p.x.abs() < 1e-4 * p.z.abs().max(1e-3);
    let gpu = evaluate(&ctx, &PatternQuery::SphereUv, &pts).unwrap();
    assert_parity(
        "sphere uv",
        &gpu,
        &pts,
        1e-4,
        |p| texture::sphere_uv(p).extend(0.0).extend(0.0).to_array(),
        near_seam,
    );
    // The poles and the centre stay finite on the GPU too.
    let poles = [Vec3::Y, Vec3::NEG_Y, Vec3::ZERO, Vec3::new(0.0, 3.0, 0.0)];
    for (g, p) in evaluate(&ctx, &PatternQuery::SphereUv, &poles)
        .unwrap()
        .iter()
        .zip(poles)
    {
        assert!(g.iter().all(|c| c.is_finite()), "{p}: {g:?}");
        assert!((g[0] - 0.5).abs() < 1e-6, "{p}: {g:?}");
    }

    let height = 1.7;
    let gpu = evaluate(&ctx, &PatternQuery::CylinderUv { height }, &pts).unwrap();
    assert_parity(
        "cylinder uv",
        &gpu,
        &pts,
        1e-4,
        |p| {
            texture::cylinder_uv(p, height)
                .extend(0.0)
                .extend(0.0)
                .to_array()
        },
        near_seam,
    );

    let (origin, u_axis, v_axis) = (
        Vec3::new(0.5, -1.0, 2.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 1.0),
    );
    let query = PatternQuery::PlaneUv {
        origin,
        u_axis,
        v_axis,
    };
    let gpu = evaluate(&ctx, &query, &pts).unwrap();
    assert_parity(
        "plane uv",
        &gpu,
        &pts,
        1e-4,
        |p| {
            texture::plane_uv(p, origin, u_axis, v_axis)
                .extend(0.0)
                .extend(0.0)
                .to_array()
        },
        |_| false,
    );

    let vertices = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(2.0, 0.0, 0.5),
        Vec3::new(0.3, 1.5, -0.4),
    ];
    let uvs = [
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 0.2),
        Vec2::new(0.4, 1.0),
    ];
    let gpu = evaluate(&ctx, &PatternQuery::TriangleUv { vertices, uvs }, &pts).unwrap();
    assert_parity(
        "triangle uv",
        &gpu,
        &pts,
        1e-4,
        |p| {
            texture::triangle_uv(p, vertices, uvs)
                .extend(0.0)
                .extend(0.0)
                .to_array()
        },
        |_| false,
    );

    let transform = texture::TextureTransform {
        translate: Vec3::new(0.3, -2.0, 1.0),
        rotate_degrees: Vec3::new(10.0, 35.0, -70.0),
        scale: Vec3::new(0.5, 2.0, 1.5),
    };
    let to_texture = transform.to_texture();
    let gpu = evaluate(&ctx, &PatternQuery::Transform { to_texture }, &pts).unwrap();
    assert_parity(
        "3D transform",
        &gpu,
        &pts,
        1e-5,
        |p| to_texture.transform_point3(p).extend(0.0).to_array(),
        |_| false,
    );
}

/// Image textures: the shipped uv grid and a small non-square image packed
/// in one atlas, sampled with every filter and wrap at (u, v) over
/// [-1.5, 1.5]² (every wrap region) and levels of detail over [−1, 10]
/// (clamped at both ends). The GPU reads the same half floats with the same
/// integer texel arithmetic, so only rounding of the weights may differ.
/// Nearest sampling can pick the neighbouring texel where (u, v) lies on a
/// texel edge to within rounding: those points are exempt.
#[test]
fn images_match_the_cpu() {
    let Some(ctx) = gpu_or_skip("images_match_the_cpu") else {
        return;
    };
    use marbre_core::texture::{ImageAtlas, ImageFilter, ImageLevel, ImageWrap, MipImage};
    let grid = texture::load_image(
        &std::path::Path::new(crate::REPO).join("presets/images/uv_grid.png"),
        texture::ColorSpace::Srgb,
    )
    .unwrap()
    .image;
    let stripes = MipImage::new(ImageLevel {
        width: 8,
        height: 2,
        texels: (0..16)
            .map(|k| [(k % 8) as f32 / 7.0, (k / 8) as f32, 0.5, 1.0])
            .collect(),
    });
    let atlas = ImageAtlas::pack(&[&grid, &stripes], 8192).unwrap();
    let pts: Vec<Vec3> = points(1.0)
        .iter()
        .map(|p| Vec3::new(1.5 * p.x, 1.5 * p.y, 4.5 + 5.5 * p.z))
        .collect();
    for entry in 0..2 {
        let size = Vec2::new(
            atlas.entries[entry].width as f32,
            atlas.entries[entry].height as f32,
        );
        for filter in [
            ImageFilter::Nearest,
            ImageFilter::Bilinear,
            ImageFilter::Trilinear,
        ] {
            for wrap in [ImageWrap::Repeat, ImageWrap::Clamp, ImageWrap::Mirror] {
                let query = PatternQuery::Image {
                    atlas: atlas.clone(),
                    entry,
                    filter,
                    wrap,
                };
                let gpu = evaluate(&ctx, &query, &pts).unwrap();
                assert_parity(
                    &format!("image {entry} {filter:?} {wrap:?}"),
                    &gpu,
                    &pts,
                    1e-5,
                    |p| {
                        atlas
                            .sample(entry, Vec2::new(p.x, p.y), filter, wrap, p.z)
                            .to_array()
                    },
                    |p| {
                        filter == ImageFilter::Nearest
                            && (off_integer(p.x * size.x) < 1e-3
                                || off_integer((1.0 - p.y) * size.y) < 1e-3)
                    },
                );
            }
        }
    }
}
