//! The orthographic camera (Massal's figures): parallel rays, so a
//! sphere's image does not shrink with depth and the environment seen
//! directly is one colour.

use crate::common::{lambert, render};
use glam::{Vec2, Vec3};
use marbre_core::scene::{OrbitCamera, Projection, Scene, Sphere, View};
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::session::{accumulate, load_scene, renderer_for};

/// Two unit spheres, one 6 units behind the other and off to the side,
/// seen head-on with `projection` from 10 away (the view 2 · 10 · tan 20°
/// high at the target), in the hit-mask view.
fn two_depths(projection: Projection) -> Scene {
    let sphere = |x: f32, z: f32| Sphere {
        center: Vec3::new(x, 0.0, z),
        radius: 1.0,
        material: lambert(0.5),
        ..Sphere::default()
    };
    let mut scene = Scene {
        spheres: vec![sphere(-1.8, 0.0), sphere(1.8, -6.0)],
        camera: OrbitCamera {
            target: Vec3::ZERO,
            distance: 10.0,
            pitch_degrees: 0.0,
            fov_degrees: 40.0,
            projection,
            ..OrbitCamera::default()
        },
        ground: None,
        point_light: None,
        ..Scene::default()
    };
    scene.render.view = View::HitMask;
    scene
}

/// The hit mask summed over the left and the right half of the image: the
/// pixels each sphere covers.
fn covered_by_halves(pixels: &[[f32; 4]], (w, h): (u32, u32)) -> [f64; 2] {
    let mut halves = [0.0; 2];
    for y in 0..h {
        for x in 0..w {
            halves[usize::from(x >= w / 2)] += f64::from(pixels[(y * w + x) as usize][0]);
        }
    }
    halves
}

/// Orthographically both spheres cover the disc of radius r / (distance ·
/// tan(fov/2)) half-heights, π(r·h / (2·10·tan 20°))² pixels, whatever
/// their depth (within 2 %); the perspective control covers less for the
/// far one (its depth 16 against 10).
#[test]
fn orthographic_spheres_keep_their_size_at_any_depth() {
    let Some(ctx) = gpu_or_skip("orthographic_spheres_keep_their_size_at_any_depth") else {
        return;
    };
    let size = (96, 48);
    let radius_px = 1.0 / (10.0 * 20f64.to_radians().tan()) * f64::from(size.1) / 2.0;
    let disc = std::f64::consts::PI * radius_px * radius_px;
    let ortho = covered_by_halves(
        &render(&ctx, &two_depths(Projection::Orthographic), size, 16),
        size,
    );
    for covered in ortho {
        assert!(
            (covered - disc).abs() < 0.02 * disc,
            "orthographic: {ortho:?} pixels, the disc {disc:.1}"
        );
    }
    let perspective = covered_by_halves(
        &render(&ctx, &two_depths(Projection::Perspective), size, 16),
        size,
    );
    assert!(
        perspective[1] < 0.6 * perspective[0],
        "perspective: {perspective:?}"
    );
}

/// The CPU twin of the shader's camera ray: each pixel's orthographic ray
/// leaves from its place on the camera's plane along the view, so the
/// sphere the GPU covers is where the CPU's rays meet it; the centre
/// pixel's ray passes through the target.
#[test]
fn the_cpu_camera_ray_is_the_shaders() {
    let Some(ctx) = gpu_or_skip("the_cpu_camera_ray_is_the_shaders") else {
        return;
    };
    let scene = two_depths(Projection::Orthographic);
    // A pixel 0.23 units high: its corners lie within 0.17 of its centre.
    let size = (64, 32);
    let pixels = render(&ctx, &scene, size, 16);
    let frame = scene.camera.frame();
    let aspect = size.0 as f32 / size.1 as f32;
    for y in 0..size.1 {
        for x in 0..size.0 {
            let ndc = Vec2::new(
                (x as f32 + 0.5) / size.0 as f32 * 2.0 - 1.0,
                1.0 - (y as f32 + 0.5) / size.1 as f32 * 2.0,
            );
            let (o, d) = frame.ray(ndc, aspect);
            let distance_to_axis = |c: Vec3| (c - o).cross(d).length();
            let inside = scene
                .spheres
                .iter()
                .map(|s| distance_to_axis(s.center))
                .fold(f32::INFINITY, f32::min);
            let mask = pixels[(y * size.0 + x) as usize][0];
            // Pixels wholly inside or wholly outside a disc.
            if inside < 0.8 {
                assert_eq!(mask, 1.0, "pixel ({x}, {y}) inside");
            } else if inside > 1.2 {
                assert_eq!(mask, 0.0, "pixel ({x}, {y}) outside");
            }
        }
    }
    let (o, d) = frame.ray(Vec2::ZERO, aspect);
    assert!((o - Vec3::new(0.0, 0.0, 10.0)).length() < 1e-5);
    assert!((d - Vec3::NEG_Z).length() < 1e-6);
}

/// Massal's page-3 preset: seen orthographically, every camera ray that
/// escapes has the same direction, so the environment behind the spheres
/// is one colour (his figure's uniform background): the image's corners
/// and edge midpoints are equal. The same scene in perspective shows the
/// cube map varying there.
#[test]
fn massal_page3_shows_the_environment_as_one_colour() {
    let Some(ctx) = gpu_or_skip("massal_page3_shows_the_environment_as_one_colour") else {
        return;
    };
    let mut loaded = load_scene(
        &std::path::Path::new(crate::REPO).join("presets/massal_page3.ron"),
        None,
    )
    .unwrap();
    assert_eq!(loaded.scene.camera.projection, Projection::Orthographic);
    let size = (64, 48);
    let mut background = |projection| {
        loaded.scene.camera.projection = projection;
        let mut r = renderer_for(&ctx, &loaded, size).unwrap();
        accumulate(&ctx, &mut r, 4, |_| {}).unwrap();
        let (_, _, pixels) = r.read_radiance(&ctx).unwrap();
        let (w, h) = size;
        [
            (0, 0),
            (w - 1, 0),
            (0, h - 1),
            (w - 1, h - 1),
            (w / 2, 0),
            (0, h / 2),
        ]
        .map(|(x, y)| pixels[(y * w + x) as usize])
    };
    let ortho = background(Projection::Orthographic);
    for p in &ortho[1..] {
        for c in 0..3 {
            assert!(
                (p[c] - ortho[0][c]).abs() <= 1e-4 * (1.0 + ortho[0][c].abs()),
                "{ortho:?}"
            );
        }
    }
    let perspective = background(Projection::Perspective);
    assert!(
        perspective[1..].iter().any(|p| (0..3).any(|c| {
            (p[c] - perspective[0][c]).abs() > 0.01 * (1.0 + perspective[0][c].abs())
        })),
        "{perspective:?}"
    );
}
