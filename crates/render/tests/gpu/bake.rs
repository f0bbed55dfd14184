//! `marbre bake` on the GPU: the generated texture code at each texel's
//! surface point, against closed forms and the CPU reference
//! (`marbre_core::bake::reference`).

use glam::{Vec2, Vec3};
use marbre_core::bake::{self, BakeProperty, ObjectRef, UvSurface};
use marbre_core::noise::NoiseSettings;
use marbre_core::scene::{Pattern, Polygon, Scene, Sphere, Texture};
use marbre_core::texture::ImageSet;
use marbre_render::gpu::bake::bake;
use marbre_render::gpu::testing::gpu_or_skip;

/// A 4 × 4 checker (cells of 0.25 in u and v) on a unit-square polygon,
/// baked at 64 × 64: each cell is 16 × 16 texels, and every texel holds
/// the colour of the cell its centre lies in (even cells `a`, odd ones
/// `b`, v counted up from the bottom row), so the colour changes exactly
/// between texels 15 and 16, 31 and 32, 47 and 48 of each row and column.
#[test]
fn a_baked_2d_checker_has_its_cells_at_the_expected_texels() {
    let Some(ctx) = gpu_or_skip("a_baked_2d_checker_has_its_cells_at_the_expected_texels") else {
        return;
    };
    let (red, blue) = (Vec3::new(0.8, 0.1, 0.0), Vec3::new(0.0, 0.2, 0.9));
    let mut polygon = Polygon {
        name: "board".into(),
        vertices: vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 0.0, 1.0),
        ],
        ..Polygon::default()
    };
    polygon.material.diffuse = Texture::blend(
        Pattern::Checker2d {
            size: Vec2::splat(0.25),
            phase: 0.0,
        },
        red,
        blue,
    );
    let scene = Scene {
        polygons: vec![polygon],
        ..Scene::default()
    };
    let size = 64;
    let object = ObjectRef::find(&scene, "board").unwrap();
    let surface = UvSurface::new(&scene, object, size).unwrap();
    let baked = bake(
        &ctx,
        &scene,
        &ImageSet::empty(),
        &surface,
        BakeProperty::Diffuse,
        size,
    )
    .unwrap();
    for (index, texel) in baked.iter().enumerate() {
        let (i, j) = (index % 64, index / 64);
        let (column, row) = (i / 16, 3 - j / 16);
        let expected = if (column + row) % 2 == 0 { red } else { blue };
        let got = Vec3::new(texel[0], texel[1], texel[2]);
        assert!(
            (got - expected).abs().max_element() < 1e-6 && texel[3] == 1.0,
            "texel ({i}, {j}): {texel:?}, expected {expected} (cell {column}, {row})"
        );
    }
    // The bottom-left texel is cell (0, 0), even; one texel right of the
    // first edge is odd.
    assert_eq!(baked[63 * 64][..3], red.to_array());
    assert_eq!(baked[63 * 64 + 16][..3], blue.to_array());
}

/// A 3D marble (fBm noise) as the diffuse colour and a 3D checker as the
/// bump height of an off-centre sphere: every texel of the GPU bake equals
/// the CPU reference at the texel's surface point, and the marble does
/// vary over the image (a constant would pass trivially).
#[test]
fn a_baked_3d_pattern_on_a_sphere_equals_the_cpu_reference() {
    let Some(ctx) = gpu_or_skip("a_baked_3d_pattern_on_a_sphere_equals_the_cpu_reference") else {
        return;
    };
    let mut sphere = Sphere {
        name: "ball".into(),
        center: Vec3::new(0.7, 1.3, -0.4),
        radius: 1.2,
        ..Sphere::default()
    };
    sphere.material.diffuse = Texture::blend(
        Pattern::Marble {
            noise: NoiseSettings::default(),
            stripe_frequency: 3.0,
        },
        Vec3::new(0.9, 0.85, 0.8),
        Vec3::new(0.2, 0.1, 0.05),
    );
    sphere.material.bump = Texture::blend(Pattern::Checker { size: 0.3 }, 0.0, 1.0);
    let scene = Scene {
        spheres: vec![Sphere::default(), sphere],
        ..Scene::default()
    };
    let size = 48;
    let surface = UvSurface::new(&scene, ObjectRef::Sphere(1), size).unwrap();
    for (property, tolerance) in [(BakeProperty::Diffuse, 2e-3), (BakeProperty::Bump, 0.0)] {
        let gpu = bake(&ctx, &scene, &ImageSet::empty(), &surface, property, size).unwrap();
        let cpu = bake::reference(&scene, &surface, property, size);
        let worst = gpu
            .iter()
            .zip(&cpu)
            .map(|(g, c)| (0..4).map(|k| (g[k] - c[k]).abs()).fold(0.0, f32::max))
            .fold(0.0, f32::max);
        assert!(
            worst <= tolerance,
            "{}: GPU and CPU differ by {worst}",
            property.name()
        );
        let (lo, hi) = cpu.iter().fold((f32::MAX, f32::MIN), |(lo, hi), v| {
            (lo.min(v[0]), hi.max(v[0]))
        });
        assert!(hi - lo > 0.3, "{}: nearly constant", property.name());
    }
}
