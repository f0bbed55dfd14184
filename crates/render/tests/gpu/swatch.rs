//! The panel's preview swatches (`gpu::swatch`): each texture of a batch,
//! through the generated WGSL, equals the CPU reference `Texture::eval_at`
//! at the swatch's sample points, within the texture parity tests'
//! tolerance; only points the GPU's rounding puts across a pattern's edge
//! may differ, and fewer than 1 % of them.

use glam::{Vec2, Vec3};
use marbre_core::noise::{NoiseKind, NoiseSettings};
use marbre_core::scene::{MathOp, Pattern, Texture, TextureMapping};
use marbre_core::texture::RampStop;
use marbre_render::gpu::swatch::{SWATCH_SIZE, SwatchRenderer, sample_points};
use marbre_render::gpu::testing::gpu_or_skip;

/// A batch of one of each kind of node: nested cells of marble, bricks
/// through a ramp, fBm after math steps, a cutout, Perlin wood, a mix by
/// turbulence, and a mapped 3D checker. Each differs from the others, so a
/// swatch read from the wrong row fails.
fn textures() -> Vec<Texture> {
    let marble = Texture::blend(
        Pattern::Marble {
            noise: NoiseSettings::default(),
            stripe_frequency: 4.0,
        },
        Vec3::new(0.9, 0.9, 0.85),
        Vec3::new(0.2, 0.2, 0.3),
    );
    let nested = Texture::blend(
        Pattern::Checker2d {
            size: Vec2::splat(0.25),
            phase: 0.0,
        },
        marble,
        Vec3::new(0.8, 0.1, 0.1),
    );
    let mut bricks = Texture::blend(
        Pattern::Brick {
            size: Vec2::new(0.25, 0.1),
            mortar: 0.02,
            row_offset: 0.5,
        },
        0.0,
        1.0,
    );
    bricks.ramp = vec![
        RampStop {
            position: 0.0,
            color: Vec3::new(0.1, 0.5, 0.2),
        },
        RampStop {
            position: 1.0,
            color: Vec3::new(0.9, 0.6, 0.1),
        },
    ];
    let mut fbm = Texture::blend(
        Pattern::Fbm {
            noise: NoiseSettings::default(),
        },
        0.1,
        0.9,
    );
    fbm.ops = vec![MathOp::Scale(1.5), MathOp::Bias(-0.2), MathOp::Invert];
    let perlin = NoiseSettings {
        kind: NoiseKind::Perlin,
        ..NoiseSettings::default()
    };
    let wood = Texture::blend(
        Pattern::Wood {
            noise: perlin,
            ring_width: 0.12,
            turbulence_amount: 0.3,
        },
        Vec3::new(0.3, 0.15, 0.05),
        Vec3::new(0.8, 0.6, 0.4),
    );
    let mix = Texture::mix(
        Texture::blend(Pattern::Turbulence { noise: perlin }, 0.0, 1.0),
        Vec3::new(0.0, 0.2, 0.9),
        Vec3::new(1.0, 0.9, 0.0),
    );
    let mut checker = Texture::blend(Pattern::Checker { size: 0.5 }, 0.05, 0.95);
    checker.mapping = Some(TextureMapping::default());
    if let Some(m) = checker.mapping.as_mut() {
        m.transform.rotate_degrees = Vec3::new(20.0, 30.0, 0.0);
    }
    vec![
        nested,
        bricks,
        fbm,
        Texture::blend(
            Pattern::Cutout {
                sides: 5,
                radius: 0.4,
            },
            0.2,
            0.7,
        ),
        wood,
        mix,
        checker,
    ]
}

/// How many of the swatch's points on the sphere differ from the CPU
/// reference by more than 1e-4, of how many; and the spread of its values.
fn compare(texture: &Texture, swatch: &[[f32; 4]]) -> (usize, usize, f32) {
    let points = sample_points();
    assert_eq!(swatch.len(), SWATCH_SIZE * SWATCH_SIZE);
    let (mut off, mut inside) = (0, 0);
    let (mut lo, mut hi) = (f32::MAX, f32::MIN);
    for (pixel, point) in swatch.iter().zip(&points) {
        let Some(point) = point else {
            assert_eq!(*pixel, [0.0; 4], "outside the disc");
            continue;
        };
        inside += 1;
        assert_eq!(pixel[3], 1.0, "alpha on the sphere");
        let gpu = Vec3::new(pixel[0], pixel[1], pixel[2]);
        if (gpu - texture.eval_at(point)).abs().max_element() > 1e-4 {
            off += 1;
        }
        let sum = gpu.element_sum();
        (lo, hi) = (lo.min(sum), hi.max(sum));
    }
    (off, inside, hi - lo)
}

#[test]
fn swatches_equal_the_cpu_reference_at_their_sample_points() {
    let Some(ctx) = gpu_or_skip("swatches_equal_the_cpu_reference_at_their_sample_points") else {
        return;
    };
    let textures = textures();
    let mut renderer = SwatchRenderer::new(ctx).unwrap();
    let swatches = renderer.render(&textures).unwrap();
    assert_eq!(swatches.len(), textures.len());
    for (k, (texture, swatch)) in textures.iter().zip(&swatches).enumerate() {
        let (off, inside, spread) = compare(texture, swatch);
        // Nearly π/4 of the square is the sphere's disc.
        assert!(
            inside > SWATCH_SIZE * SWATCH_SIZE * 3 / 4,
            "swatch {k}: {inside}"
        );
        assert!(
            (off as f32) < 0.01 * inside as f32,
            "swatch {k}: {off} of {inside} points differ from the CPU"
        );
        // The pattern shows: its swatch is not one flat value.
        assert!(spread > 0.1, "swatch {k} is flat: {spread}");
    }
    // A batch with the same structure and other numbers (a slider drag)
    // reuses the pipeline and shows its own numbers.
    let mut other = textures[3].clone();
    other.b = 0.95.into();
    let again = renderer.render(std::slice::from_ref(&other)).unwrap();
    let (off, inside, _) = compare(&other, &again[0]);
    assert!((off as f32) < 0.01 * inside as f32, "{off} of {inside}");
    assert_ne!(again[0], swatches[3]);
}

/// Evolving noise (issue 29) through the swatches' generated code: a
/// drifting gradient marble and a looping Perlin wood equal the CPU
/// reference at two moments, which differ from each other (the moment
/// reaches the GPU as numbers, through the same pipeline).
#[test]
fn evolving_swatches_equal_the_cpu_reference_at_two_moments() {
    use marbre_core::noise::Evolution;
    let Some(ctx) = gpu_or_skip("evolving_swatches_equal_the_cpu_reference_at_two_moments") else {
        return;
    };
    let at = |t: f32| {
        let evolution = |looping: Option<f32>| {
            let mut e = Evolution {
                w: 0.3,
                speed: 0.9,
                drift: Vec3::new(0.25, -0.1, 0.05),
                ..Evolution::default()
            };
            e.at(t, looping);
            Some(e)
        };
        let marble = Texture::blend(
            Pattern::Marble {
                noise: NoiseSettings {
                    evolution: evolution(None),
                    ..NoiseSettings::default()
                },
                stripe_frequency: 4.0,
            },
            Vec3::new(0.9, 0.9, 0.85),
            Vec3::new(0.2, 0.2, 0.3),
        );
        let wood = Texture::blend(
            Pattern::Wood {
                noise: NoiseSettings {
                    kind: NoiseKind::Perlin,
                    evolution: evolution(Some(3.0)),
                    ..NoiseSettings::default()
                },
                ring_width: 0.12,
                turbulence_amount: 0.3,
            },
            Vec3::new(0.3, 0.15, 0.05),
            Vec3::new(0.8, 0.6, 0.4),
        );
        vec![marble, wood]
    };
    let mut renderer = SwatchRenderer::new(ctx).unwrap();
    let mut previous: Option<Vec<Vec<[f32; 4]>>> = None;
    for t in [0.4, 1.9] {
        let textures = at(t);
        let swatches = renderer.render(&textures).unwrap();
        for (k, (texture, swatch)) in textures.iter().zip(&swatches).enumerate() {
            let (off, inside, spread) = compare(texture, swatch);
            assert!(
                (off as f32) < 0.01 * inside as f32,
                "t {t} swatch {k}: {off} of {inside} points differ from the CPU"
            );
            assert!(spread > 0.1, "t {t} swatch {k} is flat: {spread}");
        }
        if let Some(before) = &previous {
            for k in 0..2 {
                assert_ne!(before[k], swatches[k], "swatch {k} did not move in time");
            }
        }
        previous = Some(swatches);
    }
}
