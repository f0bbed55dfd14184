//! `marbre merge`: a farm's sample batches and tiles of one render (EXR
//! files that `render --sample-offset` and `--tile` wrote, each with its
//! render record) put together into one image (`marbre_core::merge`),
//! with its estimated error: an EXR of linear radiance, or a PNG
//! tone-mapped after the merge by the display pass's CPU twin.

use anyhow::{Result, anyhow, bail};
use clap::Args;
use marbre_core::image_io::LayerName;
use marbre_core::image_io::{self, ImageFormat};
use marbre_core::merge::{Batch, Guides, Merged, merge};
use marbre_core::render_record::{RECORD_ATTRIBUTE, RenderRecord, check_seal};
use marbre_core::scene::{DenoiseQuality, Denoiser, DisplaySettings, Metering};
use marbre_core::shown::shown;
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
            shown(&input.display().to_string())
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
    for note in &merged.notes {
        println!("{note}");
    }
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
        shown(&args.output.display().to_string()),
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

/// One batch: its pixels, its layers and its render's record, or why not.
///
/// The file is read as it is ([`image_io::read_exr_channels`]), not
/// through the texture decoder, which clamps: a merge averages the
/// radiance the render wrote. Its record must match its pixels (its seal,
/// [`marbre_core::render_record::check_seal`]): an `spp` edited after the
/// render would weigh the file wrongly. NaN and infinite values, which
/// would make every mean they enter NaN, are set to 0, and a note counts
/// them.
pub fn read_batch(path: &Path) -> Result<Batch> {
    let name = shown(&path.display().to_string());
    let attributes = image_io::read_exr_attributes(path)?;
    let record = RenderRecord::from_attributes(&attributes)
        .map_err(|e| anyhow!("{name}: {}", shown(&e)))?
        .ok_or_else(|| {
            anyhow!(
                "{name} has no marbre render record: merge takes the EXR files `marbre render` \
                 writes"
            )
        })?;
    let file = image_io::read_exr_channels(path)?;
    let mut notes = Vec::new();
    match check_seal(&attributes[RECORD_ATTRIBUTE], &file.named()) {
        Ok(true) => {}
        Ok(false) => notes.push(format!(
            "{name}: its render record has no seal (a file of a marbre before seals): its samples \
             are taken as its record says, unchecked"
        )),
        Err(e) => bail!("{name}: {e}"),
    }
    let count = file.width as usize * file.height as usize;
    let channel = |c: &str| file.channel(c).filter(|v| v.len() == count);
    let (Some(r), Some(g), Some(b)) = (channel("R"), channel("G"), channel("B")) else {
        bail!(
            "{name}: no R, G and B channels of one value a pixel of its {}×{} picture",
            file.width,
            file.height
        );
    };
    let alpha = channel("A");
    let mut pixels: Vec<[f32; 4]> = (0..count)
        .map(|p| [r[p], g[p], b[p], alpha.map_or(1.0, |a| a[p])])
        .collect();
    notes.extend(replace_not_finite(
        &name,
        "picture",
        pixels.iter_mut().flatten(),
    ));
    let mut layers =
        [image_io::VARIANCE, image_io::ALBEDO, image_io::NORMAL].map(|l| file.layer(l));
    // A layer of another size (subsampled channels) is not the picture's.
    for (layer, values) in ["variance", "albedo", "normal"].iter().zip(&mut layers) {
        if let Some(values) = values {
            if values.len() != count {
                bail!(
                    "{name}: its {layer} layer has {} values, not one a pixel of its {}×{} \
                     picture",
                    values.len(),
                    file.width,
                    file.height
                );
            }
            let what = format!("{layer} layer");
            notes.extend(replace_not_finite(
                &name,
                &what,
                values.iter_mut().flatten(),
            ));
        }
    }
    let [variance, albedo, normal] = layers;
    Ok(Batch {
        path: path.to_path_buf(),
        width: file.width,
        height: file.height,
        pixels,
        variance,
        guides: match (albedo, normal) {
            (Some(albedo), Some(normal)) => Some(Guides { albedo, normal }),
            _ => None,
        },
        record,
        notes,
    })
}

/// Sets the NaN and infinite `values` to 0; a note naming the file and
/// `what` of it counts them, if any.
fn replace_not_finite<'a>(
    name: &str,
    what: &str,
    values: impl Iterator<Item = &'a mut f32>,
) -> Option<String> {
    let (mut nan, mut infinite) = (0usize, 0usize);
    for v in values {
        if v.is_nan() {
            nan += 1;
        } else if v.is_infinite() {
            infinite += 1;
        } else {
            continue;
        }
        *v = 0.0;
    }
    (nan + infinite > 0).then(|| {
        format!(
            "note: {name}: {nan} NaN and {infinite} infinite values of its {what} set to 0 \
             before the merge"
        )
    })
}

/// Whether two paths name one file (the output may not exist yet).
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}
