//! What `marbre tx` makes of its files, short of rendering: the report's
//! preview scene wearing a TX text, and the `gallery.ron` index of a folder
//! of examples. Here in core, beside `tx` (which holds the language), so
//! that the command and the fuzz targets read the same way.

use crate::scene::{
    Cylinder, EnvSource, Ground, Material, OrbitCamera, PointLight, Polygon, Scene, Sphere,
    Texture, ToneMap,
};
use crate::tx;
use glam::Vec3;
use serde::Deserialize;
use std::path::{Component, Path};

/// The neutral material the text is applied onto: a light grey, slightly
/// glossy dielectric.
pub fn neutral_material() -> Material {
    Material {
        diffuse: Texture::color(Vec3::splat(0.6)),
        specular: Texture::color(Vec3::splat(0.04)),
        roughness: Texture::scalar(0.45),
        ..Material::default()
    }
}

/// The report's preview: a square polygon standing behind (its default
/// frame: (u, v) spanning it from its first vertex), a sphere and a
/// cylinder in front, on a grey ground, all wearing the lowered material
/// (the ground too when the text gives a plane frame, APTX: without one
/// N3D ignores a plane's texture). Images resolve against `base_dir`.
pub fn preview_scene(doc: &tx::Document, base_dir: &Path) -> Result<Scene, tx::TxError> {
    let lowered = tx::lower_document(doc, &neutral_material(), base_dir)?;
    let m = lowered.material;
    let mut scene = Scene {
        camera: OrbitCamera {
            target: Vec3::new(0.0, 1.0, 0.0),
            distance: 6.2,
            yaw_degrees: 0.0,
            pitch_degrees: 12.0,
            fov_degrees: 40.0,
            ..Default::default()
        },
        spheres: vec![Sphere {
            name: "sphere".into(),
            center: Vec3::new(-1.05, 0.55, 0.7),
            radius: 0.55,
            material: m.clone(),
        }],
        cylinders: vec![Cylinder {
            name: "cylinder".into(),
            base: Vec3::new(1.05, 0.0, 0.7),
            radius: 0.45,
            height: 1.1,
            material: m.clone(),
        }],
        polygons: vec![Polygon {
            name: "polygon".into(),
            vertices: vec![
                Vec3::new(-1.4, 0.0, -1.2),
                Vec3::new(1.4, 0.0, -1.2),
                Vec3::new(1.4, 2.8, -1.2),
                Vec3::new(-1.4, 2.8, -1.2),
            ],
            uv_frame: lowered.polygon_frame,
            material: m.clone(),
        }],
        ground: Some(Ground {
            height: 0.0,
            uv_frame: lowered.plane_frame,
            material: if lowered.plane_frame.is_some() {
                m
            } else {
                Material {
                    diffuse: Texture::color(Vec3::splat(0.35)),
                    ..neutral_material()
                }
            },
        }),
        point_light: Some(PointLight {
            position: Vec3::new(2.5, 5.0, 4.0),
            color: Vec3::ONE,
            intensity: 25.0,
        }),
        ..Scene::default()
    };
    scene.environment.source = EnvSource::Constant {
        radiance: Vec3::splat(0.5),
    };
    // The course display: no tone curve, so that a colour the text types
    // shows as typed where the polygon is lit about evenly (ACES showed
    // BOIS's FONCE 0.54 0.27 0.074 as 0.48 0.21 0.09).
    scene.render.display.tone_map = ToneMap::Clamp;
    Ok(scene)
}

/// One example of a gallery: its TX file, a title, and what the report
/// says of it.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct GalleryEntry {
    /// The TX file, relative to the gallery's folder; its PNG takes the
    /// same relative name in the output folder.
    pub file: String,
    pub title: String,
    pub description: String,
}

/// Why a `gallery.ron` cannot be used (the caller names the file).
#[derive(Debug, thiserror::Error)]
pub enum GalleryError {
    #[error("{0}")]
    Syntax(#[from] ron::error::SpannedError),
    #[error(
        "entry {number} (`{file}`): the file must be a relative path inside the gallery's folder"
    )]
    OutsideFolder { number: usize, file: String },
}

/// The entries of a `gallery.ron` (a list of `(file, title, description)`),
/// in order. A file that is empty, absolute or climbs out with `..` is
/// refused: the command reads it from the gallery's folder and writes its
/// PNG under the same relative name in the output folder, which such a
/// name would leave.
pub fn parse_gallery(text: &str) -> Result<Vec<GalleryEntry>, GalleryError> {
    let entries: Vec<GalleryEntry> = ron::from_str(text)?;
    let inside = |file: &str| {
        let path = Path::new(file);
        path.components().next().is_some()
            && path
                .components()
                .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
            && path.file_name().is_some()
    };
    match entries.iter().position(|e| !inside(&e.file)) {
        Some(i) => Err(GalleryError::OutsideFolder {
            number: i + 1,
            file: entries[i].file.clone(),
        }),
        None => Ok(entries),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The report's ATX example typed literally (u = (1, 0, 0), v = (1, 0,
    /// 1), axes of its horizontal polygon) spans one line of the upright
    /// preview polygon: the scene's notes, which `marbre tx` prints, warn
    /// of it; the shipped example, whose axes lie in the polygon's plane,
    /// draws no warning.
    #[test]
    fn the_literal_atx_example_warns_that_its_frame_is_flat_on_the_preview_polygon() {
        let notes = |text: &str| {
            let doc = tx::parse(text).unwrap();
            preview_scene(&doc, Path::new("")).unwrap().sanitize()
        };
        let quad = "TX QUAD UNI CD 0.8 0 0 FTX UNI CD 0 0 0.8 FTX GU 0.25 GV 0.25 FTX";
        let literal = notes(&format!("ATX 0 0 0 1 0 0 1 0 1 FATX {quad}"));
        assert!(
            literal
                .iter()
                .any(|n| n.contains("polygon `polygon`: warning") && n.contains("one colour")),
            "{literal:?}"
        );
        let shipped = notes(&format!("ATX -1.4 0 -1.2 2.8 0 0 2.8 2.8 0 FATX {quad}"));
        assert!(shipped.is_empty(), "{shipped:?}");
    }

    #[test]
    fn gallery_entries_read_in_order() {
        let text = r#"[
            (file: "uni.tx", title: "UNI", description: "A red surface."),
            (file: "sub/quad.tx", title: "QUAD", description: "A checker."),
        ]"#;
        let entries = parse_gallery(text).unwrap();
        let files: Vec<&str> = entries.iter().map(|e| e.file.as_str()).collect();
        assert_eq!(files, ["uni.tx", "sub/quad.tx"]);
        assert_eq!(entries[1].title, "QUAD");
        assert_eq!(entries[1].description, "A checker.");
    }

    /// The PNG of `/tmp/x.tx` would be written to `/tmp/x.png`, whatever
    /// the output folder: such names are refused, by their entry's number.
    #[test]
    fn gallery_files_outside_the_folder_are_refused() {
        for file in ["/tmp/x.tx", "../x.tx", "a/../../x.tx", "", ".", "a/.."] {
            let text = format!(
                r#"[(file: "uni.tx", title: "", description: ""), (file: "{file}", title: "", description: "")]"#
            );
            match parse_gallery(&text) {
                Err(GalleryError::OutsideFolder { number: 2, file: f }) => assert_eq!(f, file),
                other => panic!("{file:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn a_malformed_gallery_says_where() {
        let e = parse_gallery("[(file: \"uni.tx\", title: 1)]").unwrap_err();
        assert!(e.to_string().starts_with("1:"), "{e}");
    }

    /// The preview wears the text on every object; the ground only with
    /// a plane frame (APTX).
    #[test]
    fn the_preview_wears_the_text() {
        let doc = tx::parse("TX UNI CD 1 0 0 FTX").unwrap();
        let scene = preview_scene(&doc, Path::new("/presets")).unwrap();
        let red = tx::lower_document(&doc, &neutral_material(), Path::new("/presets"))
            .unwrap()
            .material;
        assert_eq!(scene.spheres[0].material, red);
        assert_eq!(scene.cylinders[0].material, red);
        assert_eq!(scene.polygons[0].material, red);
        assert_ne!(scene.ground.as_ref().unwrap().material, red);
    }
}
