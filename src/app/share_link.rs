//! A scene in a link (issue 34): the preset's RON, deflated and written in
//! base64's URL-safe alphabet, in the fragment of the page's address
//! (`#scene=…`). The fragment never reaches a server, so a shared scene
//! stays between the people who pass the link on.
//!
//! Images, env maps and meshes travel by name: the preset is written as if
//! saved at the page's root ([`SHARED_PRESET_PATH`]), so its paths name the
//! files the page serves beside itself (`envmaps/sky.exr`). A file the
//! sender dropped on their page is not in the link; the receiver's page
//! says which file is missing, as for any preset.
//!
//! The standard crates do the work (miniz_oxide's deflate, as the PNG
//! encoder uses; base64's URL-safe alphabet without padding).

use base64::Engine as _;
use base64::engine::general_purpose::URL_SAFE_NO_PAD;

/// The fragment's key: `#scene=<data>`.
pub const FRAGMENT_KEY: &str = "scene=";

/// Where a link's preset is put among the page's files and opened from:
/// the page's root, which the preset's relative paths start from.
pub const SHARED_PRESET_PATH: &str = "shared.ron";

/// The longest fragment a link carries. Browsers take far longer
/// addresses, but chat programs, mail and forms cut or refuse them well
/// before: 8000 characters is the common floor (RFC 9110 recommends
/// senders and receivers support at least 8000 octets). The shipped
/// presets take 600 to 2200.
pub const MAX_FRAGMENT_CHARS: usize = 8000;

/// The most bytes a link's preset may inflate to: as a preset file's own
/// cap is kept out of a link's reach, a small link cannot ask for a large
/// allocation (a deflate bomb).
pub const MAX_PRESET_BYTES: usize = 1 << 20;

/// Why a scene could not go in a link, or a link gave no scene.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LinkError {
    /// The fragment would be `chars` long, over [`MAX_FRAGMENT_CHARS`].
    TooLarge { chars: usize },
    /// The link's data is not base64, not deflate, too large inflated, or
    /// not UTF-8 text: a link cut short or edited by hand.
    Damaged(String),
}

impl std::fmt::Display for LinkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LinkError::TooLarge { chars } => write!(
                f,
                "the scene is too large for a link ({chars} characters, at most \
                 {MAX_FRAGMENT_CHARS}): save the preset and send the file instead"
            ),
            LinkError::Damaged(why) => write!(
                f,
                "the link's scene cannot be read ({why}): the link may have been cut short"
            ),
        }
    }
}

impl std::error::Error for LinkError {}

/// The fragment (without `#`) that carries `preset_text`.
pub fn encode(preset_text: &str) -> Result<String, LinkError> {
    let deflated = miniz_oxide::deflate::compress_to_vec(preset_text.as_bytes(), 10);
    let fragment = format!("{FRAGMENT_KEY}{}", URL_SAFE_NO_PAD.encode(deflated));
    if fragment.len() > MAX_FRAGMENT_CHARS {
        return Err(LinkError::TooLarge {
            chars: fragment.len(),
        });
    }
    Ok(fragment)
}

/// The preset text a fragment (with or without its `#`) carries; None when
/// the fragment carries no scene (an ordinary address).
pub fn decode(fragment: &str) -> Option<Result<String, LinkError>> {
    let data = fragment
        .strip_prefix('#')
        .unwrap_or(fragment)
        .strip_prefix(FRAGMENT_KEY)?;
    Some(decode_data(data))
}

fn decode_data(data: &str) -> Result<String, LinkError> {
    if data.len() > MAX_FRAGMENT_CHARS {
        return Err(LinkError::TooLarge { chars: data.len() });
    }
    let deflated = URL_SAFE_NO_PAD
        .decode(data.trim_end_matches('='))
        .map_err(|e| LinkError::Damaged(format!("not base64: {e}")))?;
    let bytes = miniz_oxide::inflate::decompress_to_vec_with_limit(&deflated, MAX_PRESET_BYTES)
        .map_err(|e| LinkError::Damaged(format!("not a deflated scene: {:?}", e.status)))?;
    String::from_utf8(bytes).map_err(|e| {
        LinkError::Damaged(format!(
            "not UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use marbre_core::preset;
    use std::path::Path;

    /// Every shipped preset, written as a link saves it, fits in a link
    /// and comes back as the same text, which parses to the same scene.
    #[test]
    fn every_shipped_preset_travels_in_a_link_unchanged() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut checked = 0;
        for entry in std::fs::read_dir(root.join("presets")).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "ron") {
                continue;
            }
            let loaded = preset::load(&path).unwrap();
            let text = preset::to_text(&loaded.preset, &root.join(SHARED_PRESET_PATH)).unwrap();
            let fragment = encode(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert!(fragment.len() <= MAX_FRAGMENT_CHARS);
            assert!(
                fragment
                    .bytes()
                    .all(|b| b.is_ascii_alphanumeric() || b"-_=".contains(&b)),
                "only characters an address keeps as they are"
            );
            let back = decode(&format!("#{fragment}")).unwrap().unwrap();
            assert_eq!(back, text);
            let reparsed = preset::parse(&back, &root.join(SHARED_PRESET_PATH)).unwrap();
            assert_eq!(
                reparsed.preset.scene,
                loaded.preset.scene,
                "{}",
                path.display()
            );
            checked += 1;
        }
        assert!(checked >= 10, "only {checked} presets found");
    }

    /// Text that an address or the preset's syntax would misread, in the
    /// description and an object's name, travels in the link as it was:
    /// the fragment holds only characters an address keeps (no `#`, `&`,
    /// `%`, quote or space of the text reaches it), and the scene comes
    /// back equal (issue 47).
    #[test]
    fn hostile_text_in_a_scene_travels_in_a_link_unchanged() {
        let mut preset = preset::Preset::default();
        let hostile = "a\"b'c#scene=x&spp=1?%00%2F ${IFS}$(touch P)`x`;\n\r\t\\ \u{202e}é\u{0}";
        preset.description = hostile.to_owned();
        preset.scene.spheres.push(marbre_core::scene::Sphere {
            name: hostile.chars().rev().collect(),
            ..Default::default()
        });
        let root = Path::new("/page");
        let text = preset::to_text(&preset, &root.join(SHARED_PRESET_PATH)).unwrap();
        let fragment = encode(&text).unwrap();
        assert!(
            fragment
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b"-_=".contains(&b)),
            "{fragment}"
        );
        let back = decode(&format!("#{fragment}")).unwrap().unwrap();
        let reparsed = preset::parse(&back, &root.join(SHARED_PRESET_PATH)).unwrap();
        assert_eq!(reparsed.preset.description, hostile);
        assert_eq!(reparsed.preset.scene, preset.scene);
    }

    /// A scene whose link would be too long says so, with the length, and
    /// points to the file; text that does not compress well is such a one.
    #[test]
    fn a_scene_too_large_for_a_link_says_so() {
        let mut state = 0x9e37_79b9_u32;
        let noise: String = (0..12_000)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                char::from(b'a' + (state % 26) as u8)
            })
            .collect();
        let e = encode(&format!("// {noise}\n()")).unwrap_err();
        assert!(matches!(e, LinkError::TooLarge { chars } if chars > MAX_FRAGMENT_CHARS));
        assert!(e.to_string().contains("send the file instead"));
    }

    /// An ordinary address carries no scene; a cut or edited one is named
    /// damaged rather than misread; a deflate bomb stops at the cap.
    #[test]
    fn a_damaged_link_is_refused_with_the_reason() {
        assert_eq!(decode(""), None);
        assert_eq!(decode("#section-2"), None);
        let fragment = encode("(format_version: 1)").unwrap();
        let cut = &fragment[..fragment.len() - 4];
        assert!(matches!(decode(cut), Some(Err(LinkError::Damaged(_)))));
        assert!(matches!(
            decode("#scene=not*base64"),
            Some(Err(LinkError::Damaged(why))) if why.contains("base64")
        ));
        let zeros = vec![0u8; 4 * MAX_PRESET_BYTES];
        let bomb = URL_SAFE_NO_PAD.encode(miniz_oxide::deflate::compress_to_vec(&zeros, 10));
        assert!(bomb.len() < MAX_FRAGMENT_CHARS, "a small link");
        assert!(matches!(
            decode(&format!("scene={bomb}")),
            Some(Err(LinkError::Damaged(_)))
        ));
    }
}
