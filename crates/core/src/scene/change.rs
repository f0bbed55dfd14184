//! What an edit changed, worked out once.
//!
//! The viewer compares the scene with the one of the frame before once per
//! frame ([`Scene::changes_from`]) and hands the answer on: the renderer
//! decides from it whether to rebuild a pipeline, rewrite buffers or only
//! move the camera, the undo history whether to open a step, the document
//! whether it has unsaved edits. None of them compares whole scenes again,
//! so an edit costs one comparison however many parts react to it.
//!
//! Destructured in full below: a new field of the scene, of a primitive or
//! of a material does not compile until it is sorted into a class.

use super::{Cylinder, Material, Mesh, Polygon, Scene, Sphere, Texture};
use crate::scene::material::Layer;
use crate::scene::texture_tree::Child;

bitflags::bitflags! {
    /// The classes of an edit, as flags: one edit may set several.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
    pub struct Change: u16 {
        /// The camera moved: the image restarts, nothing is rebuilt, and
        /// it is not an edit of the document (orbiting is looking).
        const CAMERA = 1 << 0;
        /// Exposure, tone map, the debug overlays, the denoiser's display:
        /// the accumulated samples stay.
        const DISPLAY = 1 << 1;
        /// The traced render settings (integrator, bounces, view, …).
        const RENDER = 1 << 2;
        /// A number of a material (a colour, a frequency, an octave
        /// count): its texture code stays; a parameter buffer is rewritten.
        const MATERIAL_PARAMETERS = 1 << 3;
        /// The shape of a material's textures (a pattern kind, a nested
        /// texture, a layer, which noise sums it shares): its texture code
        /// is generated again.
        const MATERIAL_STRUCTURE = 1 << 4;
        /// Where the primitives and meshes are, and how many.
        const GEOMETRY = 1 << 5;
        /// The point light.
        const LIGHTS = 1 << 6;
        /// The environment (its source, rotation, intensity, sampling).
        const ENVIRONMENT = 1 << 7;
        /// Saved but not traced: names, saved views, the node editor's
        /// layout.
        const ANNOTATIONS = 1 << 8;
        /// The animation: its length, rate, loop or keys. Saved and
        /// undone; what it changes in the traced scene at the current
        /// time is compared there (`Scene::at_time`).
        const ANIMATION = 1 << 9;
    }
}

impl Change {
    /// Whether the samples accumulated so far no longer describe the
    /// scene: anything traced changed.
    pub fn resets_accumulation(self) -> bool {
        self.intersects(
            Change::CAMERA
                | Change::RENDER
                | Change::MATERIAL_PARAMETERS
                | Change::MATERIAL_STRUCTURE
                | Change::GEOMETRY
                | Change::LIGHTS
                | Change::ENVIRONMENT,
        )
    }

    /// Whether the document has something new to save, and the undo
    /// history a step: anything but the camera.
    pub fn edits_document(self) -> bool {
        !self.difference(Change::CAMERA).is_empty()
    }

    /// Whether the generated texture code may differ: a structural edit of
    /// a material, or materials added or removed.
    pub fn regenerates_code(self) -> bool {
        self.contains(Change::MATERIAL_STRUCTURE)
    }
}

impl Scene {
    /// What changed from `old` to `self`, in classes (see [`Change`]).
    pub fn changes_from(&self, old: &Scene) -> Change {
        let Scene {
            camera,
            views,
            spheres,
            cylinders,
            polygons,
            ground,
            meshes,
            point_light,
            environment,
            render,
            graph_layout,
            animation,
        } = self;
        let mut change = Change::empty();
        change.set(Change::CAMERA, *camera != old.camera);
        change.set(
            Change::ANNOTATIONS,
            *views != old.views || *graph_layout != old.graph_layout,
        );
        change.set(Change::ANIMATION, *animation != old.animation);
        change.set(Change::LIGHTS, *point_light != old.point_light);
        change.set(Change::ENVIRONMENT, *environment != old.environment);
        change.set(Change::DISPLAY, render.display != old.render.display);
        change.set(Change::RENDER, !render.traces_like(&old.render));
        change |= pairs(spheres, &old.spheres, sphere_change);
        change |= pairs(cylinders, &old.cylinders, cylinder_change);
        change |= pairs(polygons, &old.polygons, polygon_change);
        change |= match (ground, &old.ground) {
            (None, None) => Change::empty(),
            (Some(a), Some(b)) => {
                let mut c = material_change(&a.material, &b.material);
                c.set(
                    Change::GEOMETRY,
                    a.height != b.height || a.uv_frame != b.uv_frame,
                );
                c
            }
            _ => Change::GEOMETRY | Change::MATERIAL_STRUCTURE,
        };
        change |= pairs(meshes, &old.meshes, mesh_change);
        change
    }
}

/// The changes of two lists of primitives: an added or removed one adds
/// geometry and a material (which the texture code dispatches on).
fn pairs<T>(new: &[T], old: &[T], change: fn(&T, &T) -> Change) -> Change {
    if new.len() != old.len() {
        return Change::GEOMETRY | Change::MATERIAL_STRUCTURE | Change::ANNOTATIONS;
    }
    new.iter()
        .zip(old)
        .fold(Change::empty(), |c, (a, b)| c | change(a, b))
}

fn named(new: &str, old: &str) -> Change {
    if new == old {
        Change::empty()
    } else {
        Change::ANNOTATIONS
    }
}

fn moved(moved: bool) -> Change {
    if moved {
        Change::GEOMETRY
    } else {
        Change::empty()
    }
}

fn sphere_change(new: &Sphere, old: &Sphere) -> Change {
    let Sphere {
        name,
        center,
        radius,
        material,
    } = new;
    named(name, &old.name)
        | moved(*center != old.center || *radius != old.radius)
        | material_change(material, &old.material)
}

fn cylinder_change(new: &Cylinder, old: &Cylinder) -> Change {
    let Cylinder {
        name,
        base,
        radius,
        height,
        material,
    } = new;
    named(name, &old.name)
        | moved(*base != old.base || *radius != old.radius || *height != old.height)
        | material_change(material, &old.material)
}

fn polygon_change(new: &Polygon, old: &Polygon) -> Change {
    let Polygon {
        name,
        vertices,
        uv_frame,
        material,
    } = new;
    named(name, &old.name)
        | moved(*vertices != old.vertices || *uv_frame != old.uv_frame)
        | material_change(material, &old.material)
}

fn mesh_change(new: &Mesh, old: &Mesh) -> Change {
    let Mesh {
        name,
        obj,
        placement,
        materials,
        geometry,
    } = new;
    let mut change = named(name, &old.name)
        | moved(*obj != old.obj || *placement != old.placement || *geometry != old.geometry);
    if materials.len() != old.materials.len() {
        return change | Change::MATERIAL_STRUCTURE;
    }
    for (a, b) in materials.iter().zip(&old.materials) {
        // `from_file` is what the MTL said, kept to tell overrides apart:
        // not traced, and it changes only with the geometry.
        change |= named(&a.name, &b.name) | material_change(&a.material, &b.material);
    }
    change
}

/// A material's edit: none, its numbers alone, or its structure.
pub fn material_change(new: &Material, old: &Material) -> Change {
    if new == old {
        Change::empty()
    } else if new.same_structure(old) {
        Change::MATERIAL_PARAMETERS
    } else {
        Change::MATERIAL_STRUCTURE
    }
}

impl Material {
    /// Whether the two materials' textures have one shape: the same trees
    /// of the same pattern kinds, the same layers, the same noise sums
    /// shared, so that the generated code of one serves the other with
    /// its own parameters. What the code reads as a number
    /// (`texture_params`, the material's noise parameters) may differ.
    pub fn same_structure(&self, other: &Material) -> bool {
        let Material {
            diffuse,
            specular,
            roughness,
            mirror,
            opacity,
            transmission,
            emission,
            emission_strength: _,
            diffuse_transmission,
            bump,
            bump_height: _,
            layers,
        } = self;
        let trees = [
            (diffuse, &other.diffuse),
            (specular, &other.specular),
            (roughness, &other.roughness),
            (mirror, &other.mirror),
            (opacity, &other.opacity),
            (transmission, &other.transmission),
            (emission, &other.emission),
            (diffuse_transmission, &other.diffuse_transmission),
            (bump, &other.bump),
        ];
        trees.iter().all(|(a, b)| a.same_structure(b))
            && layers.len() == other.layers.len()
            && layers
                .iter()
                .zip(&other.layers)
                .all(|(a, b)| layer_structure(a, b))
            && self.signal_slots() == other.signal_slots()
    }
}

fn layer_structure(a: &Layer, b: &Layer) -> bool {
    a.mask.same_structure(&b.mask)
        && crate::scene::Property::ALL
            .iter()
            .all(|&p| match (a.texture(p), b.texture(p)) {
                (None, None) => true,
                (Some(x), Some(y)) => x.same_structure(y),
                _ => false,
            })
}

impl Texture {
    /// Whether the two trees have one shape: the same pattern kinds (and
    /// the choices compiled into code: image filter and wrap, noise kind),
    /// the same children kinds, ramps of as many stops, the same math
    /// steps, mappings in the same places, the same image files.
    pub fn same_structure(&self, other: &Texture) -> bool {
        let Texture {
            pattern,
            a,
            b,
            factor,
            image,
            mapping,
            ramp,
            ops,
        } = self;
        pattern.same_kind(&other.pattern)
            && child_structure(a, &other.a)
            && child_structure(b, &other.b)
            && match (factor, &other.factor) {
                (None, None) => true,
                (Some(x), Some(y)) => x.same_structure(y),
                _ => false,
            }
            && *image == other.image
            && match (mapping, &other.mapping) {
                (None, None) => true,
                (Some(x), Some(y)) => x.space == y.space && x.frame.is_some() == y.frame.is_some(),
                _ => false,
            }
            && ramp.len() == other.ramp.len()
            && ops.len() == other.ops.len()
            && ops
                .iter()
                .zip(&other.ops)
                .all(|(x, y)| x.index() == y.index())
    }
}

fn child_structure(a: &Child, b: &Child) -> bool {
    match (a, b) {
        (Child::Scalar(_), Child::Scalar(_)) | (Child::Color(_), Child::Color(_)) => true,
        (Child::Texture(x), Child::Texture(y)) => x.same_structure(y),
        _ => false,
    }
}

#[cfg(test)]
mod tests;
