//! The bad-input corpus, `tests/data/bad/` (its README.md lists every file
//! and the message it gives): each file goes through the functions the
//! viewer calls (`session::load_scene` for presets and the meshes they
//! name, `session::load_images` for image textures,
//! `session::load_environment` for environment maps). A failure must name
//! the file and the cause, and the position where the format has one; a
//! file that can be used with a repair loads with a note saying so. On a GPU,
//! no failed load changes the renderer, and an environment map larger than
//! the GPU's textures still renders.

#[path = "bad_input/corpus.rs"]
mod corpus;

use glam::Vec3;
use marbre_core::envmap::EnvImage;
use marbre_core::image_decode::MAX_TEXELS;
use marbre_core::scene::{EnvSource, LdrImages, Material, Mesh, Pattern, Scene, Sphere, Texture};
use marbre_core::texture::{ColorSpace, ImageSource, load_image};
use marbre_render::gpu::renderer::Renderer;
use marbre_render::session::{
    self, LoadedScene, load_environment, load_images, load_scene, prepare_scene,
};
use std::path::{Path, PathBuf};

fn bad(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/bad")
        .join(path)
}

/// Fails unless `message` names `file` (by its path, as the loaders do)
/// and contains every one of `expected`.
fn assert_says(file: &Path, message: &str, expected: &[&str]) {
    eprintln!("{message}");
    let name = file.display().to_string();
    assert!(
        message.contains(&name),
        "the message does not name {name}: {message}"
    );
    // The cause is looked for beside the name: `truncated.png` says nothing.
    let beside = message.replace(&name, "");
    for want in expected {
        assert!(
            beside.contains(want),
            "{}: `{want}` missing from: {message}",
            file.display()
        );
    }
}

/// The viewer's message for a failed preset load (`{e:#}`), checked.
fn preset_error(file: &str, expected: &[&str]) {
    let path = bad(file);
    match load_scene(&path, None) {
        Ok(_) => panic!("{} loaded, but it is broken", path.display()),
        Err(e) => assert_says(&path, &format!("{e:#}"), expected),
    }
}

#[test]
fn broken_presets_are_refused_with_file_position_and_cause() {
    preset_error(
        "presets/bad_field.ron",
        &[
            ":10:24: ",
            "in field `scene.spheres[0].radius`",
            "Expected float",
        ],
    );
    preset_error("presets/unknown_variant.ron", &[":10:40: ", "Plaid"]);
    preset_error("presets/truncated.ron", &[":14:62: "]);
    preset_error(
        "presets/future_version.ron",
        &["format version 99 is newer", "update marbre"],
    );
    preset_error("presets/not_utf8.ron", &["not UTF-8 text (byte 113)"]);
}

#[test]
fn unknown_preset_fields_are_skipped_with_a_note() {
    let path = bad("presets/unknown_fields.ron");
    let loaded = load_scene(&path, None).unwrap();
    assert_eq!(loaded.scene.camera.distance, 6.0);
    assert_eq!(loaded.scene.spheres[0].name, "shiny");
    for field in [
        "colour_grading",
        "scene.camera.zoom",
        "scene.spheres[0].shininess",
    ] {
        let note = loaded
            .notes
            .iter()
            .find(|n| n.contains(&format!("unknown field `{field}` ignored")))
            .unwrap_or_else(|| panic!("no note for {field}: {:?}", loaded.notes));
        assert_says(&path, note, &[]);
    }
}

/// A scene of one mesh from `obj`, prepared as `load_scene` prepares a
/// preset's.
fn load_mesh(obj: &Path) -> anyhow::Result<LoadedScene> {
    let scene = Scene {
        meshes: vec![Mesh {
            name: "corpus".into(),
            obj: obj.to_owned(),
            ..Mesh::default()
        }],
        ..Scene::default()
    };
    prepare_scene(scene, Vec::new())
}

fn mesh_error(file: &str, expected: &[&str]) {
    let path = bad(file);
    match load_mesh(&path) {
        Ok(_) => panic!("{} loaded, but it is broken", path.display()),
        Err(e) => assert_says(&path, &format!("{e:#}"), expected),
    }
}

#[test]
fn broken_obj_files_are_refused_with_file_line_and_cause() {
    mesh_error("obj/index_out_of_range.obj", &[":6: ", "`f 1 2 9`"]);
    mesh_error(
        "obj/all_nan.obj",
        &["every triangle has a non-finite vertex"],
    );
}

/// The note of `notes` that mentions `needle`, which must name `file`.
fn note_about<'a>(notes: &'a [String], file: &Path, needle: &str) -> &'a str {
    let note = notes
        .iter()
        .find(|n| n.contains(needle))
        .unwrap_or_else(|| panic!("no note with `{needle}`: {notes:?}"));
    assert_says(file, note, &[]);
    note
}

#[test]
fn repairable_obj_files_load_with_a_note() {
    let path = bad("obj/nan_vertex.obj");
    let loaded = load_mesh(&path).unwrap();
    assert_eq!(loaded.scene.triangle_count(), 1);
    note_about(
        &loaded.notes,
        &path,
        "1 triangles with a NaN or infinite vertex were dropped",
    );

    let path = bad("obj/missing_mtl.obj");
    let loaded = load_mesh(&path).unwrap();
    assert_eq!(loaded.scene.triangle_count(), 1);
    let note = note_about(&loaded.notes, &path, "nowhere.mtl");
    assert!(note.contains("cannot be read") && note.contains("grey is used instead"));
    assert_eq!(loaded.scene.meshes[0].materials[0].name, "(default)");

    let path = bad("obj/missing_texture.obj");
    let loaded = load_mesh(&path).unwrap();
    let texture = bad("obj/nowhere.png");
    let note = note_about(&loaded.notes, &path, "nowhere.png not found");
    assert!(note.contains("magenta placeholder"), "{note}");
    // The image loader then shows the placeholder, and says why.
    let note = note_about(&loaded.notes, &texture, "cannot read the file");
    assert!(note.ends_with("showing a placeholder"), "{note}");
    assert_eq!(loaded.images.sources().len(), 1);
}

/// A scene whose sphere's diffuse colour is the image at `path`.
fn scene_with_image(path: &Path) -> Scene {
    let mut diffuse = Texture::blend(
        Pattern::Image {
            filter: Default::default(),
            wrap: Default::default(),
        },
        0.0,
        1.0,
    );
    diffuse.image = Some(ImageSource {
        path: path.to_owned(),
        color_space: ColorSpace::Srgb,
    });
    Scene {
        spheres: vec![Sphere {
            material: Material {
                diffuse,
                ..Material::default()
            },
            ..Sphere::default()
        }],
        ..Scene::default()
    }
}

/// The note `load_images` gives for the image at `file`: an unreadable image
/// becomes a placeholder, never an error.
fn image_note(file: &str, expected: &[&str]) {
    let path = bad(file);
    let mut notes = Vec::new();
    let images = load_images(&scene_with_image(&path), &mut notes).unwrap();
    assert_eq!(images.sources().len(), 1);
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert_says(&path, &notes[0], expected);
    assert!(notes[0].ends_with("showing a placeholder"), "{}", notes[0]);
}

#[test]
fn broken_images_become_placeholders_with_a_note() {
    image_note("images/truncated.png", &["cannot decode PNG", "truncated"]);
    image_note("images/truncated.jpg", &["cannot decode JPEG", "truncated"]);
    image_note("images/empty_0x0.png", &["the image is empty (0x0)"]);
    let declared = format!(
        "declares {side}x{side} texels, more than the {MAX_TEXELS}",
        side = corpus::HUGE_SIDE
    );
    image_note("images/huge_header.png", &[&declared]);
}

#[test]
fn sixteen_bit_and_grey_pngs_read_their_values() {
    let level0 = |file: &str| {
        let loaded = load_image(&bad(file), ColorSpace::Linear).unwrap();
        assert!(loaded.notes.is_empty(), "{file}: {:?}", loaded.notes);
        loaded.image.levels()[0].clone()
    };
    let code = f32::from(corpus::CODE16) / 65535.0;
    assert!((code - 0.5).abs() < 1e-4);
    for texel in level0("images/rgb16.png").texels {
        assert_eq!(texel, [code, code, code, 1.0]);
    }
    let grey = f32::from(corpus::GREY8) / 255.0;
    for texel in level0("images/grey.png").texels {
        assert_eq!(texel, [grey, grey, grey, 1.0]);
    }
}

/// An environment map at `path` loaded as the viewer loads one dropped on
/// it, with no size limit in the way.
fn environment(path: &Path) -> Result<marbre_core::envmap::EnvLoad, String> {
    load_environment(
        &EnvSource::LatLong {
            path: path.to_owned(),
        },
        LdrImages::Srgb,
        u32::MAX,
    )
    .map(|loaded| loaded.expect("a lat-long source has a map"))
    .map_err(|e| format!("{e:#}"))
}

fn environment_error(file: &str, expected: &[&str]) {
    let path = bad(file);
    match environment(&path) {
        Ok(_) => panic!("{} loaded, but it is broken", path.display()),
        Err(message) => assert_says(&path, &message, expected),
    }
}

const RESAVE: &str = "oiiotool in.exr --compression zip -o out.exr";

#[test]
fn broken_exr_files_are_refused_saying_why_and_what_to_do() {
    environment_error("exr/truncated.exr", &["cannot decode OpenEXR", "truncated"]);
    environment_error(
        "exr/dwab_bad_data.exr",
        &["cannot decode OpenEXR with DWAB compression", RESAVE],
    );
    environment_error(
        "exr/htj2k.exr",
        &[
            "HTJ2K compression",
            "marbre's OpenEXR reader (the `exr` crate) does not support it",
            RESAVE,
        ],
    );
    environment_error(
        "exr/no_colour.exr",
        &["no part has R, G, B or Y channels", "part 0: N.x, Z"],
    );
    // As an image texture, the same reasons, and a placeholder.
    image_note("exr/htj2k.exr", &["HTJ2K compression", RESAVE]);
}

/// Every texel of `image` is `rgb`.
fn assert_uniform(image: &EnvImage, rgb: [f32; 3], what: &str) {
    for p in &image.pixels {
        assert_eq!(p[..3], rgb, "{what}");
    }
}

#[test]
fn exr_files_with_a_choice_of_picture_load_the_colour_with_a_note() {
    for (file, needle) in [
        (
            "exr/multi_part.exr",
            "read the unnamed layer of part 1 (`beauty`) (channels R, G, B), \
             one of the file's 2 layers",
        ),
        (
            "exr/multi_layer.exr",
            "read layer `diffuse` of part 0 (`render`) (channels diffuse.R, diffuse.G, \
             diffuse.B), one of the file's 3 layers",
        ),
        (
            "exr/lowercase_rgb.exr",
            "channels r, g, b read as red, green, blue",
        ),
    ] {
        let path = bad(file);
        let loaded = environment(&path).unwrap();
        assert_uniform(&loaded.image, corpus::PICKED, file);
        assert_eq!(loaded.notes.len(), 1, "{file}: {:?}", loaded.notes);
        note_about(&loaded.notes, Path::new(path.file_name().unwrap()), needle);
    }
    let path = bad("exr/luminance_only.exr");
    let loaded = environment(&path).unwrap();
    assert_uniform(&loaded.image, [corpus::LUMINANCE; 3], "luminance");
    note_about(
        &loaded.notes,
        Path::new("luminance_only.exr"),
        "luminance only: channel Y of the unnamed layer of part 0 (`grey`) shown as grey",
    );
}

/// The `exr` crate reads DWAA (and DWAB): such a file loads like any other.
#[test]
fn a_dwaa_exr_loads() {
    let loaded = environment(&bad("exr/dwaa.exr")).unwrap();
    assert!(loaded.notes.is_empty(), "{:?}", loaded.notes);
    let image = &loaded.image;
    assert_eq!((image.width, image.height), (64, 32));
    // Lossy, but close to the ramp it was written from.
    for (x, y) in [(0u32, 0u32), (63, 0), (0, 31), (40, 20)] {
        let want = 0.5 + x as f32 / 64.0 + y as f32 / 16.0;
        let got = image.texel(x, y)[1];
        assert!(
            (got - want).abs() < 0.05 * want,
            "({x}, {y}): {got} vs {want}"
        );
    }
}

#[test]
fn non_finite_environment_texels_are_zeroed_and_counted() {
    let loaded = environment(&bad("envmaps/nan_inf.exr")).unwrap();
    assert_eq!(
        loaded.notes,
        [
            "nan_inf.exr: 3 NaN values set to 0",
            "nan_inf.exr: 3 infinite values set to 0",
        ]
    );
    assert_eq!(loaded.image.texel(0, 0), [0.0, 1.0, 1.0, 1.0]);
    assert_eq!(loaded.image.texel(2, 0), [0.0, 0.0, 0.0, 1.0]);
    assert_eq!(loaded.image.texel(3, 1), [0.5, 0.5, 0.5, 1.0]);
    environment_error(
        "envmaps/truncated.hdr",
        &["cannot decode Radiance HDR", "truncated"],
    );
}

/// A 64×32 map of a left half at 1 and a right half at 3, written where
/// `dir` says.
fn write_two_tone_map(dir: &Path) -> PathBuf {
    let path = dir.join("two_tone.exr");
    exr::prelude::write_rgb_file(&path, 64, 32, |x, _| {
        let v = if x < 32 { 1.0f32 } else { 3.0 };
        (v, v, v)
    })
    .unwrap();
    path
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("marbre-bad-input-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn an_environment_map_larger_than_the_gpu_allows_is_downscaled_with_a_note() {
    let dir = scratch("oversize");
    let path = write_two_tone_map(&dir);
    let source = EnvSource::LatLong { path: path.clone() };
    let loaded = load_environment(&source, LdrImages::Srgb, 16)
        .unwrap()
        .unwrap();
    assert_eq!((loaded.image.width, loaded.image.height), (16, 8));
    let note = format!(
        "{} is 64×32, larger than this GPU's max texture side 16: \
         downscaled to 16×8 (area average, mean radiance kept)",
        path.display()
    );
    assert_eq!(loaded.notes, std::slice::from_ref(&note));
    // Whole blocks of one tone: the halves stay 1 and 3, the mean 2.
    assert_eq!(loaded.image.texel(7, 4)[0], 1.0);
    assert_eq!(loaded.image.texel(8, 4)[0], 3.0);

    // A preset's map, through the same fit.
    let scene = Scene {
        environment: marbre_core::scene::Environment {
            source,
            ..Default::default()
        },
        ..Scene::default()
    };
    let fitted = prepare_scene(scene, Vec::new())
        .unwrap()
        .fit_environment(16);
    assert_eq!(fitted.env.as_ref().map(|e| e.width), Some(16));
    assert_eq!(fitted.notes, [note]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
#[ignore = "rewrites tests/data/bad/; run by hand after changing the corpus"]
fn regenerate_the_binary_corpus() {
    corpus::write_all(&bad(""));
}

/// On a GPU: failed loads leave the renderer's scene and accumulation as
/// they were; an environment map wider than the GPU's largest texture is
/// downscaled by the renderer itself and renders finite pixels.
#[test]
fn bad_files_leave_the_renderer_alone_and_oversize_maps_render() {
    let Some(ctx) = marbre_render::gpu::testing::gpu_or_skip(
        "bad_files_leave_the_renderer_alone_and_oversize_maps_render",
    ) else {
        return;
    };
    let mut scene = Scene::default();
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::splat(0.5),
    };
    let good = prepare_scene(scene, Vec::new()).unwrap();
    let mut renderer = session::renderer_for(&ctx, &good, (16, 8)).unwrap();
    session::trace_frame(&ctx, &mut renderer).unwrap();
    let samples = renderer.accumulated_samples();
    assert!(samples > 0);

    for preset in [
        "presets/bad_field.ron",
        "presets/future_version.ron",
        "presets/not_utf8.ron",
        "presets/truncated.ron",
        "presets/unknown_variant.ron",
    ] {
        assert!(load_scene(&bad(preset), None).is_err(), "{preset}");
    }
    for map in [
        "exr/truncated.exr",
        "exr/dwab_bad_data.exr",
        "exr/htj2k.exr",
        "exr/no_colour.exr",
        "exr/huge_header.exr",
        "envmaps/truncated.hdr",
        "images/empty_0x0.png",
        "images/huge_header.png",
    ] {
        assert!(environment(&bad(map)).is_err(), "{map}");
    }
    assert_eq!(renderer.scene(), &good.scene);
    assert_eq!(renderer.accumulated_samples(), samples);

    // One texel wider than the GPU takes: without the renderer's own
    // downscale, creating the texture would fail.
    let max_side = session::max_texture_side(&ctx);
    let wide = EnvImage::constant(max_side + 1, 2, [0.25, 0.5, 1.0]);
    let mut lit = good.scene.clone();
    lit.environment.source = EnvSource::LatLong {
        path: "wide.exr".into(),
    };
    renderer.set_scene(&ctx, &lit).unwrap();
    renderer.set_environment(&ctx, Some(&wide));
    session::trace_frame(&ctx, &mut renderer).unwrap();
    let (_, _, pixels) = renderer.read_radiance(&ctx).unwrap();
    assert!(
        pixels.iter().all(|p| p.iter().all(|c| c.is_finite())),
        "non-finite pixels"
    );
    assert!(renderer.count_non_finite(&ctx).unwrap().is_zero());
    // The sky seen past the sphere is the map's colour.
    let brightest = pixels.iter().map(|p| p[2]).fold(0.0f32, f32::max);
    assert!(brightest > 0.5, "the map did not render: {brightest}");
}

/// A scene of one mesh of `count` small triangles, its geometry in place.
fn scene_of_triangles(count: usize) -> Scene {
    let positions: Vec<[Vec3; 3]> = (0..count)
        .map(|i| {
            let x = i as f32 * 0.01;
            [
                Vec3::new(x, -1.0, -1.0),
                Vec3::new(x + 0.01, -1.0, -1.0),
                Vec3::new(x, -0.99, -1.0),
            ]
        })
        .collect();
    let geometry = marbre_core::scene::TriangleMesh {
        uvs: vec![[glam::Vec2::ZERO; 3]; count],
        materials: vec![0; count],
        positions,
    };
    Scene {
        meshes: vec![Mesh {
            name: "many".into(),
            geometry: marbre_core::scene::mesh::Geometry(std::sync::Arc::new(geometry)),
            ..Mesh::default()
        }],
        ..Scene::default()
    }
}

/// A mesh whose buffers exceed the device's storage-binding limit is
/// refused before any buffer is made, naming the buffer and the limit
/// (issue 47): at the renderer's creation, and at an edit, which leaves
/// the scene on screen as it was and its device free of errors. The
/// triangles' buffer is 48 bytes a triangle (`TriangleVerts`): 100 take
/// 4800 bytes, over a limit of 4096; 10 fit.
#[test]
fn a_mesh_over_the_devices_buffer_limits_is_refused_naming_the_limit() {
    let Some(ctx) = marbre_render::gpu::testing::gpu_or_skip(
        "a_mesh_over_the_devices_buffer_limits_is_refused_naming_the_limit",
    ) else {
        return;
    };
    let small = ctx
        .limited(wgpu::Limits {
            max_storage_buffer_binding_size: 4096,
            ..ctx.device.limits()
        })
        .unwrap();
    let too_big = scene_of_triangles(100);
    let e = Renderer::new(&small, &too_big, None, (16, 8))
        .err()
        .expect("a renderer over the limits");
    let e = format!("{e:#}");
    assert!(
        e.contains("`mesh triangles` buffer would take 4800 bytes")
            && e.contains("max_storage_buffer_binding_size of 4096"),
        "{e}"
    );

    let fits = scene_of_triangles(10);
    let mut renderer = Renderer::new(&small, &fits, None, (16, 8)).unwrap();
    session::trace_frame(&small, &mut renderer).unwrap();
    let e = renderer
        .set_scene(&small, &too_big)
        .expect_err("an edit over the limits");
    assert!(
        format!("{e:#}").contains("max_storage_buffer_binding_size"),
        "{e:#}"
    );
    assert_eq!(renderer.scene(), &fits);
    session::trace_frame(&small, &mut renderer).unwrap();
    small.uncaptured.check().unwrap();
}
