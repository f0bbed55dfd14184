//! `marbre tx`: a TX text (the IFT528 report's texture language) rendered
//! on the report's preview scene, a polygon with its default frame, a
//! sphere and a cylinder, through the session functions `marbre render`
//! uses; `--print` writes the parsed text back; `--gallery` renders every
//! example of a folder and writes a Markdown page of them.

use crate::markdown;
use crate::render::parse_size;
use anyhow::{Context, Result, bail};
use clap::Args;
use marbre_core::capped_read::{self, read_capped_to_string};
use marbre_core::image_io;
use marbre_core::tx;
use marbre_core::tx_preview::{self, preview_scene};
use marbre_render::final_render::refuse_substitutes;
use marbre_render::gpu::{GpuContext, Kernel};
use marbre_render::session::{accumulate, prepare_scene, renderer_with};
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

fn gallery(folder: &Path, out: &Path, markdown: &Path, size: (u32, u32), spp: u32) -> Result<()> {
    let index = folder.join("gallery.ron");
    let text = read_capped_to_string(&index, capped_read::TX)
        .with_context(|| format!("{}: cannot read", index.display()))?;
    let entries = tx_preview::parse_gallery(&text)
        .map_err(|e| anyhow::anyhow!("{}: {e}", index.display()))?;
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
        // The title, the link and the source as the page's reader must
        // read them back (`markdown`); the description is the author's
        // own Markdown prose.
        page.push_str(&format!(
            "## {}\n\n![{}]({})\n\n{}\n\n{}\n",
            markdown::inline(&entry.title),
            markdown::inline(&entry.title),
            markdown::link_target(&link.to_string_lossy()),
            entry.description,
            markdown::code_block(source.trim_end())
        ));
    }
    std::fs::write(markdown, page).with_context(|| format!("writing {}", markdown.display()))?;
    eprintln!("wrote {}", markdown.display());
    Ok(())
}
