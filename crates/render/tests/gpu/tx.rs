//! The TX language rendered: the report's 4 × 4 red and blue QUAD, lowered
//! onto a Lambert polygon under a white sky, shows its 16 cells where the
//! polygon's default frame puts them, in the colours the text types
//! (display values, decoded by the sRGB EOTF).

use crate::common::{camera_ray, lambert, point_sampled, render};
use glam::{Vec2, Vec3};
use marbre_core::scene::{EnvSource, OrbitCamera, Polygon, Scene};
use marbre_core::tx;
use marbre_render::gpu::testing::gpu_or_skip;
use std::path::Path;

/// The report's example #1 of QUAD, verbatim.
const QUAD00: &str = "QUAD UNI CD 0.8 0 0 FTX UNI CD 0 0 0.8 FTX GU 0.25 GV 0.25 FTX";

/// The sRGB EOTF (IEC 61966-2-1), written here independently.
fn eotf(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[test]
fn the_reports_4x4_checker_renders_its_16_cells_on_a_polygon() {
    let Some(ctx) = gpu_or_skip("the_reports_4x4_checker_renders_its_16_cells_on_a_polygon") else {
        return;
    };
    let doc = tx::parse(QUAD00).unwrap();
    let material = tx::lower_document(&doc, &lambert(0.5), Path::new(""))
        .unwrap()
        .material;
    // A 2 × 2 square in the plane z = 0, facing the camera: its default
    // frame has (u, v) = ((x + 1) / 2, y / 2).
    let mut scene = Scene {
        camera: OrbitCamera {
            target: Vec3::new(0.0, 1.0, 0.0),
            distance: 3.2,
            yaw_degrees: 0.0,
            pitch_degrees: 0.0,
            fov_degrees: 40.0,
            ..Default::default()
        },
        polygons: vec![Polygon {
            vertices: vec![
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 2.0, 0.0),
                Vec3::new(-1.0, 2.0, 0.0),
            ],
            material,
            ..Polygon::default()
        }],
        ground: None,
        point_light: None,
        render: point_sampled(),
        ..Scene::default()
    };
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::ONE,
    };
    let size = (64, 48);
    let pixels = render(&ctx, &scene, size, 4);
    let red = Vec3::new(eotf(0.8), 0.0, 0.0);
    let blue = Vec3::new(0.0, 0.0, eotf(0.8));
    // The cell under image point `at`, if the ray meets the polygon.
    let cell = |at: Vec2| {
        let (o, d) = camera_ray(&scene, size, at);
        let p = o - o.z / d.z * d;
        let uv = Vec2::new((p.x + 1.0) / 2.0, p.y / 2.0);
        ((0.0..1.0).contains(&uv.x) && (0.0..1.0).contains(&uv.y))
            .then(|| ((uv.x * 4.0).floor() as i32, (uv.y * 4.0).floor() as i32))
    };
    let mut seen = [[0; 4]; 4];
    for y in 0..size.1 {
        for x in 0..size.0 {
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)]
                .map(|(dx, dy)| cell(Vec2::new(x as f32 + dx, y as f32 + dy)));
            let Some((i, j)) = corners[0] else { continue };
            if corners.iter().any(|c| *c != Some((i, j))) {
                continue;
            }
            let expected = if (i + j) % 2 == 0 { red } else { blue };
            let got = pixels[(y * size.0 + x) as usize];
            for c in 0..3 {
                assert!(
                    (got[c] - expected[c]).abs() < 2e-3,
                    "pixel {x},{y} in cell ({i}, {j}): {got:?}, expected {expected}"
                );
            }
            seen[i as usize][j as usize] += 1;
        }
    }
    for (i, column) in seen.iter().enumerate() {
        for (j, n) in column.iter().enumerate() {
            assert!(
                *n >= 4,
                "cell ({i}, {j}) shows in only {n} whole pixels: {seen:?}"
            );
        }
    }
}
