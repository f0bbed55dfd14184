//! A scene made from an OBJ file alone, for opening a mesh in the viewer
//! (Open…, drag and drop, `marbre --obj`) without writing a preset first.
//!
//! The scene holds the mesh as the file places it, with its MTL materials,
//! seen by the orbit camera from the front (the OBJ convention: +y up, the
//! model facing +z; the camera looks along −z, level), framing the mesh's
//! bounding box. A file whose materials emit light (`Ke`, as the Cornell
//! box's ceiling lamp) is lit by them alone, over a black background, as
//! `presets/cornell.ron` is; any other gets a default light: a point light
//! above, right of and in front of the mesh, and a dim grey sky as fill
//! (Blender's grey world), so that nothing opens black.

use crate::obj_loader::{self, LoadedObj, ObjError};
use crate::scene::mesh::Geometry;
use crate::scene::{EnvSource, Mesh, OrbitCamera, PointLight, Scene};
use glam::Vec3;
use std::path::Path;
use std::sync::Arc;

/// A scene opened from an OBJ file, and what the loader and the defaults
/// have to say about it.
#[derive(Debug, Clone)]
pub struct ObjScene {
    pub scene: Scene,
    pub notes: Vec<String>,
    /// The files replaced because they could not be read
    /// ([`LoadedObj::substitutes`]).
    pub substitutes: Vec<std::path::PathBuf>,
}

/// Paths of up to this many bounces: OBJ scenes are often rooms, lit
/// mostly by light that bounced (as `presets/cornell.ron` has it).
const MAX_BOUNCES: u32 = 8;

/// The default light's direction from the mesh's centre (x right, y up,
/// z towards the camera), before normalising.
const LIGHT_DIRECTION: Vec3 = Vec3::new(0.6, 1.0, 0.8);
/// The default light's distance from the centre, in radii of the box's
/// bounding sphere: far enough that its falloff across the mesh is gentle.
const LIGHT_DISTANCE_RADII: f32 = 3.0;
/// The irradiance the default light gives at the mesh's centre, facing it:
/// a white Lambertian surface (albedo 0.8) facing it then has radiance
/// 0.8 · 2 / π ≈ 0.51, bright but far from clipped at the default
/// exposure (3 looked washed out on saturated MTL colours).
const LIGHT_IRRADIANCE: f32 = 2.0;
/// The fill sky's radiance: its irradiance on an upward face, π · 0.1,
/// is about a sixth of the key light's.
const FILL_RADIANCE: f32 = 0.1;

/// Reads the OBJ file at `path` (and its MTL) into a scene framed for an
/// image of width / height `aspect`. Errors name the file and the cause.
pub fn scene_from_obj(path: &Path, aspect: f32) -> Result<ObjScene, ObjError> {
    let loaded = obj_loader::load(path)?;
    Ok(scene_around(path, loaded, aspect))
}

/// The scene around the already loaded OBJ `loaded`, read from `path`.
pub fn scene_around(path: &Path, loaded: LoadedObj, aspect: f32) -> ObjScene {
    let mut notes = loaded.notes;
    let substitutes = loaded.substitutes;
    // The loader never returns a mesh without triangles.
    let (lo, hi) = loaded
        .triangles
        .bounds()
        .unwrap_or((Vec3::ZERO, Vec3::ZERO));
    let name = path
        .file_stem()
        .map_or_else(|| "mesh".to_owned(), |s| s.to_string_lossy().into_owned());
    let emits = loaded.materials.iter().any(|m| m.material.has_emission());
    let mut scene = Scene {
        camera: OrbitCamera {
            yaw_degrees: 0.0,
            pitch_degrees: 0.0,
            ..OrbitCamera::default()
        }
        .framing(lo, hi, aspect),
        meshes: vec![Mesh {
            name,
            obj: path.to_owned(),
            materials: loaded.materials,
            geometry: Geometry(Arc::new(loaded.triangles)),
            ..Mesh::default()
        }],
        ..Scene::default()
    };
    scene.render.max_bounces = MAX_BOUNCES;
    if !emits {
        let centre = (lo + hi) * 0.5;
        let radius = ((hi - lo) * 0.5).length().max(1e-3);
        let distance = LIGHT_DISTANCE_RADII * radius;
        scene.point_light = Some(PointLight {
            position: centre + LIGHT_DIRECTION.normalize() * distance,
            color: Vec3::ONE,
            intensity: LIGHT_IRRADIANCE * distance * distance,
        });
        scene.environment.source = EnvSource::Constant {
            radiance: Vec3::splat(FILL_RADIANCE),
        };
        notes.push(format!(
            "{}: no material emits light: a default point light and a grey sky were added",
            path.display()
        ));
    }
    ObjScene {
        scene,
        notes,
        substitutes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Texture;

    fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> std::path::PathBuf {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    /// A unit cube from (1, 2, 3) to (3, 5, 4) (not at the origin, not
    /// cubic, so a framing that ignored the centre or an axis would show),
    /// with the MTL material `clay` (Kd 0.2 0.4 0.6).
    fn cube(dir: &tempfile::TempDir, mtl: &str) -> std::path::PathBuf {
        write(dir, "cube.mtl", mtl);
        let mut obj = String::from("mtllib cube.mtl\nusemtl clay\n");
        for z in [3.0, 4.0] {
            for y in [2.0, 5.0] {
                for x in [1.0, 3.0] {
                    obj += &format!("v {x} {y} {z}\n");
                }
            }
        }
        // Vertices: index = 1 + x_bit + 2·y_bit + 4·z_bit.
        obj += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
        write(dir, "cube.obj", &obj)
    }

    /// The eight corners of the box, projected with the camera as the
    /// shader casts rays (x scaled by tan(fov/2)·aspect, y by tan(fov/2)):
    /// normalised image coordinates, and the depth in front of the camera.
    fn project(camera: &OrbitCamera, aspect: f32, lo: Vec3, hi: Vec3) -> Vec<(f32, f32, f32)> {
        let f = camera.frame();
        (0..8)
            .map(|k| {
                let corner = Vec3::new(
                    if k & 1 == 0 { lo.x } else { hi.x },
                    if k & 2 == 0 { lo.y } else { hi.y },
                    if k & 4 == 0 { lo.z } else { hi.z },
                );
                let v = corner - f.position;
                let depth = v.dot(f.forward);
                let x = v.dot(f.right) / (depth * f.tan_half_fov * aspect);
                let y = v.dot(f.up) / (depth * f.tan_half_fov);
                (x, y, depth)
            })
            .collect()
    }

    #[test]
    fn a_cube_without_emitter_is_framed_and_gets_a_default_light() {
        let dir = tempfile::tempdir().unwrap();
        let path = cube(&dir, "newmtl clay\nKd 0.2 0.4 0.6\n");
        let (lo, hi) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(3.0, 5.0, 4.0));
        for aspect in [0.5, 1.0, 16.0 / 9.0] {
            let opened = scene_from_obj(&path, aspect).unwrap();
            let camera = opened.scene.camera;
            assert_eq!(camera.target, (lo + hi) * 0.5, "centred on the box");
            let corners = project(&camera, aspect, lo, hi);
            for &(x, y, depth) in &corners {
                assert!(depth > 0.0, "{corners:?}");
                assert!(
                    x.abs() <= 1.0 && y.abs() <= 1.0,
                    "aspect {aspect}: {corners:?}"
                );
            }
            // A sensible distance: the box fills most of the image along
            // its tighter axis rather than being a speck.
            let reach = corners
                .iter()
                .map(|&(x, y, _)| x.abs().max(y.abs()))
                .fold(0.0, f32::max);
            assert!(reach > 0.85, "aspect {aspect}: reach {reach}");
        }
        let scene = scene_from_obj(&path, 1.0).unwrap().scene;
        let light = scene.point_light.expect("a default light");
        assert!(light.intensity > 0.0 && light.position.is_finite());
        // The light is outside the box, above it.
        assert!(light.position.y > hi.y, "{light:?}");
        assert!(
            matches!(scene.environment.source, EnvSource::Constant { radiance } if radiance.min_element() > 0.0)
        );
    }

    #[test]
    fn the_mtl_materials_arrive() {
        let dir = tempfile::tempdir().unwrap();
        let path = cube(&dir, "newmtl clay\nKd 0.2 0.4 0.6\n");
        let scene = scene_from_obj(&path, 1.0).unwrap().scene;
        let mesh = &scene.meshes[0];
        assert_eq!(mesh.name, "cube");
        assert_eq!(mesh.obj, path);
        assert_eq!(mesh.geometry.0.len(), 12, "six quads, two triangles each");
        let clay = mesh.materials.iter().find(|m| m.name == "clay").unwrap();
        assert_eq!(
            clay.material.diffuse,
            Texture::color(Vec3::new(0.2, 0.4, 0.6))
        );
        assert!(!clay.is_override(), "nothing to write into a preset yet");
    }

    #[test]
    fn an_emitting_material_means_no_extra_light() {
        let dir = tempfile::tempdir().unwrap();
        let path = cube(&dir, "newmtl clay\nKd 0.2 0.4 0.6\nKe 5 5 5\n");
        let scene = scene_from_obj(&path, 1.0).unwrap().scene;
        assert_eq!(scene.point_light, None);
        assert_eq!(scene.environment.source, EnvSource::None);
    }

    /// The lab's Cornell box opens as `presets/cornell.ron` shows it: its
    /// `Ke` lamp alone, seen from the front, level, at about the preset's
    /// distance (3.9).
    #[test]
    fn the_cornell_box_opens_like_its_preset() {
        let path =
            Path::new(crate::REPO).join("presets/scenes/cornell-box/CornellBox-Original.obj");
        let opened = scene_from_obj(&path, 16.0 / 9.0).unwrap();
        assert!(opened.notes.is_empty(), "{:?}", opened.notes);
        let scene = opened.scene;
        assert_eq!(scene.point_light, None);
        assert_eq!(scene.meshes[0].materials.len(), 8);
        let camera = scene.camera;
        assert_eq!((camera.yaw_degrees, camera.pitch_degrees), (0.0, 0.0));
        assert!((camera.target - Vec3::new(0.0, 1.0, 0.0)).length() < 0.05);
        assert!((3.6..4.4).contains(&camera.distance), "{camera:?}");
    }

    #[test]
    fn a_broken_obj_gives_an_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = write(&dir, "broken.obj", "v 0 0 0\nv 1 0 0\nf 1 2 x\n");
        let e = scene_from_obj(&path, 1.0).unwrap_err().to_string();
        assert!(e.contains("broken.obj:3") && e.contains("`f 1 2 x`"), "{e}");
        let e = scene_from_obj(&dir.path().join("gone.obj"), 1.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("gone.obj") && e.contains("cannot read"), "{e}");
    }
}
