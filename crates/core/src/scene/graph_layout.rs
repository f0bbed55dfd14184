//! Where the node editor draws each material's texture nodes, saved in the
//! preset (`graph_layout`) so that a graph arranged by hand opens as it was
//! left.
//!
//! It belongs to the scene, not to the materials: it is not traced
//! (`Scene::changes_from` calls it an annotation, so moving a node keeps the
//! accumulation and the shader), but it is part of the document (a moved
//! node is an undoable edit and unsaved work). Keys are text, a material's
//! place in the scene and then a node's [`NodePath`], so the file reads
//! `graph_layout: { "spheres[0]": { "diffuse.a": (-420.0, 80.0) } }`. An
//! entry that names no material or node is never read (the node editor
//! lays such nodes out itself), so a stale or hand-mangled layout cannot
//! break a preset; a node without an entry is laid out automatically.

use super::Scene;
use super::material::Material;
use super::node_path::NodePath;
use glam::Vec2;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;

/// Which material of a scene: its object's place in the preset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MaterialKey {
    Sphere(usize),
    Cylinder(usize),
    Polygon(usize),
    Ground,
    /// Material `material` of mesh `mesh`.
    Mesh {
        mesh: usize,
        material: usize,
    },
}

impl fmt::Display for MaterialKey {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            MaterialKey::Sphere(i) => write!(f, "spheres[{i}]"),
            MaterialKey::Cylinder(i) => write!(f, "cylinders[{i}]"),
            MaterialKey::Polygon(i) => write!(f, "polygons[{i}]"),
            MaterialKey::Ground => f.write_str("ground"),
            MaterialKey::Mesh { mesh, material } => {
                write!(f, "meshes[{mesh}].materials[{material}]")
            }
        }
    }
}

/// One material's node positions, keyed by node path.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(transparent)]
pub struct MaterialLayout(BTreeMap<String, Vec2>);

impl MaterialLayout {
    /// Where the node at `path` was put, if it was and the place is finite.
    pub fn position(&self, path: &NodePath) -> Option<Vec2> {
        self.0
            .get(&path.to_string())
            .copied()
            .filter(|p| p.is_finite())
    }

    pub fn set(&mut self, path: &NodePath, position: Vec2) {
        self.0.insert(path.to_string(), position);
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Re-keys every entry whose key is a node path by `f`: Some(new
    /// path) keeps the position under it, None forgets it. Entries that
    /// are no node path are left alone.
    pub fn rename(&mut self, f: impl Fn(&NodePath) -> Option<NodePath>) {
        let old = std::mem::take(&mut self.0);
        let mut renamed = BTreeMap::new();
        let mut kept = BTreeMap::new();
        for (key, position) in old {
            match key.parse::<NodePath>() {
                Ok(path) => {
                    if let Some(new) = f(&path) {
                        renamed.insert(new.to_string(), position);
                    }
                }
                Err(_) => {
                    kept.insert(key, position);
                }
            }
        }
        // A moved node's new place wins over a stale entry kept there.
        kept.extend(renamed);
        self.0 = kept;
    }
}

/// Every material's node positions, keyed by [`MaterialKey`]'s text.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(transparent)]
pub struct GraphLayout(BTreeMap<String, MaterialLayout>);

impl GraphLayout {
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The positions saved for a material, if any.
    pub fn get(&self, key: MaterialKey) -> Option<&MaterialLayout> {
        self.0.get(&key.to_string())
    }

    /// Edits a material's positions; a layout left empty is removed, so
    /// that opening a graph and moving nothing leaves the scene equal.
    pub fn edit<R>(&mut self, key: MaterialKey, f: impl FnOnce(&mut MaterialLayout) -> R) -> R {
        let name = key.to_string();
        let mut layout = self.0.remove(&name).unwrap_or_default();
        let out = f(&mut layout);
        if !layout.is_empty() {
            self.0.insert(name, layout);
        }
        out
    }
}

impl Scene {
    /// The material `key` names, if the scene has it.
    pub fn material(&self, key: MaterialKey) -> Option<&Material> {
        match key {
            MaterialKey::Sphere(i) => self.spheres.get(i).map(|s| &s.material),
            MaterialKey::Cylinder(i) => self.cylinders.get(i).map(|c| &c.material),
            MaterialKey::Polygon(i) => self.polygons.get(i).map(|p| &p.material),
            MaterialKey::Ground => self.ground.as_ref().map(|g| &g.material),
            MaterialKey::Mesh { mesh, material } => self
                .meshes
                .get(mesh)?
                .materials
                .get(material)
                .map(|m| &m.material),
        }
    }

    /// The material `key` names and the scene's node layout, both to edit
    /// (a link edit changes the tree and re-keys the positions).
    pub fn material_and_layout_mut(
        &mut self,
        key: MaterialKey,
    ) -> Option<(&mut Material, &mut GraphLayout)> {
        let material = match key {
            MaterialKey::Sphere(i) => self.spheres.get_mut(i).map(|s| &mut s.material),
            MaterialKey::Cylinder(i) => self.cylinders.get_mut(i).map(|c| &mut c.material),
            MaterialKey::Polygon(i) => self.polygons.get_mut(i).map(|p| &mut p.material),
            MaterialKey::Ground => self.ground.as_mut().map(|g| &mut g.material),
            MaterialKey::Mesh { mesh, material } => self
                .meshes
                .get_mut(mesh)
                .and_then(|m| m.materials.get_mut(material))
                .map(|m| &mut m.material),
        }?;
        Some((material, &mut self.graph_layout))
    }

    /// The object whose material `key` names, as the panel titles it
    /// (`sphere “marble”`, `mesh “box”, material “white”`), for the node
    /// editor's window; `None` when there is no such object.
    pub fn material_title(&self, key: MaterialKey) -> Option<String> {
        Some(match key {
            MaterialKey::Sphere(i) => format!("sphere “{}”", self.spheres.get(i)?.name),
            MaterialKey::Cylinder(i) => format!("cylinder “{}”", self.cylinders.get(i)?.name),
            MaterialKey::Polygon(i) => format!("polygon “{}”", self.polygons.get(i)?.name),
            MaterialKey::Ground => {
                self.ground.as_ref()?;
                "ground".to_owned()
            }
            MaterialKey::Mesh { mesh, material } => {
                let m = self.meshes.get(mesh)?;
                format!(
                    "mesh “{}”, material “{}”",
                    m.name,
                    m.materials.get(material)?.name
                )
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Sphere;

    /// Titles name the object, not its index; a missing one has none.
    #[test]
    fn a_material_is_titled_by_its_object() {
        let scene = Scene {
            spheres: vec![Sphere {
                name: "marble".into(),
                ..Sphere::default()
            }],
            ground: None,
            ..Scene::default()
        };
        assert_eq!(
            scene.material_title(MaterialKey::Sphere(0)).as_deref(),
            Some("sphere “marble”")
        );
        assert_eq!(scene.material_title(MaterialKey::Sphere(1)), None);
        assert_eq!(scene.material_title(MaterialKey::Ground), None);
    }

    fn path(text: &str) -> NodePath {
        text.parse().unwrap()
    }

    #[test]
    fn renaming_moves_kept_entries_and_forgets_others() {
        let mut layout = MaterialLayout::default();
        layout.set(&path("diffuse.a"), Vec2::new(1.0, 2.0));
        layout.set(&path("diffuse.a.b"), Vec2::new(3.0, 4.0));
        layout.set(&path("roughness"), Vec2::new(5.0, 6.0));
        layout.0.insert("not a path".into(), Vec2::ZERO);
        let (from, to) = (path("diffuse.a"), path("bump"));
        layout.rename(|p| p.starts_with(&from).then(|| p.moved(&from, &to)));
        assert_eq!(layout.position(&path("bump")), Some(Vec2::new(1.0, 2.0)));
        assert_eq!(layout.position(&path("bump.b")), Some(Vec2::new(3.0, 4.0)));
        assert_eq!(layout.position(&path("roughness")), None);
        assert!(layout.0.contains_key("not a path"));
    }

    #[test]
    fn an_edit_that_leaves_nothing_leaves_no_entry() {
        let mut layout = GraphLayout::default();
        layout.edit(MaterialKey::Ground, |_| {});
        assert!(layout.is_empty());
        layout.edit(MaterialKey::Sphere(0), |l| l.set(&path("bump"), Vec2::ONE));
        assert!(layout.get(MaterialKey::Sphere(0)).is_some());
        assert!(layout.get(MaterialKey::Ground).is_none());
    }

    #[test]
    fn non_finite_positions_are_not_read() {
        let mut layout = MaterialLayout::default();
        layout.set(&path("bump"), Vec2::new(f32::NAN, 0.0));
        assert_eq!(layout.position(&path("bump")), None);
    }

    #[test]
    fn keys_name_the_material_in_the_scene() {
        let mut scene = Scene {
            spheres: vec![Sphere::default(), Sphere::default()],
            ..Scene::default()
        };
        scene.spheres[1].material.bump_height = 0.25;
        let key = MaterialKey::Sphere(1);
        assert_eq!(key.to_string(), "spheres[1]");
        assert_eq!(scene.material(key).unwrap().bump_height, 0.25);
        assert!(scene.material(MaterialKey::Sphere(2)).is_none());
        assert!(scene.material(MaterialKey::Ground).is_none());
        let (m, _) = scene.material_and_layout_mut(key).unwrap();
        m.bump_height = 0.5;
        assert_eq!(scene.spheres[1].material.bump_height, 0.5);
    }
}
