//! `marbre merge` checks what it is told (issue 47): a record changed
//! after the render, a batch of no samples and a header that claims more
//! than its file holds are refused, naming the file; NaN and infinite
//! values are set to 0 with a note; file names and record text are shown
//! with their control characters escaped. The batches are written here,
//! as `marbre render` writes them (`image_io::save_exr_layers` with a
//! record), so that no render is needed.

use crate::batches::merge_files;
use marbre_commands::merge::read_batch;
use marbre_core::image_io::{self, VARIANCE};
use marbre_core::render_record::{RECORD_ATTRIBUTE, RenderRecord};
use marbre_core::tile::Tile;
use std::path::{Path, PathBuf};

/// The record of a batch of a 2×1 image: `spp` samples from `offset`.
fn record(offset: u32, spp: u32) -> RenderRecord {
    RenderRecord {
        spp,
        sample_offset: offset,
        image: (2, 1),
        tile: Tile::whole((2, 1)),
        frame: 0,
        time: 0.0,
        scene: "0123456789abcdef".into(),
        kernel: "cpu".into(),
        adapter: "test".into(),
        version: "0.1.0".into(),
    }
}

/// Writes a batch of `pixels` with its record (sealed, as every render's)
/// and a variance layer.
fn write_batch(path: &Path, record: &RenderRecord, pixels: &[[f32; 4]; 2]) {
    let text = record.to_text();
    image_io::save_exr_layers(
        2,
        1,
        pixels,
        &[(VARIANCE, &[[0.01; 3]; 2])],
        Some((RECORD_ATTRIBUTE, &text)),
        path,
    )
    .unwrap();
}

/// Replaces the bytes `from` of the file at `path` by `to`, of the same
/// length, in place: an edit of its header.
fn patch(path: &Path, from: &[u8], to: &[u8]) {
    assert_eq!(from.len(), to.len());
    let mut bytes = std::fs::read(path).unwrap();
    let at = bytes
        .windows(from.len())
        .position(|w| w == from)
        .expect("the bytes to patch");
    bytes[at..at + to.len()].copy_from_slice(to);
    std::fs::write(path, bytes).unwrap();
}

/// Two batches of samples 0..4 and 4..8 in a new folder.
fn two_batches(dir: &Path) -> [PathBuf; 2] {
    let (a, b) = (dir.join("a.exr"), dir.join("b.exr"));
    write_batch(&a, &record(0, 4), &[[1.0, 1.0, 1.0, 1.0]; 2]);
    write_batch(&b, &record(4, 4), &[[3.0, 3.0, 3.0, 1.0]; 2]);
    [a, b]
}

/// The probe's edit: a batch's `spp` changed in its EXR header, in place.
/// It merged, weighing the file twice as much (a mean of 2.33 for 2, and
/// a wrong error estimate); the seal refuses it, naming the file.
#[test]
fn a_record_edited_after_the_render_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let [a, b] = two_batches(dir.path());
    let out = dir.path().join("m.exr");
    merge_files(&[a.clone(), b.clone()], &out, &[]).unwrap();
    let merged = read_batch(&out).unwrap();
    assert_eq!(merged.pixels, vec![[2.0, 2.0, 2.0, 1.0]; 2]);
    assert_eq!(
        merged.notes,
        Vec::<String>::new(),
        "the merge is sealed too"
    );
    patch(&b, b"spp=4\n", b"spp=8\n");
    let e = merge_files(&[a, b.clone()], &out, &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!(
            "{}: its render record does not match its pixels",
            b.display()
        )),
        "{e}"
    );
}

/// A batch of no samples is refused: it merged, and the merge reported
/// "estimated relative error 0.000 %".
#[test]
fn a_batch_of_no_samples_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let [a, _] = two_batches(dir.path());
    let empty = dir.path().join("empty.exr");
    write_batch(&empty, &record(4, 0), &[[9.0, 9.0, 9.0, 1.0]; 2]);
    let e = merge_files(&[a, empty.clone()], &dir.path().join("m.exr"), &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("{} holds no samples", empty.display())),
        "{e}"
    );
}

/// NaN and infinite values were set to 0 without a word; now a note
/// names the file and counts them, and the merge is finite.
#[test]
fn replaced_values_are_counted_in_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let [a, _] = two_batches(dir.path());
    let bad = dir.path().join("bad.exr");
    let pixels = [
        [f32::NAN, 3.0, f32::INFINITY, 1.0],
        [3.0, f32::NAN, 3.0, 1.0],
    ];
    write_batch(&bad, &record(4, 4), &pixels);
    let batch = read_batch(&bad).unwrap();
    assert_eq!(
        batch.notes,
        vec![format!(
            "note: {}: 2 NaN and 1 infinite values of its picture set to 0 before the merge",
            bad.display()
        )]
    );
    assert_eq!(
        batch.pixels,
        vec![[0.0, 3.0, 0.0, 1.0], [3.0, 0.0, 3.0, 1.0]]
    );
    let merged = marbre_core::merge::merge(&[read_batch(&a).unwrap(), batch.clone()]).unwrap();
    assert_eq!(merged.notes, batch.notes);
    assert!(merged.pixels.iter().flatten().all(|v| v.is_finite()));
}

/// A batch patched to claim 16384×8192 texels (the probe's 598-byte
/// file, which cost 2.1 GB before it was refused) is refused from its
/// size, naming the file.
#[test]
fn a_header_claiming_more_than_its_file_holds_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let [a, lying] = two_batches(dir.path());
    let attribute = |name: &[u8], values: &[i32]| {
        let mut bytes = name.to_vec();
        bytes.extend((4 * values.len() as i32).to_le_bytes());
        bytes.extend(values.iter().flat_map(|v| v.to_le_bytes()));
        bytes
    };
    let window = |w: i32, h: i32| attribute(b"dataWindow\0box2i\0", &[0, 0, w - 1, h - 1]);
    patch(&lying, &window(2, 1), &window(16384, 8192));
    // The chunk count to match, as the `exr` crate checks it: the file's
    // 64×64 tiles.
    let meta = exr::meta::MetaData::read_from_file(&lying, false).unwrap();
    let header = &meta.headers[0];
    let chunks = |w, h| {
        exr::meta::compute_chunk_count(header.compression, exr::math::Vec2(w, h), header.blocks)
            as i32
    };
    let count = |n: i32| attribute(b"chunkCount\0int\0", &[n]);
    patch(&lying, &count(chunks(2, 1)), &count(chunks(16384, 8192)));
    let size = std::fs::metadata(&lying).unwrap().len();
    assert!(size < 2000, "{size}");
    let e = merge_files(&[a, lying.clone()], &dir.path().join("m.exr"), &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!("{}: ", lying.display()))
            && e.contains("declares 16384x8192 texels")
            && e.contains(&format!("it is {size} bytes")),
        "{e}"
    );
}

/// A file name and a record's text with control characters are printed
/// escaped: a file cannot drive the terminal that shows the merge's
/// message.
#[test]
fn control_characters_in_names_and_records_are_escaped() {
    let dir = tempfile::tempdir().unwrap();
    let [a, _] = two_batches(dir.path());
    let unrecorded = dir.path().join("e\u{1b}[2J.exr");
    image_io::save_exr(2, 1, &[[1.0; 4]; 2], None, &unrecorded).unwrap();
    let out = dir.path().join("m.exr");
    let e = merge_files(&[a.clone(), unrecorded], &out, &[])
        .unwrap_err()
        .to_string();
    assert!(
        !e.chars().any(char::is_control) && e.contains("e\\u{1b}[2J.exr has no marbre render"),
        "{e}"
    );
    let hostile = dir.path().join("h\u{7}.exr");
    let mut other = record(4, 4);
    other.scene = "\u{1b}]0;owned\u{7}".into();
    write_batch(&hostile, &other, &[[1.0; 4]; 2]);
    let e = merge_files(&[a, hostile], &out, &[])
        .unwrap_err()
        .to_string();
    assert!(
        !e.chars().any(char::is_control)
            && e.contains("h\\u{7}.exr is a render of another scene")
            && e.contains("\\u{1b}]0;owned\\u{7}"),
        "{e}"
    );
}
