//! A property written as text in a preset (`diffuse: "TX QUAD … FTX"`).
//!
//! The scene model reads such text through the reader the preset loader
//! installs around its deserialisation (`tx::read_preset_property`), so
//! that `scene` does not import `tx`, which reads the scene (issue 27's
//! import circles): serde gives a field's deserialiser no other way to
//! receive it.

use super::texture_tree::Texture;
use std::cell::Cell;

/// Reads a property's text: the field's name as the preset spells it
/// (`diffuse`, `bump`, `mask`…) and the text, to its tree or a message.
pub type TextReader = fn(field: &str, text: &str) -> Result<Texture, String>;

thread_local! {
    static READER: Cell<Option<TextReader>> = const { Cell::new(None) };
}

/// Runs `f` (a preset's deserialisation) with `reader` reading the
/// properties written as text.
pub fn with_text_reader<R>(reader: TextReader, f: impl FnOnce() -> R) -> R {
    let before = READER.with(|r| r.replace(Some(reader)));
    let out = f();
    READER.with(|r| r.set(before));
    out
}

/// `text` in field `field` read by the installed reader; without one (a
/// scene read outside a preset) refused, naming the field.
pub(crate) fn read(field: &str, text: &str) -> Result<Texture, String> {
    match READER.with(Cell::get) {
        Some(reader) => reader(field, text),
        None => Err(format!(
            "{field}: text is read only inside a preset; write it as a value or a texture"
        )),
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::Material;
    use std::path::Path;

    /// A preset reads a property's TX text; the same material read on its
    /// own (no reader installed) refuses the text, naming the field, and a
    /// field without a TX coefficient refuses it inside a preset too.
    #[test]
    fn text_is_read_by_the_presets_reader_only() {
        let material = r#"(diffuse: "UNI CD 0.7 0 0 FTX")"#;
        let e = ron::from_str::<Material>(material).unwrap_err().to_string();
        assert!(
            e.contains("diffuse: text is read only inside a preset"),
            "{e}"
        );
        let preset = format!("(format_version: 2, scene: (spheres: [(material: {material})]))");
        let loaded = crate::preset::parse(&preset, Path::new("p.ron")).unwrap();
        let diffuse = &loaded.preset.scene.spheres[0].material.diffuse;
        assert!((diffuse.eval(glam::Vec3::ZERO, glam::Vec2::ZERO).x - 0.448).abs() < 1e-3);
        let preset = preset.replace("diffuse", "roughness");
        let e = crate::preset::parse(&preset, Path::new("p.ron"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("roughness has no TX coefficient"), "{e}");
    }
}
