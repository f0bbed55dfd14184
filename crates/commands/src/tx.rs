//! `marbre tx`: a TX text (the IFT528 report's texture language) rendered
//! on the report's preview scene, a polygon with its default frame, a
//! sphere and a cylinder, through the session functions `marbre render`
//! uses; `--print` writes the parsed text back; `--gallery` renders every
//! example of a folder and writes a Markdown page of them.

use crate::render::parse_size;
use anyhow::{Context, Result, bail};
use clap::Args;
use glam::Vec3;
use marbre_core::capped_read::{self, read_capped_to_string};
use marbre_core::image_io;
use marbre_core::scene::{
    Cylinder, EnvSource, Ground, Material, OrbitCamera, PointLight, Polygon, Scene, Sphere, Texture,
};
use marbre_core::tx;
use marbre_render::final_render::refuse_substitutes;
use marbre_render::gpu::{GpuContext, Kernel};
use marbre_render::session::{accumulate, prepare_scene, renderer_with};
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct TxArgs {
    /// The TX file: optional ATX, APTX, ATX3D frames, then `TX … FTX`.
    pub file: Option<PathBuf>,
    /// The PNG to write (with --gallery, the folder of PNGs).
    #[arg(short = 'o', long)]
    pub output: Option<PathBuf>,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "256x192", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Samples per pixel.
    #[arg(long, default_value_t = 64, allow_negative_numbers = true, value_parser = crate::parse_spp)]
    pub spp: u32,
    /// Print the parsed text back as TX instead of rendering.
    #[arg(long)]
    pub print: bool,
    /// Render every example listed in this folder's `gallery.ron` into
    /// the -o folder and write the Markdown page --markdown.
    #[arg(long)]
    pub gallery: Option<PathBuf>,
    /// The gallery's Markdown page (its images linked relative to it).
    #[arg(long, default_value = "docs/gallery.md")]
    pub markdown: PathBuf,
    /// Render even if an image the text reads cannot be loaded (it shows
    /// as a magenta-and-black placeholder); without it such a render
    /// fails before tracing, naming the file.
    #[arg(long)]
    pub allow_placeholders: bool,
}

pub fn run(args: &TxArgs) -> Result<()> {
    if args.spp == 0 {
        bail!("--spp must be at least 1");
    }
    if let Some(folder) = &args.gallery {
        let out = args
            .output
            .as_deref()
            .context("--gallery needs -o FOLDER")?;
        return gallery(folder, out, &args.markdown, args.size, args.spp);
    }
    let file = args
        .file
        .as_deref()
        .context("give a TX file (or --gallery FOLDER)")?;
    let doc = read(file)?;
    if args.print {
        print!("{}", tx::print(&doc));
        return Ok(());
    }
    let output = args
        .output
        .as_deref()
        .context("give -o OUT.png (or --print)")?;
    let ctx = GpuContext::headless()?;
    let preview = Preview {
        size: args.size,
        spp: args.spp,
        allow_placeholders: args.allow_placeholders,
    };
    render(&ctx, &doc, file, output, &preview)
}

/// The parsed file; a syntax error names the file, the line and column.
fn read(file: &Path) -> Result<tx::Document> {
    let text = read_capped_to_string(file, capped_read::TX)
        .with_context(|| format!("{}: cannot read", file.display()))?;
    tx::parse(&text).map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))
}

/// The neutral material the text is applied onto: a light grey, slightly
/// glossy dielectric.
pub fn neutral_material() -> Material {
    Material {
        diffuse: Texture::color(Vec3::splat(0.6)),
        specular: Texture::color(Vec3::splat(0.04)),
        roughness: Texture::scalar(0.45),
        ..Material::default()
    }
}

/// The report's preview: a square polygon standing behind (its default
/// frame: (u, v) spanning it from its first vertex), a sphere and a
/// cylinder in front, on a grey ground, all wearing the lowered material
/// (the ground too when the text gives a plane frame, APTX: without one
/// N3D ignores a plane's texture). Images resolve against `base_dir`.
pub fn preview_scene(doc: &tx::Document, base_dir: &Path) -> Result<Scene, tx::TxError> {
    let lowered = tx::lower_document(doc, &neutral_material(), base_dir)?;
    let m = lowered.material;
    let mut scene = Scene {
        camera: OrbitCamera {
            target: Vec3::new(0.0, 1.0, 0.0),
            distance: 6.2,
            yaw_degrees: 0.0,
            pitch_degrees: 12.0,
            fov_degrees: 40.0,
        },
        spheres: vec![Sphere {
            name: "sphere".into(),
            center: Vec3::new(-1.05, 0.55, 0.7),
            radius: 0.55,
            material: m.clone(),
        }],
        cylinders: vec![Cylinder {
            name: "cylinder".into(),
            base: Vec3::new(1.05, 0.0, 0.7),
            radius: 0.45,
            height: 1.1,
            material: m.clone(),
        }],
        polygons: vec![Polygon {
            name: "polygon".into(),
            vertices: vec![
                Vec3::new(-1.4, 0.0, -1.2),
                Vec3::new(1.4, 0.0, -1.2),
                Vec3::new(1.4, 2.8, -1.2),
                Vec3::new(-1.4, 2.8, -1.2),
            ],
            uv_frame: lowered.polygon_frame,
            material: m.clone(),
        }],
        ground: Some(Ground {
            height: 0.0,
            uv_frame: lowered.plane_frame,
            material: if lowered.plane_frame.is_some() {
                m
            } else {
                Material {
                    diffuse: Texture::color(Vec3::splat(0.35)),
                    ..neutral_material()
                }
            },
        }),
        point_light: Some(PointLight {
            position: Vec3::new(2.5, 5.0, 4.0),
            color: Vec3::ONE,
            intensity: 25.0,
        }),
        ..Scene::default()
    };
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::splat(0.5),
    };
    Ok(scene)
}

/// How a TX text's preview is rendered.
struct Preview {
    size: (u32, u32),
    spp: u32,
    allow_placeholders: bool,
}

fn render(
    ctx: &GpuContext,
    doc: &tx::Document,
    file: &Path,
    output: &Path,
    preview: &Preview,
) -> Result<()> {
    let Preview {
        size,
        spp,
        allow_placeholders,
    } = *preview;
    let base_dir = file.parent().unwrap_or(Path::new("."));
    let mut scene =
        preview_scene(doc, base_dir).map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    let notes = scene.sanitize();
    let loaded = prepare_scene(scene, notes)?;
    for note in &loaded.notes {
        eprintln!("note: {}: {note}", file.display());
    }
    if !allow_placeholders {
        refuse_substitutes(&loaded).with_context(|| file.display().to_string())?;
    }
    let mut renderer = renderer_with(ctx, &loaded, size, Kernel::Fragment)?;
    accumulate(ctx, &mut renderer, spp, |_| {})?;
    let image = renderer.read_display(ctx)?;
    image_io::save_png(&image, output).with_context(|| format!("saving {}", output.display()))?;
    eprintln!("wrote {}", output.display());
    Ok(())
}

/// One example of a gallery: its TX file, a title, and what the report
/// says of it.
#[derive(Debug, Deserialize)]
struct Entry {
    file: String,
    title: String,
    description: String,
}

fn gallery(folder: &Path, out: &Path, markdown: &Path, size: (u32, u32), spp: u32) -> Result<()> {
    let index = folder.join("gallery.ron");
    let text = read_capped_to_string(&index, capped_read::TX)
        .with_context(|| format!("{}: cannot read", index.display()))?;
    let entries: Vec<Entry> =
        ron::from_str(&text).map_err(|e| anyhow::anyhow!("{}: {e}", index.display()))?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let ctx = GpuContext::headless()?;
    let page_dir = markdown.parent().unwrap_or(Path::new("."));
    let mut page = String::from(
        "# The IFT528 report's textures, in TX\n\n\
         Generated by `marbre tx --gallery presets/report -o docs/gallery --markdown docs/gallery.md`: \
         each example of the report (§2.3, §3) as its TX file in `presets/report/`, rendered on the \
         preview scene of `marbre tx` (a polygon with its default frame, a sphere, a cylinder), \
         beside what the report says of it. The language and every choice made are in \
         [VIEWER.md](VIEWER.md#tx-the-texture-reports-language).\n\n",
    );
    for entry in entries {
        let file = folder.join(&entry.file);
        let doc = read(&file)?;
        let stem = Path::new(&entry.file).with_extension("png");
        let png = out.join(&stem);
        let preview = Preview {
            size,
            spp,
            allow_placeholders: false,
        };
        render(&ctx, &doc, &file, &png, &preview)?;
        let link = pathdiff::diff_paths(&png, page_dir).unwrap_or(png.clone());
        let source = read_capped_to_string(&file, capped_read::TX)?;
        page.push_str(&format!(
            "## {}\n\n![{}]({})\n\n{}\n\n```\n{}\n```\n\n",
            entry.title,
            entry.title,
            link.display(),
            entry.description,
            source.trim_end()
        ));
    }
    std::fs::write(markdown, page).with_context(|| format!("writing {}", markdown.display()))?;
    eprintln!("wrote {}", markdown.display());
    Ok(())
}
