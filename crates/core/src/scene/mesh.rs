//! Triangle meshes from OBJ/MTL files, placed in the scene.
//!
//! The preset names the OBJ file and how to place it; the triangles are
//! derived data, read from the file at load time (`crate::obj_loader`) and
//! held behind an `Arc` so that cloning a scene for a background shader
//! build costs nothing. Materials come from the MTL file; the preset stores
//! only those it changes (overrides), so an edited wall survives a reload
//! and an untouched one follows the MTL file.

use super::Material;
use glam::{Mat3, Vec2, Vec3};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use std::sync::Arc;

/// Where a mesh goes: scaled, turned about +y, then moved.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MeshPlacement {
    pub translate: Vec3,
    pub rotate_y_degrees: f32,
    pub scale: f32,
}

impl Default for MeshPlacement {
    fn default() -> Self {
        Self {
            translate: Vec3::ZERO,
            rotate_y_degrees: 0.0,
            scale: 1.0,
        }
    }
}

impl MeshPlacement {
    pub fn apply(&self, p: Vec3) -> Vec3 {
        Mat3::from_rotation_y(self.rotate_y_degrees.to_radians()) * (p * self.scale)
            + self.translate
    }
}

/// One of a mesh's materials, by its MTL name.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeshMaterial {
    pub name: String,
    pub material: Material,
    /// What the MTL file says: a material equal to it is not written to
    /// the preset, and "reset" goes back to it.
    #[serde(skip)]
    pub from_file: Option<Material>,
}

impl MeshMaterial {
    /// Whether the preset must store this material (it differs from the
    /// file's, or the file has none by that name).
    pub fn is_override(&self) -> bool {
        self.from_file.as_ref() != Some(&self.material)
    }
}

/// Triangles in the OBJ file's coordinates, with their texture coordinates
/// and the index of their material in [`Mesh::materials`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleMesh {
    pub positions: Vec<[Vec3; 3]>,
    pub uvs: Vec<[Vec2; 3]>,
    pub materials: Vec<u32>,
}

impl TriangleMesh {
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// The bounding box of every vertex (None without triangles).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut vertices = self.positions.iter().flatten();
        let first = *vertices.next()?;
        Some(vertices.fold((first, first), |(lo, hi), &v| (lo.min(v), hi.max(v))))
    }
}

/// The loaded triangles, shared between clones of a scene. Two scenes hold
/// equal geometry when they share the same load, or their triangles match.
#[derive(Debug, Clone, Default)]
pub struct Geometry(pub Arc<TriangleMesh>);

impl PartialEq for Geometry {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0) || self.0 == other.0
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default)]
pub struct Mesh {
    pub name: String,
    /// The OBJ file; a relative path is relative to the preset.
    pub obj: PathBuf,
    pub placement: MeshPlacement,
    /// The MTL file's materials, each possibly edited. The preset writes
    /// only the edited ones.
    #[serde(serialize_with = "serialize_overrides")]
    pub materials: Vec<MeshMaterial>,
    #[serde(skip)]
    pub geometry: Geometry,
}

impl Mesh {
    /// The triangles' vertices placed in the world.
    pub fn world_positions(&self) -> impl Iterator<Item = [Vec3; 3]> + '_ {
        self.geometry
            .0
            .positions
            .iter()
            .map(|t| t.map(|p| self.placement.apply(p)))
    }
}

fn serialize_overrides<S: serde::Serializer>(
    materials: &[MeshMaterial],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let overrides: Vec<&MeshMaterial> = materials.iter().filter(|m| m.is_override()).collect();
    let mut seq = serializer.serialize_seq(Some(overrides.len()))?;
    for m in overrides {
        seq.serialize_element(m)?;
    }
    seq.end()
}
