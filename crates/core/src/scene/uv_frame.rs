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

    /// Why the frame, sound in space, spans nothing on a plane of unit
    /// normal `normal`, if it does not: its axes project there onto one
    /// line, so every point of the plane gets the same (u, v) and the
    /// texture shows one colour (the report's ATX u = (1, 0, 0), v = (1, 0,
    /// 1) on an upright polygon).
    pub fn problem_on_plane(&self, normal: Vec3) -> Option<String> {
        let flat = |a: Vec3| a - a.dot(normal) * normal;
        let on_plane = UvFrame {
            u_axis: flat(self.u_axis),
            v_axis: flat(self.v_axis),
            ..*self
        };
        on_plane.problem()?;
        Some(format!(
            "its frame's axes u = {} and v = {} lie along one line on its plane (normal {normal}), \
             so (u, v) does not vary there and the texture shows one colour; give axes in the \
             polygon's plane",
            self.u_axis, self.v_axis
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The report's literal ATX vectors span the ground's plane but only one
    /// line of an upright polygon's.
    #[test]
    fn a_frame_flat_on_the_ground_is_degenerate_on_an_upright_plane() {
        let frame = UvFrame {
            origin: Vec3::ZERO,
            u_axis: Vec3::new(1.0, 0.0, 0.0),
            v_axis: Vec3::new(1.0, 0.0, 1.0),
        };
        assert_eq!(frame.problem(), None);
        assert_eq!(frame.problem_on_plane(Vec3::Y), None);
        let problem = frame
            .problem_on_plane(Vec3::Z)
            .expect("degenerate on z = const");
        assert!(problem.contains("one colour"), "{problem}");
    }
}
