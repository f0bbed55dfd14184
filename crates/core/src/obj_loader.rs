//! OBJ/MTL files into triangle meshes and materials, through `tobj`.
//!
//! MTL keys map onto the material model as the lab reads them: `Kd`
//! diffuse, `Ks` specular, `Ns` roughness (see [`roughness_from_ns`]),
//! `Ke` emission, `d` or `Tr` opacity, `Tf` transmission (`Kd` when a
//! see-through material has none, so it tints by its colour), `map_Kd` and
//! `map_Ks` image textures, `map_bump`/`bump` a bump height image. Texture
//! paths are relative to the .mtl file; a missing one keeps the magenta
//! placeholder of image textures and a note naming it.

use crate::capped_read::{self, read_capped};
use crate::obj_syntax;
use crate::scene::mesh::{Geometry, MeshMaterial, TriangleMesh};
use crate::scene::{Material, Pattern, Scene, Texture};
use crate::shown::shown;
use crate::texture::{ColorSpace, ImageSource};
use glam::{Vec2, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Debug, thiserror::Error)]
pub enum ObjError {
    #[error("{path}: cannot read the OBJ file: {cause}")]
    Read {
        path: PathBuf,
        cause: std::io::Error,
    },
    #[error("{path}:{line}: {why}: `{statement}`")]
    Syntax {
        path: PathBuf,
        line: usize,
        statement: String,
        why: String,
    },
    #[error("{path}: not a valid OBJ file: {cause}")]
    Parse {
        path: PathBuf,
        cause: tobj::LoadError,
    },
    #[error("{path}: the OBJ reader failed on this file (a malformed statement it does not check)")]
    Crashed { path: PathBuf },
    #[error("{path}: no triangle left to draw ({reason})")]
    Empty { path: PathBuf, reason: String },
    #[error("{path}: not a text file ({what}); an OBJ file is text (`v`, `vt`, `f` lines)")]
    NotText { path: PathBuf, what: &'static str },
}

/// An OBJ file's triangles (in the file's coordinates) and materials.
#[derive(Debug, Clone, Default)]
pub struct LoadedObj {
    pub triangles: TriangleMesh,
    pub materials: Vec<MeshMaterial>,
    /// What was skipped or replaced, each naming the file.
    pub notes: Vec<String>,
    /// The files that could not be read and were replaced (a material
    /// library, by grey): a note says why.
    pub substitutes: Vec<PathBuf>,
}

/// The material of faces the OBJ gives none, or whose MTL is unreadable.
const DEFAULT_MATERIAL: &str = "(default)";

pub fn load(path: &Path) -> Result<LoadedObj, ObjError> {
    let bytes = read_capped(path, capped_read::OBJ).map_err(|cause| ObjError::Read {
        path: path.to_owned(),
        cause,
    })?;
    parse_bytes(&bytes, path, |library| {
        read_capped(library, capped_read::MTL)
    })
}

/// Reads the bytes of an OBJ file. `path` names it in messages, and its
/// folder resolves the material libraries (whose bytes `read_library`
/// returns: the file system for [`load`], memory for the fuzz target and
/// its regression tests) and their textures.
pub fn parse_bytes(
    bytes: &[u8],
    path: &Path,
    read_library: impl Fn(&Path) -> std::io::Result<Vec<u8>>,
) -> Result<LoadedObj, ObjError> {
    if let Some(what) = binary_kind(bytes) {
        return Err(ObjError::NotText {
            path: path.to_owned(),
            what,
        });
    }
    let text = String::from_utf8_lossy(bytes);
    // tobj says what is wrong but not where, and panics on some malformed
    // statements: the syntax check runs first and names the line.
    if let Some(bad) = obj_syntax::first_bad_obj_line(&text) {
        return Err(ObjError::Syntax {
            path: path.to_owned(),
            line: bad.line,
            statement: shown(&bad.statement),
            why: bad.why,
        });
    }
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mtl_folder = path.parent().unwrap_or(Path::new("."));
    // Why the library failed, where tobj's error alone would not say.
    let library_problem = std::cell::RefCell::new(None);
    let load_library = |name: &Path| {
        let mtl = mtl_folder.join(name);
        let text = match read_library(&mtl) {
            Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
            Err(e) => {
                *library_problem.borrow_mut() = Some((
                    mtl.clone(),
                    format!(
                        "its material library {} cannot be read: {e}",
                        shown(&mtl.display().to_string())
                    ),
                ));
                return Err(tobj::LoadError::OpenFileFailed);
            }
        };
        if let Some((line, statement)) = obj_syntax::first_bad_mtl_line(&text) {
            *library_problem.borrow_mut() = Some((
                mtl.clone(),
                format!(
                    "its material library {}:{line} cannot be read: `{}`",
                    shown(&mtl.display().to_string()),
                    shown(&statement)
                ),
            ));
            return Err(tobj::LoadError::MaterialParseError);
        }
        tobj::load_mtl_buf(&mut text.as_bytes())
    };
    let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut text.as_bytes(), &options, load_library)
    }))
    .map_err(|_| ObjError::Crashed {
        path: path.to_owned(),
    })?;
    let (models, materials) = parsed.map_err(|cause| ObjError::Parse {
        path: path.to_owned(),
        cause,
    })?;
    let mut notes = Vec::new();
    let mut substitutes = Vec::new();
    let mtl = match materials {
        Ok(m) => m,
        Err(e) => {
            let (library, why) = library_problem.into_inner().unwrap_or_else(|| {
                (
                    path.to_owned(),
                    format!("its material library cannot be read ({e})"),
                )
            });
            notes.push(format!("{}: {why}; grey is used instead", path.display()));
            substitutes.push(library);
            Vec::new()
        }
    };
    // A library that failed has its own note; else each `usemtl` naming
    // none of its materials gets one (tobj gives such faces no material).
    if substitutes.is_empty() {
        for (line, name) in undefined_materials(&text, &mtl) {
            notes.push(format!(
                "{}:{line}: `usemtl {}` names no material of its library; grey is used",
                path.display(),
                shown(name)
            ));
        }
    }
    let mut out = LoadedObj {
        substitutes,
        ..LoadedObj::default()
    };
    for m in &mtl {
        let (material, material_notes) = convert_material(m, mtl_folder);
        notes.extend(
            material_notes
                .into_iter()
                .map(|n| format!("{}: material `{}`: {n}", path.display(), shown(&m.name))),
        );
        out.materials.push(MeshMaterial {
            name: m.name.clone(),
            from_file: Some(material.clone()),
            material,
        });
    }
    let mut default_index = None;
    let mut non_finite = 0usize;
    let mut degenerate = 0usize;
    for model in &models {
        let mesh = &model.mesh;
        let material = match mesh.material_id.filter(|&i| i < out.materials.len()) {
            Some(i) => i as u32,
            None => *default_index.get_or_insert_with(|| {
                out.materials.push(MeshMaterial {
                    name: DEFAULT_MATERIAL.into(),
                    from_file: Some(Material::default()),
                    material: Material::default(),
                });
                (out.materials.len() - 1) as u32
            }),
        };
        let position = |i: u32| {
            let i = i as usize * 3;
            Vec3::new(
                mesh.positions[i],
                mesh.positions[i + 1],
                mesh.positions[i + 2],
            )
        };
        let uv = |i: u32| {
            let i = i as usize * 2;
            if mesh.texcoords.len() >= i + 2 {
                Vec2::new(mesh.texcoords[i], mesh.texcoords[i + 1])
            } else {
                Vec2::ZERO
            }
        };
        for face in mesh.indices.chunks_exact(3) {
            let v = [position(face[0]), position(face[1]), position(face[2])];
            if !v.iter().all(|p| p.is_finite()) {
                non_finite += 1;
                continue;
            }
            if (v[1] - v[0]).cross(v[2] - v[0]).length_squared() == 0.0 {
                degenerate += 1;
            }
            out.triangles.positions.push(v);
            out.triangles
                .uvs
                .push([uv(face[0]), uv(face[1]), uv(face[2])]);
            out.triangles.materials.push(material);
        }
    }
    if non_finite > 0 {
        notes.push(format!(
            "{}: {non_finite} triangles with a NaN or infinite vertex were dropped",
            path.display()
        ));
    }
    if degenerate > 0 {
        notes.push(format!(
            "{}: {degenerate} triangles have zero area (kept: rays never hit them, and they give no light)",
            path.display()
        ));
    }
    if out.triangles.is_empty() {
        return Err(ObjError::Empty {
            path: path.to_owned(),
            reason: if non_finite > 0 {
                "every triangle has a non-finite vertex".into()
            } else {
                "the file has no faces".into()
            },
        });
    }
    out.notes = notes;
    Ok(out)
}

/// GGX roughness from a Phong exponent: the Beckmann match α = √(2/(Ns+2))
/// (Walter et al. 2007), read as GGX α, with roughness = √α.
pub fn roughness_from_ns(ns: f32) -> f32 {
    let alpha = (2.0 / (ns.max(0.0) + 2.0)).sqrt();
    alpha.sqrt().clamp(0.0, 1.0)
}

/// The MTL colour `key` (`default` when absent): one with a component that
/// is not finite is replaced by `default`, one outside 0 to `max` (no upper
/// bound for `None`) clamped, each with a note, so that nothing an MTL
/// says is changed without a word.
fn checked_color(
    key: &str,
    value: Option<[f32; 3]>,
    default: Vec3,
    max: Option<f32>,
    notes: &mut Vec<String>,
) -> Vec3 {
    let Some(c) = value.map(Vec3::from_array) else {
        return default;
    };
    if !c.is_finite() {
        notes.push(format!(
            "`{key} {} {} {}` is not finite; {} {} {} is used",
            c.x, c.y, c.z, default.x, default.y, default.z
        ));
        return default;
    }
    let clamped = c.clamp(Vec3::ZERO, Vec3::splat(max.unwrap_or(f32::MAX)));
    if clamped != c {
        let range = max.map_or("at least 0".to_owned(), |m| format!("0 to {m}"));
        notes.push(format!(
            "`{key} {} {} {}` is outside {range}; {} {} {} is used",
            c.x, c.y, c.z, clamped.x, clamped.y, clamped.z
        ));
    }
    clamped
}

/// An image texture of `file` (relative to the MTL's folder), scaled by
/// the grey level of `tint` (a colour tint has no node; its mean stands in).
fn image_texture(
    file: &str,
    folder: &Path,
    color_space: ColorSpace,
    tint: Vec3,
    notes: &mut Vec<String>,
) -> Texture {
    let (file, _) = strip_options(file);
    let path = folder.join(file);
    if !crate::capped_read::is_file(&path) {
        notes.push(format!(
            "texture {} not found: shown as the magenta placeholder",
            shown(&path.display().to_string())
        ));
    }
    let mut t = Texture::blend(
        Pattern::Image {
            filter: Default::default(),
            wrap: Default::default(),
        },
        0.0,
        1.0,
    );
    t.image = Some(ImageSource { path, color_space });
    let scale = tint.element_sum() / 3.0;
    if tint.max_element() - tint.min_element() > 1e-3 {
        notes.push(format!(
            "colour {tint} times its texture: only its mean {scale:.3} is applied"
        ));
    }
    if scale != 1.0 {
        t.ops.push(crate::scene::MathOp::Scale(scale));
    }
    t
}

/// MTL texture statements may carry options before the file name
/// (`-bm 0.5 bumps.png`): the file name, and `-bm`'s value if any.
fn strip_options(statement: &str) -> (&str, Option<f32>) {
    let words: Vec<&str> = statement.split_whitespace().collect();
    let mut bump_multiplier = None;
    let mut i = 0;
    while i < words.len() && words[i].starts_with('-') && i + 1 < words.len() {
        if words[i] == "-bm" {
            bump_multiplier = words[i + 1].parse().ok();
        }
        // Every MTL option takes one value except -o/-s/-t (three) and
        // -mm (two); only the common ones matter here.
        i += match words[i] {
            "-o" | "-s" | "-t" => 4,
            "-mm" => 3,
            _ => 2,
        };
    }
    let file = words.get(i..).map_or("", |rest| {
        let start = rest.first().map_or(statement.len(), |first| {
            statement.find(first).unwrap_or(statement.len())
        });
        statement[start..].trim()
    });
    (file, bump_multiplier)
}

/// What binary file `bytes` look like, if they are not text: an image
/// renamed `.obj` gave tobj's "face parse error" with no line.
fn binary_kind(bytes: &[u8]) -> Option<&'static str> {
    const MAGIC: [(&[u8], &str); 4] = [
        (b"\x89PNG", "a PNG image"),
        (b"\xff\xd8\xff", "a JPEG image"),
        (b"\x76\x2f\x31\x01", "an EXR image"),
        (b"PK\x03\x04", "a ZIP archive"),
    ];
    let head = &bytes[..bytes.len().min(4096)];
    MAGIC
        .iter()
        .find(|(magic, _)| bytes.starts_with(magic))
        .map(|&(_, what)| what)
        .or_else(|| head.contains(&0).then_some("it holds NUL bytes"))
}

/// The `usemtl` statements of `text` naming none of `materials`: their
/// line and the name, the first use of each name only.
fn undefined_materials<'t>(text: &'t str, materials: &[tobj::Material]) -> Vec<(usize, &'t str)> {
    let mut seen = std::collections::HashSet::new();
    text.lines()
        .enumerate()
        .filter_map(|(i, line)| {
            let (key, name) = line.trim().split_once(char::is_whitespace)?;
            let name = name.trim();
            if key != "usemtl" {
                return None;
            }
            let undefined = !name.is_empty() && !materials.iter().any(|m| m.name == name);
            (undefined && seen.insert(name)).then_some((i + 1, name))
        })
        .collect()
}

/// One MTL material as a marbre material, and notes on what was replaced.
pub fn convert_material(m: &tobj::Material, folder: &Path) -> (Material, Vec<String>) {
    let mut notes = Vec::new();
    let kd = checked_color("Kd", m.diffuse, Vec3::splat(0.8), Some(1.0), &mut notes);
    let ks = checked_color("Ks", m.specular, Vec3::ZERO, Some(1.0), &mut notes);
    // No upper bound: the emission's brightness goes into its strength.
    let ke = checked_color("Ke", m.emissive, Vec3::ZERO, None, &mut notes);
    let params: HashMap<&str, &str> = m
        .unknown_param
        .iter()
        .map(|(k, v)| (k.as_str(), v.as_str()))
        .collect();
    let (dissolve_key, dissolve) = match m.dissolve {
        Some(d) => ("d", Some(d)),
        None => (
            "Tr",
            params
                .get("Tr")
                .and_then(|t| t.parse::<f32>().ok())
                .map(|tr| 1.0 - tr),
        ),
    };
    let opacity = match dissolve {
        None => 1.0,
        Some(d) if !d.is_finite() => {
            notes.push(format!(
                "`{dissolve_key}` is not a finite number; opaque is used"
            ));
            1.0
        }
        Some(d) if !(0.0..=1.0).contains(&d) => {
            notes.push(format!(
                "`{dissolve_key}` gives an opacity of {d}, outside 0 to 1; {} is used",
                d.clamp(0.0, 1.0)
            ));
            d.clamp(0.0, 1.0)
        }
        Some(d) => d,
    };
    let tf = params.get("Tf").and_then(|t| {
        let v: Vec<f32> = t
            .split_whitespace()
            .filter_map(|x| x.parse().ok())
            .collect();
        match v.as_slice() {
            [g] => Some([*g; 3]),
            [r, g, b, ..] => Some([*r, *g, *b]),
            _ => None,
        }
    });
    let transmission = checked_color(
        "Tf",
        tf,
        if opacity < 1.0 { kd } else { Vec3::ONE },
        Some(1.0),
        &mut notes,
    );
    let mut material = Material {
        diffuse: Texture::color(kd),
        specular: Texture::color(ks),
        roughness: Texture::scalar(m.shininess.map_or(1.0, roughness_from_ns)),
        mirror: Texture::scalar(0.0),
        opacity: Texture::scalar(opacity),
        transmission: Texture::color(transmission),
        // Colours stay within [0, 1] (the panel's colour editor): the
        // emission's brightness goes into its strength.
        emission: Texture::color(ke / ke.max_element().max(1.0)),
        emission_strength: ke.max_element().max(1.0),
        ..Material::default()
    };
    if let Some(file) = &m.diffuse_texture {
        material.diffuse = image_texture(file, folder, ColorSpace::Srgb, kd, &mut notes);
    }
    if let Some(file) = &m.specular_texture {
        material.specular = image_texture(file, folder, ColorSpace::Srgb, ks, &mut notes);
    }
    if let Some(statement) = &m.normal_texture {
        let (_, multiplier) = strip_options(statement);
        material.bump = image_texture(statement, folder, ColorSpace::Linear, Vec3::ONE, &mut notes);
        // Heights in [0, 1] over a hundredth of a unit: a visible relief on
        // objects a few units across, as most OBJ scenes are.
        material.bump_height = 0.01 * multiplier.unwrap_or(1.0);
    }
    (material, notes)
}

/// Reads every mesh's OBJ file into the scene: its triangles and its
/// materials, with the preset's overrides kept (matched by name). A
/// preset override naming no MTL material is kept too, with a note.
/// Returns the files replaced because they could not be read
/// ([`LoadedObj::substitutes`]).
pub fn load_meshes(scene: &mut Scene, notes: &mut Vec<String>) -> Result<Vec<PathBuf>, ObjError> {
    let mut substitutes = Vec::new();
    for mesh in &mut scene.meshes {
        let loaded = load(&mesh.obj)?;
        notes.extend(loaded.notes);
        substitutes.extend(loaded.substitutes);
        let overrides = std::mem::take(&mut mesh.materials);
        let mut materials = loaded.materials;
        for o in overrides {
            match materials.iter_mut().find(|m| m.name == o.name) {
                Some(m) => m.material = o.material,
                None => {
                    notes.push(format!(
                        "mesh `{}`: the preset's material `{}` is not in {}",
                        mesh.name,
                        o.name,
                        mesh.obj.display()
                    ));
                    materials.push(o);
                }
            }
        }
        mesh.materials = materials;
        mesh.geometry = Geometry(Arc::new(loaded.triangles));
    }
    Ok(substitutes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Mesh, Property};

    /// Names from the file (a library, a material, a texture) reach the
    /// notes with their control characters escaped: an OBJ cannot drive
    /// the terminal that prints them.
    #[test]
    fn control_characters_from_the_file_are_escaped_in_notes() {
        let dir = tempfile::tempdir().unwrap();
        let obj = write(
            &dir,
            "e.obj",
            &format!("mtllib \u{1b}[2Jx.mtl\n{QUAD}usemtl \u{1b}[31m\nf 1 2 3\n"),
        );
        let notes = load(&obj).unwrap().notes;
        assert!(!notes.is_empty());
        for note in &notes {
            assert!(!note.contains('\u{1b}'), "{note}");
            assert!(note.contains("\\u{1b}"), "{note}");
        }
    }

    /// An image renamed `.obj` is named as what it is, not "face parse
    /// error" without a line.
    #[test]
    fn a_binary_file_is_refused_as_not_text() {
        let png = parse_bytes(b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR", Path::new("p.obj"), |_| {
            Ok(Vec::new())
        });
        assert_eq!(
            png.unwrap_err().to_string(),
            "p.obj: not a text file (a PNG image); an OBJ file is text (`v`, `vt`, `f` lines)"
        );
        let nul = parse_bytes(b"v 0 0 0\n\0\0", Path::new("n.obj"), |_| Ok(Vec::new()));
        assert!(nul.unwrap_err().to_string().contains("NUL bytes"));
    }

    /// What an MTL or a `usemtl` says that marbre cannot take is replaced
    /// with a note each, never silently: non-finite colours, colours and an
    /// opacity out of range, an undefined material.
    #[test]
    fn replaced_values_and_undefined_materials_get_notes() {
        let dir = tempfile::tempdir().unwrap();
        write(
            &dir,
            "m.mtl",
            "newmtl a\nKd nan inf -1\nKs 2 0.5 0.5\nKe 1e39 0 0\nd 2\n",
        );
        let obj = write(
            &dir,
            "m.obj",
            &format!("mtllib m.mtl\n{QUAD}usemtl a\nf 1 2 3\nusemtl b\nf 1 3 4\n"),
        );
        let loaded = load(&obj).unwrap();
        let has = |parts: &[&str]| {
            assert!(
                loaded
                    .notes
                    .iter()
                    .any(|n| parts.iter().all(|p| n.contains(p))),
                "no note with {parts:?}: {:#?}",
                loaded.notes
            )
        };
        has(&[
            "material `a`",
            "`Kd NaN inf -1` is not finite; 0.8 0.8 0.8 is used",
        ]);
        has(&["`Ks 2 0.5 0.5` is outside 0 to 1; 1 0.5 0.5 is used"]);
        has(&["`Ke inf 0 0` is not finite"]);
        has(&["`d` gives an opacity of 2, outside 0 to 1; 1 is used"]);
        has(&["m.obj:12: `usemtl b` names no material of its library; grey is used"]);
        let a = &loaded
            .materials
            .iter()
            .find(|m| m.name == "a")
            .unwrap()
            .material;
        assert_eq!(a.diffuse.eval(Vec3::ZERO, Vec2::ZERO), Vec3::splat(0.8));
        assert_eq!(
            a.specular.eval(Vec3::ZERO, Vec2::ZERO),
            Vec3::new(1.0, 0.5, 0.5)
        );
    }

    /// A library that is a device or a FIFO is refused (its note says why)
    /// instead of read until memory runs out or blocked on forever; an OBJ
    /// that is one is an error naming it.
    #[test]
    fn a_device_or_fifo_library_or_obj_is_refused_without_blocking() {
        use crate::capped_read::test_support::{make_fifo, within_10_s};
        let dir = tempfile::tempdir().unwrap();
        make_fifo(&dir.path().join("pipe.mtl"));
        std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.mtl")).unwrap();
        for library in ["pipe.mtl", "zero.mtl"] {
            let obj = write(&dir, "m.obj", &format!("mtllib {library}\n{QUAD}f 1 2 3\n"));
            let notes = within_10_s(move || load(&obj).unwrap().notes);
            assert!(
                notes
                    .iter()
                    .any(|n| n.contains(library) && n.contains("not a regular file")),
                "{library}: {notes:?}"
            );
        }
        let fifo = dir.path().join("pipe.obj");
        make_fifo(&fifo);
        let error = within_10_s(move || load(&fifo).unwrap_err().to_string());
        assert!(
            error.contains("pipe.obj") && error.contains("it is a FIFO"),
            "{error}"
        );
    }

    const CORNELL: &str = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../presets/scenes/cornell-box/CornellBox-Original.obj"
    );

    /// The Cornell box: every quad in two triangles, its eight materials
    /// with the MTL's values, the light emitting Ke.
    #[test]
    fn the_cornell_box_loads_with_its_materials() {
        let obj = load(Path::new(CORNELL)).unwrap();
        assert!(obj.notes.is_empty(), "{:?}", obj.notes);
        assert_eq!(obj.materials.len(), 8);
        // 5 walls + 1 light + 2 boxes of 5 visible quads... count from the file.
        let quads = std::fs::read_to_string(CORNELL)
            .unwrap()
            .lines()
            .filter(|l| l.starts_with("f "))
            .count();
        assert_eq!(obj.triangles.len(), 2 * quads);
        let light = obj.materials.iter().find(|m| m.name == "light").unwrap();
        let at = crate::scene::SurfacePoint::new(Vec3::ZERO, Vec2::ZERO);
        assert_eq!(
            light.material.value_at(Property::Emission, &at),
            Vec3::new(17.0, 12.0, 4.0)
        );
        let left = obj.materials.iter().find(|m| m.name == "leftWall").unwrap();
        assert_eq!(
            left.material.value_at(Property::Diffuse, &at),
            Vec3::new(0.63, 0.065, 0.05)
        );
        assert!(!left.is_override());
    }

    fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> PathBuf {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";

    /// d, Tr, Tf, Ns and the texture maps, with paths relative to the MTL.
    #[test]
    fn mtl_keys_map_onto_the_material() {
        let dir = tempfile::Builder::new()
            .prefix("obj-keys")
            .tempdir()
            .unwrap();
        write(
            &dir,
            "m.mtl",
            "newmtl glass\nKd 0.2 0.4 0.8\nd 0.25\nNs 100\nKs 0.5 0.5 0.5\n\
             newmtl film\nKd 1 1 1\nTr 0.75\nTf 1 0 0\n\
             newmtl pictured\nKd 1 1 1\nmap_Kd pic.png\nmap_bump -bm 2 bumps.png\n",
        );
        let obj = write(
            &dir,
            "m.obj",
            &format!(
                "mtllib m.mtl\n{QUAD}usemtl glass\nf 1/1 2/2 3/3\nusemtl film\nf 1/1 3/3 4/4\nusemtl pictured\nf 1/1 2/2 4/4\n"
            ),
        );
        let loaded = load(&obj).unwrap();
        let at = crate::scene::SurfacePoint::new(Vec3::ZERO, Vec2::ZERO);
        let get = |name: &str, p: Property| {
            loaded
                .materials
                .iter()
                .find(|m| m.name == name)
                .unwrap()
                .material
                .value_at(p, &at)
        };
        assert_eq!(get("glass", Property::Opacity).x, 0.25);
        // Without Tf, a see-through material tints by its diffuse colour.
        assert_eq!(
            get("glass", Property::Transmission),
            Vec3::new(0.2, 0.4, 0.8)
        );
        assert!((get("glass", Property::Roughness).x - roughness_from_ns(100.0)).abs() < 1e-6);
        assert_eq!(get("film", Property::Opacity).x, 0.25);
        assert_eq!(get("film", Property::Transmission), Vec3::X);
        let pictured = &loaded.materials[2].material;
        assert_eq!(
            pictured.diffuse.image.as_ref().unwrap().path,
            dir.path().join("pic.png")
        );
        assert_eq!(
            pictured.bump.image.as_ref().unwrap().path,
            dir.path().join("bumps.png")
        );
        assert!((pictured.bump_height - 0.02).abs() < 1e-6);
        // Both textures are missing: each named in a note.
        for file in ["pic.png", "bumps.png"] {
            assert!(
                loaded
                    .notes
                    .iter()
                    .any(|n| n.contains(file) && n.contains("not found")),
                "{:?}",
                loaded.notes
            );
        }
        assert_eq!(loaded.triangles.uvs[0], [Vec2::ZERO, Vec2::X, Vec2::ONE]);
    }

    /// Smoother surfaces have higher Phong exponents: roughness falls with
    /// Ns, from 1 (Ns = 0) towards 0.
    #[test]
    fn roughness_falls_as_the_phong_exponent_grows() {
        assert_eq!(roughness_from_ns(0.0), 1.0);
        let values: Vec<f32> = [1.0, 10.0, 100.0, 1000.0].map(roughness_from_ns).to_vec();
        assert!(values.windows(2).all(|w| w[1] < w[0]), "{values:?}");
        assert!(values[3] < 0.3);
    }

    /// Broken files: a clear error naming the file and the cause.
    #[test]
    fn broken_obj_files_give_errors_naming_them() {
        let dir = tempfile::Builder::new()
            .prefix("obj-broken")
            .tempdir()
            .unwrap();
        let missing = dir.path().join("missing.obj");
        let e = load(&missing).unwrap_err().to_string();
        assert!(
            e.contains("missing.obj") && e.contains("cannot read"),
            "{e}"
        );
        let out_of_range = write(&dir, "range.obj", "v 0 0 0\nv 1 0 0\nf 1 2 9\n");
        let e = load(&out_of_range).unwrap_err().to_string();
        assert!(e.contains("range.obj:3") && e.contains("`f 1 2 9`"), "{e}");
        let garbage = write(&dir, "garbage.obj", "v 0 0 0\nv 0 zero 0\nf 1 1 1\n");
        let e = load(&garbage).unwrap_err().to_string();
        assert!(e.contains("garbage.obj:2"), "{e}");
        // Truncated mid-statement: the face lost its last corners.
        let cornell = std::fs::read_to_string(CORNELL).unwrap();
        let cut = cornell.rfind("\nf ").unwrap() + 6;
        let truncated = write(&dir, "truncated.obj", &cornell[..cut]);
        let e = load(&truncated).unwrap_err().to_string();
        let last_line = cornell[..cut].lines().count();
        assert!(e.contains(&format!("truncated.obj:{last_line}:")), "{e}");
        let no_faces = write(&dir, "empty.obj", "v 0 0 0\n");
        let e = load(&no_faces).unwrap_err().to_string();
        assert!(e.contains("empty.obj") && e.contains("no faces"), "{e}");
    }

    /// NaN vertices are rejected with a note, the rest still renders; a
    /// missing MTL file gives grey and a note naming it.
    #[test]
    fn nan_vertices_and_a_missing_library_are_reported() {
        let dir = tempfile::Builder::new()
            .prefix("obj-nan")
            .tempdir()
            .unwrap();
        let obj = write(
            &dir,
            "nan.obj",
            &format!("mtllib nowhere.mtl\n{QUAD}v nan 0 0\nf 1 2 3\nf 1 3 5\n"),
        );
        let loaded = load(&obj).unwrap();
        assert_eq!(loaded.triangles.len(), 1);
        assert!(
            loaded
                .notes
                .iter()
                .any(|n| n.contains("NaN") && n.contains("nan.obj")),
            "{:?}",
            loaded.notes
        );
        assert!(
            loaded
                .notes
                .iter()
                .any(|n| n.contains("nowhere.mtl") && n.contains("cannot be read")),
            "{:?}",
            loaded.notes
        );
        // A broken library: its file and line are named, grey is used.
        write(&dir, "broken.mtl", "newmtl a\nKd 1 1\n");
        let obj = write(
            &dir,
            "b.obj",
            &format!("mtllib broken.mtl\n{QUAD}usemtl a\nf 1 2 3\n"),
        );
        let loaded = load(&obj).unwrap();
        assert!(
            loaded
                .notes
                .iter()
                .any(|n| n.contains("broken.mtl:2") && n.contains("`Kd 1 1`")),
            "{:?}",
            loaded.notes
        );
        assert_eq!(loaded.materials[0].name, DEFAULT_MATERIAL);
    }

    /// A preset's edited material survives loading the file again, and only
    /// edited materials are written back.
    #[test]
    fn preset_overrides_win_and_only_they_are_saved() {
        let marble = Material {
            roughness: Texture::scalar(0.123),
            ..Material::default()
        };
        let mut scene = Scene {
            meshes: vec![Mesh {
                name: "box".into(),
                obj: CORNELL.into(),
                materials: vec![MeshMaterial {
                    name: "leftWall".into(),
                    material: marble.clone(),
                    from_file: None,
                }],
                ..Mesh::default()
            }],
            ..Scene::default()
        };
        let mut notes = Vec::new();
        assert!(load_meshes(&mut scene, &mut notes).unwrap().is_empty());
        let mesh = &scene.meshes[0];
        assert_eq!(mesh.materials.len(), 8);
        let left = mesh
            .materials
            .iter()
            .find(|m| m.name == "leftWall")
            .unwrap();
        assert_eq!(left.material, marble);
        let text = ron::to_string(mesh).unwrap();
        assert_eq!(text.matches("name:").count(), 2, "{text}");
        assert!(
            text.contains("leftWall") && !text.contains("rightWall"),
            "{text}"
        );
        assert_eq!(scene.triangle_count(), mesh.geometry.0.len());
    }
}
