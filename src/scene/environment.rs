//! What rays that leave the scene see.

use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub enum EnvSource {
    /// Black: no light from infinity.
    #[default]
    None,
    /// The same radiance from every direction (the white-furnace setting).
    Constant { radiance: Vec3 },
    /// A latitude-longitude image (.exr, .hdr, .png, .jpg). A relative path is
    /// relative to the preset file that names it.
    LatLong { path: PathBuf },
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Environment {
    pub source: EnvSource,
    /// Turns the map about the vertical axis, degrees.
    pub rotation_degrees: f32,
    /// Multiplies the radiance.
    pub intensity: f32,
    /// Whether camera rays that miss show the environment (otherwise black);
    /// it lights the scene either way.
    pub background_visible: bool,
}

impl Default for Environment {
    fn default() -> Self {
        Self {
            source: EnvSource::None,
            rotation_degrees: 0.0,
            intensity: 1.0,
            background_visible: true,
        }
    }
}
