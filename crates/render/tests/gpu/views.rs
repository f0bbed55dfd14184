//! The views of the first hit (`scene::View`, the Monte Carlo lab's
//! exercises 1 and 2): each against geometry computed on the CPU, the
//! radiance target holding the view's values as they are, and the display
//! showing them unexposed.

use crate::common::*;
use glam::{Vec2, Vec3};
use marbre_core::scene::{
    DisplaySettings, Material, OrbitCamera, Scene, Sphere, Texture, ToneMap, View,
};
use marbre_render::gpu::Renderer;
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::session::accumulate;

/// A unit sphere at the origin, looked at head-on from 4 away.
fn sphere_scene(view: View, material: Material) -> Scene {
    let mut scene = Scene {
        spheres: vec![Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
            material,
            ..Sphere::default()
        }],
        camera: OrbitCamera {
            target: Vec3::ZERO,
            distance: 4.0,
            pitch_degrees: 0.0,
            ..OrbitCamera::default()
        },
        ..Scene::default()
    };
    scene.render.view = view;
    scene
}

/// The fraction of pixel (x, y) whose camera rays meet the unit sphere at
/// the origin, on a 32 × 32 grid of points in the pixel.
fn sphere_coverage(scene: &Scene, size: (u32, u32), x: u32, y: u32) -> f64 {
    let n = 32;
    let mut hits = 0;
    for i in 0..n {
        for j in 0..n {
            let at = Vec2::new(
                x as f32 + (i as f32 + 0.5) / n as f32,
                y as f32 + (j as f32 + 0.5) / n as f32,
            );
            let (o, d) = camera_ray(scene, size, at);
            if (-o).cross(d).length() < 1.0 {
                hits += 1;
            }
        }
    }
    f64::from(hits) / f64::from(n * n)
}

/// Exercise 1: the hit mask of a sphere, averaged over 64 jittered samples
/// a pixel, is each pixel's coverage (within 4 standard deviations of a
/// coverage estimated by 64 samples, plus the CPU grid's 1/32), and its
/// sum is the area of the projected disc: radius tan(asin(r / D)) on the
/// image plane at distance 1, where a pixel is 2 tan(fov/2) / h wide.
#[test]
fn the_hit_mask_is_the_coverage_of_the_projected_disc() {
    let Some(ctx) = gpu_or_skip("the_hit_mask_is_the_coverage_of_the_projected_disc") else {
        return;
    };
    let scene = sphere_scene(View::HitMask, lambert(0.5));
    let (size, spp) = ((48, 32), 64);
    let pixels = render(&ctx, &scene, size, spp);
    let mut sum = 0.0f64;
    let mut variance = 0.0f64;
    for y in 0..size.1 {
        for x in 0..size.0 {
            let p = pixels[(y * size.0 + x) as usize];
            assert!(p[0] == p[1] && p[1] == p[2], "grey mask {p:?}");
            let c = sphere_coverage(&scene, size, x, y);
            let v = c * (1.0 - c);
            let tolerance = 4.0 * (v.max(0.03) / f64::from(spp)).sqrt() + 1.0 / 32.0;
            assert!(
                (f64::from(p[0]) - c).abs() < tolerance,
                "pixel ({x}, {y}): mask {} vs coverage {c}",
                p[0]
            );
            if c == 0.0 {
                assert_eq!(p[0], 0.0, "pixel ({x}, {y}) misses the sphere");
            }
            sum += f64::from(p[0]);
            variance += v / f64::from(spp);
        }
    }
    let tan_half_fov = (f64::from(scene.camera.fov_degrees) / 2.0)
        .to_radians()
        .tan();
    let disc = (1.0f64 / 4.0).asin().tan();
    let pixel = 2.0 * tan_half_fov / f64::from(size.1);
    let expected = std::f64::consts::PI * disc * disc / (pixel * pixel);
    eprintln!("hit mask: {sum:.2} pixels covered, the disc {expected:.2}");
    assert!(
        (sum - expected).abs() < 4.0 * variance.sqrt() + 0.5,
        "{sum} pixels covered, the projected disc is {expected}"
    );
}

/// Exercise 2: a quad of two triangles facing the camera, in the
/// primitive view. Every pixel wholly inside one triangle has that
/// triangle's colour exactly, the two colours differ, and pixels wholly
/// off the quad are black.
#[test]
fn each_triangle_of_a_quad_has_one_flat_colour() {
    let Some(ctx) = gpu_or_skip("each_triangle_of_a_quad_has_one_flat_colour") else {
        return;
    };
    let [a, b, c, d] =
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, y)| Vec3::new(x, y, 0.0));
    let mut scene = Scene {
        meshes: vec![mesh_of(vec![[a, b, c], [a, c, d]], lambert(0.5))],
        camera: OrbitCamera {
            target: Vec3::ZERO,
            distance: 4.0,
            pitch_degrees: 0.0,
            ..OrbitCamera::default()
        },
        ..Scene::default()
    };
    scene.render.view = View::Primitive;
    let size = (32, 32);
    let pixels = render(&ctx, &scene, size, 16);
    // Which part of the plane z = 0 the pixel's four corners (so, the
    // pixel, each part being convex) lie in: 0 below the diagonal y = x
    // (triangle abc), 1 above it (acd), 2 off the quad.
    let part = |at: Vec2| {
        let (o, dir) = camera_ray(&scene, size, at);
        let p = o - o.z / dir.z * dir;
        if p.x.abs() >= 1.0 || p.y.abs() >= 1.0 {
            2
        } else if p.y < p.x - 1e-3 {
            0
        } else if p.y > p.x + 1e-3 {
            1
        } else {
            3
        }
    };
    let mut colours: [Vec<[f32; 4]>; 3] = Default::default();
    for y in 0..size.1 {
        for x in 0..size.0 {
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .map(|(i, j)| part(Vec2::new(x as f32 + i, y as f32 + j)));
            if corners.iter().all(|&k| k == corners[0]) && corners[0] < 3 {
                colours[corners[0]].push(pixels[(y * size.0 + x) as usize]);
            }
        }
    }
    for (k, list) in colours.iter().enumerate() {
        assert!(
            list.len() > 20,
            "part {k}: only {} whole pixels",
            list.len()
        );
        for p in list {
            assert!(
                (0..3).all(|c| (p[c] - list[0][c]).abs() < 1e-6),
                "part {k}: {p:?} vs {:?}",
                list[0]
            );
        }
    }
    assert_eq!(colours[2][0][..3], [0.0; 3], "off the quad");
    let (t0, t1) = (colours[0][0], colours[1][0]);
    assert!(
        (0..3).map(|c| (t0[c] - t1[c]).abs()).fold(0.0, f32::max) > 0.05,
        "the two triangles share a colour: {t0:?}, {t1:?}"
    );
    assert!(t0[..3].iter().chain(&t1[..3]).all(|&c| c >= 0.15));
}

/// The normal, albedo and depth views at the pixel on the axis of a unit
/// sphere 4 away (a 65 × 65 image: the middle pixel straddles the axis):
/// the normal faces the camera (0.5, 0.5, 1), the albedo is the diffuse
/// colour, the depth t / (t + d) = 3 / 7. Where the ray escapes: black, and
/// depth 1. The radiance target holds the values as they are.
#[test]
fn normal_albedo_and_depth_on_the_axis_of_a_sphere() {
    let Some(ctx) = gpu_or_skip("normal_albedo_and_depth_on_the_axis_of_a_sphere") else {
        return;
    };
    let material = Material {
        diffuse: Texture::color(Vec3::new(0.3, 0.5, 0.7)),
        ..lambert(0.0)
    };
    let size = (65, 65);
    let middle = (32 * 65 + 32) as usize;
    for (view, on_axis, escaped) in [
        (View::Normal, [0.5, 0.5, 1.0], [0.0; 3]),
        (View::Albedo, [0.3, 0.5, 0.7], [0.0; 3]),
        (View::Depth, [3.0 / 7.0; 3], [1.0; 3]),
    ] {
        let pixels = render(&ctx, &sphere_scene(view, material.clone()), size, 64);
        for c in 0..3 {
            assert!(
                (pixels[middle][c] - on_axis[c]).abs() < 3e-3,
                "{view:?} on the axis: {:?}, expected {on_axis:?}",
                pixels[middle]
            );
            assert_eq!(pixels[0][c], escaped[c], "{view:?} in the corner");
        }
    }
}

/// What the display shows of a view: its values, neither exposed nor tone
/// mapped, whatever the preset's exposure and tone map. A hit mask under
/// +3 stops of ACES is white (255) on the sphere and black off it; an
/// albedo of 0.3 is sRGB(0.3), not ACES(0.3 · 8).
#[test]
fn views_are_displayed_unexposed() {
    let Some(ctx) = gpu_or_skip("views_are_displayed_unexposed") else {
        return;
    };
    let size = (33, 33);
    let mut scene = sphere_scene(View::HitMask, lambert(0.3));
    scene.render.display = DisplaySettings {
        exposure: 3.0,
        auto_exposure: false,
        tone_map: ToneMap::Aces,
        ..DisplaySettings::default()
    };
    let mut r = Renderer::new(&ctx, &scene, None, size).unwrap();
    accumulate(&ctx, &mut r, 4, |_| {}).unwrap();
    let image = r.read_display(&ctx).unwrap();
    assert_eq!(image.get_pixel(16, 16).0, [255, 255, 255, 255]);
    assert_eq!(image.get_pixel(0, 0).0, [0, 0, 0, 255]);
    scene.render.view = View::Albedo;
    r.set_scene(&ctx, &scene).unwrap();
    accumulate(&ctx, &mut r, 4, |_| {}).unwrap();
    let srgb = (1.055 * 0.3f32.powf(1.0 / 2.4) - 0.055) * 255.0;
    let shown = f32::from(r.read_display(&ctx).unwrap().get_pixel(16, 16).0[0]);
    assert!(
        (shown - srgb).abs() <= 1.0,
        "albedo 0.3 shown as {shown}, sRGB {srgb}"
    );
}
