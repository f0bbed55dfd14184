//! The scene model: everything a preset stores and the panel edits.
//!
//! This is the single source of truth. The GPU side derives from it a
//! [`crate::gpu::features::FeatureSet`] (which shader to build) and flat
//! buffers (what to feed it), so any edit is a change here followed by a
//! re-derivation.

pub mod camera;
pub mod change;
pub mod color_encoding;
pub mod contrast;
pub mod environment;
pub mod graph_layout;
pub mod material;
pub mod mesh;
pub mod node_path;
pub mod pattern;
pub mod pattern_table;
pub mod primitives;
pub mod render_settings;
pub mod render_view;
pub mod text_property;
pub mod texture_graph;
pub mod texture_tree;
mod time;
pub mod transport;
pub mod uv_frame;

pub use camera::{OrbitCamera, Projection, SavedView};
pub use change::Change;
pub use color_encoding::ColorEncoding;
pub use environment::{EnvSource, Environment};
pub use graph_layout::{GraphLayout, MaterialKey, MaterialLayout};
pub use material::{Layer, Material, Property};
pub use mesh::{Mesh, MeshMaterial, MeshPlacement, TriangleMesh};
pub use pattern::{MappingSpace, Pattern, Signal, SurfacePoint, TextureMapping};
pub use pattern_table::{PATTERNS, PatternCode, PatternInfo, PatternKind};
pub use primitives::{Cylinder, MAX_CYLINDERS, MAX_POLYGONS, Polygon};
pub use render_settings::{
    DenoiseQuality, Denoiser, DisplaySettings, Metering, RenderSettings, ToneMap,
};
pub use render_view::View;
pub use texture_tree::{Child, MathOp, Texture};
pub use transport::{Integrator, LightPoints, Strategy, TransportSettings};
pub use uv_frame::UvFrame;
// An environment's `ldr_images` setting, defined beside the loader that
// reads it (`envmap::load_ldr`) so that `envmap` imports nothing from here.
pub use crate::envmap::LdrImages;

use glam::Vec3;
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Sphere {
    pub name: String,
    pub center: Vec3,
    pub radius: f32,
    pub material: Material,
}

impl Default for Sphere {
    fn default() -> Self {
        Self {
            name: "sphere".into(),
            center: Vec3::new(0.0, 1.0, 0.0),
            radius: 1.0,
            material: Material::default(),
        }
    }
}

/// The infinite horizontal plane `y = height`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Ground {
    pub height: f32,
    /// The (u, v) frame of its 2D textures (the texture report's APTX):
    /// None reads world (x, z); a frame gives the point's coordinates on its
    /// axes, oblique ones included, exactly as a polygon's `uv_frame`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uv_frame: Option<UvFrame>,
    pub material: Material,
}

impl Default for Ground {
    fn default() -> Self {
        Self {
            height: 0.0,
            uv_frame: None,
            material: Material::default(),
        }
    }
}

impl Ground {
    /// The frame the renderer uses: `uv_frame`, or world (x, z) as the
    /// frame at the origin on +x and +z (for which the shader's plane
    /// solve gives x and z exactly).
    pub fn frame(&self) -> UvFrame {
        self.uv_frame.unwrap_or(UvFrame {
            origin: Vec3::ZERO,
            u_axis: Vec3::X,
            v_axis: Vec3::Z,
        })
    }

    /// The (u, v) of the ground point `p`: the CPU twin of the ground's
    /// hit in `intersect.wgsl`.
    pub fn uv(&self, p: Vec3) -> glam::Vec2 {
        let f = self.frame();
        crate::texture::plane_uv(p, f.origin, f.u_axis, f.v_axis)
    }
}

/// An isotropic point light of `intensity · color` watts per steradian.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PointLight {
    pub position: Vec3,
    pub color: Vec3,
    pub intensity: f32,
}

impl Default for PointLight {
    fn default() -> Self {
        Self {
            position: Vec3::new(4.0, 6.0, 3.0),
            color: Vec3::ONE,
            intensity: 40.0,
        }
    }
}

/// The most spheres a scene holds: the renderer keeps spheres and their
/// materials (one more, the ground's) in fixed-size uniform arrays
/// (`shaders/scene.wgsl`), whose divergent reads cost far less than
/// storage-buffer reads on lavapipe.
pub const MAX_SPHERES: usize = 63;

/// The most materials a scene holds: every primitive's, the ground's and the
/// meshes' (a uniform array in `shaders/scene.wgsl`, within the 64 KiB a
/// uniform binding may hold).
pub const MAX_MATERIALS: usize = 160;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default)]
pub struct Scene {
    pub camera: OrbitCamera,
    /// Named cameras to come back to; keys 1–9 recall the first nine.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub views: Vec<SavedView>,
    pub spheres: Vec<Sphere>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub cylinders: Vec<Cylinder>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub polygons: Vec<Polygon>,
    pub ground: Option<Ground>,
    /// Triangle meshes read from OBJ/MTL files.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub meshes: Vec<Mesh>,
    pub point_light: Option<PointLight>,
    pub environment: Environment,
    pub render: RenderSettings,
    /// Where the node editor draws each material's texture nodes: not
    /// traced, but saved (see `graph_layout`).
    #[serde(skip_serializing_if = "GraphLayout::is_empty")]
    pub graph_layout: GraphLayout,
    /// Time: the length, frame rate and keyframe tracks (`animation`);
    /// a still scene has none. What is traced at a time is
    /// [`Scene::at_time`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub animation: Option<crate::animation::Animation>,
}

impl Scene {
    /// Every material in GPU order: the spheres', the cylinders', the
    /// polygons', the ground's, then each mesh's.
    pub fn materials(&self) -> impl Iterator<Item = &Material> {
        self.spheres
            .iter()
            .map(|s| &s.material)
            .chain(self.cylinders.iter().map(|c| &c.material))
            .chain(self.polygons.iter().map(|p| &p.material))
            .chain(self.ground.iter().map(|g| &g.material))
            .chain(
                self.meshes
                    .iter()
                    .flat_map(|m| m.materials.iter().map(|m| &m.material)),
            )
    }

    /// The index (in [`Scene::materials`]) of each mesh's first material.
    pub fn mesh_material_bases(&self) -> Vec<u32> {
        let mut next = (self.spheres.len()
            + self.cylinders.len()
            + self.polygons.len()
            + usize::from(self.ground.is_some())) as u32;
        self.meshes
            .iter()
            .map(|m| {
                let base = next;
                next += m.materials.len() as u32;
                base
            })
            .collect()
    }

    /// Triangles of every mesh, in the world.
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.geometry.0.len()).sum()
    }

    /// Moves the camera to saved view `index` (0-based); false if there is
    /// none.
    pub fn recall_view(&mut self, index: usize) -> bool {
        match self.views.get(index) {
            Some(view) => {
                self.camera = view.camera;
                true
            }
            None => false,
        }
    }

    /// Saves the current camera as a new view named after its number.
    pub fn save_view(&mut self) {
        self.views.push(SavedView {
            name: format!("view {}", self.views.len() + 1),
            camera: self.camera,
        });
    }

    /// Every material, mutably, in GPU order.
    pub fn materials_mut(&mut self) -> impl Iterator<Item = &mut Material> {
        self.spheres
            .iter_mut()
            .map(|s| &mut s.material)
            .chain(self.cylinders.iter_mut().map(|c| &mut c.material))
            .chain(self.polygons.iter_mut().map(|p| &mut p.material))
            .chain(self.ground.iter_mut().map(|g| &mut g.material))
            .chain(
                self.meshes
                    .iter_mut()
                    .flat_map(|m| m.materials.iter_mut().map(|m| &mut m.material)),
            )
    }

    /// The image files the scene's image textures show, each once, in order
    /// of appearance.
    pub fn image_sources(&self) -> Vec<crate::texture::ImageSource> {
        let mut out = Vec::new();
        for material in self.materials() {
            for texture in material.all_textures() {
                texture.visit(&mut |t| {
                    if let (Pattern::Image { .. }, Some(source)) = (&t.pattern, &t.image)
                        && !out.contains(source)
                    {
                        out.push(source.clone());
                    }
                });
            }
        }
        out
    }

    /// Values no control can produce (a NaN radius, 40 octaves) are clamped
    /// into range; each clamp is reported so a preset author can see it.
    pub fn sanitize(&mut self) -> Vec<String> {
        let mut notes = Vec::new();
        if self.spheres.len() > MAX_SPHERES {
            notes.push(format!(
                "{} spheres: only the first {MAX_SPHERES} are kept (the renderer's limit)",
                self.spheres.len()
            ));
            self.spheres.truncate(MAX_SPHERES);
        }
        for s in &mut self.spheres {
            if !(s.radius.is_finite() && s.radius > 0.0) {
                notes.push(format!("sphere `{}`: radius {} set to 1", s.name, s.radius));
                s.radius = 1.0;
            }
            if !s.center.is_finite() {
                notes.push(format!("sphere `{}`: non-finite centre set to 0", s.name));
                s.center = Vec3::ZERO;
            }
            s.material
                .sanitize(&format!("sphere `{}`", s.name), &mut notes);
        }
        self.sanitize_cylinders(&mut notes);
        self.sanitize_polygons(&mut notes);
        if let Some(g) = &mut self.ground {
            if !g.height.is_finite() {
                notes.push("ground: non-finite height set to 0".into());
                g.height = 0.0;
            }
            if let Some(problem) = g.uv_frame.as_ref().and_then(UvFrame::problem) {
                notes.push(format!(
                    "ground: uv frame refused ({problem}); world (x, z) used"
                ));
                g.uv_frame = None;
            }
            g.material.sanitize("ground", &mut notes);
        }
        self.sanitize_meshes(&mut notes);
        if let Some(light) = &mut self.point_light {
            light.sanitize(&mut notes);
        }
        self.render.sanitize(&mut notes);
        self.camera.sanitize(&mut notes);
        for view in &mut self.views {
            view.camera.sanitize(&mut notes);
        }
        notes
    }

    fn sanitize_cylinders(&mut self, notes: &mut Vec<String>) {
        if self.cylinders.len() > MAX_CYLINDERS {
            notes.push(format!(
                "{} cylinders: only the first {MAX_CYLINDERS} are kept (the renderer's limit)",
                self.cylinders.len()
            ));
            self.cylinders.truncate(MAX_CYLINDERS);
        }
        for c in &mut self.cylinders {
            for (what, v) in [("radius", &mut c.radius), ("height", &mut c.height)] {
                if !(v.is_finite() && *v > 0.0) {
                    notes.push(format!("cylinder `{}`: {what} {v} set to 1", c.name));
                    *v = 1.0;
                }
            }
            if !c.base.is_finite() {
                notes.push(format!("cylinder `{}`: non-finite base set to 0", c.name));
                c.base = Vec3::ZERO;
            }
            c.material
                .sanitize(&format!("cylinder `{}`", c.name), notes);
        }
    }

    /// Mesh placements stay invertible and finite; materials beyond the
    /// renderer's limit are dropped (their triangles then show the last kept
    /// one).
    fn sanitize_meshes(&mut self, notes: &mut Vec<String>) {
        let fixed = self.spheres.len()
            + self.cylinders.len()
            + self.polygons.len()
            + usize::from(self.ground.is_some());
        let mut room = MAX_MATERIALS.saturating_sub(fixed);
        for mesh in &mut self.meshes {
            let p = &mut mesh.placement;
            if !(p.scale.is_finite() && p.scale > 0.0) {
                notes.push(format!("mesh `{}`: scale {} set to 1", mesh.name, p.scale));
                p.scale = 1.0;
            }
            if !p.translate.is_finite() || !p.rotate_y_degrees.is_finite() {
                notes.push(format!("mesh `{}`: non-finite placement reset", mesh.name));
                *p = MeshPlacement::default();
            }
            if mesh.materials.len() > room {
                notes.push(format!(
                    "mesh `{}`: {} materials, only {room} fit (the renderer holds {MAX_MATERIALS})",
                    mesh.name,
                    mesh.materials.len()
                ));
                mesh.materials.truncate(room);
            }
            room -= mesh.materials.len();
            for m in &mut mesh.materials {
                m.material.sanitize(
                    &format!("mesh `{}` material `{}`", mesh.name, m.name),
                    notes,
                );
            }
        }
    }

    /// Polygons the renderer cannot draw (too few vertices, warped,
    /// concave) are dropped, each with the reason.
    fn sanitize_polygons(&mut self, notes: &mut Vec<String>) {
        self.polygons.retain(|p| match p.problem() {
            Some(problem) => {
                notes.push(format!("polygon `{}` dropped: {problem}", p.name));
                false
            }
            None => true,
        });
        if self.polygons.len() > MAX_POLYGONS {
            notes.push(format!(
                "{} polygons: only the first {MAX_POLYGONS} are kept (the renderer's limit)",
                self.polygons.len()
            ));
            self.polygons.truncate(MAX_POLYGONS);
        }
        for p in &mut self.polygons {
            let flat = p
                .uv_frame
                .zip(p.normal())
                .and_then(|(frame, n)| frame.problem_on_plane(n));
            if let Some(problem) = flat {
                notes.push(format!("polygon `{}`: warning: {problem}", p.name));
            }
            p.material.sanitize(&format!("polygon `{}`", p.name), notes);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Saving keeps the camera under the next number; recalling brings it
    /// back after the camera moved; a missing view changes nothing.
    #[test]
    fn saved_views_come_back() {
        let mut scene = Scene::default();
        scene.save_view();
        let saved = scene.camera;
        scene.camera.orbit(40.0, 10.0);
        scene.save_view();
        assert_eq!(scene.views[1].name, "view 2");
        assert!(scene.recall_view(0));
        assert_eq!(scene.camera, saved);
        let before = scene.camera;
        assert!(!scene.recall_view(5));
        assert_eq!(scene.camera, before);
    }

    #[test]
    fn spheres_beyond_the_renderer_limit_are_dropped_with_a_note() {
        let mut scene = Scene {
            spheres: vec![Sphere::default(); MAX_SPHERES + 2],
            ..Default::default()
        };
        let notes = scene.sanitize();
        assert_eq!(scene.spheres.len(), MAX_SPHERES);
        assert!(
            notes
                .iter()
                .any(|n| n.contains(&format!("{}", MAX_SPHERES + 2))),
            "{notes:?}"
        );
    }

    /// Ramps come out of `sanitize` in order, finite, within the limit.
    #[test]
    fn ramp_stops_are_sorted_and_bounded() {
        use crate::texture::{MAX_RAMP_STOPS, RampStop};
        let mut scene = Scene {
            spheres: vec![Sphere::default()],
            ..Default::default()
        };
        let stops = &mut scene.spheres[0].material.diffuse.ramp;
        for k in 0..MAX_RAMP_STOPS + 3 {
            stops.push(RampStop {
                position: 1.0 - k as f32 * 0.1,
                color: Vec3::splat(2.0),
            });
        }
        stops[1].position = f32::NAN;
        let notes = scene.sanitize();
        let ramp = &scene.spheres[0].material.diffuse.ramp;
        assert_eq!(ramp.len(), MAX_RAMP_STOPS);
        assert!(ramp.is_sorted_by(|a, b| a.position <= b.position));
        assert!(
            ramp.iter()
                .all(|s| s.position.is_finite() && s.color.max_element() <= 1.0)
        );
        assert!(notes.len() >= 3, "{notes:?}");
    }

    /// The ground's (u, v): world (x, z) without a frame; with an oblique
    /// frame (the report's APTX), the coefficients of the point on its
    /// axes, at points built from known coefficients.
    #[test]
    fn the_ground_reads_uv_from_its_frame() {
        let mut ground = Ground::default();
        assert_eq!(
            ground.uv(Vec3::new(1.5, 0.0, -2.25)),
            glam::Vec2::new(1.5, -2.25)
        );
        let frame = UvFrame {
            origin: Vec3::new(1.0, 0.0, -0.5),
            u_axis: Vec3::new(2.0, 0.0, 0.5),
            v_axis: Vec3::new(-0.5, 0.0, 1.5),
        };
        ground.uv_frame = Some(frame);
        for (a, b) in [
            (0.0, 0.0),
            (1.0, 0.0),
            (0.0, 1.0),
            (0.25, 0.75),
            (-3.0, 2.5),
        ] {
            let p = frame.origin + a * frame.u_axis + b * frame.v_axis;
            let uv = ground.uv(p);
            assert!(
                (uv - glam::Vec2::new(a, b)).abs().max_element() < 1e-5,
                "({a}, {b}): {uv}"
            );
        }
    }

    /// A ground frame whose axes are parallel, zero or not finite is
    /// refused with a note, leaving world (x, z).
    #[test]
    fn a_degenerate_ground_frame_is_refused() {
        for (u, v) in [
            (Vec3::X, Vec3::X * 3.0),
            (Vec3::ZERO, Vec3::Z),
            (Vec3::X, Vec3::new(f32::NAN, 0.0, 1.0)),
        ] {
            let mut scene = Scene {
                ground: Some(Ground {
                    uv_frame: Some(UvFrame {
                        origin: Vec3::ZERO,
                        u_axis: u,
                        v_axis: v,
                    }),
                    ..Ground::default()
                }),
                ..Default::default()
            };
            let notes = scene.sanitize();
            assert_eq!(scene.ground.unwrap().uv_frame, None);
            assert!(
                notes.iter().any(|n| n.contains("ground: uv frame refused")),
                "{notes:?}"
            );
        }
    }

    #[test]
    fn a_scene_at_the_limit_keeps_every_sphere() {
        let mut scene = Scene {
            spheres: vec![Sphere::default(); MAX_SPHERES],
            ..Default::default()
        };
        assert!(scene.sanitize().is_empty());
        assert_eq!(scene.spheres.len(), MAX_SPHERES);
    }
}
