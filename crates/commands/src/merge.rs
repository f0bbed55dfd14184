//! `marbre merge`: a farm's sample batches and tiles of one render (EXR
//! files that `render --sample-offset` and `--tile` wrote, each with its
//! render record) put together into one image (`marbre_core::merge`),
//! with its estimated error: an EXR of linear radiance, or a PNG
//! tone-mapped after the merge by the display pass's CPU twin.

use anyhow::{Result, anyhow, bail};
use clap::Args;
use marbre_core::image_decode::{IntegerDecode, decode_file};
use marbre_core::image_io::{self, ImageFormat};
use marbre_core::merge::{Batch, merge};
use marbre_core::render_record::{RECORD_ATTRIBUTE, RenderRecord};
use marbre_core::scene::{DisplaySettings, Metering};
use marbre_render::cpu_display;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The batches and tiles: EXR files written by `marbre render` (two
    /// or more).
    #[arg(required = true, num_args = 1..)]
    pub inputs: Vec<PathBuf>,
    /// The merged image: .exr (linear radiance, with the merged render's
    /// record) or .png (exposed and tone-mapped after the merge).
    #[arg(short, long)]
    pub output: PathBuf,
    /// For a PNG: show it as this preset's display says (exposure, auto
    /// exposure, tone map); without it, ACES at exposure 0.
    #[arg(long)]
    pub preset: Option<PathBuf>,
    /// For a PNG: expose it automatically over the merged image, the
    /// exposure becoming a compensation, by Reinhard's key (`key`, the
    /// default) or Massal's RMS (`massal`).
    #[arg(long, value_enum, num_args = 0..=1, default_missing_value = "key", value_name = "METERING")]
    pub auto_exposure: Option<crate::render::MeteringArg>,
}

pub fn run(args: &MergeArgs) -> Result<()> {
    let format = ImageFormat::from_path(&args.output)?;
    if let Some(input) = args.inputs.iter().find(|i| same_file(i, &args.output)) {
        bail!(
            "{} is one of the inputs: the merge would write over it",
            input.display()
        );
    }
    image_io::check_output(&args.output)?;
    let display = display_of(args)?;
    let batches = args
        .inputs
        .iter()
        .map(|path| read_batch(path))
        .collect::<Result<Vec<Batch>>>()?;
    let merged = merge(&batches).map_err(|e| anyhow!(e))?;
    let record = merged.record.to_text();
    let text = Some((RECORD_ATTRIBUTE, record.as_str()));
    match format {
        ImageFormat::Exr => match &merged.variance {
            Some(variance) => image_io::save_exr_with_variance(
                merged.width,
                merged.height,
                &merged.pixels,
                variance,
                text,
                &args.output,
            )?,
            None => image_io::save_exr(
                merged.width,
                merged.height,
                &merged.pixels,
                text,
                &args.output,
            )?,
        },
        ImageFormat::Png => {
            let (image, metered) =
                cpu_display::show(&merged.pixels, (merged.width, merged.height), &display);
            if let Some(stops) = metered {
                println!("auto exposure: {stops:+.2} stops, metered over the merged image");
            }
            image_io::save_png_with_text(&image, text, &args.output)?;
        }
    }
    let samples = merged.record.samples();
    let error = match merged.error {
        Some(e) => format!(
            "estimated relative error {:.3} % (RMSE {:.5}), from {}",
            100.0 * e.relative,
            e.rmse,
            if merged.variance.is_some() {
                "the files' variance layers"
            } else {
                "the spread between the batches"
            }
        ),
        None => "no error estimate: every tile is one batch (render two batches or more of a \
                 tile, or each with --moments, to measure it)"
            .to_owned(),
    };
    let tiles = if merged.tiles > 1 {
        format!(" in {} tiles", merged.tiles)
    } else {
        String::new()
    };
    println!(
        "merged {} files{tiles} into {}: {}×{} at {} spp (samples {}..{}); {error}",
        batches.len(),
        args.output.display(),
        merged.width,
        merged.height,
        merged.record.spp,
        samples.start,
        samples.end,
    );
    Ok(())
}

/// How a merged PNG is shown: the preset's display, if given, with
/// `--auto-exposure` on top.
fn display_of(args: &MergeArgs) -> Result<DisplaySettings> {
    let mut display = match &args.preset {
        Some(path) => marbre_core::preset::load(path)?
            .preset
            .scene
            .render
            .shown_display(),
        None => DisplaySettings::default(),
    };
    if let Some(metering) = args.auto_exposure {
        display.auto_exposure = true;
        display.metering = match metering {
            crate::render::MeteringArg::Key => Metering::Key,
            crate::render::MeteringArg::Massal => Metering::MassalRms,
        };
    }
    Ok(display)
}

/// One batch: its pixels and its render's record, or why not.
pub fn read_batch(path: &Path) -> Result<Batch> {
    let attributes = image_io::read_exr_attributes(path)?;
    let record = RenderRecord::from_attributes(&attributes)
        .map_err(|e| anyhow!("{}: {e}", path.display()))?
        .ok_or_else(|| {
            anyhow!(
                "{} has no marbre render record: merge takes the EXR files `marbre render` writes",
                path.display()
            )
        })?;
    let image = decode_file(path, IntegerDecode::Linear)?;
    let variance = image_io::read_exr_variance(path)?;
    if let Some(v) = &variance
        && v.len() != image.pixels.len()
    {
        bail!(
            "{}: its variance layer is not the picture's size",
            path.display()
        );
    }
    Ok(Batch {
        path: path.to_path_buf(),
        width: image.width,
        height: image.height,
        pixels: image.pixels,
        variance,
        record,
    })
}

/// Whether two paths name one file (the output may not exist yet).
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}
