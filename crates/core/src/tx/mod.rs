//! TX, the texture language of the IFT528 report (Arbre de Textures 2D +
//! 3D, 2001): `TX texture FTX` at the attribute level of an N3D scene,
//! beside the `ATX`, `APTX` and `ATX3D` application frames. One purpose
//! per file: `lexer` (tokens with line and column), `ast`, `parser`,
//! `printer`, `lower` (a text onto a material's texture trees) and `raise`
//! (a property's tree back to text, where it has a TX form). The grammar
//! accepted and every choice made are in docs/VIEWER.md, section "TX".

pub mod ast;
pub mod lexer;
pub mod lower;
pub mod parser;
pub mod printer;
pub mod raise;

pub use ast::{Attr, Attrs, Document, Frame, FrameKind, Rgb, Tex};
pub use lower::{Channel, Colors, Lowered, lower_channel, lower_document};
pub use parser::parse;
pub use printer::print;

use crate::scene::{Material, Property};
use std::path::Path;

/// What can go wrong with a TX text: a syntax error where it is, or a
/// construct that has no form on the other side.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TxError {
    #[error("TX line {line}, column {column}: expected {expected}, found {found}")]
    Syntax {
        line: usize,
        column: usize,
        expected: String,
        found: String,
    },
    #[error("TX: {0}")]
    Lower(String),
    /// What cannot be lowered, where the text wrote it.
    #[error("TX line {line}, column {column}: {message}")]
    LowerAt {
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{0}")]
    Raise(String),
}

impl TxError {
    pub(crate) fn syntax(line: usize, column: usize, expected: &str, found: &str) -> Self {
        TxError::Syntax {
            line,
            column,
            expected: expected.to_owned(),
            found: found.to_owned(),
        }
    }
}

fn channel_of(property: Property) -> Result<Channel, TxError> {
    Channel::for_property(property).ok_or_else(|| {
        TxError::Raise(format!(
            "{} has no TX coefficient (CD diffuse, CS specular, CR mirror, CT opacity and transmission, TD diffuse transmission)",
            property.name()
        ))
    })
}

/// The channels one property's text drives: CT drives opacity and
/// transmission together.
fn channels_of(property: Property) -> Result<Vec<Channel>, TxError> {
    Ok(match channel_of(property)? {
        Channel::Opacity | Channel::Transmission => vec![Channel::Opacity, Channel::Transmission],
        c => vec![c],
    })
}

/// `property`'s tree as TX text (`TX … FTX`, after `ATX3D … FATX3D` where
/// the tree has a frame); opacity and transmission raise together as CT.
pub fn raise_property(material: &Material, property: Property) -> Result<String, TxError> {
    let channel = channel_of(property)?;
    let doc = match channel {
        Channel::Opacity | Channel::Transmission => raise::raise_channel(
            &raise::combine_transmission(&material.opacity, &material.transmission)?,
            channel,
        )?,
        _ => raise::raise_channel(material.texture(property), channel)?,
    };
    Ok(print(&doc))
}

/// Sets `property` (opacity and transmission together for CT) from the
/// TX text, its images resolved against `base_dir`; on error the material
/// is left as it was. The text's ATX and APTX frames belong to an object,
/// not a material, and are refused here.
pub fn apply_to_property(
    material: &mut Material,
    property: Property,
    text: &str,
    base_dir: &Path,
) -> Result<(), TxError> {
    let doc = parse(text)?;
    if doc.polygon_frame.is_some() || doc.plane_frame.is_some() {
        return Err(TxError::Lower(
            "ATX and APTX set an object's (u, v) frame, not a material property".into(),
        ));
    }
    let channels = channels_of(property)?;
    let mut lowered = Vec::new();
    for &channel in &channels {
        let base = channel.texture(material);
        lowered.push(lower_channel(
            &doc,
            channel,
            base,
            base_dir,
            Colors::Linear,
        )?);
    }
    for (channel, texture) in channels.into_iter().zip(lowered) {
        *channel.texture_mut(material) = texture;
    }
    Ok(())
}

thread_local! {
    /// How TX text inside the preset being read lowers its colours (set by
    /// [`with_preset_colors`] around the preset's deserialisation, which
    /// has no other way to hand it down to a field).
    static PRESET_TX_COLORS: std::cell::Cell<Colors> = const { std::cell::Cell::new(Colors::Linear) };
}

/// Runs `f` (a preset's deserialisation) with TX text lowering its colours
/// as `colors` says: TX colours are display values, so in a linear preset
/// they are decoded as they are read ([`Colors::Linear`]); in an sRGB one
/// the preset decodes every colour afterwards and they are kept as typed
/// ([`Colors::AsTyped`]), so that neither is decoded twice.
pub fn with_preset_colors<R>(colors: Colors, f: impl FnOnce() -> R) -> R {
    let before = PRESET_TX_COLORS.with(|c| c.replace(colors));
    let out = f();
    PRESET_TX_COLORS.with(|c| c.set(before));
    out
}

/// The reader of a preset's properties written as text
/// (`scene::text_property`, installed by `preset::parse`): the TX text of
/// field `field` lowered onto the default material's value of its
/// coefficient (CD for diffuse, CT's opacity or transmission, TUILE and
/// VAGUE for the bump).
pub fn read_preset_property(field: &str, text: &str) -> Result<crate::scene::Texture, String> {
    let Some(channel) = Channel::ALL.into_iter().find(|c| c.name() == field) else {
        return Err(format!(
            "{field} has no TX coefficient; write it as a value or a texture"
        ));
    };
    let base = Material::default();
    lower_preset_property(text, channel, channel.texture(&base)).map_err(|e| e.to_string())
}

/// One property's tree from the TX text a preset holds in its place:
/// colours decoded from display values once (see [`with_preset_colors`]),
/// image paths as written (the preset resolves them against its folder).
pub fn lower_preset_property(
    text: &str,
    channel: Channel,
    base: &crate::scene::Texture,
) -> Result<crate::scene::Texture, TxError> {
    let colors = PRESET_TX_COLORS.with(|c| c.get());
    lower_channel(&parse(text)?, channel, base, Path::new(""), colors)
}

#[cfg(test)]
mod tests;
