//! The texture report's mapping frames on the GPU: the ground's (u, v)
//! frame (APTX) and a 3D mapping frame (ATX3D), each rendered against the
//! CPU reference pixel for pixel.

use crate::common::*;
use glam::{Vec2, Vec3};
use marbre_core::scene::{
    MappingSpace, OrbitCamera, Pattern, Property, Texture, TextureMapping, UvFrame,
};
use marbre_render::gpu::testing::gpu_or_skip;

/// The report's 4×4 QUAD (GU 0.25 GV 0.25) on the ground through an
/// oblique frame (origin (1, 0, −0.5), u = (2, 0, 0.5), v = (−0.5, 0, 1.5)):
/// every pixel lying in one cell shows the colour the CPU gives at the
/// frame's coordinates of the point, and world (x, z) would have given
/// another colour over a fifth of the image at least.
#[test]
fn a_checker_on_the_framed_ground_renders_the_cpu_reference() {
    let Some(ctx) = gpu_or_skip("a_checker_on_the_framed_ground_renders_the_cpu_reference") else {
        return;
    };
    let (red, blue) = (Vec3::new(0.8, 0.0, 0.0), Vec3::new(0.0, 0.0, 0.8));
    let quad = Texture::blend(
        Pattern::Checker2d {
            size: Vec2::splat(0.25),
            phase: 0.0,
        },
        red,
        blue,
    );
    let mut scene = textured_ground_in_white_light(quad);
    let ground = scene.ground.as_mut().unwrap();
    ground.uv_frame = Some(UvFrame {
        origin: Vec3::new(1.0, 0.0, -0.5),
        u_axis: Vec3::new(2.0, 0.0, 0.5),
        v_axis: Vec3::new(-0.5, 0.0, 1.5),
    });
    scene.camera = OrbitCamera {
        target: Vec3::new(1.0, 0.0, 0.5),
        distance: 6.0,
        yaw_degrees: 20.0,
        pitch_degrees: 60.0,
        fov_degrees: 50.0,
        ..Default::default()
    };
    let ground = scene.ground.clone().unwrap();
    let (w, h) = (64, 64);
    let pixels = render(&ctx, &scene, (w, h), 4);
    let reference = |at: Vec2| {
        let p = ground_point(&scene, (w, h), at);
        ground.material.value(Property::Diffuse, p, ground.uv(p))
    };
    assert_pixels_match(&pixels, (w, h), 0.3, |at| Some(reference(at)));
    // The frame matters: world (x, z) would give another colour over a
    // good part of the image (so the match above could not come from it).
    let differ = (0..w * h)
        .filter(|k| {
            let at = Vec2::new((k % w) as f32 + 0.5, (k / w) as f32 + 0.5);
            let p = ground_point(&scene, (w, h), at);
            let world = ground
                .material
                .value(Property::Diffuse, p, Vec2::new(p.x, p.z));
            (reference(at) - world).length() > 0.1
        })
        .count();
    assert!(
        differ as f32 > 0.2 * (w * h) as f32,
        "only {differ} pixels tell the frame from world (x, z)"
    );
}

/// ATX3D: a 3D checker on a sphere read through an oblique, stretched frame
/// in world space and then a translation: every pixel lying in one cell
/// shows `Material::value_at` of the hit.
#[test]
fn a_framed_3d_mapping_renders_the_cpu_reference() {
    let Some(ctx) = gpu_or_skip("a_framed_3d_mapping_renders_the_cpu_reference") else {
        return;
    };
    use marbre_core::texture::TextureTransform;
    let mut cubes = Texture::blend(
        Pattern::Checker { size: 0.5 },
        Vec3::new(0.1, 0.5, 0.2),
        Vec3::new(0.9, 0.9, 0.9),
    );
    cubes.mapping = Some(TextureMapping {
        space: MappingSpace::World,
        frame: Some(UvFrame {
            origin: Vec3::new(0.3, -0.2, 0.1),
            u_axis: Vec3::new(0.8, 0.3, 0.0),
            v_axis: Vec3::new(0.2, 1.2, 0.4),
        }),
        transform: TextureTransform {
            translate: Vec3::new(0.1, 0.0, 0.2),
            ..TextureTransform::default()
        },
    });
    assert_sphere_shows_its_diffuse(&ctx, cubes);
}
