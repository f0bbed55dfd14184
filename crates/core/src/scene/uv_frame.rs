//! A plane's (u, v) frame, shared by polygons, the ground and texture
//! mappings (ATX3D): a leaf of the scene model that imports none of it.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// The (u, v) frame of a plane: the point at (u, v) is `origin + u·u_axis +
/// v·v_axis`, the axes possibly oblique (the texture report's ATX).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct UvFrame {
    pub origin: Vec3,
    pub u_axis: Vec3,
    pub v_axis: Vec3,
}

impl UvFrame {
    /// Why the frame spans no plane, if it does not: a non-finite
    /// coordinate, or axes that are zero or parallel (the same test as
    /// `texture::plane_uv`'s, which would give (0, 0) everywhere).
    pub fn problem(&self) -> Option<String> {
        if !(self.origin.is_finite() && self.u_axis.is_finite() && self.v_axis.is_finite()) {
            return Some("a non-finite origin or axis".into());
        }
        let (u, v) = (self.u_axis, self.v_axis);
        let (uu, uv, vv) = (u.dot(u), u.dot(v), v.dot(v));
        let det = uu * vv - uv * uv;
        if !(uu > 0.0 && vv > 0.0 && det.is_finite() && det > 1e-12 * uu * vv) {
            return Some(format!("the axes u = {u} and v = {v} are zero or parallel"));
        }
        None
    }
}
