//! The texture graph's material bindings on the GPU: layers, mix and math
//! against the CPU reference; opacity and emission against closed forms.

use crate::common::*;
use glam::{Vec2, Vec3};
use marbre_core::scene::{
    Cylinder, EnvSource, Ground, Layer, Material, MathOp, OrbitCamera, Pattern, PatternKind,
    PointLight, Polygon, Property, Scene, Sphere, Texture, UvFrame,
};
use marbre_render::gpu::testing::gpu_or_skip;

/// A diffuse property built from every node kind of the graph that is not a
/// pattern: a mix whose factor is a checker passed through math steps (0.2
/// or 0.8), of red and of bricks; and a layer whose mask is a cutout, setting
/// the diffuse colour to a waves ramp inside the discs. Rendered on a
/// Lambert ground in white light, each pixel must show
/// `Material::value(Diffuse)`.
#[test]
fn layers_mix_and_math_render_the_cpu_reference() {
    let Some(ctx) = gpu_or_skip("layers_mix_and_math_render_the_cpu_reference") else {
        return;
    };
    let mut factor = Texture::blend(
        Pattern::Checker2d {
            size: Vec2::splat(0.5),
            phase: 0.0,
        },
        0.0,
        1.0,
    );
    factor.ops = vec![
        MathOp::Scale(0.6),
        MathOp::Bias(0.2),
        MathOp::Invert,
        MathOp::Power(1.0),
    ];
    let bricks = Texture::blend(
        Pattern::Brick {
            size: Vec2::new(0.5, 0.25),
            mortar: 0.08,
            row_offset: 0.5,
        },
        Vec3::new(0.9, 0.9, 0.85),
        Vec3::new(0.6, 0.2, 0.1),
    );
    let mut diffuse = Texture::mix(factor, Vec3::new(0.8, 0.1, 0.1), bricks);
    diffuse.ops = vec![MathOp::Clamp {
        min: 0.15,
        max: 0.7,
    }];
    let mut scene = textured_ground_in_white_light(diffuse);
    let ground = scene.ground.as_mut().unwrap();
    ground.material.layers.push(Layer {
        name: "discs".into(),
        mask: Texture::blend(
            Pattern::Cutout {
                sides: 0,
                radius: 0.3,
            },
            0.0,
            1.0,
        ),
        diffuse: Some(Texture::color(Vec3::new(0.1, 0.3, 0.9))),
        ..Layer::default()
    });
    scene.camera = OrbitCamera {
        target: Vec3::new(0.3, 0.0, -0.2),
        distance: 3.0,
        yaw_degrees: 20.0,
        pitch_degrees: 70.0,
        fov_degrees: 40.0,
        ..Default::default()
    };
    let material = scene.ground.as_ref().unwrap().material.clone();
    let (w, h) = (96, 64);
    let pixels = render(&ctx, &scene, (w, h), 4);
    assert_ground_matches(&scene, &pixels, (w, h), 0.3, |p, uv| {
        material.value(Property::Diffuse, p, uv)
    });
}

/// Massal's marble through the generated WGSL (his turbulence as the
/// material's signal, in linear levels): its blend factor thresholded at
/// 0.505 by math steps (t − 0.5, × 100, clamped to [0.2, 0.8]: the GPU's
/// 1e-5 from the CPU cannot cross the 6e-3 wide band) so that each
/// pixel away from a stripe's edge has one value, which must be the CPU
/// reference's (`Material::value`).
#[test]
fn massal_marble_renders_the_cpu_reference() {
    let Some(ctx) = gpu_or_skip("massal_marble_renders_the_cpu_reference") else {
        return;
    };
    let mut diffuse = Texture::blend(
        Pattern::MassalMarble {
            noise: marbre_core::noise::NoiseSettings::massal(1.5),
            stripe_frequency: 1.5,
        },
        0.0,
        1.0,
    );
    diffuse.ops = vec![
        MathOp::Bias(-0.5),
        MathOp::Scale(100.0),
        MathOp::Clamp { min: 0.2, max: 0.8 },
    ];
    let mut scene = textured_ground_in_white_light(diffuse);
    scene.camera = OrbitCamera {
        target: Vec3::new(0.5, 0.0, -0.3),
        distance: 4.0,
        yaw_degrees: 10.0,
        pitch_degrees: 75.0,
        fov_degrees: 50.0,
        ..Default::default()
    };
    let material = scene.ground.as_ref().unwrap().material.clone();
    let (w, h) = (96, 64);
    let pixels = render(&ctx, &scene, (w, h), 4);
    assert_ground_matches(&scene, &pixels, (w, h), 0.3, |p, uv| {
        material.value(Property::Diffuse, p, uv)
    });
    // Both sides of the threshold are on screen: the stripes are drawn.
    let values: Vec<f32> = pixels.iter().map(|p| p[0]).collect();
    let lo = values.iter().copied().fold(f32::MAX, f32::min);
    let hi = values.iter().copied().fold(f32::MIN, f32::max);
    assert!(hi > 2.0 * lo, "one tone only: {lo}..{hi}");
}

/// Every pattern of the table (the image apart: `image_texture_renders_the_
/// cpu_reference`) with its fresh numbers, through the generated WGSL, on
/// a ground in white light (their noise in two octaves): its blend factor
/// thresholded halfway across its range in the image by math steps (t −
/// threshold, × 100, clamped to [0.2, 0.8]) so that each pixel away
/// from an edge has one value, which must be the CPU reference's. A pattern
/// added to the table is tested here without a line more.
#[test]
fn every_pattern_of_the_table_renders_its_cpu_reference() {
    let Some(ctx) = gpu_or_skip("every_pattern_of_the_table_renders_its_cpu_reference") else {
        return;
    };
    for kind in PatternKind::all().filter(|&k| k != PatternKind::Image) {
        let name = kind.info().name;
        let mut pattern = Pattern::fresh(kind, None);
        // Two octaves: finer islands of the thresholded sum would slip
        // between the reference's samples of a pixel.
        if let Some(noise) = pattern.noise_mut() {
            noise.fractal.octaves = 2.0;
        }
        let mut diffuse = Texture::blend(pattern, 0.0, 1.0);
        if kind == PatternKind::Mix {
            diffuse.factor = Some(Box::new(Texture::blend(
                Pattern::Checker { size: 0.7 },
                0.0,
                1.0,
            )));
        }
        println!("pattern: {name}");
        let mut scene = textured_ground_in_white_light(diffuse.clone());
        scene.camera = OrbitCamera {
            target: Vec3::new(0.3, 0.0, 0.3),
            distance: 1.5,
            yaw_degrees: 10.0,
            pitch_degrees: 75.0,
            fov_degrees: 50.0,
            ..Default::default()
        };
        let (w, h) = (64, 48);
        // The threshold: halfway between the least and the greatest t at
        // the pixels' centres.
        let t: Vec<f32> = (0..w * h)
            .map(|i| {
                let at = Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
                let p = ground_point(&scene, (w, h), at);
                diffuse.eval(p, Vec2::new(p.x, p.z)).x
            })
            .collect();
        let lo = t.iter().copied().fold(f32::MAX, f32::min);
        let hi = t.iter().copied().fold(f32::MIN, f32::max);
        diffuse.ops = vec![
            MathOp::Bias(-0.5 * (lo + hi)),
            MathOp::Scale(100.0),
            MathOp::Clamp { min: 0.2, max: 0.8 },
        ];
        scene.ground.as_mut().unwrap().material.diffuse = diffuse;
        let material = scene.ground.as_ref().unwrap().material.clone();
        let pixels = render(&ctx, &scene, (w, h), 4);
        assert_ground_matches(&scene, &pixels, (w, h), 0.3, |p, uv| {
            material.value(Property::Diffuse, p, uv)
        });
        // Both sides of the threshold are on screen, but for the constant.
        let values: Vec<f32> = pixels.iter().map(|p| p[0]).collect();
        let lo = values.iter().copied().fold(f32::MAX, f32::min);
        let hi = values.iter().copied().fold(f32::MIN, f32::max);
        assert_eq!(
            hi > 2.0 * lo,
            kind != PatternKind::Constant,
            "{name}: {lo}..{hi}"
        );
    }
}

/// A sphere that is black but emits E, with opacity α, in a constant
/// environment L, looked at through its centre: the ray meets the front
/// surface (emission E, then nothing: black) with probability α, else
/// crosses it and meets the back one the same way, else escapes. So the
/// pixel is `αE + (1-α)(αE + (1-α)L)`.
#[test]
fn opacity_and_emission_match_the_closed_form() {
    let Some(ctx) = gpu_or_skip("opacity_and_emission_match_the_closed_form") else {
        return;
    };
    let (alpha, emission, strength, env) = (0.5, 0.3, 2.0, 1.0);
    let material = Material {
        opacity: Texture::scalar(alpha),
        emission: Texture::color(Vec3::splat(emission)),
        emission_strength: strength,
        ..lambert(0.0)
    };
    let mut scene = Scene {
        spheres: vec![Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
            material,
            ..Sphere::default()
        }],
        camera: OrbitCamera {
            target: Vec3::ZERO,
            distance: 5.0,
            yaw_degrees: 0.0,
            pitch_degrees: 0.0,
            fov_degrees: 10.0,
            ..Default::default()
        },
        ..Scene::default()
    };
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::splat(env),
    };
    scene.environment.background_visible = true;
    let (w, h) = (16, 16);
    let pixels = render(&ctx, &scene, (w, h), 64);
    // The sphere fills the view (its radius subtends 11.5°, the view ±5°).
    let mean = pixels.iter().map(|p| p[0]).sum::<f32>() / pixels.len() as f32;
    let e = emission * strength;
    let expected = alpha * e + (1.0 - alpha) * (alpha * e + (1.0 - alpha) * env);
    // Each sample is 0.6 or 1.0 (std 0.17); 16,384 of them: std 0.0013.
    assert!(
        (mean - expected).abs() < 0.01,
        "mean {mean}, closed form {expected}"
    );
    for p in &pixels {
        assert!(p[..3].iter().all(|c| (0.55..=1.0).contains(c)), "{p:?}");
    }
}

/// A point light over a Lambert ground, a black sphere of opacity α in
/// between: under the sphere the shadow ray crosses two surfaces, each
/// letting 1 - α through, so the ground there gets (1 - α)² of the light it
/// gets without the sphere. Shadow rays are deterministic: the ratio is
/// exact up to rounding.
#[test]
fn a_half_opaque_sphere_lets_a_quarter_of_the_light_through() {
    let Some(ctx) = gpu_or_skip("a_half_opaque_sphere_lets_a_quarter_of_the_light_through") else {
        return;
    };
    let alpha = 0.5;
    let mut scene = Scene {
        ground: Some(Ground {
            height: 0.0,
            uv_frame: None,
            material: lambert(0.5),
        }),
        point_light: Some(PointLight {
            position: Vec3::new(0.0, 4.0, 0.0),
            color: Vec3::ONE,
            intensity: 10.0,
        }),
        camera: OrbitCamera {
            target: Vec3::ZERO,
            distance: 3.0,
            yaw_degrees: 0.0,
            pitch_degrees: 60.0,
            fov_degrees: 6.0,
            ..Default::default()
        },
        ..Scene::default()
    };
    scene.render.max_bounces = 1;
    let (w, h) = (8, 8);
    let open = render(&ctx, &scene, (w, h), 4);
    scene.spheres.push(Sphere {
        center: Vec3::new(0.0, 2.0, 0.0),
        radius: 0.5,
        material: Material {
            opacity: Texture::scalar(alpha),
            ..lambert(0.0)
        },
        ..Sphere::default()
    });
    let shaded = render(&ctx, &scene, (w, h), 4);
    for (a, b) in open.iter().zip(&shaded) {
        assert!(a[0] > 0.01, "the ground is lit: {a:?}");
        let ratio = b[0] / a[0];
        assert!(
            (ratio - (1.0 - alpha) * (1.0 - alpha)).abs() < 1e-3,
            "ratio {ratio}: {b:?} / {a:?}"
        );
    }
}

/// A noise bump: a Lambert ground whose height is fBm, lit by a point light
/// straight above. Each pixel must show ρ/π · I/d² · n·l with n the normal
/// the CPU gets from central differences of the same height texture (the
/// fractal sums taken at the offset points, as the shader must), averaged
/// over the pixel.
#[test]
fn noise_bump_renders_the_cpu_finite_difference_normal() {
    let Some(ctx) = gpu_or_skip("noise_bump_renders_the_cpu_finite_difference_normal") else {
        return;
    };
    let (albedo, intensity, bump_height) = (0.5_f32, 20.0_f32, 0.3_f32);
    let light = Vec3::new(0.0, 2.0, 0.0);
    let mut material = lambert(albedo);
    material.bump = Texture::blend(
        Pattern::Fbm {
            noise: marbre_core::noise::NoiseSettings {
                fractal: marbre_core::noise::FractalParams {
                    octaves: 2.0,
                    frequency: 2.0,
                    ..Default::default()
                },
                ..Default::default()
            },
        },
        0.0,
        1.0,
    );
    material.bump_height = bump_height;
    let mut scene = Scene {
        ground: Some(Ground {
            height: 0.0,
            uv_frame: None,
            material: material.clone(),
        }),
        point_light: Some(PointLight {
            position: light,
            color: Vec3::ONE,
            intensity,
        }),
        camera: OrbitCamera {
            target: Vec3::ZERO,
            distance: 5.0,
            yaw_degrees: 0.0,
            pitch_degrees: 89.0,
            fov_degrees: 20.0,
            ..Default::default()
        },
        ..Scene::default()
    };
    scene.render.max_bounces = 1;
    let (w, h) = (48, 48);
    let pixels = render(&ctx, &scene, (w, h), 64);
    let height = |p: Vec3| material.bump.eval(p, Vec2::new(p.x, p.z)).x;
    let step = 1e-3;
    let mut tilted = 0;
    for y in 0..h {
        for x in 0..w {
            // The pixel's mean over an 8×8 grid of points, as the jittered
            // samples average it.
            let (mut expected, mut n) = (0.0, Vec3::ZERO);
            for k in 0..64 {
                let at = Vec2::new(
                    x as f32 + (k % 8) as f32 / 8.0 + 0.0625,
                    y as f32 + (k / 8) as f32 / 8.0 + 0.0625,
                );
                let p = ground_point(&scene, (w, h), at);
                let dh_du =
                    (height(p + step * Vec3::X) - height(p - step * Vec3::X)) / (2.0 * step);
                let dh_dv =
                    (height(p + step * Vec3::Z) - height(p - step * Vec3::Z)) / (2.0 * step);
                n = marbre_core::texture::bumped_normal(
                    Vec3::Y,
                    Vec3::X,
                    Vec3::Z,
                    bump_height * dh_du,
                    bump_height * dh_dv,
                );
                let to_light = light - p;
                expected += albedo / std::f32::consts::PI * intensity / to_light.length_squared()
                    * n.dot(to_light.normalize()).max(0.0)
                    / 64.0;
            }
            let got = pixels[(y * w + x) as usize][0];
            assert!(
                (got - expected).abs() < 0.02 * expected + 1e-3,
                "pixel {x},{y}: rendered {got}, CPU normal {n} gives {expected}"
            );
            tilted += usize::from(n.y < 0.98);
        }
    }
    assert!(
        tilted > (w * h / 4) as usize,
        "only {tilted} pixels are tilted"
    );
}

/// A Lambert surface of a convex object alone in a white environment of
/// radiance 1 reflects exactly its albedo, so the image shows the diffuse
/// texture. A polygon with an oblique (u, v) frame given in the scene, and a
/// capped cylinder, each with a uv checker: every pixel lying in one cell
/// must show the checker at the (u, v) the CPU mapping gives there.
#[test]
fn polygon_and_cylinder_map_uv_as_the_cpu() {
    let Some(ctx) = gpu_or_skip("polygon_and_cylinder_map_uv_as_the_cpu") else {
        return;
    };
    let checker = Texture::blend(
        Pattern::Checker2d {
            size: Vec2::new(0.25, 0.2),
            phase: 0.5,
        },
        Vec3::new(0.8, 0.3, 0.1),
        Vec3::new(0.1, 0.4, 0.8),
    );
    let material = Material {
        diffuse: checker.clone(),
        ..lambert(0.5)
    };
    let frame = UvFrame {
        origin: Vec3::new(-1.0, 0.0, 0.0),
        u_axis: Vec3::new(2.0, 0.0, 0.0),
        v_axis: Vec3::new(0.5, 1.5, 0.0),
    };
    let polygon = Polygon {
        vertices: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.2, 0.8, 0.0),
            Vec3::new(0.0, 1.2, 0.0),
            Vec3::new(-1.1, 0.6, 0.0),
        ],
        uv_frame: Some(frame),
        material: material.clone(),
        ..Polygon::default()
    };
    let camera = OrbitCamera {
        target: Vec3::ZERO,
        distance: 4.0,
        yaw_degrees: 15.0,
        pitch_degrees: 10.0,
        fov_degrees: 40.0,
        ..Default::default()
    };
    let mut scene = Scene {
        polygons: vec![polygon.clone()],
        camera,
        render: point_sampled(),
        ..Scene::default()
    };
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::ONE,
    };
    let (w, h) = (64, 64);
    let pixels = render(&ctx, &scene, (w, h), 4);
    let n = polygon.normal().unwrap();
    let inside = |p: Vec3| {
        let v = &polygon.vertices;
        (0..v.len()).all(|i| (v[(i + 1) % v.len()] - v[i]).cross(p - v[i]).dot(n) > 0.0)
    };
    assert_pixels_match(&pixels, (w, h), 0.2, |at| {
        let (o, d) = camera_ray(&scene, (w, h), at);
        let p = o + (polygon.vertices[0] - o).dot(n) / d.dot(n) * d;
        let uv = marbre_core::texture::plane_uv(p, frame.origin, frame.u_axis, frame.v_axis);
        inside(p).then(|| checker.eval(p, uv))
    });

    let cylinder = Cylinder {
        base: Vec3::new(0.0, -1.0, 0.0),
        radius: 0.8,
        height: 2.0,
        material,
        ..Cylinder::default()
    };
    scene.polygons.clear();
    scene.cylinders.push(cylinder.clone());
    let pixels = render(&ctx, &scene, (w, h), 4);
    assert_pixels_match(&pixels, (w, h), 0.2, |at| {
        let (o, d) = camera_ray(&scene, (w, h), at);
        // The nearest side hit (the caps are out of view from this pitch
        // only at the top; rays through a cap are left out).
        let f = o - cylinder.base;
        let a = d.x * d.x + d.z * d.z;
        let b = f.x * d.x + f.z * d.z;
        let c = f.x * f.x + f.z * f.z - cylinder.radius * cylinder.radius;
        let disc = b * b - a * c;
        if disc < 0.0 {
            return None;
        }
        let t = (-b - disc.sqrt()) / a;
        let local = f + t * d;
        ((0.0..=cylinder.height).contains(&local.y)).then(|| {
            let uv = marbre_core::texture::cylinder_uv(local, cylinder.height);
            checker.eval(local, uv)
        })
    });
}

/// Mappings: on a sphere away from the origin, a uv checker whose cells
/// hold wood rings taken in world coordinates through a rotation and scale
/// (their turbulence signal mapped the same way) and a 3D checker taken in
/// the object's frame through a translation. Every pixel lying in one region
/// must show `Material::value_at` of the hit, with the object point relative
/// to the centre and the world point as is.
#[test]
fn mapped_textures_render_the_cpu_reference() {
    let Some(ctx) = gpu_or_skip("mapped_textures_render_the_cpu_reference") else {
        return;
    };
    use marbre_core::scene::{MappingSpace, TextureMapping};
    use marbre_core::texture::TextureTransform;
    let mut wood = Texture::blend(
        Pattern::Wood {
            noise: marbre_core::noise::NoiseSettings::default(),
            ring_width: 0.15,
            turbulence_amount: 0.3,
        },
        Vec3::new(0.4, 0.2, 0.05),
        Vec3::new(0.8, 0.6, 0.3),
    );
    wood.mapping = Some(TextureMapping {
        frame: None,
        space: MappingSpace::World,
        transform: TextureTransform {
            translate: Vec3::new(0.2, 0.0, 0.0),
            rotate_degrees: Vec3::new(0.0, 30.0, 10.0),
            scale: Vec3::splat(0.7),
        },
    });
    let mut cubes = Texture::blend(
        Pattern::Checker { size: 0.5 },
        Vec3::new(0.1, 0.5, 0.2),
        Vec3::new(0.9, 0.9, 0.9),
    );
    cubes.mapping = Some(TextureMapping {
        frame: None,
        space: MappingSpace::Object,
        transform: TextureTransform {
            translate: Vec3::new(0.25, 0.1, 0.0),
            ..TextureTransform::default()
        },
    });
    let diffuse = Texture::blend(
        Pattern::Checker2d {
            size: Vec2::new(0.25, 0.5),
            phase: 0.0,
        },
        wood,
        cubes,
    );
    assert_sphere_shows_its_diffuse(&ctx, diffuse);
}

/// An image texture in a render: an 8×8 PNG of distinct colours, nearest
/// filtered and mirrored twice across a polygon (through a mapping), lit as
/// the polygon above. Every pixel lying in one texel shows that texel as the
/// CPU samples the atlas (sRGB decoded to linear).
#[test]
fn image_texture_renders_the_cpu_reference() {
    let Some(ctx) = gpu_or_skip("image_texture_renders_the_cpu_reference") else {
        return;
    };
    use marbre_core::scene::{MappingSpace, SurfacePoint, TextureMapping};
    use marbre_core::texture::{ImageFilter, ImageSource, ImageWrap, TextureTransform};
    let dir = std::env::temp_dir().join(format!("marbre-image-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("colours.png");
    let png = image::RgbImage::from_fn(8, 8, |x, y| {
        image::Rgb([(x * 32 + 8) as u8, (y * 32 + 8) as u8, ((x + y) * 16) as u8])
    });
    png.save(&path).unwrap();
    let mut diffuse = Texture::blend(
        Pattern::Image {
            filter: ImageFilter::Nearest,
            wrap: ImageWrap::Mirror,
        },
        0.0,
        0.0,
    );
    diffuse.image = Some(ImageSource {
        path: path.clone(),
        color_space: Default::default(),
    });
    diffuse.mapping = Some(TextureMapping {
        frame: None,
        space: MappingSpace::Object,
        transform: TextureTransform {
            scale: Vec3::new(0.5, 0.5, 1.0),
            ..TextureTransform::default()
        },
    });
    let polygon = Polygon {
        vertices: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        material: Material {
            diffuse: diffuse.clone(),
            ..lambert(0.5)
        },
        ..Polygon::default()
    };
    let mut scene = Scene {
        polygons: vec![polygon.clone()],
        camera: OrbitCamera {
            target: Vec3::ZERO,
            distance: 3.0,
            yaw_degrees: 0.0,
            pitch_degrees: 0.0,
            fov_degrees: 40.0,
            ..Default::default()
        },
        ..Scene::default()
    };
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::ONE,
    };
    let mut notes = Vec::new();
    let images = marbre_render::session::load_images(&scene, &mut notes).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    let (w, h) = (64, 64);
    let mut renderer = marbre_render::gpu::Renderer::new(&ctx, &scene, None, (w, h)).unwrap();
    renderer.set_images(&ctx, images.clone()).unwrap();
    marbre_render::session::accumulate(&ctx, &mut renderer, 4, |_| {}).unwrap();
    let (_, _, pixels) = renderer.read_radiance(&ctx).unwrap();
    let frame = polygon.frame().unwrap();
    assert_pixels_match(&pixels, (w, h), 0.3, |at| {
        let (o, d) = camera_ray(&scene, (w, h), at);
        let p = o + (-o.z / d.z) * d;
        let uv = marbre_core::texture::plane_uv(p, frame.origin, frame.u_axis, frame.v_axis);
        let inside = p.x.abs() < 1.0 && p.y.abs() < 1.0;
        inside.then(|| diffuse.eval_with(&SurfacePoint::new(p, uv), &images))
    });
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The RMS difference of two images over the rows `rows` (the far ground).
fn rms_over_rows(a: &[[f32; 4]], b: &[[f32; 4]], w: u32, rows: std::ops::Range<u32>) -> f32 {
    let mut sum = 0.0;
    let mut n = 0;
    for y in rows {
        for x in 0..w {
            let (p, q) = (a[(y * w + x) as usize], b[(y * w + x) as usize]);
            sum += (0..3).map(|c| (p[c] - q[c]).powi(2)).sum::<f32>();
            n += 3;
        }
    }
    (sum / n as f32).sqrt()
}

/// Procedural anti-aliasing, measured: a ground seen at a grazing angle,
/// where far cells and octaves are far smaller than a pixel. One sample per
/// pixel with footprint filtering must be much closer to the supersampled
/// (256 jittered samples, point sampled) image than one point sample is:
/// for a 2D checker and a 3D one (box-filtered in closed form) and for fBm
/// (octaves clamped to the footprint). The same holds seen in a mirror,
/// where the footprint is the cone's after the bounce. Measured on
/// lavapipe (RMSE over the far rows, point → filtered): 2D checker 0.40 →
/// 0.05, 3D checker 0.40 → 0.04, fBm 0.085 → 0.039; in the mirror 0.36 →
/// 0.07, 0.36 → 0.07, 0.099 → 0.070.
#[test]
fn footprint_filtering_brings_one_sample_near_the_supersampled_image() {
    let Some(ctx) =
        gpu_or_skip("footprint_filtering_brings_one_sample_near_the_supersampled_image")
    else {
        return;
    };
    let (w, h) = (96, 48);
    // The fraction of the point-sampled error filtering must stay under:
    // a checker's edges filter exactly; noise keeps the jitter of the
    // octaves a pixel resolves.
    for ((name, texture), ratio) in marbre_core::aa_scenes::textures()
        .into_iter()
        .zip([0.3, 0.3, 0.8])
    {
        for mirrored in [false, true] {
            let mut scene = marbre_core::aa_scenes::grazing_ground(texture.clone());
            if mirrored {
                // An upright mirror facing the camera: it shows the ground
                // behind the camera, as far away and as grazing.
                scene.polygons.push(Polygon {
                    vertices: vec![
                        Vec3::new(-4.0, 0.2, -1.0),
                        Vec3::new(4.0, 0.2, -1.0),
                        Vec3::new(4.0, 3.0, -1.0),
                        Vec3::new(-4.0, 3.0, -1.0),
                    ],
                    material: Material {
                        mirror: Texture::scalar(1.0),
                        ..lambert(0.0)
                    },
                    ..Polygon::default()
                });
            }
            let reference = render(&ctx, &scene, (w, h), 256);
            let point = render(&ctx, &scene, (w, h), 1);
            scene.render.filter_checkers = true;
            scene.render.clamp_octaves = true;
            let filtered = render(&ctx, &scene, (w, h), 1);
            // The upper half of the image: the far ground (or its reflection).
            let rows = if mirrored { 8..24 } else { 14..24 };
            let e_point = rms_over_rows(&point, &reference, w, rows.clone());
            let e_filtered = rms_over_rows(&filtered, &reference, w, rows);
            eprintln!(
                "{name}, mirror {mirrored}: 1 spp RMSE point {e_point:.4}, filtered {e_filtered:.4}"
            );
            assert!(
                e_filtered < ratio * e_point,
                "{name}, mirror {mirrored}: filtered {e_filtered} vs point {e_point}"
            );
        }
    }
}

/// A structural edit builds its shader off the render thread: until the
/// build is done the renderer keeps the old pipeline and draws the old
/// scene; then it installs the new one. An edit the code generator refuses
/// (more texture parameters than the renderer holds) leaves everything as
/// it was and says why.
#[test]
fn structural_edits_build_in_the_background_and_keep_the_old_pipeline() {
    let Some(ctx) =
        gpu_or_skip("structural_edits_build_in_the_background_and_keep_the_old_pipeline")
    else {
        return;
    };
    let red = Vec3::new(0.8, 0.1, 0.1);
    let mut scene = textured_ground_in_white_light(Texture::color(red));
    scene.camera = OrbitCamera {
        target: Vec3::new(1.0, 0.0, 1.0),
        distance: 2.0,
        yaw_degrees: 0.0,
        pitch_degrees: 89.0,
        fov_degrees: 10.0,
        ..Default::default()
    };
    let size = (16, 16);
    let mut renderer = marbre_render::gpu::Renderer::new(&ctx, &scene, None, size).unwrap();
    let before = renderer.features().clone();

    let mut edited = scene.clone();
    edited.ground.as_mut().unwrap().material.diffuse = Texture::blend(
        Pattern::Checker2d {
            size: Vec2::splat(1000.0),
            phase: 0.0,
        },
        Vec3::new(0.1, 0.8, 0.1),
        Vec3::new(0.1, 0.1, 0.8),
    );
    renderer
        .request_scene(
            &ctx,
            &edited,
            edited.changes_from(renderer.requested_scene()),
        )
        .unwrap();
    assert!(renderer.is_building());
    // Meanwhile: the old pipeline, the old scene.
    assert_eq!(renderer.features(), &before);
    assert_eq!(renderer.scene(), &scene);
    marbre_render::session::accumulate(&ctx, &mut renderer, 1, |_| {}).unwrap();
    let (_, _, pixels) = renderer.read_radiance(&ctx).unwrap();
    assert!((pixels[0][0] - red.x).abs() < 1e-3, "{:?}", pixels[0]);

    let started = std::time::Instant::now();
    let took = loop {
        if let Some(result) = renderer.poll_build(&ctx) {
            break result.unwrap();
        }
        // Generous: a loaded machine only makes the build slower.
        assert!(
            started.elapsed().as_secs() < 300,
            "the build never finished"
        );
        std::thread::sleep(std::time::Duration::from_millis(5));
    };
    eprintln!("background shader build: {took:?}");
    assert!(!renderer.is_building());
    assert!(
        renderer
            .features()
            .contains(marbre_render::gpu::Feature::Pattern(
                marbre_core::scene::PatternKind::Checker2d
            ))
    );
    assert_eq!(renderer.scene(), &edited);
    let first_frame = std::time::Instant::now();
    marbre_render::session::accumulate(&ctx, &mut renderer, 1, |_| {}).unwrap();
    eprintln!(
        "first frame with the new pipeline: {:?}",
        first_frame.elapsed()
    );
    let (_, _, pixels) = renderer.read_radiance(&ctx).unwrap();
    assert!((pixels[0][1] - 0.8).abs() < 1e-3, "{:?}", pixels[0]);

    // Refused: 300 ramps of 8 stops need 2,400 parameter slots.
    let mut huge = edited.clone();
    let mut ramped = Texture::blend(
        Pattern::Waves {
            frequency: 1.0,
            direction: Vec2::X,
        },
        0.0,
        1.0,
    );
    ramped.ramp = (0..8)
        .map(|i| marbre_core::texture::RampStop {
            position: i as f32 / 7.0,
            color: Vec3::splat(i as f32 / 7.0),
        })
        .collect();
    let mut layers = Vec::new();
    for i in 0..300 {
        layers.push(Layer {
            name: format!("layer {i}"),
            mask: ramped.clone(),
            ..Layer::default()
        });
    }
    huge.ground.as_mut().unwrap().material.layers = layers;
    let error = renderer
        .request_scene(&ctx, &huge, huge.changes_from(renderer.requested_scene()))
        .unwrap_err();
    assert!(
        format!("{error:#}").contains("parameter slots"),
        "{error:#}"
    );
    assert!(!renderer.is_building());
    assert_eq!(renderer.scene(), &edited);
}
