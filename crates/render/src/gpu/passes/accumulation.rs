//! The targets the trace pass accumulates into, and how much they hold.
//!
//! Three images per pixel, each ping-ponged (a frame reads the latest set
//! and writes the other): the running mean of every sample, which is the
//! image; the running spread of the frames' means about it, from which
//! [`crate::gpu::error_meter`] estimates the image's error (its alpha counts the
//! pixel's dropped non-finite samples, see [`crate::gpu::non_finite`]); and the
//! Kahan compensation of the mean, the low-order bits its updates lost.
//! Averages rather than sums, and the mean compensated, so that rounding
//! error does not grow with the frame count: a plain f32 running mean
//! drifts by about 1e-3 after 1e6 frames of an HDR pixel, the compensated
//! one stays within 1e-7 (`crates/render/tests/gpu/accumulation.rs`).
//!
//! A frame may trace only part of a round (a band of rows,
//! [`crate::gpu::trace_bands`]): the round writes the other set band by band,
//! and the latest set, which the display shows, flips only when the round
//! is complete. So the window always shows a whole image: the last
//! complete round, or the preview of a new accumulation at a reduced size.

use super::preview_ladder::Previews;
use std::time::Duration;
use web_time::Instant;

/// The format of both targets: linear radiance needs floats, and the
/// running mean needs more than half precision to keep averaging.
pub const ACCUMULATION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// One ping-ponged image: two textures, one read while the other is written.
struct PingPong {
    textures: [wgpu::Texture; 2],
    views: [wgpu::TextureView; 2],
}

impl PingPong {
    fn new(device: &wgpu::Device, label: &str, size: (u32, u32), storage: bool) -> Self {
        // The compute kernel writes them as storage textures.
        let storage = if storage {
            wgpu::TextureUsages::STORAGE_BINDING
        } else {
            wgpu::TextureUsages::empty()
        };
        let make = |i: usize| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(&format!("{label} {i}")),
                size: wgpu::Extent3d {
                    width: size.0.max(1),
                    height: size.1.max(1),
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: ACCUMULATION_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC
                    | storage,
                view_formats: &[],
            })
        };
        let textures = [make(0), make(1)];
        let views = [
            textures[0].create_view(&Default::default()),
            textures[1].create_view(&Default::default()),
        ];
        Self { textures, views }
    }
}

/// The denoiser's guides, accumulated beside the mean when the trace
/// pipeline has `Feature::DenoiseGuides`: the first hit's albedo and
/// normal.
struct Guides {
    albedo: PingPong,
    normal: PingPong,
}

pub struct Accumulation {
    mean: PingPong,
    spread: PingPong,
    compensation: PingPong,
    /// Allocated only while the pipeline writes them ([`Self::set_guides`]).
    guides: Option<Guides>,
    /// Bound in their place otherwise: a 1 × 1 texture the shader never
    /// reads.
    no_guide: wgpu::TextureView,
    size: (u32, u32),
    storage: bool,
    /// Index of the pair holding the latest frame.
    latest: usize,
    samples: u32,
    frames: u32,
    /// The first row the round under way has not traced yet (0: no round
    /// under way).
    next_row: u32,
    /// The size of the traced region the latest set holds: the display's
    /// source, which may be a preview at a reduced size.
    shown_size: (u32, u32),
    /// Where this accumulation's previews stand (`preview_ladder`).
    previews: Previews,
    /// Images shown so far (rounds and previews): what auto exposure
    /// metered is compared with it.
    shown_count: u32,
    /// When the current accumulation started (its first frame).
    started: Instant,
    /// Counts resets: tells measurements of one accumulation from the next.
    generation: u32,
}

impl Accumulation {
    /// Targets of `size`, usable as storage textures if `storage` (for the
    /// compute kernel).
    pub fn new(device: &wgpu::Device, size: (u32, u32), storage: bool) -> Self {
        Self {
            mean: PingPong::new(device, "accumulated mean", size, storage),
            spread: PingPong::new(device, "accumulated spread", size, storage),
            compensation: PingPong::new(device, "mean compensation", size, storage),
            guides: None,
            no_guide: PingPong::new(device, "no guide", (1, 1), false).views[0].clone(),
            size,
            storage,
            latest: 0,
            samples: 0,
            frames: 0,
            next_row: 0,
            shown_size: (size.0.max(1), size.1.max(1)),
            previews: Previews::default(),
            shown_count: 0,
            started: Instant::now(),
            generation: 0,
        }
    }

    /// Allocates the guides' targets, or frees them: whether the trace
    /// pipeline writes them. Call it before recording a band; a pipeline
    /// change that adds them (new features) restarts the accumulation, so
    /// new targets start empty.
    pub fn set_guides(&mut self, device: &wgpu::Device, on: bool) {
        if on && self.guides.is_none() {
            self.guides = Some(Guides {
                albedo: PingPong::new(device, "albedo guide", self.size, self.storage),
                normal: PingPong::new(device, "normal guide", self.size, self.storage),
            });
        } else if !on {
            self.guides = None;
        }
    }

    /// The latest albedo and normal guides, if accumulated.
    pub fn latest_guides(&self) -> Option<(&wgpu::TextureView, &wgpu::TextureView)> {
        self.guides
            .as_ref()
            .map(|g| (&g.albedo.views[self.latest], &g.normal.views[self.latest]))
    }

    /// The latest guides' textures (albedo, normal), if accumulated.
    pub fn latest_guide_textures(&self) -> Option<[&wgpu::Texture; 2]> {
        self.guides.as_ref().map(|g| {
            [
                &g.albedo.textures[self.latest],
                &g.normal.textures[self.latest],
            ]
        })
    }

    /// The guides the next frame reads (bindings 19 and 20): the latest,
    /// or the 1 × 1 stand-in.
    pub fn previous_guide_views(&self) -> [&wgpu::TextureView; 2] {
        match self.latest_guides() {
            Some((albedo, normal)) => [albedo, normal],
            None => [&self.no_guide, &self.no_guide],
        }
    }

    /// Starts over: the next frame ignores what the targets hold.
    pub fn reset(&mut self) {
        if self.frames > 0 {
            self.generation = self.generation.wrapping_add(1);
        }
        self.samples = 0;
        self.frames = 0;
        self.next_row = 0;
        self.previews = Previews::default();
    }

    /// Targets of another `size`, empty: a new accumulation, the next
    /// generation if this one showed a frame (so that what measured the
    /// old one, the Quality strip's error history, starts over), its
    /// shown images counted on.
    pub fn resize(&mut self, device: &wgpu::Device, size: (u32, u32)) {
        let generation = self.generation.wrapping_add(u32::from(self.frames > 0));
        let shown_count = self.shown_count;
        *self = Self::new(device, size, self.storage);
        self.generation = generation;
        self.shown_count = shown_count;
    }

    /// Drops the round under way, keeping the rounds traced: the next
    /// trace starts the round again from its first row (its seeds are the
    /// same), writing over the rows already in the write set.
    pub fn restart_round(&mut self) {
        if self.frames == 0 {
            self.reset();
        } else {
            self.next_row = 0;
        }
    }

    /// The first row the round under way has yet to trace.
    pub fn next_row(&self) -> u32 {
        self.next_row
    }

    /// Records that the round under way traced up to `row` (exclusive).
    pub fn traced_to(&mut self, row: u32) {
        if self.frames == 0 && self.next_row == 0 {
            self.started = Instant::now();
        }
        self.next_row = row;
    }

    /// Images shown so far (rounds and previews), wrapping.
    pub fn shown_count(&self) -> u32 {
        self.shown_count
    }

    /// The size of the region the latest set holds (what is displayed).
    pub fn shown_size(&self) -> (u32, u32) {
        self.shown_size
    }

    /// Where the previews stand: none are due once a round is done.
    pub fn previews(&self) -> Previews {
        self.previews
    }

    /// Where the previews stand after a call's passes.
    pub fn set_previews(&mut self, previews: Previews) {
        self.previews = previews;
    }

    /// Records that the write set now holds a preview of `size` (a whole
    /// image at a reduced size, not counted as samples): it becomes the
    /// latest, what the display shows until a finer preview or the first
    /// real round is done.
    pub fn show_preview(&mut self, size: (u32, u32)) {
        self.shown_count = self.shown_count.wrapping_add(1);
        self.latest = 1 - self.latest;
        self.shown_size = size;
        self.next_row = 0;
    }

    pub fn generation(&self) -> u32 {
        self.generation
    }

    /// Samples per pixel averaged so far.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Frames averaged so far.
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// Time since the first frame of this accumulation.
    pub fn elapsed(&self) -> Duration {
        if self.frames == 0 {
            Duration::ZERO
        } else {
            self.started.elapsed()
        }
    }

    /// The latest mean and spread, which the next frame reads.
    pub fn latest_views(&self) -> (&wgpu::TextureView, &wgpu::TextureView) {
        (
            &self.mean.views[self.latest],
            &self.spread.views[self.latest],
        )
    }

    /// The Kahan compensation of the latest mean, which the next frame reads.
    pub fn latest_compensation_view(&self) -> &wgpu::TextureView {
        &self.compensation.views[self.latest]
    }

    pub fn latest_mean_texture(&self) -> &wgpu::Texture {
        &self.mean.textures[self.latest]
    }

    pub fn latest_spread_texture(&self) -> &wgpu::Texture {
        &self.spread.textures[self.latest]
    }

    /// The views a round writes: mean, spread, compensation, then the
    /// albedo and normal guides if allocated (the compute kernel's storage
    /// textures 0 to 4).
    pub fn write_views(&self) -> Vec<&wgpu::TextureView> {
        let write = 1 - self.latest;
        let mut views = vec![
            &self.mean.views[write],
            &self.spread.views[write],
            &self.compensation.views[write],
        ];
        if let Some(g) = &self.guides {
            views.extend([&g.albedo.views[write], &g.normal.views[write]]);
        }
        views
    }

    /// The colour attachments a round writes: mean, spread, compensation
    /// and the guides (the trace shader's locations 0 to 4). Loaded, not
    /// cleared: a round is written a band at a time.
    pub fn attachments(&self) -> Vec<Option<wgpu::RenderPassColorAttachment<'_>>> {
        self.write_views()
            .into_iter()
            .map(|view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })
            })
            .collect()
    }

    /// Records that a round of `samples` samples per pixel over a region
    /// of `size` was written whole (its bands reported by
    /// [`Self::traced_to`]).
    pub fn advance(&mut self, samples: u32, size: (u32, u32)) {
        self.shown_count = self.shown_count.wrapping_add(1);
        self.latest = 1 - self.latest;
        self.shown_size = size;
        self.next_row = 0;
        self.previews.done = true;
        self.samples = self.samples.saturating_add(samples);
        self.frames = self.frames.saturating_add(1);
    }
}
