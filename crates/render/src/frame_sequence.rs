//! Which moments of a scene's time a final render traces, and the file
//! each one goes to: one frame at a time (`render --time`), or a sequence
//! of frames (`render --frames 0..119 -o out/frame_####.png`) whose files
//! already written are skipped, so that a stopped sequence resumes.

use anyhow::{Result, bail};
use marbre_core::atomic_write::check_replaceable;
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};

/// The frame index (the sample sequence's seed, `Renderer::restart_at_sample`)
/// advances by this from one animation frame to the next: each frame's
/// samples are its own (the noise of the estimate does not freeze on
/// moving images), deterministic, and disjoint for up to 2¹⁶ rounds a
/// frame. Frame 0 traces the samples a still always traced.
pub const FRAME_SEED_STRIDE: u32 = 1 << 16;

/// The most frames one render traces: 100 000, more than an hour at 24
/// fps. A sequence's plan holds each frame's path and checks each file
/// before tracing, so a range of 100 million frames would fill the memory
/// before the first frame; a longer sequence is rendered as several
/// ranges (or on a farm, which cuts it into tasks).
pub const MAX_SEQUENCE_FRAMES: u64 = 100_000;

/// What a final render traces in time.
#[derive(Debug, Clone, PartialEq)]
pub enum Timing {
    /// One frame: the scene at `time` seconds, its samples those of frame
    /// `frame`.
    Still { time: f32, frame: u32 },
    /// Frames `frames` at `fps`, each to the output with its run of `#`
    /// replaced by its number; a frame whose file exists is skipped
    /// unless `overwrite`. With `animation`, the frames (PNG) are then
    /// assembled into that file too (`marbre_core::animated_image`).
    Sequence {
        frames: RangeInclusive<u32>,
        fps: f32,
        overwrite: bool,
        animation: Option<PathBuf>,
    },
}

impl Default for Timing {
    fn default() -> Self {
        Timing::Still {
            time: 0.0,
            frame: 0,
        }
    }
}

/// One frame to trace.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedFrame {
    pub frame: u32,
    pub time: f32,
    pub output: PathBuf,
}

/// `A..B` (both included, as Blender's frame range), `A..=B`, or one
/// frame `A`; refused reversed.
pub fn parse_frame_range(s: &str) -> Result<RangeInclusive<u32>, String> {
    let number = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("`{v}` is not a frame number (0, 1, 2, …)"))
    };
    let (first, last) = match s.split_once("..") {
        Some((a, b)) => (number(a)?, number(b.strip_prefix('=').unwrap_or(b))?),
        None => (number(s)?, number(s)?),
    };
    if last < first {
        return Err(format!(
            "`{s}`: the range is reversed (the last frame {last} comes before the first {first})"
        ));
    }
    Ok(first..=last)
}

/// `pattern` with its last run of `#` replaced by `frame`, zero-padded to
/// the run's length (`frame_####.png` → `frame_0042.png`), as Blender
/// names a sequence's files.
pub fn frame_path(pattern: &Path, frame: u32) -> PathBuf {
    let name = pattern
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let Some(end) = name.rfind('#') else {
        return pattern.to_owned();
    };
    let start = name[..end].trim_end_matches('#').len();
    let width = end + 1 - start;
    let named = format!("{}{frame:0width$}{}", &name[..start], &name[end + 1..]);
    pattern.with_file_name(named)
}

/// The frames a render traces, in order, with the files that exist
/// already (skipped) apart; an error before any work if a sequence of
/// more than one frame has no `#` in its output's name, has more than
/// [`MAX_SEQUENCE_FRAMES`], or a frame's file is there but is not a
/// regular file (a FIFO or a device is no frame written, nor one to
/// replace).
pub fn plan(timing: &Timing, output: &Path) -> Result<(Vec<PlannedFrame>, Vec<PlannedFrame>)> {
    match timing {
        Timing::Still { time, frame } => Ok((
            vec![PlannedFrame {
                frame: *frame,
                time: *time,
                output: output.to_owned(),
            }],
            Vec::new(),
        )),
        Timing::Sequence {
            frames,
            fps,
            overwrite,
            ..
        } => {
            if !(fps.is_finite() && *fps > 0.0) {
                bail!("the frame rate must be a positive number of frames a second, such as 24");
            }
            let numbered = output
                .file_name()
                .is_some_and(|n| n.to_string_lossy().contains('#'));
            let count = u64::from(frames.end() - frames.start()) + 1;
            if count > MAX_SEQUENCE_FRAMES {
                bail!(
                    "--frames {}..{} is {count} frames, more than one render traces \
                     ({MAX_SEQUENCE_FRAMES}); render the sequence as several ranges",
                    frames.start(),
                    frames.end()
                );
            }
            if !numbered && frames.start() != frames.end() {
                bail!(
                    "{}: a sequence's output names each frame's number with a run of # \
                     (such as out/frame_####.png)",
                    output.display()
                );
            }
            let mut todo = Vec::new();
            let mut written = Vec::new();
            for frame in frames.clone() {
                let planned = PlannedFrame {
                    frame,
                    time: (f64::from(frame) / f64::from(*fps)) as f32,
                    output: frame_path(output, frame),
                };
                check_replaceable(&planned.output).map_err(|e| {
                    anyhow::anyhow!("cannot write {}: {e}", planned.output.display())
                })?;
                if *overwrite || !planned.output.exists() {
                    todo.push(planned);
                } else {
                    written.push(planned);
                }
            }
            Ok((todo, written))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_ranges_read_as_blender_writes_them() {
        assert_eq!(parse_frame_range("0..119"), Ok(0..=119));
        assert_eq!(parse_frame_range("3..=5"), Ok(3..=5));
        assert_eq!(parse_frame_range("7"), Ok(7..=7));
        let reversed = parse_frame_range("9..2").unwrap_err();
        assert!(reversed.contains("reversed"), "{reversed}");
        assert!(parse_frame_range("a..2").is_err());
        assert!(parse_frame_range("-1..2").is_err());
    }

    #[test]
    fn a_frame_number_replaces_the_last_run_of_hashes() {
        let p = |s: &str, f| frame_path(Path::new(s), f).to_string_lossy().into_owned();
        assert_eq!(p("out/frame_####.png", 42), "out/frame_0042.png");
        assert_eq!(p("out/v#/f_##.exr", 7), "out/v#/f_07.exr");
        assert_eq!(p("f_#.png", 123), "f_123.png");
        assert_eq!(p("a##b##.png", 3), "a##b03.png");
    }

    /// Files written are skipped (resume) unless overwriting; a sequence
    /// without `#` is refused.
    #[test]
    fn a_plan_skips_frames_written() {
        let dir = tempfile::tempdir().unwrap();
        let pattern = dir.path().join("f_###.png");
        std::fs::write(dir.path().join("f_001.png"), b"x").unwrap();
        let timing = |overwrite| Timing::Sequence {
            frames: 0..=2,
            fps: 4.0,
            overwrite,
            animation: None,
        };
        let (todo, done) = plan(&timing(false), &pattern).unwrap();
        assert_eq!(todo.iter().map(|f| f.frame).collect::<Vec<_>>(), [0, 2]);
        assert_eq!(todo[1].time, 0.5);
        assert_eq!(done.len(), 1);
        let (todo, _) = plan(&timing(true), &pattern).unwrap();
        assert_eq!(todo.len(), 3);
        let e = plan(&timing(false), &dir.path().join("f.png")).unwrap_err();
        assert!(e.to_string().contains("run of #"), "{e}");
    }

    fn sequence(frames: RangeInclusive<u32>, overwrite: bool) -> Timing {
        Timing::Sequence {
            frames,
            fps: 24.0,
            overwrite,
            animation: None,
        }
    }

    /// A range over the maximum is refused before any path is made (it
    /// used to build 100 million paths, 1.66 GB, before the first frame);
    /// the whole u32 range too, whose count does not fit a u32. The
    /// pattern's folder does not exist: nothing is looked at on disk.
    #[test]
    fn a_range_over_the_maximum_is_refused_before_any_work() {
        let pattern = Path::new("/nonexistent/f_####.png");
        let last = (MAX_SEQUENCE_FRAMES - 1) as u32;
        for (range, count) in [
            (0..=last + 1, "100001"),
            (0..=100_000_000, "100000001"),
            (0..=u32::MAX, "4294967296"),
        ] {
            let e = plan(&sequence(range.clone(), false), pattern)
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(&format!("is {count} frames")) && e.contains("(100000)"),
                "{e}"
            );
        }
        let (todo, _) = plan(&sequence(7..=7 + last, false), pattern).unwrap();
        assert_eq!(todo.len() as u64, MAX_SEQUENCE_FRAMES);
    }

    /// A frame's file that is a FIFO (or a link to one) is refused before
    /// tracing, with or without --overwrite, and stays a FIFO.
    #[test]
    fn a_frame_that_is_a_fifo_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("f_01.png");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        for overwrite in [false, true] {
            let e = plan(&sequence(0..=2, overwrite), &dir.path().join("f_##.png"))
                .unwrap_err()
                .to_string();
            assert_eq!(
                e,
                format!(
                    "cannot write {}: it is a FIFO, not a regular file; marbre replaces only \
                     regular files",
                    fifo.display()
                )
            );
        }
        use std::os::unix::fs::FileTypeExt;
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    }
}
