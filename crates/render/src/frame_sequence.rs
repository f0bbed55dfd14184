//! Which moments of a scene's time a final render traces, and the file
//! each one goes to: one frame at a time (`render --time`), or a sequence
//! of frames (`render --frames 0..119 -o out/frame_####.png`) whose files
//! already written are skipped, so that a stopped sequence resumes.

use anyhow::{Result, bail};
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};

/// The frame index (the sample sequence's seed, `Renderer::restart_at_sample`)
/// advances by this from one animation frame to the next: each frame's
/// samples are its own (the noise of the estimate does not freeze on
/// moving images), deterministic, and disjoint for up to 2¹⁶ rounds a
/// frame. Frame 0 traces the samples a still always traced.
pub const FRAME_SEED_STRIDE: u32 = 1 << 16;

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
/// more than one frame has no `#` in its output's name.
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
            if !numbered && frames.start() != frames.end() {
                bail!(
                    "{}: a sequence's output names each frame's number with a run of # \
                     (such as out/frame_####.png)",
                    output.display()
                );
            }
            let all = frames.clone().map(|frame| PlannedFrame {
                frame,
                time: (f64::from(frame) / f64::from(*fps)) as f32,
                output: frame_path(output, frame),
            });
            Ok(all.partition(|f| *overwrite || !f.output.exists()))
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
}
