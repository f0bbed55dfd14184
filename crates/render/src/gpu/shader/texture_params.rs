//! Where each number of the generated texture code comes from.
//!
//! `texture_codegen` fixes a scene's texture structure in WGSL and reads
//! every number from the `texture_params` uniform at a constant index. As
//! it generates, it records for each slot the node it reads (by its
//! `NodePath`, the name the node editor uses too) and which of its numbers
//! ([`Slot`]): a [`ParamPlan`]. A parameter edit (an octave
//! count, a colour; `Change::MATERIAL_PARAMETERS`) keeps the structure, so
//! the plan of the code in place fills the buffer from the edited scene
//! ([`ParamPlan::evaluate`]) and no code is generated, hashed or compared.
//!
//! One function, [`Field::value`], reads a number for the generator and for
//! the plan alike: the two cannot disagree on a value, and the order is the
//! generator's own.

use marbre_core::scene::node_path::{NodePath, Socket};
use marbre_core::scene::texture_graph::texture_at;
use marbre_core::scene::texture_tree::IMAGE_UNAVAILABLE;
use marbre_core::scene::{Child, Material, Scene, Texture};
use marbre_core::texture::ImageSet;

/// Entries in the `texture_params` uniform array (`MAX_TEXTURE_PARAMS` in
/// shaders/scene.wgsl): 16 KiB.
pub const MAX_TEXTURE_PARAMS: usize = 1024;

/// Which number of a node a slot holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Field {
    /// Row `i` of its mapping's point transform.
    MappingRow(usize),
    /// Row `i` of its mapping's (u, v) transform (framed mappings).
    UvRow(usize),
    /// How its mapping scales the footprint.
    FootprintScale,
    /// The pattern's own numbers ([`Pattern::numbers`]).
    Pattern,
    /// The constant child `a` or `b`.
    Constant(Socket),
    /// Ramp stop `i`: its colour and position.
    RampStop(usize),
    /// Where its image lies in the atlas.
    ImageRect,
    /// The stand-in colour of an image not loaded.
    ImageUnavailable,
    /// Math step `i`'s numbers.
    Op(usize),
}

impl Field {
    /// The number this field reads from `node`; None when the node has no
    /// such number (a plan evaluated against another structure).
    pub(crate) fn value(self, node: &Texture, images: &ImageSet) -> Option<[f32; 4]> {
        let mapping = || node.mapping.as_ref();
        match self {
            Field::MappingRow(i) => Some(mapping()?.rows()[i]),
            Field::UvRow(i) => Some(mapping()?.uv_rows()[i]),
            Field::FootprintScale => {
                let [u, v, w] = mapping()?.footprint_scale();
                Some([u, v, w, 0.0])
            }
            Field::Pattern => node.pattern.numbers(),
            Field::Constant(socket) => match socket {
                Socket::A => constant(&node.a),
                Socket::B => constant(&node.b),
                Socket::Factor => None,
            },
            Field::RampStop(i) => node
                .ramp
                .get(i)
                .map(|s| [s.color.x, s.color.y, s.color.z, s.position]),
            Field::ImageRect => images.rect(node.image.as_ref()?),
            Field::ImageUnavailable => {
                let c = IMAGE_UNAVAILABLE;
                Some([c.x, c.y, c.z, 0.0])
            }
            Field::Op(i) => node.ops.get(i).map(|op| op.params()),
        }
    }
}

fn constant(child: &Child) -> Option<[f32; 4]> {
    match child {
        Child::Scalar(v) => Some([*v, *v, *v, 0.0]),
        Child::Color(c) => Some([c.x, c.y, c.z, 0.0]),
        Child::Texture(_) => None,
    }
}

/// Where in a material a slot's number lies.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Place {
    /// A number of the texture node at the path.
    Node(NodePath, Field),
    /// The material's emission strength.
    EmissionStrength,
}

/// One slot of `texture_params`: a number of material `owner` (in
/// `Scene::materials` order; a swatch's index for swatches, whose texture
/// is their material's diffuse).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Slot {
    pub(crate) owner: usize,
    pub(crate) place: Place,
}

/// The slots of generated texture code, in order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ParamPlan {
    pub(crate) slots: Vec<Slot>,
}

impl ParamPlan {
    /// The `texture_params` of `scene` for code generated from a scene of
    /// the same texture structure, padded to [`MAX_TEXTURE_PARAMS`]; None
    /// if `scene`'s structure differs (a node or number the plan reads is
    /// missing), when the code must be generated again.
    pub fn evaluate(&self, scene: &Scene, images: &ImageSet) -> Option<Vec<[f32; 4]>> {
        let materials: Vec<&Material> = scene.materials().collect();
        let mut params = Vec::with_capacity(MAX_TEXTURE_PARAMS);
        for slot in &self.slots {
            let material = materials.get(slot.owner)?;
            let value = match &slot.place {
                Place::EmissionStrength => [material.emission_strength, 0.0, 0.0, 0.0],
                Place::Node(path, field) => field.value(texture_at(material, path)?, images)?,
            };
            params.push(value);
        }
        params.resize(MAX_TEXTURE_PARAMS, [0.0; 4]);
        Some(params)
    }
}

#[cfg(test)]
mod tests;
