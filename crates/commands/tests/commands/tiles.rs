//! `marbre render --tile` and `--tiles` (issue 30): a tile is traced with
//! the whole image's camera and per-pixel samples, so that `marbre merge`
//! assembles tiles (each in one batch or several) to the whole render;
//! a render larger than `--max-tile-pixels` is traced in pieces and is
//! the same image; outputs record how they were made, in EXR and PNG. On
//! the GPU (lavapipe here).

use super::batches::{
    largest_relative_difference, merge_files, render_ball, render_ball_on, render_ball_with,
    scratch,
};
use marbre_commands::merge;
use marbre_core::image_io;
use marbre_core::render_record::{RECORD_ATTRIBUTE, RenderRecord};
use marbre_core::tile::Tile;
use marbre_render::gpu::testing::gpu_or_skip;
use std::path::{Path, PathBuf};

/// Renders every tile of a `grid` (`CxR`) of the ball with `flags`, to
/// `{prefix}{i}.exr` in `dir`; their paths.
fn render_tiles(dir: &Path, prefix: &str, grid: &str, flags: &[&str]) -> Vec<PathBuf> {
    let count: u32 = marbre_core::tile::TileGrid::parse(grid).unwrap().count();
    (0..count)
        .map(|i| {
            let name = format!("{prefix}{i}.exr");
            let index = i.to_string();
            let all = [flags, &["--tiles", grid, "--tile-index", &index]].concat();
            render_ball_with(dir, &name, &all).unwrap();
            dir.join(name)
        })
        .collect()
}

/// The six tiles of a 3x2 grid, merged, are the whole render bit for bit;
/// so is a 2x2 grid whose tiles are each two batches of 2 samples (to
/// float rounding), and its merge estimates an error. A missing tile is
/// named by its first pixel and nothing is written.
#[test]
fn tiles_assemble_to_the_whole_render() {
    if gpu_or_skip("tiles_assemble_to_the_whole_render").is_none() {
        return;
    }
    let dir = scratch("tiles", 1);
    let whole = render_ball(&dir, "whole.exr", 4, 0).unwrap();
    let tiles = render_tiles(&dir, "t", "3x2", &["--spp", "4"]);
    let t4 = merge::read_batch(&tiles[4]).unwrap();
    assert_eq!(t4.record.tile, Tile::parse("13,12,26,24").unwrap());
    assert_eq!((t4.width, t4.height, t4.record.image), (13, 12, (40, 24)));
    let merged = dir.join("merged.exr");
    merge_files(&tiles, &merged, &[]).unwrap();
    let assembled = merge::read_batch(&merged).unwrap();
    assert!(
        assembled.pixels == whole,
        "the assembled tiles differ from the whole render"
    );
    assert_eq!(assembled.record.tile, Tile::whole((40, 24)));

    let batches = [
        render_tiles(&dir, "q-first", "2x2", &["--spp", "2"]),
        render_tiles(
            &dir,
            "q-second",
            "2x2",
            &["--spp", "2", "--sample-offset", "2"],
        ),
    ]
    .concat();
    let merged = dir.join("batched.exr");
    merge_files(&batches, &merged, &[]).unwrap();
    let d = largest_relative_difference(&merge::read_batch(&merged).unwrap().pixels, &whole);
    assert!(
        d < 1e-4,
        "tiles of two batches are {d} from the whole render"
    );

    let missing = dir.join("missing.exr");
    let e = merge_files(&tiles[..5], &missing, &[]).unwrap_err();
    assert!(
        format!("{e:#}").contains("leave 168 of the 40 × 24")
            && format!("{e:#}").contains("(26, 12)"),
        "{e:#}"
    );
    assert!(!missing.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The CPU kernel's tiles (issue 33) assemble to its whole render bit
/// for bit, as the GPU kernels' do: a tile traces its pixels with the
/// whole image's camera and seeds, on the CPU too; each file records the
/// kernel that traced it.
#[test]
fn cpu_kernel_tiles_assemble_to_its_whole_render() {
    if gpu_or_skip("cpu_kernel_tiles_assemble_to_its_whole_render").is_none() {
        return;
    }
    let dir = scratch("cpu-tiles", 1);
    let whole = render_ball_on(&dir, "whole.exr", "cpu", &["--spp", "4"]).unwrap();
    let tiles: Vec<PathBuf> = (0..4)
        .map(|i| {
            let name = format!("t{i}.exr");
            let index = i.to_string();
            let flags = ["--spp", "4", "--tiles", "2x2", "--tile-index", &index];
            render_ball_on(&dir, &name, "cpu", &flags).unwrap();
            dir.join(name)
        })
        .collect();
    assert_eq!(merge::read_batch(&tiles[0]).unwrap().record.kernel, "cpu");
    let merged = dir.join("merged.exr");
    merge_files(&tiles, &merged, &[]).unwrap();
    assert!(
        merge::read_batch(&merged).unwrap().pixels == whole,
        "the CPU kernel's assembled tiles differ from its whole render"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// With at most 200 pixels at once, the 40×24 render is traced in five
/// pieces of 5 rows (the last of 4): the EXR is the whole render bit for
/// bit, and its PNG, shown by the display pass's CPU twin, is within one
/// level of the GPU display pass's (rounding), at a manual exposure and
/// with auto exposure.
#[test]
fn a_render_in_pieces_is_the_whole_render() {
    if gpu_or_skip("a_render_in_pieces_is_the_whole_render").is_none() {
        return;
    }
    let dir = scratch("pieces", 2);
    let whole = render_ball(&dir, "whole.exr", 4, 0).unwrap();
    let pieces = render_ball_with(
        &dir,
        "pieces.exr",
        &["--spp", "4", "--max-tile-pixels", "200"],
    )
    .unwrap();
    assert!(pieces == whole, "the render in pieces differs");
    for flags in [&[][..], &["--auto-exposure"][..]] {
        let gpu = [&["--spp", "4"][..], flags].concat();
        let cpu = [&["--spp", "4", "--max-tile-pixels", "200"][..], flags].concat();
        render_ball_with(&dir, "gpu.png", &gpu).unwrap();
        render_ball_with(&dir, "cpu.png", &cpu).unwrap();
        let read = |name: &str| image::open(dir.join(name)).unwrap().to_rgba8();
        let (gpu, cpu) = (read("gpu.png"), read("cpu.png"));
        let largest = gpu
            .as_raw()
            .iter()
            .zip(cpu.as_raw())
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap();
        assert!(
            largest <= 1,
            "{flags:?}: the PNGs differ by {largest} levels"
        );
        let _ = std::fs::remove_file(dir.join("gpu.png"));
        let _ = std::fs::remove_file(dir.join("cpu.png"));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A PNG and an EXR say how they were made; a merged PNG too. A
/// truncated input is refused by name.
#[test]
fn outputs_record_their_render() {
    if gpu_or_skip("outputs_record_their_render").is_none() {
        return;
    }
    let dir = scratch("records", 1);
    render_ball_with(&dir, "b.png", &["--spp", "3", "--sample-offset", "5"]).unwrap();
    let text = image_io::read_png_text(&dir.join("b.png")).unwrap();
    let record = RenderRecord::from_attributes(&text).unwrap().unwrap();
    assert_eq!(
        (record.spp, record.sample_offset, record.image),
        (3, 5, (40, 24))
    );
    assert_eq!(record.kernel, "fragment");
    let inputs: Vec<PathBuf> = (0..2)
        .map(|i| {
            let name = format!("b{i}.exr");
            render_ball(&dir, &name, 2, 2 * i).unwrap();
            dir.join(name)
        })
        .collect();
    let exr = image_io::read_exr_attributes(&inputs[1]).unwrap();
    let record = RenderRecord::from_attributes(&exr).unwrap().unwrap();
    assert_eq!((record.spp, record.sample_offset), (2, 2));
    assert_eq!(record.scene.len(), 16);
    let merged = dir.join("merged.png");
    merge_files(&inputs, &merged, &["--auto-exposure"]).unwrap();
    let text = image_io::read_png_text(&merged).unwrap();
    let merged_record = RenderRecord::from_attributes(&text).unwrap().unwrap();
    assert_eq!((merged_record.spp, merged_record.scene), (4, record.scene));
    assert!(text.contains_key(RECORD_ATTRIBUTE));
    // A truncated batch is named, and nothing is written.
    let bytes = std::fs::read(&inputs[1]).unwrap();
    let cut = dir.join("cut.exr");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let out = dir.join("from-cut.exr");
    let e = merge_files(&[inputs[0].clone(), cut], &out, &[]).unwrap_err();
    assert!(
        format!("{e:#}").contains("cut.exr") && format!("{e:#}").contains("truncated"),
        "{e:#}"
    );
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Bad tiles, an offset past the last sample and a denoised render in
/// pieces are refused before anything is traced, each naming its cause,
/// and nothing is written.
#[test]
fn bad_tiles_are_refused_by_name() {
    if gpu_or_skip("bad_tiles_are_refused_by_name").is_none() {
        return;
    }
    let dir = scratch("bad-tiles", 1);
    let cases: [(&str, &[&str], &str); 4] = [
        (
            "outside.exr",
            &["--tile", "0,0,41,8"],
            "outside the 40 × 24 image",
        ),
        (
            "index.exr",
            &["--tiles", "2x2", "--tile-index", "4"],
            "tiles 0 to 3",
        ),
        (
            "grid.exr",
            &["--tiles", "41x1", "--tile-index", "0"],
            "does not divide",
        ),
        ("tile.png", &["--tile", "0,0,8,8"], "an .exr"),
    ];
    for (name, flags, cause) in cases {
        let e = render_ball_with(&dir, name, flags).unwrap_err();
        assert!(format!("{e:#}").contains(cause), "{flags:?}: {e:#}");
        assert!(!dir.join(name).exists(), "{name} was written");
    }
    let e = render_ball_with(
        &dir,
        "denoised.png",
        &["--denoise", "--max-tile-pixels", "100"],
    )
    .unwrap_err();
    assert!(format!("{e:#}").contains("denoiser"), "{e:#}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Four tiles, one batch of 16 samples each, with `--moments`: the merge
/// estimates its error from the variance layers (the tiles alone have no
/// spread between batches), within 0.6–1.5× the error measured against
/// an independent reference (256 samples from 4096), and keeps the layer.
/// One round (--spp 1 here) is refused: it has no spread.
#[test]
fn moments_let_a_merge_of_single_batches_know_its_error() {
    if gpu_or_skip("moments_let_a_merge_of_single_batches_know_its_error").is_none() {
        return;
    }
    let dir = scratch("moments", 1);
    let tiles = render_tiles(&dir, "t", "2x2", &["--spp", "16", "--moments"]);
    let reference = render_ball(&dir, "reference.exr", 256, 4096).unwrap();
    let merged_path = dir.join("merged.exr");
    merge_files(&tiles, &merged_path, &[]).unwrap();
    let merged = merge::read_batch(&merged_path).unwrap();
    let variance = merged
        .variance
        .as_ref()
        .expect("the merged file keeps the layer");
    let estimate = (variance
        .iter()
        .flatten()
        .map(|v| f64::from(*v))
        .sum::<f64>()
        / (3 * variance.len()) as f64)
        .sqrt();
    let measured = super::batches::rmse(&merged.pixels, &reference);
    eprintln!("moments: estimated RMSE {estimate:.5}, measured {measured:.5}");
    assert!(
        (0.6..=1.5).contains(&(estimate / measured)),
        "estimated RMSE {estimate}, measured {measured}"
    );
    let e = render_ball_with(&dir, "one.exr", &["--spp", "1", "--moments"]).unwrap_err();
    assert!(format!("{e:#}").contains("one round"), "{e:#}");
    let e = render_ball_with(&dir, "m.png", &["--spp", "4", "--moments"]).unwrap_err();
    assert!(format!("{e:#}").contains("only an .exr"), "{e:#}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Four tiles with `--moments --guides`, merged with `--denoise oidn` or
/// `--denoise atrous`, are the whole render denoised alike (`--denoise X
/// --denoise-exr`) within 10⁻³: the same variance and guides reach the
/// same filter, and the merge filters the assembled image, so no seam is
/// left at the tiles' edges. The filtered merge is nearer the reference
/// than the unfiltered one. Without guides, `--denoise` is refused naming
/// them.
#[test]
fn a_merge_denoises_with_the_files_guides() {
    if gpu_or_skip("a_merge_denoises_with_the_files_guides").is_none() {
        return;
    }
    let dir = scratch("guides", 1);
    let tiles = render_tiles(&dir, "t", "2x2", &["--spp", "8", "--moments", "--guides"]);
    let mut filtered = Vec::new();
    for denoiser in ["oidn", "atrous"] {
        let whole = render_ball_with(
            &dir,
            &format!("whole-{denoiser}.exr"),
            &["--spp", "8", "--denoise", denoiser, "--denoise-exr"],
        )
        .unwrap();
        let denoised = dir.join(format!("denoised-{denoiser}.exr"));
        merge_files(&tiles, &denoised, &["--denoise", denoiser]).unwrap();
        let merged = merge::read_batch(&denoised).unwrap().pixels;
        let d = largest_relative_difference(&merged, &whole);
        assert!(
            d < 1e-3,
            "{denoiser}: the denoised merge is {d} from the denoised whole render"
        );
        filtered.push(merged);
    }
    let plain = dir.join("plain.exr");
    merge_files(&tiles, &plain, &[]).unwrap();
    let reference = render_ball(&dir, "reference.exr", 256, 4096).unwrap();
    let noisy = super::batches::rmse(&merge::read_batch(&plain).unwrap().pixels, &reference);
    for (denoiser, filtered) in ["oidn", "atrous"].iter().zip(&filtered) {
        let smooth = super::batches::rmse(filtered, &reference);
        eprintln!("merged RMSE {noisy:.5}, denoised by {denoiser} {smooth:.5}");
        assert!(smooth < noisy, "{denoiser}: denoised {smooth}, not {noisy}");
    }
    let bare: Vec<PathBuf> = (0..2)
        .map(|i| {
            let name = format!("b{i}.exr");
            render_ball(&dir, &name, 2, 2 * i).unwrap();
            dir.join(name)
        })
        .collect();
    let e = merge_files(&bare, &dir.join("no.exr"), &["--denoise"]).unwrap_err();
    assert!(format!("{e:#}").contains("--guides"), "{e:#}");
    let _ = std::fs::remove_dir_all(&dir);
}
