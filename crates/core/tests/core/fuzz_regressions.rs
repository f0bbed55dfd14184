//! Every input the fuzz targets kept (tests/data/fuzz/: the minimised
//! corpora and each crash found, see fuzz/README.md) through the entry point
//! of its target, read the way the target reads it: none may panic, an error
//! must name the file, and a result must keep the loader's promises.

use marbre_core::env_sampling::EnvDistribution;
use marbre_core::envmap::EnvLoad;
use marbre_core::image_decode::{F16_MAX, IntegerDecode, MAX_TEXELS, SUPPORTED_EXTENSIONS};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

/// The files of `tests/data/fuzz/<target>`, sorted.
fn inputs(target: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/fuzz")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)
        .unwrap_or_else(|e| panic!("{}: {e}", folder.display()))
        .map(|entry| entry.unwrap().path())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "{} is empty", folder.display());
    files
        .into_iter()
        .map(|file| {
            let bytes = std::fs::read(&file).unwrap();
            (file, bytes)
        })
        .collect()
}

/// Runs `check` on every input of `target`; fails naming each input that
/// panicked or broke a promise.
fn check_all(target: &str, check: impl Fn(&[u8]) -> Result<(), String>) {
    let failures: Vec<String> = inputs(target)
        .iter()
        .filter_map(|(file, bytes)| {
            let outcome = catch_unwind(AssertUnwindSafe(|| check(bytes)))
                .unwrap_or_else(|_| Err("panicked".into()));
            outcome
                .err()
                .map(|why| format!("{}: {why}", file.display()))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// An error's message must name the file it is about.
fn names_the_file(message: String, file_name: &str) -> Result<(), String> {
    if message.contains(file_name) {
        Ok(())
    } else {
        Err(format!("the error does not name {file_name}: {message}"))
    }
}

#[test]
fn preset_inputs_parse_or_give_an_error_naming_the_file() {
    let path = Path::new("/fuzz/presets/input.ron");
    check_all("preset", |bytes| {
        match marbre_core::preset::parse_bytes(bytes, path) {
            Err(e) => names_the_file(e.to_string(), "input.ron"),
            Ok(loaded) => {
                let scene = &loaded.preset.scene;
                // Paths in the file are resolved against the preset's folder.
                match scene.meshes.iter().find(|m| !m.obj.is_absolute()) {
                    Some(mesh) => Err(format!("mesh path {} left relative", mesh.obj.display())),
                    None => Ok(()),
                }
            }
        }
    });
}

/// The fuzz target's split: the OBJ, then after a NUL the `input.mtl` it
/// may name.
fn obj_and_library(bytes: &[u8]) -> (&[u8], Option<&[u8]>) {
    match bytes.iter().position(|&b| b == 0) {
        Some(i) => (&bytes[..i], Some(&bytes[i + 1..])),
        None => (bytes, None),
    }
}

#[test]
fn obj_inputs_load_or_give_an_error_naming_the_file() {
    let path = Path::new("/fuzz/obj/input.obj");
    check_all("obj", |bytes| {
        let (obj, mtl) = obj_and_library(bytes);
        let loaded = marbre_core::obj_loader::parse_bytes(obj, path, |library| {
            match (library == Path::new("/fuzz/obj/input.mtl"), mtl) {
                (true, Some(bytes)) => Ok(bytes.to_vec()),
                _ => Err(std::io::ErrorKind::NotFound.into()),
            }
        });
        let loaded = match loaded {
            Err(e) => return names_the_file(e.to_string(), "input.obj"),
            Ok(loaded) => loaded,
        };
        let mesh = &loaded.triangles;
        if mesh.is_empty() || mesh.uvs.len() != mesh.len() || mesh.materials.len() != mesh.len() {
            return Err(format!(
                "{} triangles, {} uv triples, {} material indices",
                mesh.len(),
                mesh.uvs.len(),
                mesh.materials.len()
            ));
        }
        if !mesh.positions.iter().flatten().all(|p| p.is_finite()) {
            return Err("a non-finite vertex was kept".into());
        }
        match mesh
            .materials
            .iter()
            .find(|&&m| m as usize >= loaded.materials.len())
        {
            Some(m) => Err(format!("material index {m} of {}", loaded.materials.len())),
            None => Ok(()),
        }
    });
}

/// The input that overflowed `tobj` 4.0.5 (`f 1/-2 …` before the file's
/// `vt` lines: counted back from none, the index wrapped to nearly
/// `usize::MAX` and `tobj` multiplied it) is refused before `tobj` reads
/// it, naming the file and the face's line.
#[test]
fn the_tobj_overflow_is_refused_with_its_line() {
    let (file, bytes) = inputs("obj")
        .into_iter()
        .find(|(file, _)| file.ends_with("tobj_overflow_texcoord_before_declared"))
        .expect("the regression file");
    let (obj, _) = obj_and_library(&bytes);
    let e = marbre_core::obj_loader::parse_bytes(obj, Path::new("/fuzz/obj/input.obj"), |_| {
        Err(std::io::ErrorKind::NotFound.into())
    })
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("input.obj:4: corner `1/-2` names texture coordinate -2, but 0 texture coordinates are declared above this line: `f 1/-2 2/-2 3/-2`"),
        "{}: {e}",
        file.display()
    );
}

/// The fuzz target's split: the first byte picks the extension (by its low
/// seven bits) and how integer codes decode (by its top bit), the rest is the
/// file.
fn envmap_path_and_file(bytes: &[u8]) -> Option<(PathBuf, IntegerDecode, &[u8])> {
    let (&selector, file) = bytes.split_first()?;
    let extension = SUPPORTED_EXTENSIONS[usize::from(selector & 0x7f) % SUPPORTED_EXTENSIONS.len()];
    let decode = if selector & 0x80 == 0 {
        IntegerDecode::Srgb
    } else {
        IntegerDecode::Linear
    };
    Some((
        PathBuf::from(format!("/fuzz/envmaps/input.{extension}")),
        decode,
        file,
    ))
}

#[test]
fn envmap_inputs_decode_to_clean_images_or_give_an_error_naming_the_file() {
    check_all("envmap", |bytes| {
        let Some((path, decode, file)) = envmap_path_and_file(bytes) else {
            return Err("empty input".into());
        };
        let file_name = path.file_name().unwrap().to_string_lossy().into_owned();
        let image = match marbre_core::image_decode::decode_bytes(file, &path, decode) {
            Err(e) => return names_the_file(e.to_string(), &file_name),
            Ok(decoded) => EnvLoad::from(decoded).image,
        };
        let texels = u64::from(image.width) * u64::from(image.height);
        if texels == 0 || texels > MAX_TEXELS || image.pixels.len() as u64 != texels {
            return Err(format!(
                "{}x{} with {} texels",
                image.width,
                image.height,
                image.pixels.len()
            ));
        }
        let clean =
            |px: &[f32; 4]| px[..3].iter().all(|c| (0.0..=F16_MAX).contains(c)) && px[3] == 1.0;
        if let Some(px) = image.pixels.iter().find(|px| !clean(px)) {
            return Err(format!("texel {px:?} was not sanitised"));
        }
        let distribution = EnvDistribution::new(&image);
        let (t, pdf) = distribution.sample(0.5, 0.5);
        if pdf.is_finite() && t.is_finite() {
            Ok(())
        } else {
            Err(format!("the sampling table drew {t} with density {pdf}"))
        }
    });
}

/// Headers declaring more than [`MAX_TEXELS`] texels (the files
/// `too_large_<width>x<height>.*`) are refused with their size, before the
/// decoder allocates the image.
#[test]
fn oversized_envmap_headers_are_refused_with_their_size() {
    let oversized: Vec<(PathBuf, Vec<u8>)> = inputs("envmap")
        .into_iter()
        .filter(|(file, _)| {
            file.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("too_large_")
        })
        .collect();
    assert_eq!(oversized.len(), 3, "one file per format with a size check");
    for (file, bytes) in oversized {
        let stem = file.file_stem().unwrap().to_string_lossy().into_owned();
        let size = stem.trim_start_matches("too_large_");
        let (path, decode, data) = envmap_path_and_file(&bytes).unwrap();
        let e = marbre_core::image_decode::decode_bytes(data, &path, decode)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("declares {size} texels, more than")),
            "{}: {e}",
            file.display()
        );
    }
}

/// The hand-made seeds (`<what>_<width>x<height>.*`: EXR float, half and
/// ZIP-compressed, luminance-only EXR, flat and run-length Radiance HDR,
/// 8- and 16-bit, grey, alpha and palette PNG, JPEG) decode to their size:
/// the corpus starts from files each decoder accepts.
#[test]
fn envmap_seeds_decode_to_their_size() {
    let mut decoded = 0;
    for (file, bytes) in inputs("envmap") {
        let stem = file.file_stem().unwrap().to_string_lossy().into_owned();
        let Some(size) = stem.rsplit('_').next().filter(|s| s.contains('x')) else {
            continue;
        };
        if stem.starts_with("too_large_") {
            continue;
        }
        let (path, decode, data) = envmap_path_and_file(&bytes).unwrap();
        let image = marbre_core::image_decode::decode_bytes(data, &path, decode)
            .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        assert_eq!(
            format!("{}x{}", image.width, image.height),
            size,
            "{}",
            file.display()
        );
        decoded += 1;
    }
    assert_eq!(decoded, 12);
}

/// A RON error must point inside the text: a line between the first and
/// just past the last, and a column.
fn ron_error_inside(e: &ron::error::SpannedError, text: &str) -> Result<(), String> {
    let lines = text.lines().count() + 1;
    let at = e.span.start;
    if (1..=lines).contains(&at.line) && at.col >= 1 {
        Ok(())
    } else {
        Err(format!("the error points at {at} in {lines} lines: {e}"))
    }
}

/// The text formats' targets skip bytes that are not UTF-8 (the app
/// refuses them when it reads the file): so do their tests.
fn utf8(bytes: &[u8]) -> Option<&str> {
    std::str::from_utf8(bytes).ok()
}

#[test]
fn tx_inputs_lower_and_print_back_or_give_a_syntax_error_inside_the_text() {
    use marbre_core::scene::Texture;
    use marbre_core::tx::{self, TxError};
    check_all("tx", |bytes| {
        let Some(text) = utf8(bytes) else {
            return Ok(());
        };
        for channel in tx::Channel::ALL {
            // Whatever it returns, the preset's reader must not panic.
            let _ = tx::read_preset_property(channel.name(), text);
        }
        let doc = match tx::parse(text) {
            Err(TxError::Syntax { line, column, .. }) => {
                let lines = text.lines().count().max(1);
                return if (1..=lines).contains(&line) && column >= 1 {
                    Ok(())
                } else {
                    Err(format!("syntax error at {line}:{column} of {lines} lines"))
                };
            }
            Err(e) => return Err(format!("parsing gave a non-syntax error: {e}")),
            Ok(doc) => doc,
        };
        let printed = tx::print(&doc);
        if tx::parse(&printed).as_ref() != Ok(&doc) {
            return Err(format!("printed as {printed:?}, which reads otherwise"));
        }
        let mut scene = match marbre_core::tx_preview::preview_scene(&doc, Path::new("/fuzz/tx")) {
            Err(TxError::Lower(_)) => return Ok(()),
            Err(e) => return Err(format!("lowering gave a non-lowering error: {e}")),
            Ok(scene) => scene,
        };
        let material = &scene.spheres[0].material;
        let deepest = [
            &material.diffuse,
            &material.specular,
            &material.mirror,
            &material.opacity,
            &material.transmission,
            &material.diffuse_transmission,
            &material.bump,
        ]
        .iter()
        .map(|t| t.depth())
        .max()
        .unwrap();
        if deepest > Texture::MAX_DEPTH {
            return Err(format!("a texture nests {deepest} deep"));
        }
        scene.sanitize();
        Ok(())
    });
}

#[test]
fn gallery_inputs_list_files_inside_the_folder_or_say_what_is_wrong() {
    use marbre_core::tx_preview::{GalleryError, parse_gallery};
    use std::path::Component;
    // Inside: a relative path naming a file, that never climbs out.
    let inside = |file: &str| {
        let path = Path::new(file);
        !path.is_absolute()
            && path.file_name().is_some()
            && !path.components().any(|c| c == Component::ParentDir)
    };
    check_all("gallery", |bytes| {
        let Some(text) = utf8(bytes) else {
            return Ok(());
        };
        match parse_gallery(text) {
            Ok(entries) => match entries.iter().find(|e| !inside(&e.file)) {
                Some(e) => Err(format!("`{}` was accepted", e.file)),
                None => Ok(()),
            },
            Err(GalleryError::Syntax(e)) => ron_error_inside(&e, text),
            Err(GalleryError::OutsideFolder { file, .. }) if inside(&file) => {
                Err(format!("`{file}` was refused"))
            }
            Err(GalleryError::OutsideFolder { .. }) => Ok(()),
        }
    });
}

#[test]
fn noise_inputs_give_each_line_in_order_as_a_finite_point_or_why_not() {
    use marbre_core::noise::points::read_points;
    check_all("noise", |bytes| {
        // The lines that are neither blank nor a comment, counted apart.
        let expected: Vec<usize> = bytes
            .split(|&b| b == b'\n')
            .enumerate()
            .filter(|(_, line)| {
                let t = String::from_utf8_lossy(line);
                let t = t.trim();
                !t.is_empty() && !t.starts_with('#')
            })
            .map(|(i, _)| i + 1)
            .collect();
        let mut numbers = Vec::new();
        for line in read_points(bytes) {
            let line = line.map_err(|e| format!("reading memory failed: {e}"))?;
            if let Ok(p) = line.point
                && !p.is_finite()
            {
                return Err(format!("line {}: {p} was accepted", line.number));
            }
            numbers.push(line.number);
        }
        if numbers == expected {
            Ok(())
        } else {
            Err(format!("lines {numbers:?}, expected {expected:?}"))
        }
    });
}

/// The seeds of `noise` hold Perlin's 80 reference points and a file of
/// good and bad lines, each bad line reported as what it is.
#[test]
fn the_noise_seeds_read_as_written() {
    use marbre_core::noise::points::{BadPoint, read_points};
    let (_, bytes) = inputs("noise")
        .into_iter()
        .find(|(file, _)| file.ends_with("good_and_bad_lines.txt"))
        .unwrap();
    let lines: Vec<(usize, Result<glam::DVec3, BadPoint>)> = read_points(&bytes[..])
        .map(|l| l.unwrap())
        .map(|l| (l.number, l.point))
        .collect();
    let bad = |number, why| (number, Err(why));
    assert_eq!(
        lines,
        vec![
            (2, Ok(glam::DVec3::splat(0.5))),
            (4, Ok(glam::DVec3::new(1.0, 2.0, 3.0))),
            bad(5, BadPoint::Count(2)),
            bad(6, BadPoint::Count(4)),
            bad(7, BadPoint::NotANumber("x".into())),
            bad(8, BadPoint::NotFinite),
            bad(9, BadPoint::NotFinite),
            (10, Ok(glam::DVec3::new(-0.25, 7e-3, 42.0))),
        ]
    );
}

#[test]
fn settings_inputs_read_back_from_what_is_written_or_say_where_they_fail() {
    use marbre_core::viewer_files::{MAX_RECENT_FILES, Settings};
    check_all("settings", |bytes| {
        let Some(text) = utf8(bytes) else {
            return Ok(());
        };
        let settings = match Settings::parse(text) {
            Err(e) => return ron_error_inside(&e, text),
            Ok(settings) => settings,
        };
        if settings.recent_files.len() > MAX_RECENT_FILES {
            return Err(format!("{} recent files", settings.recent_files.len()));
        }
        let written = settings
            .to_text()
            .map_err(|e| format!("cannot write: {e}"))?;
        match Settings::parse(&written) {
            Ok(back) if back == settings => Ok(()),
            other => Err(format!("written as {written:?}, read back as {other:?}")),
        }
    });
}

#[test]
fn recovery_inputs_read_back_from_what_is_written_or_say_where_they_fail() {
    use marbre_core::viewer_files::RecoveryInfo;
    check_all("recovery", |bytes| {
        let Some(text) = utf8(bytes) else {
            return Ok(());
        };
        let info = match RecoveryInfo::parse(text) {
            Err(e) => return ron_error_inside(&e, text),
            Ok(info) => info,
        };
        let written = info.to_text().map_err(|e| format!("cannot write: {e}"))?;
        match RecoveryInfo::parse(&written) {
            Ok(back) if back == info => Ok(()),
            other => Err(format!("written as {written:?}, read back as {other:?}")),
        }
    });
}
