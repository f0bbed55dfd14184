//! An orbit camera, as in Blender or a turntable: it looks at a target from a
//! distance, and the mouse turns it around that target.

use glam::{Mat3, Vec3};
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OrbitCamera {
    pub target: Vec3,
    pub distance: f32,
    /// Rotation about the vertical axis, degrees.
    pub yaw_degrees: f32,
    /// Elevation above the horizontal, degrees, kept inside (-89, 89).
    pub pitch_degrees: f32,
    /// Vertical field of view, degrees.
    pub fov_degrees: f32,
    /// How the image is projected: perspective, or orthographic (Massal's
    /// figures). Old presets, which have no such field, are perspective.
    pub projection: Projection,
}

/// How camera rays leave the camera.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Projection {
    /// Every ray leaves the camera's position through its pixel: far
    /// things look smaller.
    #[default]
    Perspective,
    /// Parallel rays along the view direction, each from its pixel's place
    /// on a plane through the camera: size does not change with depth.
    /// The view is as high as the perspective view's at the target,
    /// 2·distance·tan(fov/2), so switching keeps the target's framing and
    /// the distance zooms.
    Orthographic,
}

impl Projection {
    pub const ALL: [Projection; 2] = [Projection::Perspective, Projection::Orthographic];

    pub fn label(self) -> &'static str {
        match self {
            Projection::Perspective => "perspective",
            Projection::Orthographic => "orthographic",
        }
    }
}

impl Default for OrbitCamera {
    fn default() -> Self {
        Self {
            target: Vec3::new(0.0, 0.8, 0.0),
            distance: 9.0,
            yaw_degrees: 0.0,
            pitch_degrees: 15.0,
            fov_degrees: 40.0,
            projection: Projection::Perspective,
        }
    }
}

/// The fraction of the image's half-height (and half-width) a framed box
/// may reach: [`OrbitCamera::framing`] leaves the rest as a margin.
const FRAMING_FILL: f32 = 0.9;

/// A named camera the preset keeps (the lab's saved orbiter): keys 1–9
/// recall the first nine.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SavedView {
    pub name: String,
    pub camera: OrbitCamera,
}

impl Default for SavedView {
    fn default() -> Self {
        Self {
            name: "view".into(),
            camera: OrbitCamera::default(),
        }
    }
}

/// A camera frame: position and the orthonormal basis the shader needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraFrame {
    pub position: Vec3,
    pub right: Vec3,
    pub up: Vec3,
    pub forward: Vec3,
    /// tan(fov/2): the half-height of the image plane at distance 1.
    pub tan_half_fov: f32,
    /// An orthographic view's half-height in scene units (distance ·
    /// tan(fov/2)); 0 for a perspective one.
    pub ortho_half_height: f32,
}

impl CameraFrame {
    /// The camera ray through `ndc` (x right, y up, each -1 to 1 across an
    /// image of width / height `aspect`): its origin and unit direction.
    /// CPU twin of `camera_ray` in shaders/trace.wgsl.
    pub fn ray(&self, ndc: glam::Vec2, aspect: f32) -> (Vec3, Vec3) {
        if self.ortho_half_height > 0.0 {
            let h = self.ortho_half_height;
            let origin = self.position + ndc.x * h * aspect * self.right + ndc.y * h * self.up;
            return (origin, self.forward);
        }
        let d = self.forward
            + ndc.x * self.tan_half_fov * aspect * self.right
            + ndc.y * self.tan_half_fov * self.up;
        (self.position, d.normalize())
    }
}

impl OrbitCamera {
    pub const MIN_DISTANCE: f32 = 0.05;

    pub fn frame(&self) -> CameraFrame {
        let yaw = self.yaw_degrees.to_radians();
        let pitch = self.pitch_degrees.clamp(-89.0, 89.0).to_radians();
        // The camera sits on +z at yaw 0, looking towards -z.
        let rotation = Mat3::from_rotation_y(yaw) * Mat3::from_rotation_x(-pitch);
        let back = rotation * Vec3::Z;
        let forward = -back;
        let right = (rotation * Vec3::X).normalize();
        let up = right.cross(forward).normalize();
        let tan_half_fov = (self.fov_degrees.clamp(1.0, 170.0).to_radians() * 0.5).tan();
        CameraFrame {
            position: self.target + back * self.distance,
            right,
            up,
            forward,
            tan_half_fov,
            ortho_half_height: match self.projection {
                Projection::Perspective => 0.0,
                Projection::Orthographic => self.distance * tan_half_fov,
            },
        }
    }

    /// The camera turned as `self` (yaw, pitch, field of view) that looks
    /// at the centre of the box `lo`..`hi` from the nearest distance at
    /// which all eight corners fall inside the central 90 % of an image of
    /// width / height `aspect` (so the box is whole, centred, with a thin
    /// margin). Each corner gives the distance at which it touches the
    /// image's edge; the farthest of these wins.
    pub fn framing(&self, lo: Vec3, hi: Vec3, aspect: f32) -> OrbitCamera {
        let centre = (lo + hi) * 0.5;
        let half = (hi - lo) * 0.5;
        let f = OrbitCamera {
            target: centre,
            ..*self
        }
        .frame();
        let tan_y = f.tan_half_fov * FRAMING_FILL;
        let tan_x = tan_y * aspect.max(1e-3);
        let mut distance = Self::MIN_DISTANCE;
        for corner in 0..8 {
            let pick = |bit: u32| if corner & (1 << bit) == 0 { -1.0 } else { 1.0 };
            let p = half * Vec3::new(pick(0), pick(1), pick(2));
            // The corner's depth is `distance + p·forward`; it is inside
            // the image when |p·right| ≤ depth·tan_x and |p·up| ≤ depth·tan_y.
            let ahead = p.dot(f.forward);
            let needed = (p.dot(f.right).abs() / tan_x).max(p.dot(f.up).abs() / tan_y) - ahead;
            distance = distance.max(needed);
        }
        OrbitCamera {
            target: centre,
            distance,
            ..*self
        }
    }

    /// Turns the camera by a mouse drag, in degrees.
    pub fn orbit(&mut self, dyaw: f32, dpitch: f32) {
        self.yaw_degrees = (self.yaw_degrees + dyaw).rem_euclid(360.0);
        self.pitch_degrees = (self.pitch_degrees + dpitch).clamp(-89.0, 89.0);
    }

    /// Moves the target in the image plane; `dx`, `dy` are fractions of the
    /// view height, so a drag moves the scene with the mouse.
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let f = self.frame();
        let scale = 2.0 * self.distance * f.tan_half_fov;
        self.target += (-f.right * dx + f.up * dy) * scale;
    }

    /// Zooms by a factor per wheel notch, never through the target.
    pub fn zoom(&mut self, notches: f32) {
        self.distance = (self.distance * 0.9f32.powf(notches)).max(Self::MIN_DISTANCE);
    }

    pub(crate) fn sanitize(&mut self, notes: &mut Vec<String>) {
        let d = Self::default();
        if !self.target.is_finite() {
            notes.push("camera: non-finite target reset".into());
            self.target = d.target;
        }
        if !(self.distance.is_finite() && self.distance >= Self::MIN_DISTANCE) {
            notes.push(format!("camera: distance {} reset", self.distance));
            self.distance = d.distance;
        }
        if !(self.fov_degrees.is_finite() && (1.0..=170.0).contains(&self.fov_degrees)) {
            notes.push(format!(
                "camera: field of view {} clamped",
                self.fov_degrees
            ));
            self.fov_degrees = self.fov_degrees.clamp(1.0, 170.0);
            if !self.fov_degrees.is_finite() {
                self.fov_degrees = d.fov_degrees;
            }
        }
        if !self.yaw_degrees.is_finite() || !self.pitch_degrees.is_finite() {
            notes.push("camera: non-finite angles reset".into());
            self.yaw_degrees = d.yaw_degrees;
            self.pitch_degrees = d.pitch_degrees;
        }
        self.pitch_degrees = self.pitch_degrees.clamp(-89.0, 89.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A perspective ray leaves the camera through its pixel; orthographic
    /// rays run along the view, parallel, from the pixel's place on a
    /// plane through the camera as high as the view at the target.
    #[test]
    fn camera_rays_by_projection() {
        let mut camera = OrbitCamera {
            target: Vec3::ZERO,
            distance: 4.0,
            pitch_degrees: 0.0,
            fov_degrees: 90.0,
            ..OrbitCamera::default()
        };
        let corner = glam::Vec2::new(1.0, 1.0);
        let (o, d) = camera.frame().ray(corner, 2.0);
        assert_eq!(o, Vec3::new(0.0, 0.0, 4.0));
        assert!((d - Vec3::new(2.0, 1.0, -1.0).normalize()).length() < 1e-6);
        camera.projection = Projection::Orthographic;
        let (o, d) = camera.frame().ray(corner, 2.0);
        assert!((o - Vec3::new(8.0, 4.0, 4.0)).length() < 1e-5, "{o}");
        assert!((d - Vec3::NEG_Z).length() < 1e-6);
    }

    #[test]
    fn frame_is_orthonormal_and_looks_at_the_target() {
        let mut c = OrbitCamera::default();
        for (yaw, pitch) in [(0.0, 0.0), (37.0, 20.0), (200.0, -80.0)] {
            c.yaw_degrees = yaw;
            c.pitch_degrees = pitch;
            let f = c.frame();
            assert!((f.forward.length() - 1.0).abs() < 1e-5);
            assert!(f.right.dot(f.forward).abs() < 1e-5);
            assert!(f.up.dot(f.forward).abs() < 1e-5);
            assert!(f.up.y > 0.0, "up points up");
            let to_target = (c.target - f.position).normalize();
            assert!(to_target.dot(f.forward) > 0.9999);
        }
    }
}
