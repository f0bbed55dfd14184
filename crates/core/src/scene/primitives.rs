//! The primitives beyond spheres and the ground: capped cylinders and
//! convex polygons, there to show the cylinder and plane mappings (a box is
//! six polygons).

use super::material::Material;
use super::uv_frame::UvFrame;
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// The most cylinders and polygons a scene holds (the renderer's uniform
/// arrays, `shaders/scene.wgsl`).
pub const MAX_CYLINDERS: usize = 8;
pub const MAX_POLYGONS: usize = 16;
/// The most vertices of one polygon.
pub const MAX_POLYGON_VERTICES: usize = 8;

/// A closed cylinder standing on `base` along +y. Its side maps (u, v) as
/// angle and height (`texture::cylinder_uv`); its caps map the disc onto
/// the unit square.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Cylinder {
    pub name: String,
    pub base: Vec3,
    pub radius: f32,
    pub height: f32,
    pub material: Material,
}

impl Default for Cylinder {
    fn default() -> Self {
        Self {
            name: "cylinder".into(),
            base: Vec3::ZERO,
            radius: 0.5,
            height: 1.5,
            material: Material::default(),
        }
    }
}

/// A flat convex polygon. Its (u, v) follow `uv_frame` if given, else the
/// report's default: the first vertex, the first edge, and the last edge
/// made orthogonal to it (`texture::polygon_frame`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Polygon {
    pub name: String,
    pub vertices: Vec<Vec3>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uv_frame: Option<UvFrame>,
    pub material: Material,
}

impl Default for Polygon {
    fn default() -> Self {
        Self {
            name: "polygon".into(),
            vertices: vec![
                Vec3::new(-1.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, -1.0),
                Vec3::new(1.0, 2.0, -1.0),
                Vec3::new(-1.0, 2.0, -1.0),
            ],
            uv_frame: None,
            material: Material::default(),
        }
    }
}

impl Polygon {
    /// The unit normal by Newell's method (robust for any planar polygon),
    /// facing the side from which the vertices turn counter-clockwise.
    pub fn normal(&self) -> Option<Vec3> {
        let n = self
            .vertices
            .iter()
            .zip(self.vertices.iter().cycle().skip(1))
            .fold(Vec3::ZERO, |n, (a, b)| {
                n + Vec3::new(
                    (a.y - b.y) * (a.z + b.z),
                    (a.z - b.z) * (a.x + b.x),
                    (a.x - b.x) * (a.y + b.y),
                )
            });
        n.try_normalize()
    }

    /// The (u, v) frame the renderer uses.
    pub fn frame(&self) -> Option<UvFrame> {
        self.uv_frame.or_else(|| {
            crate::texture::polygon_frame(&self.vertices).map(|(origin, u_axis, v_axis)| UvFrame {
                origin,
                u_axis,
                v_axis,
            })
        })
    }

    /// Why the renderer cannot draw the polygon, if it cannot: it needs 3 to
    /// [`MAX_POLYGON_VERTICES`] finite vertices, in one plane, convex.
    pub fn problem(&self) -> Option<String> {
        let n = self.vertices.len();
        if !(3..=MAX_POLYGON_VERTICES).contains(&n) {
            return Some(format!(
                "{n} vertices (a polygon has 3 to {MAX_POLYGON_VERTICES})"
            ));
        }
        if !self.vertices.iter().all(|v| v.is_finite()) {
            return Some("a non-finite vertex".into());
        }
        let Some(normal) = self.normal() else {
            return Some("no area".into());
        };
        let size = self
            .vertices
            .iter()
            .map(|v| (*v - self.vertices[0]).length())
            .fold(0.0, f32::max);
        for (i, v) in self.vertices.iter().enumerate() {
            if (*v - self.vertices[0]).dot(normal).abs() > 1e-4 * size {
                return Some(format!("vertex {i} is off the plane of the others"));
            }
            let next = self.vertices[(i + 1) % n];
            let after = self.vertices[(i + 2) % n];
            if (next - *v).cross(after - next).dot(normal) < 0.0 {
                return Some(format!("not convex at vertex {}", (i + 1) % n));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Polygon {
        Polygon::default()
    }

    #[test]
    fn the_default_square_faces_plus_z_and_is_drawable() {
        let p = square();
        assert_eq!(p.normal(), Some(Vec3::Z));
        assert_eq!(p.problem(), None);
        let f = p.frame().unwrap();
        assert_eq!(f.origin, Vec3::new(-1.0, 0.0, -1.0));
        assert_eq!(f.u_axis, Vec3::new(2.0, 0.0, 0.0));
        assert_eq!(f.v_axis, Vec3::new(0.0, 2.0, 0.0));
    }

    #[test]
    fn degenerate_concave_and_warped_polygons_are_refused() {
        let mut p = square();
        p.vertices.truncate(2);
        assert!(p.problem().unwrap().contains("2 vertices"));
        let mut p = square();
        p.vertices[2] = Vec3::new(0.0, 0.5, -1.0);
        assert!(
            p.problem().unwrap().contains("not convex"),
            "{:?}",
            p.problem()
        );
        let mut p = square();
        p.vertices[2].z += 0.5;
        assert!(p.problem().unwrap().contains("off the plane"));
        let mut p = square();
        p.vertices = vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
        assert_eq!(p.problem().as_deref(), Some("no area"));
    }
}
