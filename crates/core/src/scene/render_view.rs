//! What each pixel sample records: the lit image, or one of the Monte
//! Carlo lab's first views of the first surface a camera ray meets (its
//! exercises 1 and 2) and the usual debugging views. Every view is traced
//! and accumulated like the lit image, so jittered anti-aliasing averages
//! it over each pixel (a hit mask's edge pixels read their coverage).

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum View {
    /// The radiance: light transport as the transport settings say.
    #[default]
    Lit,
    /// 1 where the camera ray meets a surface, 0 where it escapes
    /// (exercise 1: a white pixel for each visible point).
    HitMask,
    /// One flat colour for each primitive: each sphere, cylinder, polygon,
    /// the ground and each mesh triangle (exercise 2's colour per triangle),
    /// a hash of its kind and index, so the same scene always shows the
    /// same colours.
    Primitive,
    /// The shading normal (bumps included), turned to face the camera,
    /// as 0.5 + 0.5·n.
    Normal,
    /// The diffuse reflectance of the first surface (its textures
    /// evaluated).
    Albedo,
    /// The distance t along the camera ray, as t / (t + d) with d the
    /// camera's distance to its target: 0 at the eye, 0.5 at the target's
    /// distance, 1 where the ray escapes. A depth v reads back as
    /// t = d·v / (1 − v).
    Depth,
}

impl View {
    pub const ALL: [View; 6] = [
        View::Lit,
        View::HitMask,
        View::Primitive,
        View::Normal,
        View::Albedo,
        View::Depth,
    ];

    pub fn label(self) -> &'static str {
        match self {
            View::Lit => "lit",
            View::HitMask => "hit mask",
            View::Primitive => "primitive",
            View::Normal => "normal",
            View::Albedo => "albedo",
            View::Depth => "depth",
        }
    }

    /// The name `marbre render --view` takes.
    pub fn name(self) -> &'static str {
        match self {
            View::Lit => "lit",
            View::HitMask => "hit-mask",
            View::Primitive => "primitive",
            View::Normal => "normal",
            View::Albedo => "albedo",
            View::Depth => "depth",
        }
    }

    /// The number `shaders/view.wgsl` reads.
    pub fn id(self) -> u32 {
        self as u32
    }

    /// Whether the samples are values in [0, 1] rather than radiance: they
    /// are shown as they are, neither exposed nor tone mapped.
    pub fn is_data(self) -> bool {
        self != View::Lit
    }
}

/// The depth view's value for a distance `t` along a camera ray whose
/// target lies `d` away (see [`View::Depth`]); the shader's formula.
pub fn depth_value(t: f32, d: f32) -> f32 {
    t / (t + d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_is_a_half_at_the_target_and_reads_back() {
        assert_eq!(depth_value(4.0, 4.0), 0.5);
        assert_eq!(depth_value(0.0, 4.0), 0.0);
        let v = depth_value(7.0, 2.0);
        assert!((2.0 * v / (1.0 - v) - 7.0).abs() < 1e-5);
    }

    #[test]
    fn ids_follow_the_shader_constants() {
        let ids: Vec<u32> = View::ALL.iter().map(|v| v.id()).collect();
        assert_eq!(ids, [0, 1, 2, 3, 4, 5]);
    }
}
