//! What a final render records in its EXR output (issue 30): how many
//! samples it traced and which of the one long render's, of which frame
//! and moment, of which scene, by which kernel, adapter and marbre. A
//! farm's batches are merged by it (`merge`), and any file says how it
//! was made. Written as one text attribute of the EXR header,
//! `marbre:render`, `key=value` lines, which other tools show and keep
//! (`exrheader`, Blender's metadata panel).

use crate::scene::Scene;
use crate::tile::Tile;
use std::collections::BTreeMap;
use std::ops::Range;

#[derive(Debug, Clone, PartialEq)]
pub struct RenderRecord {
    /// Samples per pixel traced.
    pub spp: u32,
    /// The first of them in the long render (`render --sample-offset`).
    pub sample_offset: u32,
    /// The size of the whole image, and the tile of it the file holds
    /// (the whole image but for `render --tile`).
    pub image: (u32, u32),
    pub tile: Tile,
    /// The animation frame whose samples they are, and its time.
    pub frame: u32,
    pub time: f32,
    /// The traced scene's [`scene_hash`].
    pub scene: String,
    pub kernel: String,
    pub adapter: String,
    /// marbre's version.
    pub version: String,
}

/// The EXR header attribute that holds the record, as `key=value` lines:
/// one attribute, so that the file's bytes do not depend on the order of
/// `exr`'s attribute map (`image_io::encode_exr`).
pub const RECORD_ATTRIBUTE: &str = "marbre:render";

/// The keys, in the order they are written.
const SPP: &str = "spp";
const SAMPLE_OFFSET: &str = "sampleOffset";
const IMAGE: &str = "image";
const TILE: &str = "tile";
const FRAME: &str = "frame";
const TIME: &str = "time";
const SCENE: &str = "scene";
const KERNEL: &str = "kernel";
const ADAPTER: &str = "adapter";
const VERSION: &str = "version";

impl RenderRecord {
    /// The samples traced: [offset, offset + spp).
    pub fn samples(&self) -> Range<u64> {
        let start = u64::from(self.sample_offset);
        start..start + u64::from(self.spp)
    }

    /// The record as `key=value` lines.
    pub fn to_text(&self) -> String {
        [
            (SPP, self.spp.to_string()),
            (SAMPLE_OFFSET, self.sample_offset.to_string()),
            (IMAGE, format!("{}x{}", self.image.0, self.image.1)),
            (TILE, self.tile.to_string()),
            (FRAME, self.frame.to_string()),
            (TIME, self.time.to_string()),
            (SCENE, self.scene.clone()),
            (KERNEL, self.kernel.clone()),
            (ADAPTER, self.adapter.replace('\n', " ")),
            (VERSION, self.version.clone()),
        ]
        .iter()
        .map(|(key, value)| format!("{key}={value}\n"))
        .collect()
    }

    /// The record in a file's header `attributes`; `None` when they hold
    /// none (a file marbre did not render), an error naming the key that
    /// is missing or unreadable.
    pub fn from_attributes(attributes: &BTreeMap<String, String>) -> Result<Option<Self>, String> {
        let Some(text) = attributes.get(RECORD_ATTRIBUTE) else {
            return Ok(None);
        };
        let lines: BTreeMap<&str, &str> = text.lines().filter_map(|l| l.split_once('=')).collect();
        let text = |key: &str| {
            lines
                .get(key)
                .map(|v| (*v).to_owned())
                .ok_or_else(|| format!("its render record has no `{key}`"))
        };
        fn number<T: std::str::FromStr>(key: &str, text: String) -> Result<T, String> {
            text.trim()
                .parse()
                .map_err(|_| format!("its render record's `{key}` is not a number: {text:?}"))
        }
        let image = text(IMAGE)?;
        let image = image
            .split_once('x')
            .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)))
            .ok_or_else(|| {
                format!("its render record's `{IMAGE}` is not WIDTHxHEIGHT: {image:?}")
            })?;
        let tile =
            Tile::parse(&text(TILE)?).map_err(|e| format!("its render record's `{TILE}`: {e}"))?;
        tile.check_within(image)
            .map_err(|e| format!("its render record's `{TILE}`: {e}"))?;
        Ok(Some(Self {
            spp: number(SPP, text(SPP)?)?,
            sample_offset: number(SAMPLE_OFFSET, text(SAMPLE_OFFSET)?)?,
            image,
            tile,
            frame: number(FRAME, text(FRAME)?)?,
            time: number(TIME, text(TIME)?)?,
            scene: text(SCENE)?,
            kernel: text(KERNEL)?,
            adapter: text(ADAPTER)?,
            version: text(VERSION)?,
        }))
    }
}

/// A name of the traced scene: 16 hex digits of the 64-bit FNV-1a hash of
/// the scene written as RON, the same on every machine and run (unlike
/// std's hasher, whose keys are random), so that the batches of one scene
/// are known and those of another refused. What does not change the
/// traced radiance is left out: the display (exposure, tone map,
/// denoise: applied to a PNG, not to the EXR) and the animation's keys
/// (the scene is the one traced at its moment).
pub fn scene_hash(scene: &Scene) -> String {
    let traced = Scene {
        animation: None,
        render: crate::scene::RenderSettings {
            display: Default::default(),
            ..scene.render
        },
        ..scene.clone()
    };
    let text = ron::to_string(&traced).expect("a scene writes as RON");
    fnv1a_hex(text.as_bytes())
}

/// 16 hex digits of the 64-bit FNV-1a hash of `bytes`: the same on every
/// machine and run.
pub fn fnv1a_hex(bytes: &[u8]) -> String {
    let mut hash = Fnv1a::default();
    hash.write(bytes);
    hash.hex()
}

/// The 64-bit FNV-1a hash, fed in pieces.
struct Fnv1a(u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv1a {
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 = (self.0 ^ u64::from(*b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn hex(&self) -> String {
        format!("{:016x}", self.0)
    }
}

/// The record's last line in a file: the seal of the record's other
/// lines and of the file's channels.
const SEAL: &str = "seal";

/// `text`, a record as a file's header holds it, with its seal appended:
/// the FNV-1a hash of `text` and of `channels` (name, values) as the file
/// holds them.
///
/// Why: merge weighs each file by its record's samples, and nothing in
/// the pixels says how many there were. The seal binds the record to the
/// pixels, so that a record edited after the render (the probe's `spp`
/// changed in place), or pixels changed under it, are refused
/// ([`check_seal`]) rather than merged with wrong weights. It is a
/// checksum, not a signature: it finds a change made by hand or by
/// another tool, not a forger who computes it again.
pub fn sealed(text: &str, channels: &[(&str, &[f32])]) -> String {
    let mut body = text.to_owned();
    if !body.is_empty() && !body.ends_with('\n') {
        body.push('\n');
    }
    let seal = seal_of(&body, channels);
    format!("{body}{SEAL}={seal}\n")
}

/// Whether a file's record `text` (its header attribute) matches the
/// file's `channels`: `Ok(true)` when its seal does, `Ok(false)` when it
/// has none (a file of a marbre before seals), else why not.
pub fn check_seal(text: &str, channels: &[(&str, &[f32])]) -> Result<bool, String> {
    let prefix = format!("{SEAL}=");
    let at = if text.starts_with(&prefix) {
        Some(0)
    } else {
        text.find(&format!("\n{prefix}")).map(|at| at + 1)
    };
    let Some(at) = at else {
        return Ok(false);
    };
    let (body, line) = text.split_at(at);
    let seal = line[prefix.len()..].trim_end_matches('\n');
    if seal != seal_of(body, channels) {
        return Err(
            "its render record does not match its pixels (its seal is not theirs): the record \
             or the pixels were changed after marbre wrote the file, and merge weighs a file by \
             its record's samples; merge the files as `marbre render` wrote them"
                .into(),
        );
    }
    Ok(true)
}

/// The seal's hash: the record's text, then each channel, in name order,
/// as its name, a 0 byte, its value count and its values (little-endian
/// u64 and f32, so the same on every machine).
fn seal_of(text: &str, channels: &[(&str, &[f32])]) -> String {
    let mut sorted: Vec<&(&str, &[f32])> = channels.iter().collect();
    sorted.sort_by_key(|(name, _)| *name);
    let mut hash = Fnv1a::default();
    hash.write(text.as_bytes());
    for (name, values) in sorted {
        hash.write(name.as_bytes());
        hash.write(&[0]);
        hash.write(&(values.len() as u64).to_le_bytes());
        for v in *values {
            hash.write(&v.to_le_bytes());
        }
    }
    hash.hex()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record() -> RenderRecord {
        RenderRecord {
            spp: 16,
            sample_offset: 32,
            image: (64, 48),
            tile: Tile::parse("16,0,48,24").unwrap(),
            frame: 3,
            time: 0.125,
            scene: "0123456789abcdef".into(),
            kernel: "fragment".into(),
            adapter: "llvmpipe (Vulkan)".into(),
            version: "0.1.0".into(),
        }
    }

    /// A record reads back from its text; a file without one reads as
    /// none; a missing or unreadable key is named.
    #[test]
    fn a_record_round_trips_through_its_text() {
        let attributes = |text: String| BTreeMap::from([(RECORD_ATTRIBUTE.to_owned(), text)]);
        let text = record().to_text();
        assert_eq!(
            RenderRecord::from_attributes(&attributes(text.clone())),
            Ok(Some(record()))
        );
        assert_eq!(record().samples(), 32..48);
        assert_eq!(RenderRecord::from_attributes(&BTreeMap::new()), Ok(None));
        let missing = text.replace("scene=0123456789abcdef\n", "");
        let e = RenderRecord::from_attributes(&attributes(missing)).unwrap_err();
        assert!(e.contains("`scene`"), "{e}");
        let bad = text.replace("spp=16", "spp=many");
        let e = RenderRecord::from_attributes(&attributes(bad)).unwrap_err();
        assert!(e.contains("`spp`") && e.contains("many"), "{e}");
        let outside = text.replace("tile=16,0,48,24", "tile=16,0,80,24");
        let e = RenderRecord::from_attributes(&attributes(outside)).unwrap_err();
        assert!(e.contains("`tile`") && e.contains("64 × 48"), "{e}");
    }

    /// A sealed record checks against its channels, in any order; a
    /// changed `spp`, a changed value, a changed channel name or a line
    /// after the seal does not; a record without a seal says so.
    #[test]
    fn a_seal_binds_the_record_to_the_channels() {
        let (r, g) = ([0.5f32, 1.0], [2.0f32, f32::NAN]);
        let channels = [("R", &r[..]), ("G", &g[..])];
        let text = record().to_text();
        let sealed = sealed(&text, &channels);
        assert!(sealed.starts_with(&text) && sealed.ends_with('\n'));
        assert_eq!(check_seal(&sealed, &channels), Ok(true));
        assert_eq!(check_seal(&sealed, &[channels[1], channels[0]]), Ok(true));
        assert_eq!(check_seal(&text, &channels), Ok(false));
        let edited = sealed.replace("spp=16", "spp=32");
        let e = check_seal(&edited, &channels).unwrap_err();
        assert!(e.contains("does not match its pixels"), "{e}");
        let other = [0.5f32, 1.5];
        assert!(check_seal(&sealed, &[("R", &other[..]), channels[1]]).is_err());
        assert!(check_seal(&sealed, &[("B", &r[..]), channels[1]]).is_err());
        assert!(check_seal(&format!("{sealed}spp=32\n"), &channels).is_err());
        let read =
            RenderRecord::from_attributes(&BTreeMap::from([(RECORD_ATTRIBUTE.to_owned(), sealed)]));
        assert_eq!(
            read,
            Ok(Some(record())),
            "the seal is no field of the record"
        );
    }

    /// FNV-1a's published value for "a" (0xaf63dc4c8601ec8c) pins the
    /// hash; a scene's name changes with any number in it.
    #[test]
    fn the_scene_hash_is_fnv1a_of_the_scene() {
        let fnv = |text: &str| {
            text.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
                (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
            })
        };
        assert_eq!(fnv("a"), 0xaf63_dc4c_8601_ec8c);
        let scene = Scene::default();
        assert_eq!(
            scene_hash(&scene),
            format!("{:016x}", fnv(&ron::to_string(&scene).unwrap())),
            "a default scene has the default display and no animation"
        );
        let mut other = scene.clone();
        other.camera.fov_degrees += 1.0;
        assert_ne!(scene_hash(&scene), scene_hash(&other));
        let mut exposed = scene.clone();
        exposed.render.display.exposure += 1.0;
        assert_eq!(scene_hash(&scene), scene_hash(&exposed));
    }
}
