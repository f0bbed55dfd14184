//! The panel's pixels, kept between frames: egui is drawn again only when
//! what it draws changed. On lavapipe egui's pass takes 20-23 ms a frame
//! (the whole side panel and Quality strip rasterised on the CPU), which
//! alone held the window near 30 fps with no trace at all; most frames
//! draw the same panel (the Stats figures refresh four times a second), so
//! a copy of the kept layer (about 1 ms) stands for it.
//!
//! The layer holds the whole window but the image's rectangle, which the
//! display pass draws over it each frame. A frame whose egui output reaches
//! into the image (a tooltip, a menu, a prompt, the help overlay) is drawn
//! the plain way, the image first and egui on top.

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

/// Whether any of egui's primitives may draw inside `image` (in pixels):
/// its layer cannot then lie under the image. The panels' separators,
/// feathered, reach 1.5 px over the image's edge: the image covering
/// their inner half is no loss, so the edge's [`EDGE`] pixels do not count.
pub fn reaches_into(jobs: &[egui::ClippedPrimitive], ppp: f32, image: egui::Rect) -> bool {
    let image = image.shrink(EDGE);
    jobs.iter().any(|job| {
        let bounds = match &job.primitive {
            egui::epaint::Primitive::Mesh(mesh) => mesh.calc_bounds(),
            egui::epaint::Primitive::Callback(c) => c.rect,
        };
        let drawn = bounds.intersect(job.clip_rect);
        drawn.is_positive() && {
            let pixels = egui::Rect::from_min_max(drawn.min * ppp, drawn.max * ppp);
            pixels.intersects(image)
        }
    })
}

/// The kept layer: a texture the size and format of the window's.
pub struct UiLayer {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    /// The output the texture holds, if any.
    key: Option<u64>,
}

impl UiLayer {
    pub fn new(device: &wgpu::Device, config: &wgpu::SurfaceConfiguration) -> Self {
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
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        Self {
            texture,
            view,
            key: None,
        }
    }

    /// Whether the layer fits a window of `config`'s size.
    pub fn fits(&self, config: &wgpu::SurfaceConfiguration) -> bool {
        self.texture.width() == config.width
            && self.texture.height() == config.height
            && self.texture.format() == config.format
    }

    /// The view to draw egui into when `key` is not the one held; `None`
    /// when the layer already holds it. The layer then holds `key`.
    pub fn view_to_redraw(&mut self, key: u64) -> Option<&wgpu::TextureView> {
        if self.key == Some(key) {
            return None;
        }
        self.key = Some(key);
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

    /// A panel beside the image does not reach into it; a popup over the
    /// image does, and so does a panel clipped to the image's edge only
    /// where it crosses it. Rectangles are in points, scaled to pixels.
    #[test]
    fn reaching_into_the_image_is_found_in_pixels() {
        let image = Rect::from_min_max(pos2(0.0, 0.0), pos2(100.0, 100.0));
        let beside = [job(Rect::EVERYTHING, pos2(120.0, 10.0), Color32::WHITE)];
        assert!(!reaches_into(&beside, 1.0, image));
        let popup = [job(Rect::EVERYTHING, pos2(40.0, 40.0), Color32::WHITE)];
        assert!(reaches_into(&popup, 1.0, image));
        // A separator on the image's edge, feathered over it by 1.5 px.
        let separator = [job(Rect::EVERYTHING, pos2(98.5, 0.0), Color32::WHITE)];
        assert!(!reaches_into(&separator, 1.0, image));
        // At 2 pixels per point, the panel at x = 55 points lies at 110 px.
        let scaled = [job(Rect::EVERYTHING, pos2(55.0, 10.0), Color32::WHITE)];
        assert!(!reaches_into(&scaled, 2.0, image));
        assert!(reaches_into(&scaled, 1.0, image));
        // Clipped away from the image: it draws nothing there.
        let clip = Rect::from_min_max(pos2(100.0, 0.0), pos2(200.0, 100.0));
        let clipped = [job(clip, pos2(95.0, 10.0), Color32::WHITE)];
        assert!(!reaches_into(&clipped, 1.0, image));
    }
}
