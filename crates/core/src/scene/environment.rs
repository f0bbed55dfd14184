//! What rays that leave the scene see.

use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

use crate::envmap::LdrImages;

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
    /// A cube map from six square face files of one size, in the OpenGL
    /// order +x, -x, +y, -y, +z, -z (see `cubemap` for the orientation of
    /// each face); any format `LatLong` reads, relative paths alike. In RON,
    /// a list: `CubeFaces(faces: ["px.exr", "nx.exr", …])`.
    CubeFaces {
        #[serde(with = "six_paths")]
        faces: [PathBuf; 6],
    },
    /// A cube map laid out in one image as a horizontal cross of 4 x 3
    /// square faces (+y above +z; -x, +z, +x, -z across the middle; -y
    /// below +z).
    CubeCross { path: PathBuf },
}

impl EnvSource {
    /// Whether the source is an image map (lat-long or cube): the renderer
    /// gets a lat-long texture for it (a cube map resampled at load).
    pub fn is_map(&self) -> bool {
        !self.paths().is_empty()
    }

    /// The files the source reads (none for `None` and `Constant`).
    pub fn paths(&self) -> Vec<&PathBuf> {
        match self {
            EnvSource::None | EnvSource::Constant { .. } => Vec::new(),
            EnvSource::LatLong { path } | EnvSource::CubeCross { path } => vec![path],
            EnvSource::CubeFaces { faces } => faces.iter().collect(),
        }
    }

    /// The files the source reads, to rewrite (made relative to a preset
    /// when saved, absolute when loaded).
    pub fn paths_mut(&mut self) -> Vec<&mut PathBuf> {
        match self {
            EnvSource::None | EnvSource::Constant { .. } => Vec::new(),
            EnvSource::LatLong { path } | EnvSource::CubeCross { path } => vec![path],
            EnvSource::CubeFaces { faces } => faces.iter_mut().collect(),
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Environment {
    pub source: EnvSource,
    /// How an 8- or 16-bit map's codes become radiance.
    pub ldr_images: LdrImages,
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
            ldr_images: LdrImages::Srgb,
            rotation_degrees: 0.0,
            intensity: 1.0,
            background_visible: true,
        }
    }
}

/// The six face paths as a list of exactly six (serde writes a fixed-size
/// array as a tuple, which RON spells with parentheses; a list is what
/// people type).
mod six_paths {
    use serde::de::Error as _;
    use serde::{Deserialize, Deserializer, Serializer};
    use std::path::PathBuf;

    pub fn serialize<S: Serializer>(faces: &[PathBuf; 6], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(faces)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[PathBuf; 6], D::Error> {
        let faces = Vec::<PathBuf>::deserialize(d)?;
        let n = faces.len();
        faces
            .try_into()
            .map_err(|_| D::Error::invalid_length(n, &"six face paths: +x, -x, +y, -y, +z, -z"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn old_sources_still_read_and_cube_sources_round_trip() {
        let old: EnvSource = ron::from_str(r#"LatLong(path: "sky.exr")"#).unwrap();
        assert_eq!(
            old,
            EnvSource::LatLong {
                path: "sky.exr".into()
            }
        );
        let faces = EnvSource::CubeFaces {
            faces: ["px.png", "nx.png", "py.png", "ny.png", "pz.png", "nz.png"].map(PathBuf::from),
        };
        let cross = EnvSource::CubeCross {
            path: "cube/cross.exr".into(),
        };
        for source in [faces.clone(), cross.clone()] {
            let text = ron::to_string(&source).unwrap();
            assert_eq!(ron::from_str::<EnvSource>(&text).unwrap(), source, "{text}");
        }
        let read: EnvSource = ron::from_str(r#"CubeCross(path: "c.exr")"#).unwrap();
        let typed: EnvSource = ron::from_str(
            r#"CubeFaces(faces: ["px.png", "nx.png", "py.png", "ny.png", "pz.png", "nz.png"])"#,
        )
        .unwrap();
        assert_eq!(typed, faces);
        let five = ron::from_str::<EnvSource>(r#"CubeFaces(faces: ["a", "b", "c", "d", "e"])"#)
            .unwrap_err()
            .to_string();
        assert!(five.contains("six face paths"), "{five}");
        assert_eq!(
            read,
            EnvSource::CubeCross {
                path: "c.exr".into()
            }
        );
        assert_eq!(faces.paths().len(), 6);
        assert_eq!(faces.paths()[4], &PathBuf::from("pz.png"));
        assert!(faces.is_map() && cross.is_map() && old.is_map());
        assert!(!EnvSource::None.is_map());
        assert!(
            !EnvSource::Constant {
                radiance: Vec3::ONE
            }
            .is_map()
        );
    }
}
