//! The panel's pixels, kept between frames: egui is drawn again only when
//! what it draws changed. On lavapipe egui's pass takes 20-23 ms a frame
//! (the whole side panel and Quality strip rasterised on the CPU), which
//! alone held the window near 30 fps with no trace at all; most frames
//! draw the same panel (the Stats figures refresh four times a second), so
//! a copy of the kept layer (about 1 ms) stands for it.
//!
//! Most frames ([`Mode::Copied`]), the layer holds the whole window but
//! the image's rectangle: it is copied onto the window's image and the
//! display pass draws the image over it. A frame whose egui output reaches
//! into the image (a tooltip, a menu, a prompt and its backdrop, the help
//! overlay) keeps its layer too ([`Mode::Blended`]): egui is drawn into
//! it over transparency, and the layer is blended over the image (a pass
//! of a few milliseconds). Drawing egui every such frame instead took its
//! whole pass each time (100 to 300 ms on lavapipe): under the recovery
//! prompt the window fell to about a third of its frames, and the image
//! hardly accumulated (issue 28).
//!
//! While an animation plays the panel changes every frame, but only in a
//! few rows (the play head, the frame and time, keyed fields). The kept
//! layer is compared with the new output in bands of [`BAND`] pixel rows
//! ([`band_fingerprints`]), and only the bands that differ are cleared (to
//! the background, or to transparency for a blended layer) and drawn
//! again, egui's clip rectangles cut to them: egui's pass then costs what
//! those rows cost, not the whole panel's (issue 29). A blended layer is
//! drawn in bands too since issue 31: with the node editor open over the
//! image, every refresh of the Stats figures drew the whole graph again.

use std::hash::{Hash, Hasher};

/// How often the panel's live figures (fps, ms, samples) refresh: the
/// panel is redrawn only when what it shows changes.
pub const STATS_REFRESH: std::time::Duration = std::time::Duration::from_millis(250);

/// The pixels along the image's edge that egui may draw into and the
/// image still cover.
const EDGE: f32 = 2.0;

/// A key of what egui draws: equal keys draw equal pixels.
pub fn output_key(jobs: &[egui::ClippedPrimitive], screen: &egui_wgpu::ScreenDescriptor) -> u64 {
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    screen.size_in_pixels.hash(&mut hasher);
    screen.pixels_per_point.to_bits().hash(&mut hasher);
    for job in jobs {
        let r = job.clip_rect;
        [r.min.x, r.min.y, r.max.x, r.max.y]
            .map(f32::to_bits)
            .hash(&mut hasher);
        match &job.primitive {
            egui::epaint::Primitive::Mesh(mesh) => {
                mesh.texture_id.hash(&mut hasher);
                mesh.indices.hash(&mut hasher);
                hasher.write(bytemuck::cast_slice(&mesh.vertices));
            }
            // A callback draws what it likes: never the same twice.
            egui::epaint::Primitive::Callback(_) => return rand_key(),
        }
    }
    hasher.finish()
}

/// A key no other output has.
fn rand_key() -> u64 {
    use std::sync::atomic::{AtomicU64, Ordering};
    static NEXT: AtomicU64 = AtomicU64::new(1);
    u64::MAX - NEXT.fetch_add(1, Ordering::Relaxed)
}

/// Where egui's primitives may draw inside `image` (in pixels): the
/// pixel rectangle around all they draw there, or `None` when the layer
/// can lie wholly under the image. The panels' separators, feathered,
/// reach 1.5 px over the image's edge: the image covering their inner
/// half is no loss, so the edge's [`EDGE`] pixels do not count.
pub fn drawn_inside(
    jobs: &[egui::ClippedPrimitive],
    ppp: f32,
    image: egui::Rect,
) -> Option<egui::Rect> {
    let image = image.shrink(EDGE);
    jobs.iter()
        .filter_map(|job| {
            let bounds = match &job.primitive {
                egui::epaint::Primitive::Mesh(mesh) => mesh.calc_bounds(),
                egui::epaint::Primitive::Callback(c) => c.rect,
            };
            let drawn = bounds.intersect(job.clip_rect);
            let pixels = egui::Rect::from_min_max(drawn.min * ppp, drawn.max * ppp);
            let inside = pixels.intersect(image);
            (drawn.is_positive() && inside.is_positive()).then_some(inside)
        })
        .reduce(|a, b| a.union(b))
}

/// Height of the bands, in pixel rows, in which a copied layer is
/// compared with egui's new output and drawn again.
pub const BAND: u32 = 16;

/// A fingerprint of what egui draws in each band of [`BAND`] pixel rows of
/// a window `screen.size_in_pixels` big: each triangle reaching the band
/// (its vertices, texture and clip rectangle), in drawing order. Equal
/// fingerprints draw equal pixels in the band, and a band whose
/// fingerprint differs is drawn whole again, so the kept pixels are what a
/// full redraw gives. `None` when a callback draws (it draws what it likes).
pub fn band_fingerprints(
    jobs: &[egui::ClippedPrimitive],
    screen: &egui_wgpu::ScreenDescriptor,
) -> Option<Vec<u64>> {
    let [width, height] = screen.size_in_pixels;
    let ppp = screen.pixels_per_point;
    let mut bands = vec![0u64; height.div_ceil(BAND) as usize];
    for job in jobs {
        let egui::epaint::Primitive::Mesh(mesh) = &job.primitive else {
            return None;
        };
        let c = job.clip_rect;
        let clip = [c.min.x, c.min.y, c.max.x, c.max.y].map(|v| (v * ppp).clamp(0.0, 1e7));
        let clip = [
            clip[0],
            clip[1],
            clip[2].min(width as f32),
            clip[3].min(height as f32),
        ];
        if clip[0] >= clip[2] || clip[1] >= clip[3] {
            continue;
        }
        let texture = match mesh.texture_id {
            egui::TextureId::Managed(id) => id,
            egui::TextureId::User(id) => id ^ (1 << 63),
        };
        let head = fx(texture, clip.map(f32::to_bits));
        for triangle in mesh.indices.chunks_exact(3) {
            let v: [&egui::epaint::Vertex; 3] =
                std::array::from_fn(|k| &mesh.vertices[triangle[k] as usize]);
            let ys = v.map(|v| v.pos.y * ppp);
            let top = ys
                .iter()
                .copied()
                .fold(f32::INFINITY, f32::min)
                .max(clip[1]);
            let bottom = ys
                .iter()
                .copied()
                .fold(f32::NEG_INFINITY, f32::max)
                .min(clip[3]);
            if top >= bottom {
                continue;
            }
            let words: [u32; 15] = std::array::from_fn(|k| {
                let v = v[k / 5];
                match k % 5 {
                    0 => v.pos.x.to_bits(),
                    1 => v.pos.y.to_bits(),
                    2 => v.uv.x.to_bits(),
                    3 => v.uv.y.to_bits(),
                    _ => u32::from_le_bytes(v.color.to_array()),
                }
            });
            let h = fx(head, words);
            let first = (top as u32 / BAND) as usize;
            let last = ((bottom.ceil() as u32).saturating_sub(1) / BAND) as usize;
            let last = last.min(bands.len() - 1);
            for band in &mut bands[first..=last] {
                *band = (band.rotate_left(5) ^ h).wrapping_mul(FX);
            }
        }
    }
    Some(bands)
}

/// FxHash's multiplier (rustc's hasher): fast and good enough to tell
/// panel outputs apart; SipHash cost milliseconds over a panel's
/// triangles.
const FX: u64 = 0x51_7c_c1_b7_27_22_0a_95;

fn fx<const N: usize>(seed: u64, words: [u32; N]) -> u64 {
    words.iter().fold(seed, |h, &w| {
        (h.rotate_left(5) ^ u64::from(w)).wrapping_mul(FX)
    })
}

/// The runs of bands (as pixel rows, `start..end`) whose fingerprints
/// differ between two outputs of the same window.
pub fn changed_rows(before: &[u64], after: &[u64], height: u32) -> Vec<std::ops::Range<u32>> {
    let mut runs: Vec<std::ops::Range<u32>> = Vec::new();
    for (i, (b, a)) in before.iter().zip(after).enumerate() {
        if b == a {
            continue;
        }
        let rows = i as u32 * BAND..((i as u32 + 1) * BAND).min(height);
        match runs.last_mut() {
            Some(last) if last.end == rows.start => last.end = rows.end,
            _ => runs.push(rows),
        }
    }
    runs
}

/// Records egui's output `jobs` drawn again within pixel rows `rows` of
/// `pass`'s target (a layer holding a copied output): each run of rows
/// cleared to `background`, then every job drawn with its clip rectangle
/// cut to the run (egui's scissor is its clip rectangle in pixels,
/// rounded, so the cut is exact). The buffers must hold `jobs`, whose
/// clip rectangles are cut in place and put back (copying the jobs would
/// copy every mesh, each frame an animation plays).
pub fn draw_rows(
    renderer: &egui_wgpu::Renderer,
    compositor: &Compositor,
    pass: &mut wgpu::RenderPass<'static>,
    jobs: &mut [egui::ClippedPrimitive],
    screen: &egui_wgpu::ScreenDescriptor,
    rows: &[std::ops::Range<u32>],
    background: wgpu::Color,
) {
    let clips: Vec<egui::Rect> = jobs.iter().map(|j| j.clip_rect).collect();
    let ppp = screen.pixels_per_point;
    for run in rows {
        compositor.fill(pass, run.clone(), screen.size_in_pixels[0], background);
        let cut = egui::Rect::from_x_y_ranges(
            egui::Rangef::EVERYTHING,
            run.start as f32 / ppp..=run.end as f32 / ppp,
        );
        for (job, original) in jobs.iter_mut().zip(&clips) {
            let clip = original.intersect(cut);
            job.clip_rect = if clip.is_positive() {
                clip
            } else {
                egui::Rect::ZERO
            };
        }
        renderer.render(pass, jobs, screen);
    }
    for (job, original) in jobs.iter_mut().zip(clips) {
        job.clip_rect = original;
    }
}

/// Begins a pass of egui's onto `view` (a kept layer), timed by
/// `timestamp_writes` when given.
pub fn begin_pass(
    encoder: &mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
    timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
) -> wgpu::RenderPass<'static> {
    encoder
        .begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("egui"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            timestamp_writes,
            ..Default::default()
        })
        .forget_lifetime()
}

/// What egui's output asks of the kept layer.
pub enum Redraw<'a> {
    /// It already holds it.
    Nothing,
    /// Draw it whole into this view.
    Whole(&'a wgpu::TextureView),
    /// Clear these pixel rows of this view and draw them again: the rest
    /// holds the output already.
    Rows(&'a wgpu::TextureView, Vec<std::ops::Range<u32>>),
}

/// What the kept layer is drawn over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// The window's background: opaque, copied under the image, for
    /// output that draws nothing inside it.
    Copied,
    /// Transparency: blended over the image (where the window's image
    /// allows copies, only over what egui draws inside it; the rest is
    /// copied under the image as in `Copied`).
    Blended,
}

/// The kept layer: a texture the size and format of the window's.
pub struct UiLayer {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    /// The layer as [`Compositor::blend`] reads it.
    bind_group: wgpu::BindGroup,
    /// The output the texture holds, and how it was drawn, if any.
    key: Option<(u64, Mode)>,
    /// Its bands' fingerprints, when it has them.
    bands: Option<Vec<u64>>,
}

impl UiLayer {
    pub fn new(
        device: &wgpu::Device,
        config: &wgpu::SurfaceConfiguration,
        compositor: &Compositor,
    ) -> Self {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("panel layer"),
            size: wgpu::Extent3d {
                width: config.width,
                height: config.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: config.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("panel layer"),
            layout: &compositor.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&view),
            }],
        });
        Self {
            texture,
            view,
            bind_group,
            key: None,
            bands: None,
        }
    }

    /// Whether the layer fits a window of `config`'s size.
    pub fn fits(&self, config: &wgpu::SurfaceConfiguration) -> bool {
        self.texture.width() == config.width
            && self.texture.height() == config.height
            && self.texture.format() == config.format
    }

    /// What to draw of output `key` drawn for `mode` (`bands`: its bands'
    /// fingerprints, asked for only when a copied output changed):
    /// nothing when the layer holds it, only the rows that changed when
    /// the layer holds a copied output with fingerprints and fewer than
    /// half the rows changed, the whole output otherwise. The layer then
    /// holds it.
    pub fn redraw(
        &mut self,
        key: u64,
        mode: Mode,
        bands: impl FnOnce() -> Option<Vec<u64>>,
    ) -> Redraw<'_> {
        if self.key == Some((key, mode)) {
            return Redraw::Nothing;
        }
        let held = self.key.map(|(_, m)| m);
        let before = std::mem::replace(&mut self.bands, bands());
        self.key = Some((key, mode));
        let height = self.texture.height();
        match (held, before, &self.bands) {
            (Some(held), Some(before), Some(after))
                if held == mode && before.len() == after.len() =>
            {
                let rows = changed_rows(&before, after, height);
                let changed: u32 = rows.iter().map(|r| r.end - r.start).sum();
                if 2 * changed < height {
                    return Redraw::Rows(&self.view, rows);
                }
                Redraw::Whole(&self.view)
            }
            _ => Redraw::Whole(&self.view),
        }
    }

    /// Records the copy of the whole layer onto `target`.
    pub fn copy_to(&self, encoder: &mut wgpu::CommandEncoder, target: &wgpu::Texture) {
        encoder.copy_texture_to_texture(
            self.texture.as_image_copy(),
            target.as_image_copy(),
            self.texture.size(),
        );
    }
}

/// Blends a layer drawn over transparency onto a target: egui's output is
/// premultiplied, and drawn into a transparent layer it stays so (egui's
/// pipeline blends alpha as coverage), so the layer goes over the image
/// as egui itself would have gone.
pub struct Compositor {
    pipeline: wgpu::RenderPipeline,
    /// Writes the blend constant within a scissor: the clear of a layer's
    /// rows that are drawn again (a pass clears only whole targets).
    fill_pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    format: wgpu::TextureFormat,
}

/// One triangle over the whole target, each pixel the layer's pixel there
/// (the layer and the target have the same size).
const BLEND_SHADER: &str = r"
@group(0) @binding(0) var layer: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner.x * 2.0 - 1.0, 1.0 - corner.y * 2.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    return textureLoad(layer, vec2<i32>(position.xy), 0);
}

@fragment
fn fs_fill() -> @location(0) vec4<f32> {
    return vec4<f32>(1.0);
}
";

/// A pipeline drawing `BLEND_SHADER`'s one triangle over the target with
/// `fragment_entry`, reading `layout`'s bind group if any, blended by
/// `blend`. (`marbre_render`'s `fullscreen_pipeline` sets no blend.)
fn layer_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    label: &str,
    layout: Option<&wgpu::BindGroupLayout>,
    fragment_entry: &str,
    format: wgpu::TextureFormat,
    blend: wgpu::BlendState,
) -> wgpu::RenderPipeline {
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[layout],
        immediate_size: 0,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment_entry),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format,
                blend: Some(blend),
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

impl Compositor {
    /// The blend pipeline for targets of `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("panel layer"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("panel layer blend"),
            source: wgpu::ShaderSource::Wgsl(BLEND_SHADER.into()),
        });
        let pipeline = layer_pipeline(
            device,
            &module,
            "panel layer blend",
            Some(&layout),
            "fs_main",
            format,
            wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING,
        );
        let constant = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Constant,
            dst_factor: wgpu::BlendFactor::Zero,
            operation: wgpu::BlendOperation::Add,
        };
        let fill_pipeline = layer_pipeline(
            device,
            &module,
            "panel layer fill",
            None,
            "fs_fill",
            format,
            wgpu::BlendState {
                color: constant,
                alpha: constant,
            },
        );
        Self {
            pipeline,
            fill_pipeline,
            layout,
            format,
        }
    }

    /// Records, in `pass`, pixel rows `rows` of its `width`-pixel target
    /// set to `color`, as a clear would set them.
    pub fn fill(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        rows: std::ops::Range<u32>,
        width: u32,
        color: wgpu::Color,
    ) {
        pass.set_viewport(0.0, 0.0, width as f32, rows.end as f32, 0.0, 1.0);
        pass.set_scissor_rect(0, rows.start, width, rows.end - rows.start);
        pass.set_pipeline(&self.fill_pipeline);
        pass.set_blend_constant(color);
        pass.draw(0..3, 0..1);
    }

    /// The format of the targets it blends onto.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Records `layer` blended over what `target` holds, within `only`
    /// (pixels; the whole target when `None`): a full-window pass costs
    /// milliseconds a frame on a software rasteriser, a prompt's box next
    /// to nothing.
    pub fn blend(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        layer: &UiLayer,
        only: Option<egui::Rect>,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("panel layer blend"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        if let Some(only) = only {
            let size = layer.texture.size();
            let (x0, y0) = (
                only.min.x.floor().max(0.0) as u32,
                only.min.y.floor().max(0.0) as u32,
            );
            let x1 = (only.max.x.ceil().max(0.0) as u32).min(size.width);
            let y1 = (only.max.y.ceil().max(0.0) as u32).min(size.height);
            if x0 >= x1 || y0 >= y1 {
                return;
            }
            pass.set_scissor_rect(x0, y0, x1 - x0, y1 - y0);
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &layer.bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::epaint::{Mesh, Primitive};
    use egui::{Color32, Pos2, Rect, pos2};

    fn job(clip: Rect, corner: Pos2, color: Color32) -> egui::ClippedPrimitive {
        let mut mesh = Mesh::default();
        mesh.add_colored_rect(Rect::from_min_size(corner, egui::vec2(10.0, 10.0)), color);
        egui::ClippedPrimitive {
            clip_rect: clip,
            primitive: Primitive::Mesh(mesh),
        }
    }

    fn screen() -> egui_wgpu::ScreenDescriptor {
        egui_wgpu::ScreenDescriptor {
            size_in_pixels: [200, 100],
            pixels_per_point: 1.0,
        }
    }

    /// Equal outputs give equal keys; a moved vertex, another colour or
    /// clip, or another window size gives another key.
    #[test]
    fn the_key_follows_what_egui_draws() {
        let all = Rect::EVERYTHING;
        let a = [job(all, pos2(150.0, 10.0), Color32::WHITE)];
        let key = output_key(&a, &screen());
        assert_eq!(key, output_key(&a.clone(), &screen()));
        for other in [
            [job(all, pos2(151.0, 10.0), Color32::WHITE)],
            [job(all, pos2(150.0, 10.0), Color32::RED)],
            [job(
                Rect::from_min_size(pos2(0.0, 0.0), egui::vec2(160.0, 100.0)),
                pos2(150.0, 10.0),
                Color32::WHITE,
            )],
        ] {
            assert_ne!(key, output_key(&other, &screen()));
        }
        let larger = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [201, 100],
            pixels_per_point: 1.0,
        };
        assert_ne!(key, output_key(&a, &larger));
    }

    fn screen_of(width: u32, height: u32) -> egui_wgpu::ScreenDescriptor {
        egui_wgpu::ScreenDescriptor {
            size_in_pixels: [width, height],
            pixels_per_point: 1.0,
        }
    }

    /// A change marks the bands its triangles reach and no other: a moved
    /// square, a recoloured one, two overlapping squares drawn in the
    /// other order, a tall square across four bands; a clip rectangle
    /// cutting a square away leaves its bands alone.
    #[test]
    fn a_change_marks_the_bands_it_reaches() {
        let all = Rect::EVERYTHING;
        let screen = screen_of(64, 64);
        let bands = |jobs: &[egui::ClippedPrimitive]| band_fingerprints(jobs, &screen).unwrap();
        let changed = |a: &[egui::ClippedPrimitive], b: &[egui::ClippedPrimitive]| {
            changed_rows(&bands(a), &bands(b), 64)
        };
        let base = [
            job(all, pos2(2.0, 2.0), Color32::WHITE),
            job(all, pos2(2.0, 40.0), Color32::RED),
        ];
        assert_eq!(bands(&base), bands(&base.clone()));
        assert_eq!(bands(&base).len(), 4);
        let moved = [base[0].clone(), job(all, pos2(3.0, 40.0), Color32::RED)];
        assert_eq!(changed(&base, &moved), vec![32..64]);
        let recoloured = [job(all, pos2(2.0, 2.0), Color32::BLUE), base[1].clone()];
        assert_eq!(changed(&base, &recoloured), vec![0..16]);
        let swapped = [base[1].clone(), base[0].clone()];
        assert!(
            changed(&base, &swapped).is_empty(),
            "disjoint: no pixel differs"
        );
        let over = [
            job(all, pos2(2.0, 2.0), Color32::WHITE),
            job(all, pos2(6.0, 4.0), Color32::RED),
        ];
        let under = [over[1].clone(), over[0].clone()];
        assert_eq!(changed(&over, &under), vec![0..16]);
        let mut tall = Mesh::default();
        tall.add_colored_rect(
            Rect::from_min_size(pos2(0.0, 0.0), egui::vec2(4.0, 64.0)),
            Color32::GREEN,
        );
        let tall = [egui::ClippedPrimitive {
            clip_rect: all,
            primitive: Primitive::Mesh(tall),
        }];
        assert_eq!(changed(&[], &tall), vec![0..64]);
        let clipped_away = [job(
            Rect::from_min_max(pos2(0.0, 0.0), pos2(64.0, 30.0)),
            pos2(2.0, 40.0),
            Color32::RED,
        )];
        assert!(changed(&[], &clipped_away).is_empty());
    }

    /// Rows drawn again over a layer that held an earlier output give the
    /// pixels of the new output drawn whole, with egui's own renderer on
    /// the adapter (lavapipe in CI): a translucent square moved and
    /// recoloured across the edge of a panel's fill, so that rows of the
    /// earlier square beside the fill must be cleared.
    #[test]
    fn rows_drawn_again_equal_the_output_drawn_whole() {
        let Some(ctx) = marbre_render::gpu::testing::gpu_or_skip(
            "rows_drawn_again_equal_the_output_drawn_whole",
        ) else {
            return;
        };
        let (device, queue) = (&ctx.device, &ctx.queue);
        let format = wgpu::TextureFormat::Rgba8UnormSrgb;
        let (width, height) = (64, 80);
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width,
            height,
            present_mode: wgpu::PresentMode::Fifo,
            desired_maximum_frame_latency: 2,
            alpha_mode: wgpu::CompositeAlphaMode::Auto,
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        let compositor = Compositor::new(device, format);
        let mut renderer = egui_wgpu::Renderer::new(device, format, Default::default());
        let white = egui::ImageData::Color(std::sync::Arc::new(egui::ColorImage::filled(
            [1, 1],
            Color32::WHITE,
        )));
        renderer.update_texture(
            device,
            queue,
            egui::TextureId::default(),
            &egui::epaint::ImageDelta::full(white, egui::TextureOptions::NEAREST),
        );
        let screen = screen_of(width, height);
        let panel = |accent: Color32, y: f32| {
            let mut mesh = Mesh::default();
            mesh.add_colored_rect(
                Rect::from_min_size(pos2(8.0, 0.0), egui::vec2(48.0, 80.0)),
                Color32::from_gray(40),
            );
            mesh.add_colored_rect(
                Rect::from_min_size(pos2(10.5, 3.25), egui::vec2(20.0, 9.5)),
                Color32::from_rgba_unmultiplied(200, 100, 50, 128),
            );
            // Reaching past the panel's fill, over the cleared layer.
            mesh.add_colored_rect(
                Rect::from_min_size(pos2(36.0, y), egui::vec2(26.0, 7.5)),
                accent,
            );
            vec![egui::ClippedPrimitive {
                clip_rect: Rect::EVERYTHING,
                primitive: Primitive::Mesh(mesh),
            }]
        };
        let mut before = panel(Color32::from_rgba_unmultiplied(0, 90, 255, 100), 50.0);
        let mut after = panel(Color32::from_rgba_unmultiplied(255, 200, 0, 160), 52.5);
        let draw = |layer: &mut UiLayer,
                    renderer: &mut egui_wgpu::Renderer,
                    jobs: &mut [egui::ClippedPrimitive],
                    (mode, clear): (Mode, wgpu::Color)| {
            let mut encoder = device.create_command_encoder(&Default::default());
            let extra = renderer.update_buffers(device, queue, &mut encoder, jobs, &screen);
            let key = output_key(jobs, &screen);
            let drew_rows = match layer.redraw(key, mode, || band_fingerprints(jobs, &screen)) {
                Redraw::Nothing => None,
                Redraw::Whole(view) => {
                    let mut pass = begin_pass(&mut encoder, view, wgpu::LoadOp::Clear(clear), None);
                    renderer.render(&mut pass, jobs, &screen);
                    Some(false)
                }
                Redraw::Rows(view, rows) => {
                    let mut pass = begin_pass(&mut encoder, view, wgpu::LoadOp::Load, None);
                    draw_rows(
                        renderer,
                        &compositor,
                        &mut pass,
                        jobs,
                        &screen,
                        &rows,
                        clear,
                    );
                    Some(true)
                }
            };
            queue.submit(extra.into_iter().chain([encoder.finish()]));
            let pixels =
                marbre_render::gpu::readback::read_texture(device, queue, &layer.texture, 4)
                    .unwrap();
            (drew_rows, pixels)
        };
        // Over the background (a panel beside the image) and over
        // transparency (the node editor's window over the image).
        for drawn_over in [
            (Mode::Copied, GREY),
            (Mode::Blended, wgpu::Color::TRANSPARENT),
        ] {
            let mut kept = UiLayer::new(device, &config, &compositor);
            assert_eq!(
                draw(&mut kept, &mut renderer, &mut before, drawn_over).0,
                Some(false)
            );
            let (drew_rows, by_rows) = draw(&mut kept, &mut renderer, &mut after, drawn_over);
            assert_eq!(drew_rows, Some(true), "a small change draws rows only");
            let mut fresh = UiLayer::new(device, &config, &compositor);
            let (_, whole) = draw(&mut fresh, &mut renderer, &mut after, drawn_over);
            let differing = by_rows.iter().zip(&whole).filter(|(a, b)| a != b).count();
            assert_eq!(
                differing, 0,
                "bytes that differ from the output drawn whole, over {:?}",
                drawn_over.0
            );
            let (_, before_whole) = draw(&mut fresh, &mut renderer, &mut before, drawn_over);
            assert_ne!(before_whole, whole, "the two outputs differ");
        }
    }

    const GREY: wgpu::Color = wgpu::Color {
        r: 0.05,
        g: 0.06,
        b: 0.07,
        a: 1.0,
    };

    /// A panel beside the image draws nothing inside it; a popup over the
    /// image does, where it is, and so does a panel clipped to the image's
    /// edge only where it crosses it. Rectangles are in points, scaled to
    /// pixels.
    #[test]
    fn what_is_drawn_inside_the_image_is_found_in_pixels() {
        let image = Rect::from_min_max(pos2(0.0, 0.0), pos2(100.0, 100.0));
        let beside = [job(Rect::EVERYTHING, pos2(120.0, 10.0), Color32::WHITE)];
        assert_eq!(drawn_inside(&beside, 1.0, image), None);
        let popup = [job(Rect::EVERYTHING, pos2(40.0, 40.0), Color32::WHITE)];
        assert_eq!(
            drawn_inside(&popup, 1.0, image),
            Some(Rect::from_min_max(pos2(40.0, 40.0), pos2(50.0, 50.0)))
        );
        // Two popups: the rectangle around both.
        let two = [
            job(Rect::EVERYTHING, pos2(40.0, 40.0), Color32::WHITE),
            job(Rect::EVERYTHING, pos2(10.0, 60.0), Color32::WHITE),
        ];
        assert_eq!(
            drawn_inside(&two, 1.0, image),
            Some(Rect::from_min_max(pos2(10.0, 40.0), pos2(50.0, 70.0)))
        );
        // A separator on the image's edge, feathered over it by 1.5 px.
        let separator = [job(Rect::EVERYTHING, pos2(98.5, 0.0), Color32::WHITE)];
        assert_eq!(drawn_inside(&separator, 1.0, image), None);
        // At 2 pixels per point, the panel at x = 55 points lies at 110 px.
        let scaled = [job(Rect::EVERYTHING, pos2(55.0, 10.0), Color32::WHITE)];
        assert_eq!(drawn_inside(&scaled, 2.0, image), None);
        assert!(drawn_inside(&scaled, 1.0, image).is_some());
        // Clipped away from the image: it draws nothing there.
        let clip = Rect::from_min_max(pos2(100.0, 0.0), pos2(200.0, 100.0));
        let clipped = [job(clip, pos2(95.0, 10.0), Color32::WHITE)];
        assert_eq!(drawn_inside(&clipped, 1.0, image), None);
    }
}
