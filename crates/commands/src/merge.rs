//! `marbre merge`: a farm's sample batches of one render (EXR files that
//! `render --sample-offset` wrote, each with its render record) averaged
//! into one EXR, with the merged image's estimated error
//! (`marbre_core::merge`).

use anyhow::{Result, anyhow, bail};
use clap::Args;
use marbre_core::image_decode::{IntegerDecode, decode_file};
use marbre_core::image_io::{self, ImageFormat};
use marbre_core::merge::{Batch, merge};
use marbre_core::render_record::{RECORD_ATTRIBUTE, RenderRecord};
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The batches: EXR files written by `marbre render` (two or more).
    #[arg(required = true, num_args = 1..)]
    pub inputs: Vec<PathBuf>,
    /// The merged EXR (linear radiance, with the merged render's record).
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(args: &MergeArgs) -> Result<()> {
    if ImageFormat::from_path(&args.output)? != ImageFormat::Exr {
        bail!(
            "{}: merge writes linear radiance, an .exr; tone-map it afterwards, or render the \
             PNG from the preset",
            args.output.display()
        );
    }
    if let Some(input) = args.inputs.iter().find(|i| same_file(i, &args.output)) {
        bail!(
            "{} is one of the inputs: the merge would write over it",
            input.display()
        );
    }
    image_io::check_output(&args.output)?;
    let batches = args
        .inputs
        .iter()
        .map(|path| read_batch(path))
        .collect::<Result<Vec<Batch>>>()?;
    let merged = merge(&batches).map_err(|e| anyhow!(e))?;
    image_io::save_exr(
        merged.width,
        merged.height,
        &merged.pixels,
        Some((RECORD_ATTRIBUTE, &merged.record.to_text())),
        &args.output,
    )?;
    let samples = merged.record.samples();
    println!(
        "merged {} batches into {}: {} spp (samples {}..{}); estimated relative error {:.3} % \
         (RMSE {:.5}), from the spread between the batches",
        batches.len(),
        args.output.display(),
        merged.record.spp,
        samples.start,
        samples.end,
        100.0 * merged.relative_error,
        merged.rmse
    );
    Ok(())
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
    Ok(Batch {
        path: path.to_path_buf(),
        width: image.width,
        height: image.height,
        pixels: image.pixels,
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
