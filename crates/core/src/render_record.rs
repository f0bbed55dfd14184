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
    let hash = bytes.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0000_0100_0000_01b3)
    });
    format!("{hash:016x}")
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
