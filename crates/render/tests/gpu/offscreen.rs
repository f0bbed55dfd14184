//! Offscreen renders with closed-form answers.

use crate::common::*;
use glam::Vec3;
use marbre_core::scene::{EnvSource, Ground, OrbitCamera, PointLight, Scene, Sphere, Texture};
use marbre_render::gpu::Renderer;
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::session::accumulate;

/// A diffuse sphere of albedo ρ under a constant white environment of
/// radiance 1 reflects exactly ρ: every cosine-sampled bounce escapes to the
/// environment (a convex object never sees itself), so the estimator has
/// zero variance and the tolerance can be tight.
#[test]
fn diffuse_sphere_in_a_white_environment_reads_its_albedo() {
    let Some(ctx) = gpu_or_skip("diffuse_sphere_in_a_white_environment_reads_its_albedo") else {
        return;
    };
    // The uber shader compiles the ground, the light and the env map in: its
    // runtime switches must keep them out of this scene.
    let uber = Some(marbre_render::gpu::FeatureSet::all());
    for (albedo, bounces, features) in [
        (0.6, 1, None),
        (0.6, 4, None),
        (1.0, 2, None),
        (0.6, 3, uber),
    ] {
        let mut scene = Scene::default();
        scene.spheres.push(Sphere {
            name: "ball".into(),
            center: Vec3::ZERO,
            radius: 1.0,
            material: lambert(albedo),
        });
        scene.environment.source = EnvSource::Constant {
            radiance: Vec3::ONE,
        };
        scene.camera = OrbitCamera {
            target: Vec3::ZERO,
            distance: 4.0,
            yaw_degrees: 30.0,
            pitch_degrees: 10.0,
            fov_degrees: 40.0,
            ..Default::default()
        };
        scene.render.max_bounces = bounces;
        let (w, h) = (64, 64);
        let pixels = render_with(&ctx, &scene, (w, h), 8, features.clone());
        // The sphere subtends asin(1/4) = 14.5° of the 20° half-field: the
        // central 30×30 pixels are all on it; the corners are all background.
        for y in 17..47 {
            for x in 17..47 {
                let p = pixels[(y * w + x) as usize];
                for c in &p[..3] {
                    assert!(
                        (c - albedo).abs() < 2e-3,
                        "albedo {albedo}, bounces {bounces}: {p:?} at {x},{y}"
                    );
                }
            }
        }
        let corner = pixels[0];
        assert!((corner[0] - 1.0).abs() < 1e-4, "background {corner:?}");
    }
}

/// A Lambert ground lit by a point light of intensity I at height h, seen
/// straight down: the point below the light reflects L = ρ/π · I / h². No
/// environment, so nothing else contributes.
#[test]
fn point_light_on_a_diffuse_plane_matches_the_closed_form() {
    let Some(ctx) = gpu_or_skip("point_light_on_a_diffuse_plane_matches_the_closed_form") else {
        return;
    };
    let (albedo, intensity, height) = (0.5_f32, 20.0_f32, 2.0_f32);
    let mut scene = Scene {
        ground: Some(Ground {
            height: 0.0,
            uv_frame: None,
            material: lambert(albedo),
        }),
        ..Scene::default()
    };
    scene.point_light = Some(PointLight {
        position: Vec3::new(0.0, height, 0.0),
        color: Vec3::ONE,
        intensity,
    });
    scene.camera = OrbitCamera {
        target: Vec3::ZERO,
        distance: 5.0,
        yaw_degrees: 0.0,
        pitch_degrees: 89.0,
        fov_degrees: 10.0,
        ..Default::default()
    };
    let (w, h) = (33, 33);
    let pixels = render(&ctx, &scene, (w, h), 16);
    let expected = albedo / std::f32::consts::PI * intensity / (height * height);
    let centre = pixels[(16 * w + 16) as usize];
    // The pixel footprint is ~0.03 units wide; across it the irradiance falls
    // by cos⁴, under 0.1% here.
    assert_channels_near(centre, expected, 2e-3, "centre");
    // Farther from the light it is darker: the inverse-square law is there.
    let edge = pixels[(16 * w) as usize];
    assert!(edge[0] < centre[0], "edge {edge:?} vs centre {centre:?}");
}

/// An integrating sphere: a point light of intensity I at the centre of a
/// closed Lambert sphere of radius R and albedo ρ gives every wall point the
/// same direct irradiance I/R², so every path of N bounces carries exactly
/// (ρ/π)(I/R²)·Σ_{k<N} ρ^k, one next-event term per bounce, with no variance.
/// It pins the bounce count: one shading too many or too few changes it.
#[test]
fn integrating_sphere_counts_one_light_sample_per_bounce() {
    let Some(ctx) = gpu_or_skip("integrating_sphere_counts_one_light_sample_per_bounce") else {
        return;
    };
    let (albedo, intensity, radius) = (0.5_f32, 30.0_f32, 5.0_f32);
    for (bounces, features) in [
        (1, None),
        (2, None),
        (4, None),
        (3, Some(marbre_render::gpu::FeatureSet::all())),
    ] {
        let mut scene = Scene::default();
        scene.spheres.push(Sphere {
            name: "integrating sphere".into(),
            center: Vec3::ZERO,
            radius,
            material: lambert(albedo),
        });
        scene.point_light = Some(PointLight {
            position: Vec3::ZERO,
            color: Vec3::ONE,
            intensity,
        });
        scene.environment.source = EnvSource::None;
        scene.camera = OrbitCamera {
            target: Vec3::ZERO,
            distance: 0.5,
            yaw_degrees: 20.0,
            pitch_degrees: 10.0,
            fov_degrees: 60.0,
            ..Default::default()
        };
        scene.render.max_bounces = bounces;
        // Russian roulette would add variance (not bias): off here.
        scene.render.transport.russian_roulette_from = 0;
        let pixels = render_with(&ctx, &scene, (16, 16), 2, features.clone());
        let series: f32 = (0..bounces).map(|k| albedo.powi(k as i32)).sum();
        let expected = albedo / std::f32::consts::PI * intensity / (radius * radius) * series;
        for p in &pixels {
            assert_channels_near(*p, expected, 1e-3, &format!("{bounces} bounces"));
        }
        // With Russian roulette from the first bounce, paths end at random
        // and survivors are weighted up: the mean stays the same.
        if bounces == 4 {
            scene.render.transport.russian_roulette_from = 1;
            let pixels = render_with(&ctx, &scene, (16, 16), 256, features);
            let mean = pixels.iter().map(|p| p[0]).sum::<f32>() / pixels.len() as f32;
            assert!(
                (mean - expected).abs() < 0.01 * expected,
                "Russian roulette: mean {mean}, expected {expected}"
            );
            assert!(
                pixels
                    .iter()
                    .any(|p| (p[0] - expected).abs() > 1e-3 * expected),
                "Russian roulette ended no path"
            );
        }
    }
}

/// A Lambert ground under a constant white environment reflects exactly its
/// albedo (every cosine-sampled bounce escapes upwards), so each pixel shows
/// the diffuse texture where its ray meets the ground. With a nested tree (a
/// board whose even cells hold phased 3×3 boards of red and of bricks, and
/// whose odd cells hold a pentagon cutout), the generated WGSL must agree
/// with the CPU reference `Texture::eval` wherever a pixel's footprint lies
/// in one cell.
#[test]
fn generated_texture_code_renders_the_cpu_reference() {
    let Some(ctx) = gpu_or_skip("generated_texture_code_renders_the_cpu_reference") else {
        return;
    };
    use glam::Vec2;
    use marbre_core::scene::Pattern;
    let inner = Texture::blend(
        Pattern::Checker2d {
            size: Vec2::splat(1.0 / 3.0),
            phase: 0.5,
        },
        Vec3::new(0.8, 0.1, 0.1),
        Texture::blend(
            Pattern::Brick {
                size: Vec2::new(0.5, 0.25),
                mortar: 0.08,
                row_offset: 0.5,
            },
            Vec3::new(0.9, 0.9, 0.85),
            Vec3::new(0.6, 0.2, 0.1),
        ),
    );
    let tree = Texture::blend(
        Pattern::Checker2d {
            size: Vec2::splat(0.5),
            phase: 0.0,
        },
        inner,
        Texture::blend(
            Pattern::Cutout {
                sides: 5,
                radius: 0.4,
            },
            Vec3::new(0.1, 0.1, 0.7),
            Vec3::new(0.9, 0.8, 0.1),
        ),
    );
    let mut scene = textured_ground_in_white_light(tree.clone());
    scene.camera = OrbitCamera {
        target: Vec3::new(0.3, 0.0, -0.2),
        distance: 3.0,
        yaw_degrees: 20.0,
        pitch_degrees: 70.0,
        fov_degrees: 40.0,
        ..Default::default()
    };
    let (w, h) = (96, 64);
    let pixels = render(&ctx, &scene, (w, h), 4);
    assert_ground_matches(&scene, &pixels, (w, h), 1.0 / 3.0, |p, uv| tree.eval(p, uv));
}

/// A colour ramp in the generated code: slow waves across the ground
/// (t from 0 to 1 over two units) mapped through five stops, rendered as in
/// the test above, against `Texture::eval` at each pixel's centre: away
/// from the stops the colour changes by at most 0.04 across a pixel, nearly
/// linearly, so 16 jittered samples average to the centre's value.
#[test]
fn generated_ramp_renders_the_cpu_reference() {
    let Some(ctx) = gpu_or_skip("generated_ramp_renders_the_cpu_reference") else {
        return;
    };
    use glam::Vec2;
    use marbre_core::scene::Pattern;
    use marbre_core::texture::RampStop;
    let stop = |position, r, g, b| RampStop {
        position,
        color: Vec3::new(r, g, b),
    };
    let mut ramp = Texture::blend(
        Pattern::Waves {
            frequency: 0.25,
            direction: Vec2::X,
        },
        0.0,
        1.0,
    );
    ramp.ramp = vec![
        stop(0.05, 0.8, 0.2, 0.2),
        stop(0.3, 0.8, 0.6, 0.2),
        stop(0.3, 0.2, 0.6, 0.2),
        stop(0.7, 0.2, 0.3, 0.7),
        stop(0.95, 0.7, 0.7, 0.7),
    ];
    let mut scene = textured_ground_in_white_light(ramp.clone());
    scene.camera = OrbitCamera {
        target: Vec3::new(0.5, 0.0, 0.0),
        distance: 4.0,
        yaw_degrees: 0.0,
        pitch_degrees: 89.0,
        fov_degrees: 20.0,
        ..Default::default()
    };
    let (w, h) = (64, 32);
    let pixels = render(&ctx, &scene, (w, h), 16);
    let mut checked = 0;
    for y in 0..h {
        for x in 0..w {
            let p = ground_point(&scene, (w, h), Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let expected = ramp.eval(p, Vec2::new(p.x, p.z));
            // Where the ramp bends or jumps (at its stops) a pixel's mean
            // is not its centre's value.
            let t = marbre_core::texture::waves(Vec2::new(p.x, p.z), 0.25, Vec2::X);
            if ramp.ramp.iter().any(|s| (t - s.position).abs() < 0.03) {
                continue;
            }
            let got = pixels[(y * w + x) as usize];
            for c in 0..3 {
                assert!(
                    (got[c] - expected[c]).abs() < 0.015,
                    "pixel {x},{y} (t = {t}): rendered {got:?}, the CPU ramp gives {expected}"
                );
            }
            checked += 1;
        }
    }
    assert!(
        checked > (w * h) as usize / 2,
        "only {checked} pixels checked"
    );
}

/// A colour edit reaches the image through the parameter buffer, and a
/// camera edit (which skips regenerating the textures) keeps them.
#[test]
fn texture_edits_reach_the_image_without_a_new_renderer() {
    let Some(ctx) = gpu_or_skip("texture_edits_reach_the_image_without_a_new_renderer") else {
        return;
    };
    let mut scene = textured_ground_in_white_light(Texture::color(Vec3::new(0.2, 0.4, 0.6)));
    scene.camera.pitch_degrees = 60.0;
    let size = (8, 8);
    let mut renderer = Renderer::new(&ctx, &scene, None, size).unwrap();
    let centre = |r: &mut Renderer| {
        accumulate(&ctx, r, 1, |_| {}).unwrap();
        r.read_radiance(&ctx).unwrap().2[4 * 8 + 4]
    };
    let before = centre(&mut renderer);
    for (c, want) in before[..3].iter().zip([0.2, 0.4, 0.6]) {
        assert!((c - want).abs() < 1e-3, "before: {before:?}");
    }
    scene.ground.as_mut().unwrap().material.diffuse = Texture::color(Vec3::splat(0.7));
    renderer.set_scene(&ctx, &scene).unwrap();
    assert_channels_near(centre(&mut renderer), 0.7, 1e-3, "after a colour edit");
    scene.camera.yaw_degrees += 30.0;
    renderer.set_scene(&ctx, &scene).unwrap();
    assert_channels_near(centre(&mut renderer), 0.7, 1e-3, "after a camera edit");
}

/// Bump mapping, in closed form: a Lambert ground rippled by waves along x,
/// h(x) = H·(0.5 + 0.5·sin 2πx), lit by a point light. At x = 0 the slope is
/// s = H·π, so the shading normal is (−s, 1, 0)/√(1 + s²) and the ground
/// reflects ρ/π · I/d² · max(0, n·l). A light to the −x side (which the
/// rising slope faces) pins the tilt's sign as well as its size.
#[test]
fn waves_bump_tilts_the_shading_normal_as_the_closed_form() {
    let Some(ctx) = gpu_or_skip("waves_bump_tilts_the_shading_normal_as_the_closed_form") else {
        return;
    };
    use marbre_core::scene::Pattern;
    let (albedo, intensity, bump_height) = (0.5_f32, 20.0_f32, 0.1_f32);
    let slope = bump_height * std::f32::consts::PI;
    let normal = Vec3::new(-slope, 1.0, 0.0).normalize();
    for light in [Vec3::new(0.0, 2.0, 0.0), Vec3::new(-1.0, 2.0, 0.0)] {
        let mut material = lambert(albedo);
        material.bump = Texture::blend(
            Pattern::Waves {
                frequency: 1.0,
                direction: glam::Vec2::X,
            },
            0.0,
            1.0,
        );
        material.bump_height = bump_height;
        let mut scene = Scene {
            ground: Some(Ground {
                height: 0.0,
                uv_frame: None,
                material,
            }),
            ..Scene::default()
        };
        scene.point_light = Some(PointLight {
            position: light,
            color: Vec3::ONE,
            intensity,
        });
        scene.camera = OrbitCamera {
            target: Vec3::ZERO,
            distance: 5.0,
            yaw_degrees: 0.0,
            pitch_degrees: 89.0,
            fov_degrees: 4.0,
            ..Default::default()
        };
        let (w, h) = (33, 33);
        let pixels = render(&ctx, &scene, (w, h), 16);
        let to_light = light.normalize();
        let expected = albedo / std::f32::consts::PI * intensity / light.length_squared()
            * normal.dot(to_light);
        let flat = albedo / std::f32::consts::PI * intensity / light.length_squared() * to_light.y;
        assert!(
            (expected - flat).abs() > 0.03 * flat,
            "the test would not see the bump"
        );
        let centre = pixels[(16 * w + 16) as usize];
        assert_channels_near(
            centre,
            expected,
            5e-3,
            &format!("light at {light}, flat {flat}"),
        );
    }
}

/// Turning accumulation off shows each frame alone; turning it on averages:
/// with a noisy scene the accumulated image has a lower pixel variance.
#[test]
fn accumulation_reduces_noise() {
    let Some(ctx) = gpu_or_skip("accumulation_reduces_noise") else {
        return;
    };
    let mut scene = Scene {
        ground: Some(Ground {
            height: 0.0,
            uv_frame: None,
            material: lambert(0.8),
        }),
        ..Scene::default()
    };
    scene.spheres.push(Sphere::default());
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::ONE,
    };
    let variance = |pixels: &[[f32; 4]]| {
        // Variance of horizontal neighbour differences: noise, not image.
        let d: Vec<f32> = pixels.windows(2).map(|p| p[1][0] - p[0][0]).collect();
        let m = d.iter().sum::<f32>() / d.len() as f32;
        d.iter().map(|x| (x - m) * (x - m)).sum::<f32>() / d.len() as f32
    };
    let one = render(&ctx, &scene, (48, 32), 1);
    let many = render(&ctx, &scene, (48, 32), 32);
    assert!(
        variance(&many) < 0.25 * variance(&one),
        "{} vs {}",
        variance(&many),
        variance(&one)
    );
}

/// The uber shader (every feature compiled in) and the specialised one
/// render the same image: specialisation removes code, never behaviour.
/// The presets cover noise (gradient and Perlin), bump, opacity, images,
/// cylinders and polygons.
#[test]
fn uber_and_specialised_shaders_agree() {
    let Some(ctx) = gpu_or_skip("uber_and_specialised_shaders_agree") else {
        return;
    };
    let root = std::path::Path::new(crate::REPO);
    for preset in [
        "presets/default.ron",
        "presets/tiles.ron",
        "presets/marble.ron",
        "presets/cutouts.ron",
        "presets/images.ron",
    ] {
        let loaded = marbre_render::session::load_scene(&root.join(preset), None).unwrap();
        let size = (48, 27);
        let mut specialised = marbre_render::session::renderer_for(&ctx, &loaded, size).unwrap();
        let mut uber = marbre_render::session::renderer_for(&ctx, &loaded, size).unwrap();
        uber.set_feature_override(&ctx, Some(marbre_render::gpu::FeatureSet::all()))
            .unwrap();
        assert!(uber.features().0.len() > specialised.features().0.len());
        for r in [&mut specialised, &mut uber] {
            accumulate(&ctx, r, 4, |_| {}).unwrap();
        }
        let (_, _, a) = specialised.read_radiance(&ctx).unwrap();
        let (_, _, b) = uber.read_radiance(&ctx).unwrap();
        for (p, q) in a.iter().zip(&b) {
            for c in 0..3 {
                assert!(
                    (p[c] - q[c]).abs() <= 1e-3 * (1.0 + p[c].abs()),
                    "{preset}: specialised {p:?} vs uber {q:?}"
                );
            }
        }
    }
}

/// The Quality strip's feature-cost toggles: compiling the ground out of
/// the default preset builds (and the image loses the ground), while a
/// pattern its texture code calls cannot be compiled out; the refusal
/// names the reason and leaves the shader as it was.
#[test]
fn a_feature_can_be_compiled_out_unless_the_texture_code_needs_it() {
    use marbre_render::gpu::{Feature, FeatureSet};
    use marbre_render::session::{load_scene, renderer_for};
    let Some(ctx) = gpu_or_skip("a_feature_can_be_compiled_out_unless_the_texture_code_needs_it")
    else {
        return;
    };
    let loaded = load_scene(
        &std::path::Path::new(crate::REPO).join("presets/default.ron"),
        None,
    )
    .unwrap();
    let size = (32, 24);
    let mut renderer = renderer_for(&ctx, &loaded, size).unwrap();
    let scene_features = FeatureSet::for_scene(&loaded.scene);
    let without = |f: Feature| {
        let mut set = scene_features.clone();
        assert!(set.0.remove(&f), "the default preset uses {f:?}");
        set
    };
    let refused = renderer
        .request_feature_override(
            &ctx,
            Some(without(Feature::Pattern(
                marbre_core::scene::PatternKind::Checker,
            ))),
        )
        .expect_err("the ground's checker is called by the texture code");
    assert!(
        format!("{refused:#}").contains("cannot be built with those features"),
        "{refused:#}"
    );
    assert!(!renderer.is_building());
    assert_eq!(*renderer.features(), scene_features);

    accumulate(&ctx, &mut renderer, 4, |_| {}).unwrap();
    let with_ground = renderer.read_radiance(&ctx).unwrap().2;
    renderer
        .request_feature_override(&ctx, Some(without(Feature::Ground)))
        .unwrap();
    let started = std::time::Instant::now();
    while renderer.is_building() {
        if let Some(result) = renderer.poll_build(&ctx) {
            result.unwrap();
        }
        // Generous: a loaded machine only makes the build slower.
        assert!(
            started.elapsed() < std::time::Duration::from_secs(300),
            "the build without the ground never finished"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert_eq!(*renderer.features(), without(Feature::Ground));
    // The new pipeline draws a new image: the old samples are gone.
    assert_eq!(renderer.accumulated_samples(), 0);
    accumulate(&ctx, &mut renderer, 4, |_| {}).unwrap();
    let without_ground = renderer.read_radiance(&ctx).unwrap().2;
    // The bottom row looked at the ground; it now sees the environment.
    let bottom = |image: &[[f32; 4]]| image[image.len() - size.0 as usize..].to_vec();
    assert_ne!(bottom(&with_ground), bottom(&without_ground));
}

/// A texture read back in bands of a few rows (as a 16384² image is, in
/// bands of 256 MiB) comes back as written, rows tightly packed, whatever
/// the band: one row, three rows with a short last band, all at once; and
/// read awaited, as a web page reads it.
#[test]
fn a_texture_read_in_bands_comes_back_as_written() {
    let Some(ctx) = gpu_or_skip("a_texture_read_in_bands_comes_back_as_written") else {
        return;
    };
    let (w, h) = (70u32, 11u32);
    let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("bands"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let written: Vec<u8> = (0..w * h * 4).map(|i| (i * 7 % 251) as u8).collect();
    ctx.queue.write_texture(
        texture.as_image_copy(),
        &written,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(w * 4),
            rows_per_image: Some(h),
        },
        texture.size(),
    );
    use marbre_render::gpu::readback::read_texture_in_bands;
    // A row is padded to 512 bytes in the buffer: 512 bytes is one row a
    // band, 1536 three, and a megabyte all eleven.
    for band in [512, 1536, 1 << 20] {
        let read = read_texture_in_bands(&ctx.device, &ctx.queue, &texture, 4, band).unwrap();
        assert!(read == written, "band of {band} bytes");
    }
    // The awaited readback a web page uses reads the same bytes.
    let awaited = pollster::block_on(marbre_render::gpu::readback::read_texture_async(
        &ctx.device,
        &ctx.queue,
        &texture,
        4,
    ))
    .unwrap();
    assert!(awaited == written, "the awaited readback");
}
