//! Where each number of the generated texture code comes from.
//!
//! `texture_codegen` fixes a scene's texture structure in WGSL and reads
//! every number from the `texture_params` uniform at a constant index. As
//! it generates, it records for each slot the node it reads and which of
//! its numbers ([`Slot`]): a [`ParamPlan`]. A parameter edit (an octave
//! count, a colour; `Change::MATERIAL_PARAMETERS`) keeps the structure, so
//! the plan of the code in place fills the buffer from the edited scene
//! ([`ParamPlan::evaluate`]) and no code is generated, hashed or compared.
//!
//! One function, [`Field::value`], reads a number for the generator and for
//! the plan alike: the two cannot disagree on a value, and the order is the
//! generator's own.

use marbre_core::scene::texture_tree::IMAGE_UNAVAILABLE;
use marbre_core::scene::{Child, Material, Pattern, Property, Scene, Texture};
use marbre_core::texture::ImageSet;

/// Entries in the `texture_params` uniform array (`MAX_TEXTURE_PARAMS` in
/// crates/render/shaders/scene.wgsl): 16 KiB.
pub const MAX_TEXTURE_PARAMS: usize = 1024;

/// Which tree of a material a slot's node lies in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Tree {
    Property(Property),
    LayerMask(usize),
    LayerProperty(usize, Property),
    Bump,
    /// A swatch's texture (`generate_swatches`): not a scene's, so a plan
    /// holding one is not evaluated against a scene.
    Swatch,
    /// The material itself (its emission strength).
    Material,
}

impl Tree {
    fn root(self, material: &Material) -> Option<&Texture> {
        match self {
            Tree::Property(p) => Some(material.texture(p)),
            Tree::LayerMask(l) => material.layers.get(l).map(|l| &l.mask),
            Tree::LayerProperty(l, p) => material.layers.get(l)?.texture(p),
            Tree::Bump => Some(&material.bump),
            Tree::Swatch | Tree::Material => None,
        }
    }
}

/// A step from a texture node to a nested one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Step {
    A,
    B,
    Factor,
}

impl Step {
    fn subtree(self, node: &Texture) -> Option<&Texture> {
        match self {
            Step::A => node.a.texture(),
            Step::B => node.b.texture(),
            Step::Factor => node.factor.as_deref(),
        }
    }
}

/// Which number of a node a slot holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Field {
    /// Row `i` of its mapping's point transform.
    MappingRow(usize),
    /// Row `i` of its mapping's (u, v) transform (framed mappings).
    UvRow(usize),
    /// How its mapping scales the footprint.
    FootprintScale,
    /// The pattern's own numbers ([`pattern_params`]).
    Pattern,
    /// The constant child `a` or `b`.
    Constant(Step),
    /// Ramp stop `i`: its colour and position.
    RampStop(usize),
    /// Where its image lies in the atlas.
    ImageRect,
    /// The stand-in colour of an image not loaded.
    ImageUnavailable,
    /// Math step `i`'s numbers.
    Op(usize),
    /// The material's emission strength.
    EmissionStrength,
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
            Field::Pattern => pattern_params(&node.pattern),
            Field::Constant(step) => match step {
                Step::A => constant(&node.a),
                Step::B => constant(&node.b),
                Step::Factor => None,
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
            Field::EmissionStrength => None,
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

/// The numbers of a pattern the generated code reads as one `vec4f`
/// (None for the patterns that read none: constant, noise sums, mix,
/// image).
pub(crate) fn pattern_params(pattern: &Pattern) -> Option<[f32; 4]> {
    Some(match *pattern {
        Pattern::Checker { size } => [size, size, size, 0.0],
        Pattern::Marble {
            stripe_frequency, ..
        }
        | Pattern::MassalMarble {
            stripe_frequency, ..
        } => [stripe_frequency, 0.0, 0.0, 0.0],
        Pattern::Checker2d { size, phase } => [size.x, size.y, phase, 0.0],
        Pattern::Brick {
            size,
            mortar,
            row_offset,
        } => [size.x, size.y, mortar, row_offset],
        Pattern::Tile {
            mortar_half_width,
            bevel,
        } => [mortar_half_width, bevel, 0.0, 0.0],
        Pattern::Waves {
            frequency,
            direction,
        } => [frequency, direction.x, direction.y, 0.0],
        Pattern::Cutout { sides, radius } => [radius, sides as f32, 0.0, 0.0],
        Pattern::Wood {
            ring_width,
            turbulence_amount,
            ..
        } => [ring_width, turbulence_amount, 0.0, 0.0],
        Pattern::Veins {
            frequency,
            turbulence_amount,
            ..
        } => [frequency, turbulence_amount, 0.0, 0.0],
        Pattern::Constant
        | Pattern::Fbm { .. }
        | Pattern::Turbulence { .. }
        | Pattern::Ridged { .. }
        | Pattern::Mix
        | Pattern::Image { .. } => return None,
    })
}

/// One slot of `texture_params`: the node of material `owner`'s `tree`
/// reached by `path`, and which of its numbers.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Slot {
    pub(crate) owner: usize,
    pub(crate) tree: Tree,
    pub(crate) path: Box<[Step]>,
    pub(crate) field: Field,
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
            let value = match slot.tree {
                Tree::Material => [material.emission_strength, 0.0, 0.0, 0.0],
                tree => {
                    let mut node = tree.root(material)?;
                    for step in &slot.path {
                        node = step.subtree(node)?;
                    }
                    slot.field.value(node, images)?
                }
            };
            params.push(value);
        }
        params.resize(MAX_TEXTURE_PARAMS, [0.0; 4]);
        Some(params)
    }
}

#[cfg(test)]
mod tests;
