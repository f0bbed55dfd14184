//! `marbre soak`: the real viewer driven for many frames by seeded random
//! edits (parameters most frames, structural edits now and then, preset
//! loads, one simulated device loss), its memory sampled every frame and
//! judged at the end: RSS, the GPU allocator's bytes and wgpu's live
//! objects must stay within a bound of what they were after the warm-up.
//!
//! The viewer owns the loop and calls the driver through its one hook,
//! [`FrameScript`]: [`SoakDriver::step`] before the UI runs (the viewer
//! applies the action it returns), then [`sample_memory`] and
//! [`SoakDriver::record`] after presenting, and at the end the driver
//! prints [`SoakDriver::verdict`].

#[cfg(not(target_arch = "wasm32"))]
pub mod command;
mod edits;
mod memory;
mod rng;
mod verdict;

pub use memory::{MemorySample, sample_memory};

use super::frame_script::{FrameScript, Presented, ScriptAction};
use anyhow::{Context, Result};
use edits::Structural;
use marbre_core::scene::{EnvSource, Scene};
use rng::Pcg32;
use std::path::PathBuf;
use verdict::{Metric, Rule, Unit};

/// Presets the soak cycles through by default: each loads in about a
/// second on a software rasteriser, and together they cover image
/// textures, an OBJ mesh, cut-outs, nesting and several environment maps.
/// The heavy scenes (millions of triangles) would make a load the whole
/// run.
pub const DEFAULT_PRESETS: [&str; 5] = [
    "presets/default.ron",
    "presets/marble.ron",
    "presets/images.ron",
    "presets/cutouts.ron",
    "presets/cornell.ron",
];

/// What `marbre soak` asks of the viewer.
#[derive(Debug, Clone)]
pub struct SoakOptions {
    /// Frames to run.
    pub frames: u64,
    /// Seeds the edits: the same seed and presets give the same run.
    pub seed: u64,
    /// Loaded in turn every [`SoakDriver`] load interval.
    pub presets: Vec<PathBuf>,
    /// Frames before memory is held to its baseline.
    pub warm_up_frames: u64,
    /// Where to write the per-frame memory as CSV.
    pub report: Option<PathBuf>,
}

impl SoakOptions {
    /// A fifth of the run, at least 50 frames, at most 2000 and never more
    /// than half the run (the other half is what is judged).
    pub fn default_warm_up(frames: u64) -> u64 {
        (frames / 5).clamp(50, 2000).min(frames / 2)
    }

    /// Preset files from the command line: each argument a `.ron` file, or
    /// a folder whose `.ron` files are taken in name order.
    pub fn preset_files(arguments: &[PathBuf]) -> Result<Vec<PathBuf>> {
        let mut files = Vec::new();
        for path in arguments {
            if path.is_dir() {
                let mut found: Vec<PathBuf> = std::fs::read_dir(path)
                    .with_context(|| format!("{}: cannot list presets", path.display()))?
                    .filter_map(|entry| entry.ok().map(|e| e.path()))
                    .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "ron"))
                    .collect();
                found.sort();
                anyhow::ensure!(
                    !found.is_empty(),
                    "{}: no .ron preset in it",
                    path.display()
                );
                files.extend(found);
            } else {
                anyhow::ensure!(path.is_file(), "{}: no such preset file", path.display());
                files.push(path.clone());
            }
        }
        Ok(files)
    }
}

/// The chance that a frame makes a structural edit (a shader rebuild,
/// about a second of CPU on lavapipe, off the render thread).
const STRUCTURAL_CHANCE: f32 = 1.0 / 40.0;
/// The chance that any other frame edits a parameter.
const PARAMETER_CHANCE: f32 = 0.9;

/// A soak ends with a Render dialog render still running, so that every
/// soak exits the way a user closing the window mid-render does (the
/// render is cancelled, its thread and device joined before the process
/// ends; issue 26). It starts this many frames before the end, ...
const END_RENDER_FRAMES: u64 = 3;
/// ... at this size and this many samples per pixel, far more than those
/// frames can trace, so that it is always under way at the exit and,
/// cancelled, writes nothing.
const END_RENDER_SIZE: (u32, u32) = (320, 180);
const END_RENDER_SPP: u32 = 1 << 20;

/// Drives a soak run: edits, loads and the device loss, then the verdict.
pub struct SoakDriver {
    options: SoakOptions,
    rng: Pcg32,
    /// Frames between preset loads.
    load_interval: u64,
    /// The frame of the simulated device loss (mid-run, after the warm-up).
    loss_frame: u64,
    /// The frame that starts a background render the run ends with still
    /// under way ([`END_RENDER_FRAMES`] before the end; none in runs
    /// shorter than ten frames).
    render_frame: Option<u64>,
    loads: u64,
    losses: u64,
    parameter_edits: u64,
    structural_edits: [u64; Structural::ALL.len()],
    /// The current preset's environment map while the soak shows a
    /// constant sky instead.
    env_map: Option<EnvSource>,
    /// The frame of the last call to `step`.
    last_step: Option<u64>,
    samples: Vec<(u64, MemorySample)>,
}

impl SoakDriver {
    pub fn new(options: &SoakOptions) -> Self {
        let frames = options.frames;
        // Four loads over the run (a few seconds each on lavapipe), or one
        // every 500 frames in long runs, never more often than every 20.
        let load_interval = (frames / 4).clamp(20, 500);
        Self {
            options: options.clone(),
            rng: Pcg32::new(options.seed),
            load_interval,
            loss_frame: (frames / 2).max(options.warm_up_frames) + load_interval / 2,
            render_frame: (frames >= 10).then(|| frames - END_RENDER_FRAMES),
            loads: 0,
            losses: 0,
            parameter_edits: 0,
            structural_edits: [0; Structural::ALL.len()],
            env_map: None,
            last_step: None,
            samples: Vec::new(),
        }
    }

    /// Once per frame, before the UI runs: edits `scene` in place (a random
    /// parameter most frames, a structural edit now and then), or asks for a
    /// preset load (cycling through the presets) or, once mid-run, a
    /// simulated device loss. An edit the renderer refuses is put back by
    /// the viewer, as any refused panel edit is.
    pub fn step(&mut self, frame: u64, scene: &mut Scene) -> ScriptAction {
        // A frame the viewer could not present (an outdated surface) comes
        // round again with the same number: it gets no second action.
        if self.last_step.replace(frame) == Some(frame) {
            return ScriptAction::Nothing;
        }
        if frame == self.loss_frame {
            self.losses += 1;
            return ScriptAction::LoseDevice;
        }
        if Some(frame) == self.render_frame {
            return ScriptAction::StartRender {
                size: END_RENDER_SIZE,
                spp: END_RENDER_SPP,
                output: std::env::temp_dir()
                    .join(format!("marbre-soak-{}.exr", std::process::id())),
            };
        }
        if !self.options.presets.is_empty() && frame > 0 && frame.is_multiple_of(self.load_interval)
        {
            let index = (self.loads % self.options.presets.len() as u64) as usize;
            self.loads += 1;
            self.env_map = None;
            return ScriptAction::LoadPreset(self.options.presets[index].clone());
        }
        if scene.environment.source.is_map() {
            self.env_map = Some(scene.environment.source.clone());
        }
        if self.rng.chance(STRUCTURAL_CHANCE) {
            let kind = Structural::ALL[self.rng.below(Structural::ALL.len())];
            if edits::structural_edit(&mut self.rng, kind, scene, &mut self.env_map) {
                self.structural_edits[kind as usize] += 1;
            }
        } else if self.rng.chance(PARAMETER_CHANCE) && edits::parameter_edit(&mut self.rng, scene) {
            self.parameter_edits += 1;
        }
        ScriptAction::Nothing
    }

    /// Once per frame, after present. Every tenth of the run (a 10,000-frame
    /// soak takes over half an hour on lavapipe) it prints where the run
    /// stands on standard error.
    pub fn record(&mut self, frame: u64, sample: MemorySample) {
        self.samples.push((frame, sample));
        if let Some(line) = self.progress_line(frame, &sample) {
            eprintln!("{line}");
        }
    }

    /// "soak: frame 1000 of 10000: RSS 348.1 MiB, GPU 14.2 MiB in 61
    /// objects, heap 120.3 MiB held + 4.1 MiB free" after each tenth of the
    /// run, None on other frames.
    fn progress_line(&self, frame: u64, sample: &MemorySample) -> Option<String> {
        let step = (self.options.frames / 10).max(1);
        let done = frame + 1;
        if !done.is_multiple_of(step) || done >= self.options.frames {
            return None;
        }
        let mib = |bytes: u64| bytes as f64 / (1u64 << 20) as f64;
        let gpu = match (sample.gpu_allocated_bytes, sample.gpu_resources) {
            (Some(bytes), Some(count)) => format!(", GPU {:.1} MiB in {count} objects", mib(bytes)),
            (Some(bytes), None) => format!(", GPU {:.1} MiB", mib(bytes)),
            (None, Some(count)) => format!(", {count} GPU objects"),
            (None, None) => String::new(),
        };
        let heap = sample.heap.map_or_else(String::new, |h| {
            format!(
                ", heap {:.1} MiB held + {:.1} MiB free",
                mib(h.in_use_bytes),
                mib(h.free_bytes)
            )
        });
        Some(format!(
            "soak: frame {done} of {}: RSS {:.1} MiB{gpu}{heap}",
            self.options.frames,
            mib(sample.rss_bytes)
        ))
    }

    /// Whether `frame` (0-based, the frame just recorded) was the last.
    pub fn finished(&self, frame: u64) -> bool {
        frame + 1 >= self.options.frames
    }

    /// The verdict at the end: Ok(report) or Err(report saying what grew or
    /// failed). `validation_errors` counts the wgpu validation errors the
    /// viewer's uncaptured-error handler saw. Writes the `--report` CSV
    /// first; failing to write it fails the run.
    pub fn verdict(&self, validation_errors: u64) -> Result<String, String> {
        let mut lines = vec![self.summary(validation_errors)];
        let mut failures = Vec::new();
        if validation_errors > 0 {
            failures.push(format!("{validation_errors} wgpu validation error(s)"));
        }
        if let Some(path) = &self.options.report
            && let Err(e) = marbre_core::atomic_write::write_atomic(path, self.csv().as_bytes())
        {
            failures.push(format!("{}: cannot write the report: {e}", path.display()));
        }
        let rss_measured = self.samples.iter().any(|(_, s)| s.rss_bytes > 0);
        let series: [(Metric, Vec<(u64, u64)>); 3] = [
            (
                Metric {
                    name: "RSS",
                    unit: Unit::Bytes,
                    allowance: verdict::RSS_ALLOWANCE,
                    rule: Rule::Median,
                },
                self.series(|s| rss_measured.then_some(s.rss_bytes)),
            ),
            (
                Metric {
                    name: "GPU allocated",
                    unit: Unit::Bytes,
                    allowance: verdict::GPU_BYTES_ALLOWANCE,
                    rule: Rule::Max,
                },
                self.series(|s| s.gpu_allocated_bytes),
            ),
            (
                Metric {
                    name: "GPU resources",
                    unit: Unit::Count,
                    allowance: verdict::RESOURCE_ALLOWANCE,
                    rule: Rule::Min,
                },
                self.series(|s| s.gpu_resources),
            ),
        ];
        for (metric, points) in &series {
            let judged = verdict::judge(metric, points, self.options.warm_up_frames);
            lines.push(format!("  {}", judged.line));
            failures.extend(judged.failure);
        }
        if failures.is_empty() {
            lines.push("soak passed".into());
            Ok(lines.join("\n"))
        } else {
            lines.push(format!("soak FAILED: {}", failures.join("; ")));
            Err(lines.join("\n"))
        }
    }

    fn summary(&self, validation_errors: u64) -> String {
        let structural: Vec<String> = Structural::ALL
            .iter()
            .map(|&k| format!("{} {}", self.structural_edits[k as usize], k.name()))
            .collect();
        format!(
            "soak: {} frames recorded of {} (warm-up {}, seed {}): {} parameter edits; structural edits: {}; {} preset loads; {} device loss(es); {} validation error(s)",
            self.samples.len(),
            self.options.frames,
            self.options.warm_up_frames,
            self.options.seed,
            self.parameter_edits,
            structural.join(", "),
            self.loads,
            self.losses,
            validation_errors
        )
    }

    fn series(&self, value: impl Fn(&MemorySample) -> Option<u64>) -> Vec<(u64, u64)> {
        self.samples
            .iter()
            .filter_map(|(f, s)| value(s).map(|v| (*f, v)))
            .collect()
    }

    /// One line per recorded frame; a figure the platform does not report
    /// is left empty.
    fn csv(&self) -> String {
        let mut out = String::from(
            "frame,rss_bytes,gpu_allocated_bytes,gpu_resources,heap_in_use_bytes,heap_free_bytes\n",
        );
        let show = |v: Option<u64>| v.map(|v| v.to_string()).unwrap_or_default();
        for (frame, s) in &self.samples {
            out.push_str(&format!(
                "{frame},{},{},{},{},{}\n",
                s.rss_bytes,
                show(s.gpu_allocated_bytes),
                show(s.gpu_resources),
                show(s.heap.map(|h| h.in_use_bytes)),
                show(s.heap.map(|h| h.free_bytes)),
            ));
        }
        out
    }
}

impl FrameScript for SoakDriver {
    fn before_frame(&mut self, frame: u64, scene: &mut Scene) -> ScriptAction {
        self.step(frame, scene)
    }

    /// Records the frame's memory; after the last frame prints the verdict
    /// and fails the run if it says so.
    fn after_present(&mut self, presented: Presented<'_>) -> Result<bool> {
        self.record(presented.frame, sample_memory(presented.ctx));
        if !self.finished(presented.frame) {
            return Ok(true);
        }
        match self.verdict(presented.validation_errors) {
            Ok(report) => {
                eprintln!("{report}");
                Ok(false)
            }
            Err(report) => {
                eprintln!("{report}");
                anyhow::bail!("the soak failed (see above)")
            }
        }
    }
}

#[cfg(test)]
mod tests;
