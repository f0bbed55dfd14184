//! `marbre bake`: one material property of one object written to an image
//! in the object's (u, v) square, evaluated on the GPU by the renderer's
//! generated texture code (`marbre_render::bake_file`), with the mapping
//! written beside it.

use anyhow::{Context, Result};
use clap::Args;
use marbre_core::bake::{BakeProperty, ObjectRef, check_output, check_size};
use marbre_render::bake_file::{BakeRequest, bake_to_file};
use marbre_render::gpu::GpuContext;
use marbre_render::session::load_scene;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct BakeArgs {
    /// The preset holding the object.
    #[arg(long)]
    pub preset: PathBuf,
    /// The object's name in the preset (`ground` for the ground).
    #[arg(long)]
    pub object: String,
    /// diffuse, specular, roughness, bump, opacity or emission.
    #[arg(long, value_parser = parse_property)]
    pub property: BakeProperty,
    /// Texels a side of the square image (1 to 4096).
    #[arg(long, default_value_t = 1024)]
    pub size: u32,
    /// Output: .png (8 bits; colours sRGB-encoded, data linear) or .exr
    /// (linear float). Colours are meant for PNG, data (roughness, bump,
    /// opacity) for EXR; the other format is written when asked. The
    /// mapping goes to <output>.mapping.ron.
    #[arg(short = 'o', long)]
    pub output: PathBuf,
    /// Bake even if an image or material library the scene reads cannot
    /// be loaded (a placeholder or grey is baked in its place); without it
    /// the bake fails before it starts, naming the files.
    #[arg(long)]
    pub allow_placeholders: bool,
}

fn parse_property(s: &str) -> Result<BakeProperty, String> {
    BakeProperty::parse(s).map_err(|e| e.to_string())
}

pub fn run(args: &BakeArgs) -> Result<()> {
    // Refused before the preset loads and the GPU starts.
    check_size(args.size)?;
    check_output(&args.output)?;
    let loaded = load_scene(&args.preset, None)?;
    for note in &loaded.notes {
        eprintln!("note: {note}");
    }
    if !args.allow_placeholders {
        marbre_render::final_render::refuse_substitutes(&loaded)?;
    }
    let object = ObjectRef::find(&loaded.scene, &args.object)
        .with_context(|| format!("{}", args.preset.display()))?;
    let ctx = GpuContext::headless()?;
    let request = BakeRequest {
        object,
        property: args.property,
        size: args.size,
        output: args.output.clone(),
        preset: args.preset.display().to_string(),
    };
    let mapping = bake_to_file(&ctx, &loaded.scene, &loaded.images, &request)?;
    eprintln!(
        "wrote {} ({} of {} “{}”, {} × {}, {})",
        args.output.display(),
        mapping.property,
        mapping.primitive,
        mapping.object,
        mapping.size,
        mapping.size,
        mapping.color_space
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;
    use glam::{Vec2, Vec3};
    use marbre_core::bake::BakeMapping;
    use marbre_core::preset::{FORMAT_VERSION, Preset, save};
    use marbre_core::scene::{ColorEncoding, Pattern, Polygon, Scene, Texture};
    use marbre_render::gpu::testing::gpu_or_skip;
    use std::path::Path;

    /// The command line as `marbre bake` parses it.
    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: BakeArgs,
    }

    fn parse(line: &[&str]) -> Result<BakeArgs, clap::Error> {
        Cli::try_parse_from(std::iter::once("bake").chain(line.iter().copied())).map(|c| c.args)
    }

    /// The linear value whose sRGB encoding is 128/255: 0.2158 (0.214,
    /// the linear value of an encoded 0.5, lies at 127.47 and rounds to
    /// 127). Written linearly, 8 bits would hold it as 55.
    fn mid_grey() -> f32 {
        marbre_core::scene::color_encoding::srgb_decode(128.0 / 255.0)
    }

    /// A preset with one unit-square polygon `tile`: diffuse a uniform
    /// linear [`mid_grey`], roughness a 2 × 2 checker of 0.214 and 0.75.
    fn preset(dir: &Path) -> PathBuf {
        let mut polygon = Polygon {
            name: "tile".into(),
            vertices: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, 1.0), Vec3::Z],
            ..Polygon::default()
        };
        polygon.material.diffuse = Texture::color(Vec3::splat(mid_grey()));
        polygon.material.roughness = Texture::blend(
            Pattern::Checker2d {
                size: Vec2::splat(0.5),
                phase: 0.0,
            },
            0.214,
            0.75,
        );
        let path = dir.join("tile.ron");
        let preset = Preset {
            format_version: FORMAT_VERSION,
            description: "bake test".into(),
            colors: ColorEncoding::Linear,
            scene: Scene {
                polygons: vec![polygon],
                ..Scene::default()
            },
        };
        save(&preset, &path).unwrap();
        path
    }

    fn bake_args(preset: &Path, property: &str, output: &Path) -> BakeArgs {
        parse(&[
            "--preset",
            preset.to_str().unwrap(),
            "--object",
            "tile",
            "--property",
            property,
            "--size",
            "8",
            "-o",
            output.to_str().unwrap(),
        ])
        .unwrap()
    }

    /// A missing image texture fails the bake before it starts (no GPU
    /// is needed to see it), naming the file, unless placeholders are
    /// allowed; nothing is written.
    #[test]
    fn a_missing_image_fails_the_bake_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = preset(dir.path());
        let mut loaded = marbre_core::preset::load(&path).unwrap().preset;
        let missing = dir.path().join("missing.png");
        loaded.scene.polygons[0].material.diffuse = Texture {
            image: Some(marbre_core::texture::ImageSource {
                path: missing.clone(),
                color_space: Default::default(),
            }),
            ..Texture::blend(
                Pattern::fresh(marbre_core::scene::PatternKind::Image, None),
                0.0,
                1.0,
            )
        };
        save(&loaded, &path).unwrap();
        let output = dir.path().join("diffuse.png");
        let error = format!(
            "{:#}",
            run(&bake_args(&path, "diffuse", &output)).unwrap_err()
        );
        assert!(
            error.contains(missing.to_str().unwrap()) && error.contains("--allow-placeholders"),
            "{error}"
        );
        assert!(!output.exists());
    }

    fn read_exr(path: &Path) -> Vec<[f32; 4]> {
        use exr::prelude::*;
        let image = read_first_rgba_layer_from_file(
            path,
            |size, _| vec![[0.0f32; 4]; size.width() * size.height()],
            |pixels: &mut Vec<[f32; 4]>, at, (r, g, b, a): (f32, f32, f32, f32)| {
                pixels[at.y() * 8 + at.x()] = [r, g, b, a];
            },
        )
        .unwrap();
        image.layer_data.channel_data.pixels
    }

    /// A colour goes to PNG sRGB-encoded (linear 0.2159 reads 128), data to
    /// EXR linear (0.214 and 0.75 exactly, in the checker's cells), and a
    /// colour asked as EXR stays linear; each sidecar parses back and
    /// says what was written.
    #[test]
    fn png_is_srgb_exr_is_linear_and_the_sidecar_says_so() {
        let Some(_) = gpu_or_skip("png_is_srgb_exr_is_linear_and_the_sidecar_says_so") else {
            return;
        };
        let dir = tempfile::tempdir().unwrap();
        let preset = preset(dir.path());

        let png = dir.path().join("diffuse.png");
        run(&bake_args(&preset, "diffuse", &png)).unwrap();
        let image = image::open(&png).unwrap().to_rgba8();
        assert_eq!(image.dimensions(), (8, 8));
        assert!(
            image.pixels().all(|p| p.0 == [128, 128, 128, 255]),
            "{:?}",
            image.get_pixel(0, 0)
        );
        let text = std::fs::read_to_string(dir.path().join("diffuse.png.mapping.ron")).unwrap();
        let mapping: BakeMapping = ron::from_str(&text).unwrap();
        assert_eq!(
            (mapping.object.as_str(), mapping.primitive.as_str()),
            ("tile", "polygon")
        );
        assert_eq!((mapping.property.as_str(), mapping.size), ("diffuse", 8));
        assert_eq!(mapping.color_space, "srgb");
        assert!(
            mapping.uv_mapping.contains("u_axis [1, 0, 0]"),
            "{}",
            mapping.uv_mapping
        );

        let exr = dir.path().join("roughness.exr");
        run(&bake_args(&preset, "roughness", &exr)).unwrap();
        let texels = read_exr(&exr);
        for (index, t) in texels.iter().enumerate() {
            let (i, j) = (index % 8, index / 8);
            // Cells of half the square; v = 0 is the bottom row.
            let odd = (i / 4 + (1 - j / 4)) % 2 == 1;
            let expected = if odd { 0.75 } else { 0.214 };
            assert!(
                (t[0] - expected).abs() < 1e-6 && t[3] == 1.0,
                "({i}, {j}): {t:?}"
            );
        }
        let text = std::fs::read_to_string(dir.path().join("roughness.exr.mapping.ron")).unwrap();
        let mapping: BakeMapping = ron::from_str(&text).unwrap();
        assert_eq!(mapping.color_space, "linear");

        let linear = dir.path().join("diffuse.exr");
        run(&bake_args(&preset, "diffuse", &linear)).unwrap();
        assert!(
            read_exr(&linear)
                .iter()
                .all(|t| (t[0] - mid_grey()).abs() < 1e-6)
        );
    }

    /// Bad names, sizes and folders are refused, each naming what is wrong.
    #[test]
    fn bad_objects_properties_sizes_and_paths_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let preset = preset(dir.path());
        let out = dir.path().join("x.png");

        let mut args = bake_args(&preset, "diffuse", &out);
        args.object = "teapot".into();
        let e = format!("{:#}", run(&args).unwrap_err());
        assert!(
            e.contains("`teapot`") && e.contains("polygon “tile”"),
            "{e}"
        );
        assert!(e.contains("tile.ron"), "the preset is named: {e}");

        let e = parse(&[
            "--preset",
            "p.ron",
            "--object",
            "tile",
            "--property",
            "shine",
            "-o",
            "x.png",
        ])
        .err()
        .unwrap()
        .to_string();
        assert!(e.contains("`shine`") && e.contains("roughness"), "{e}");

        let mut args = bake_args(&preset, "diffuse", &out);
        args.size = 0;
        let e = run(&args).unwrap_err().to_string();
        assert!(e.contains("size 0"), "{e}");

        let missing = dir.path().join("no/such/folder/x.png");
        let e = run(&bake_args(&preset, "diffuse", &missing))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no/such/folder") && e.contains("does not exist"),
            "{e}"
        );
        assert!(!dir.path().join("no").exists(), "no folder is created");

        let e = run(&bake_args(&preset, "diffuse", &dir.path().join("x.tif")))
            .unwrap_err()
            .to_string();
        assert!(e.contains("x.tif"), "{e}");
    }
}
