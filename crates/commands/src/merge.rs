//! `marbre merge`: a farm's sample batches and tiles of one render (EXR
//! files that `render --sample-offset` and `--tile` wrote, each with its
//! render record) put together into one image (`marbre_core::merge`),
//! with its estimated error: an EXR of linear radiance, or a PNG
//! tone-mapped after the merge by the display pass's CPU twin.

use anyhow::{Result, anyhow, bail};
use clap::Args;
use marbre_core::image_decode::{IntegerDecode, decode_file};
use marbre_core::image_io::LayerName;
use marbre_core::image_io::{self, ImageFormat};
use marbre_core::merge::{Batch, Guides, Merged, merge};
use marbre_core::render_record::{RECORD_ATTRIBUTE, RenderRecord};
use marbre_core::scene::{DenoiseQuality, Denoiser, DisplaySettings, Metering};
use marbre_oidn::DeviceKind;
use marbre_render::cpu_display;
use marbre_render::denoiser::{GuidedImage, Running, oidn_for};
use marbre_render::gpu::denoise::{DenoiseImage, DenoiseSettings, denoise_cpu};
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
    /// Filter the merged image with a denoiser, guided by the files'
    /// albedo and normal (`render --guides`), before tone mapping, for a
    /// PNG or an EXR: oidn (Intel Open Image Denoise on the CPU, the
    /// default; where its library is not found, atrous runs instead and a
    /// line says why) or atrous (the viewer's edge-avoiding filter, its CPU
    /// twin, weighted by the merged variance where known).
    #[arg(
        long,
        num_args = 0..=1,
        default_missing_value = "oidn",
        value_name = "oidn|atrous",
        value_parser = crate::render::parse_denoiser
    )]
    pub denoise: Option<Denoiser>,
    /// OIDN's network: high (the default), balanced or fast.
    #[arg(long, default_value = "high", value_parser = crate::render::parse_denoise_quality)]
    pub denoise_quality: DenoiseQuality,
}

pub fn run(args: &MergeArgs) -> Result<()> {
    // Refused before anything is read: an output of another kind.
    ImageFormat::from_path(&args.output)?;
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
    let how = MergedOutput {
        display,
        denoise: args.denoise.map(|d| (d, args.denoise_quality)),
    };
    for line in write_merged(&merged, &args.output, &how)? {
        println!("{line}");
    }
    let samples = merged.record.samples();
    let error = match merged.error {
        Some(e) => format!(
            "estimated relative error {:.3} % (RMSE {:.5}), from {}{}",
            100.0 * e.relative,
            e.rmse,
            if batches.iter().all(|b| b.variance.is_some()) {
                "the files' variance layers"
            } else {
                "the spread between each tile's batches"
            },
            if merged.measured_tiles < merged.tiles {
                format!(
                    ", over the {} of the {} tiles with two batches or more",
                    merged.measured_tiles, merged.tiles
                )
            } else {
                String::new()
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

/// What happens to a merged image on its way to its file.
pub struct MergedOutput {
    /// How a PNG is shown.
    pub display: DisplaySettings,
    /// Filter it with this denoiser (and OIDN's network) first.
    pub denoise: Option<(Denoiser, DenoiseQuality)>,
}

/// Writes `merged` to `output` as `how` says: an EXR of its radiance with
/// the merged record and layers (its variance, unless denoised, and its
/// guides), or a PNG through the display pass's CPU twin. Returns lines
/// for the user.
pub fn write_merged(merged: &Merged, output: &Path, how: &MergedOutput) -> Result<Vec<String>> {
    let mut lines = Vec::new();
    let size = (merged.width, merged.height);
    let pixels = match how.denoise {
        Some((denoiser, quality)) => {
            let (pixels, by) = denoise_merged(merged, output, denoiser, quality)?;
            lines.push(format!("denoised after the merge by {by}"));
            pixels
        }
        None => merged.pixels.clone(),
    };
    let record = merged.record.to_text();
    let text = Some((RECORD_ATTRIBUTE, record.as_str()));
    match ImageFormat::from_path(output)? {
        ImageFormat::Exr => {
            let mut layers: Vec<(LayerName, &[[f32; 3]])> = Vec::new();
            if let Some(variance) = merged.variance.as_ref().filter(|_| how.denoise.is_none()) {
                layers.push((image_io::VARIANCE, variance));
            }
            if let Some(guides) = &merged.guides {
                layers.push((image_io::ALBEDO, &guides.albedo));
                layers.push((image_io::NORMAL, &guides.normal));
            }
            image_io::save_exr_layers(size.0, size.1, &pixels, &layers, text, output)?;
        }
        ImageFormat::Png => {
            let (image, metered) = cpu_display::show(&pixels, size, &how.display);
            if let Some(stops) = metered {
                lines.push(format!(
                    "auto exposure: {stops:+.2} stops, metered over the merged image"
                ));
            }
            image_io::save_png_with_text(&image, text, output)?;
        }
    }
    Ok(lines)
}

/// The merged image denoised, guided by the files' guides, and what
/// denoised it: OIDN on the CPU, or (asked, or OIDN not found) the à-trous
/// filter's CPU twin.
fn denoise_merged(
    merged: &Merged,
    output: &Path,
    denoiser: Denoiser,
    quality: DenoiseQuality,
) -> Result<(Vec<[f32; 4]>, String)> {
    let Some(guides) = &merged.guides else {
        bail!(
            "{}: --denoise needs the files' guides; render them with --guides",
            output.display()
        );
    };
    let instead_of_oidn = match oidn_for(denoiser) {
        Ok(None) => None,
        Ok(Some(library)) => {
            let mut oidn =
                marbre_oidn::Denoiser::new(library, DeviceKind::Cpu).map_err(|e| anyhow!("{e}"))?;
            let image = GuidedImage {
                size: (merged.width, merged.height),
                mean: merged.pixels.clone(),
                albedo: guides
                    .albedo
                    .iter()
                    .map(|a| [a[0], a[1], a[2], 1.0])
                    .collect(),
                normal: guides
                    .normal
                    .iter()
                    .map(|n| [0.5 + 0.5 * n[0], 0.5 + 0.5 * n[1], 0.5 + 0.5 * n[2], 1.0])
                    .collect(),
            };
            let running = Running::Oidn {
                device: DeviceKind::Cpu,
                version: Some(oidn.version()),
                quality,
            };
            return Ok((image.denoise(&mut oidn, quality)?, running.describe()));
        }
        Err(why) => Some(why),
    };
    let by = Running::Atrous { instead_of_oidn }.describe();
    Ok((atrous_merged(merged, guides)?, by))
}

/// The merged image through the à-trous filter's CPU twin; each pixel's
/// variance of its mean, where known, weighs its neighbours (the filter's
/// two-frame form: spread / (F − 1) with F = 2), else the filter estimates
/// it from the pixel's neighbourhood.
fn atrous_merged(merged: &Merged, guides: &Guides) -> Result<Vec<[f32; 4]>> {
    let with_alpha = |v: &[f32; 3]| [v[0], v[1], v[2], 1.0];
    let spread: Vec<[f32; 4]> = merged.variance.as_ref().map_or_else(
        || vec![[0.0; 4]; merged.pixels.len()],
        |v| v.iter().map(with_alpha).collect(),
    );
    let albedo: Vec<[f32; 4]> = guides.albedo.iter().map(with_alpha).collect();
    // The filter reads normals as the guide target holds them.
    let normal: Vec<[f32; 4]> = guides
        .normal
        .iter()
        .map(|n| with_alpha(&n.map(|v| 0.5 + 0.5 * v)))
        .collect();
    let image = DenoiseImage {
        size: (merged.width, merged.height),
        mean: &merged.pixels,
        spread: &spread,
        frames: if merged.variance.is_some() { 2 } else { 1 },
        albedo: &albedo,
        normal: &normal,
    };
    denoise_cpu(&image, &DenoiseSettings::default())
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
    let [variance, albedo, normal]: [Option<Vec<[f32; 3]>>; 3] = image_io::read_exr_layers(
        path,
        &[image_io::VARIANCE, image_io::ALBEDO, image_io::NORMAL],
    )?
    .try_into()
    .expect("one answer a layer asked");
    // A layer of another size (subsampled channels, another part) is not
    // the picture's.
    for (layer, values) in [
        ("variance", &variance),
        ("albedo", &albedo),
        ("normal", &normal),
    ] {
        if let Some(values) = values
            && values.len() != image.pixels.len()
        {
            bail!(
                "{}: its {layer} layer has {} values, not one a pixel of its {}×{} picture",
                path.display(),
                values.len(),
                image.width,
                image.height
            );
        }
    }
    Ok(Batch {
        path: path.to_path_buf(),
        width: image.width,
        height: image.height,
        pixels: image.pixels,
        variance,
        guides: match (albedo, normal) {
            (Some(albedo), Some(normal)) => Some(Guides { albedo, normal }),
            _ => None,
        },
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
