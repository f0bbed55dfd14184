//! The edit path, class by class, on the default preset: what the
//! renderer does with an edit follows from its `Change` alone. A parameter
//! edit generates no code and starts no build, yet draws exactly what a
//! renderer made for the edited scene draws; a structural edit builds; a
//! display edit keeps the samples; a camera move restarts them.

use marbre_core::scene::{Change, Pattern, Scene, Texture};
use marbre_render::gpu::testing::gpu_or_skip;
use marbre_render::gpu::{GpuContext, Kernel, Renderer};
use marbre_render::session::{LoadedScene, accumulate, load_scene, renderer_with};

const SIZE: (u32, u32) = (48, 27);

/// The default preset, every octave traced: at this small size the
/// footprint clamp would keep only the first.
fn default_preset() -> LoadedScene {
    let mut loaded = load_scene(&super::common::root().join("presets/default.ron"), None).unwrap();
    loaded.scene.render.clamp_octaves = false;
    loaded
}

/// Hands `scene` to the renderer as the viewer does: its change from the
/// scene last requested, worked out once.
fn request(ctx: &GpuContext, renderer: &mut Renderer, scene: &Scene) -> Change {
    let change = scene.changes_from(renderer.requested_scene());
    renderer.request_scene(ctx, scene, change).unwrap();
    change
}

fn image(ctx: &GpuContext, renderer: &mut Renderer, spp: u32) -> Vec<[f32; 4]> {
    accumulate(ctx, renderer, spp, |_| {}).unwrap();
    renderer.read_radiance(ctx).unwrap().2
}

/// The largest difference of two images, channel by channel.
fn largest_difference(a: &[[f32; 4]], b: &[[f32; 4]]) -> f32 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| (0..4).map(move |c| (p[c] - q[c]).abs()))
        .fold(0.0, f32::max)
}

/// A new renderer of `loaded` that has traced as many frames as the edited
/// one before its image (each frame's samples follow the frame count, which
/// an edit does not reset), then its `spp` frames.
fn fresh_image(ctx: &GpuContext, loaded: &LoadedScene, before: u32, spp: u32) -> Vec<[f32; 4]> {
    let mut renderer = renderer_with(ctx, loaded, SIZE, Kernel::Fragment).unwrap();
    image(ctx, &mut renderer, before);
    renderer.reset_accumulation();
    image(ctx, &mut renderer, spp)
}

/// The first noise pattern's octave count moved, as the octave slider does.
fn octaves_moved(scene: &Scene, octaves: f32) -> Scene {
    let mut edited = scene.clone();
    let mut done = false;
    for material in edited.materials_mut() {
        material.visit_textures_mut(&mut |t| {
            if let Some(noise) = t.pattern.noise_mut()
                && !done
            {
                noise.fractal.octaves = octaves;
                done = true;
            }
        });
    }
    assert!(done, "the default preset has a noise pattern");
    edited
}

#[test]
fn a_parameter_edit_generates_no_code_and_draws_the_edited_scene() {
    let Some(ctx) = gpu_or_skip("a_parameter_edit_generates_no_code_and_draws_the_edited_scene")
    else {
        return;
    };
    let loaded = default_preset();
    let mut renderer = renderer_with(&ctx, &loaded, SIZE, Kernel::Fragment).unwrap();
    image(&ctx, &mut renderer, 2);
    let generations = renderer.code_generations();
    let mut edited = loaded.scene.clone();
    for octaves in [3.0, 2.0, 1.0] {
        edited = octaves_moved(&edited, octaves);
        assert_eq!(
            request(&ctx, &mut renderer, &edited),
            Change::MATERIAL_PARAMETERS
        );
        assert!(!renderer.is_building(), "a parameter edit started a build");
        assert_eq!(renderer.accumulated_frames(), 0, "the old samples stay");
    }
    // A texture's colour (the marble's specular), a number of the
    // generated code's parameters.
    edited.spheres[0].material.specular = Texture::color(glam::Vec3::new(0.9, 0.1, 0.1));
    assert_eq!(
        request(&ctx, &mut renderer, &edited),
        Change::MATERIAL_PARAMETERS
    );
    assert_eq!(
        renderer.code_generations(),
        generations,
        "code was generated"
    );
    let drawn = image(&ctx, &mut renderer, 4);
    // A renderer made for the edited scene, its code generated from it.
    let fresh_scene = LoadedScene {
        scene: edited,
        ..default_preset()
    };
    let expected = fresh_image(&ctx, &fresh_scene, 2, 4);
    assert_eq!(
        largest_difference(&drawn, &expected),
        0.0,
        "the edited renderer draws another image than one made for the edited scene"
    );
    // One octave instead of six and a red gloss: another image.
    let unedited = fresh_image(&ctx, &loaded, 2, 4);
    let moved = largest_difference(&drawn, &unedited);
    assert!(
        moved > 0.01,
        "the octave edit changed nothing drawn ({moved})"
    );
}

#[test]
fn a_structural_edit_builds_a_pipeline() {
    let Some(ctx) = gpu_or_skip("a_structural_edit_builds_a_pipeline") else {
        return;
    };
    let loaded = default_preset();
    let mut renderer = renderer_with(&ctx, &loaded, SIZE, Kernel::Fragment).unwrap();
    let generations = renderer.code_generations();
    let mut edited = loaded.scene.clone();
    edited.spheres[0].material.specular = Texture::blend(
        Pattern::Checker { size: 0.5 },
        glam::Vec3::ZERO,
        glam::Vec3::ONE,
    );
    assert_eq!(
        request(&ctx, &mut renderer, &edited),
        Change::MATERIAL_STRUCTURE
    );
    assert_eq!(renderer.code_generations(), generations + 1);
    assert!(
        renderer.is_building(),
        "no pipeline build for a new structure"
    );
    // The build joins: a number moved meanwhile waits for it.
    let mut moved = edited.clone();
    moved.spheres[0].material.specular = Texture::blend(
        Pattern::Checker { size: 0.25 },
        glam::Vec3::ZERO,
        glam::Vec3::ONE,
    );
    assert_eq!(
        request(&ctx, &mut renderer, &moved),
        Change::MATERIAL_PARAMETERS
    );
    assert_eq!(renderer.code_generations(), generations + 1);
    let started = std::time::Instant::now();
    while renderer.is_building() {
        if let Some(result) = renderer.poll_build(&ctx) {
            result.unwrap();
        }
        // Generous: a loaded machine only makes the build slower.
        assert!(
            started.elapsed() < std::time::Duration::from_secs(300),
            "the build never finished"
        );
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert_eq!(
        renderer.scene(),
        &moved,
        "the build installed the last edit"
    );
}

#[test]
fn a_display_edit_keeps_the_samples_and_a_camera_move_restarts_them() {
    let Some(ctx) = gpu_or_skip("a_display_edit_keeps_the_samples_and_a_camera_move_restarts_them")
    else {
        return;
    };
    let loaded = default_preset();
    let mut renderer = renderer_with(&ctx, &loaded, SIZE, Kernel::Fragment).unwrap();
    image(&ctx, &mut renderer, 3);
    let frames = renderer.accumulated_frames();
    assert!(frames > 0);
    let generations = renderer.code_generations();

    let mut shown = loaded.scene.clone();
    shown.render.display.exposure += 1.5;
    assert_eq!(request(&ctx, &mut renderer, &shown), Change::DISPLAY);
    assert_eq!(
        renderer.accumulated_frames(),
        frames,
        "samples were dropped"
    );

    let mut moved = shown.clone();
    moved.camera.yaw_degrees += 15.0;
    assert_eq!(request(&ctx, &mut renderer, &moved), Change::CAMERA);
    assert_eq!(
        renderer.accumulated_frames(),
        0,
        "the old view's samples stay"
    );
    assert!(!renderer.is_building());
    assert_eq!(renderer.code_generations(), generations);
}

/// Playing an animation keyed on numbers of every kind (a noise's
/// frequency, a stripe frequency, a ramp colour, the camera, the light,
/// the environment, the exposure) hands the renderer one moment after
/// another: numbers only, so no code is generated and no pipeline built.
#[test]
fn a_keyed_animation_plays_without_generating_code_or_building() {
    let Some(ctx) = gpu_or_skip("a_keyed_animation_plays_without_generating_code_or_building")
    else {
        return;
    };
    use marbre_core::animation::{Animation, ParamPath};
    let loaded = default_preset();
    let mut animation = Animation::default();
    let marble = "spheres[\"marble\"].material.diffuse";
    for (path, start, end) in [
        (
            format!("{marble}.pattern.noise.fractal.frequency"),
            vec![1.0],
            vec![3.0],
        ),
        (
            format!("{marble}.pattern.stripe_frequency"),
            vec![12.0],
            vec![4.0],
        ),
        (
            format!("{marble}.ramp[1].color"),
            vec![0.3, 0.28, 0.27],
            vec![0.9, 0.1, 0.1],
        ),
        ("camera.yaw_degrees".to_owned(), vec![0.0], vec![40.0]),
        ("point_light.intensity".to_owned(), vec![1.0], vec![50.0]),
        (
            "environment.rotation_degrees".to_owned(),
            vec![0.0],
            vec![90.0],
        ),
        ("render.exposure".to_owned(), vec![0.0], vec![-1.0]),
    ] {
        let path = ParamPath::parse(&path).unwrap();
        animation.insert_key(&path, 0.0, &start);
        animation.insert_key(&path, 1.0, &end);
    }
    let scene = Scene {
        animation: Some(animation),
        ..loaded.scene.clone()
    };
    assert!(
        scene
            .animation
            .as_ref()
            .unwrap()
            .problems(&scene)
            .is_empty()
    );
    let mut renderer = renderer_with(&ctx, &loaded, SIZE, Kernel::Fragment).unwrap();
    request(&ctx, &mut renderer, &scene.at_time(0.0));
    renderer.set_scene(&ctx, &scene.at_time(0.0)).unwrap();
    let generations = renderer.code_generations();
    let builds = renderer.last_build();
    let numbers = Change::CAMERA
        | Change::MATERIAL_PARAMETERS
        | Change::LIGHTS
        | Change::ENVIRONMENT
        | Change::DISPLAY;
    let mut previous = image(&ctx, &mut renderer, 1);
    for frame in 1..=6 {
        let change = request(&ctx, &mut renderer, &scene.at_time(frame as f32 / 6.0));
        assert!(
            numbers.contains(change) && !change.is_empty(),
            "frame {frame}: {change:?}"
        );
        assert!(!renderer.is_building(), "frame {frame} started a build");
        let drawn = image(&ctx, &mut renderer, 1);
        assert!(
            largest_difference(&drawn, &previous) > 0.0,
            "frame {frame} drew the same image"
        );
        previous = drawn;
    }
    assert_eq!(
        renderer.code_generations(),
        generations,
        "code was generated"
    );
    assert_eq!(renderer.last_build(), builds, "a pipeline was built");
}

/// A looped animation's last frame meets its first: with the marble's
/// noise evolving (w moving 1.3 cells a second, snapped to whole cells
/// over the 2 s loop), the scene at t = 2 s traced with frame 0's samples
/// is frame 0's image bit for bit, while half way it is another image;
/// every moment is numbers only.
#[test]
fn a_looped_evolving_noise_meets_its_first_frame() {
    let Some(ctx) = gpu_or_skip("a_looped_evolving_noise_meets_its_first_frame") else {
        return;
    };
    use marbre_core::animation::Animation;
    use marbre_core::noise::Evolution;
    let loaded = default_preset();
    let mut scene = loaded.scene.clone();
    let mut evolving = false;
    scene.spheres[0].material.for_each_noise_mut(&mut |noise| {
        noise.evolution = Some(Evolution {
            speed: 1.3,
            ..Evolution::default()
        });
        evolving = true;
    });
    assert!(evolving, "the marble has a noise");
    scene.animation = Some(Animation {
        duration: 2.0,
        looping: true,
        ..Animation::default()
    });
    assert!(scene.moves());
    let start = LoadedScene {
        scene: scene.at_time(0.0),
        ..default_preset()
    };
    let mut renderer = renderer_with(&ctx, &start, SIZE, Kernel::Fragment).unwrap();
    let mut frame_zero_at = |t: f32| {
        let change = request(&ctx, &mut renderer, &scene.at_time(t));
        assert!(Change::MATERIAL_PARAMETERS.contains(change), "{change:?}");
        renderer.restart_at_sample(0, 0);
        image(&ctx, &mut renderer, 2)
    };
    let first = frame_zero_at(0.0);
    let half = frame_zero_at(1.0);
    let last = frame_zero_at(2.0);
    assert!(
        largest_difference(&first, &half) > 0.01,
        "the noise did not move"
    );
    assert_eq!(
        largest_difference(&first, &last),
        0.0,
        "the loop has a seam"
    );
}
