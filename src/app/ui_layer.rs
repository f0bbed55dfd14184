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
        }
    }

    /// Whether the layer fits a window of `config`'s size.
    pub fn fits(&self, config: &wgpu::SurfaceConfiguration) -> bool {
        self.texture.width() == config.width
            && self.texture.height() == config.height
            && self.texture.format() == config.format
    }

    /// The view to draw egui into when output `key` drawn for `mode` is
    /// not what the layer holds; `None` when it already holds it. The
    /// layer then holds it.
    pub fn view_to_redraw(&mut self, key: u64, mode: Mode) -> Option<&wgpu::TextureView> {
        if self.key == Some((key, mode)) {
            return None;
        }
        self.key = Some((key, mode));
        Some(&self.view)
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
";

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
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("panel layer blend"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("panel layer blend"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        Self {
            pipeline,
            layout,
            format,
        }
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
