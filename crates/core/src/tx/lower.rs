//! Lowering: a TX texture onto a material's per-property texture trees.
//!
//! Each coefficient drives a property (CD diffuse, CS specular, CR mirror,
//! CT opacity and transmission, TD diffuse transmission; TUILE's level and
//! VAGUE the bump). A subtree that does not set a coefficient keeps the
//! value below it: the material's, or what the previous MULT layer made.
//! Where the value below varies and a QUAD or BRIQUE cell would show it in
//! the cell's own space, it is given the surface's mapping back, so it
//! looks as it did under the cell (N3D computed it at the surface point).

use super::TxError;
use super::ast::{Attr, Document, Frame, Rgb, Tex};
use crate::noise::{FractalParams, NoiseSettings};
use crate::scene::{
    Child, ColorEncoding, Material, Pattern, Property, Texture, TextureMapping, UvFrame,
};
use crate::shown::shown;
use crate::texture::ImageSource;
use glam::{Vec2, Vec3};
use std::path::Path;

/// QUAD's cell size without GU and GV: the report's 8 × 8 board.
pub const QUAD_DEFAULT_CELL: f32 = 0.125;
/// DECOUPAGE's radius without RAYON: the disc inscribed in the square.
pub const DECOUPAGE_DEFAULT_RADIUS: f32 = 0.5;
/// BOIS without RAYON and TURB: the report's example's values.
pub const BOIS_DEFAULT_RING_WIDTH: f32 = 0.12;
pub const BOIS_DEFAULT_TURBULENCE: f32 = 0.3;
/// The height in scene units of a bump of 1 (TUILE's NIV3D 1, a VAGUE of
/// amplitude 1): the report gives the level without a unit.
pub const BUMP_HEIGHT: f32 = 0.02;
/// A brick's joint, as a fraction of its smaller side: BRIQUE has no
/// mortar parameter.
pub const BRIQUE_MORTAR_FRACTION: f32 = 0.1;

/// A material texture a TX text drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Channel {
    Diffuse,
    Specular,
    Mirror,
    Opacity,
    Transmission,
    DiffuseTransmission,
    Bump,
}

impl Channel {
    pub const ALL: [Channel; 7] = [
        Channel::Diffuse,
        Channel::Specular,
        Channel::Mirror,
        Channel::Opacity,
        Channel::Transmission,
        Channel::DiffuseTransmission,
        Channel::Bump,
    ];

    /// The coefficient that drives it (the bump has none: TUILE and VAGUE).
    pub fn attr(self) -> Option<Attr> {
        match self {
            Channel::Diffuse => Some(Attr::Cd),
            Channel::Specular => Some(Attr::Cs),
            Channel::Mirror => Some(Attr::Cr),
            Channel::Opacity | Channel::Transmission => Some(Attr::Ct),
            Channel::DiffuseTransmission => Some(Attr::Td),
            Channel::Bump => None,
        }
    }

    /// The channel of a material property; roughness and emission have no
    /// TX coefficient.
    pub fn for_property(property: Property) -> Option<Channel> {
        match property {
            Property::Diffuse => Some(Channel::Diffuse),
            Property::Specular => Some(Channel::Specular),
            Property::Mirror => Some(Channel::Mirror),
            Property::Opacity => Some(Channel::Opacity),
            Property::Transmission => Some(Channel::Transmission),
            Property::DiffuseTransmission => Some(Channel::DiffuseTransmission),
            Property::Roughness | Property::Emission => None,
        }
    }

    pub fn texture(self, m: &Material) -> &Texture {
        match self.property() {
            Some(p) => m.texture(p),
            None => &m.bump,
        }
    }

    pub fn texture_mut(self, m: &mut Material) -> &mut Texture {
        match self.property() {
            Some(p) => m.texture_mut(p),
            None => &mut m.bump,
        }
    }

    /// The material property it is (the bump is not one).
    pub fn property(self) -> Option<Property> {
        match self {
            Channel::Diffuse => Some(Property::Diffuse),
            Channel::Specular => Some(Property::Specular),
            Channel::Mirror => Some(Property::Mirror),
            Channel::Opacity => Some(Property::Opacity),
            Channel::Transmission => Some(Property::Transmission),
            Channel::DiffuseTransmission => Some(Property::DiffuseTransmission),
            Channel::Bump => None,
        }
    }

    pub fn name(self) -> &'static str {
        self.property().map_or("bump", Property::name)
    }
}

/// How the colours typed in a text reach the tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Colors {
    /// Decoded to linear (what TX means): files, the panel, `marbre tx`.
    Linear,
    /// Colour properties' values kept as typed, for a preset whose `colors`
    /// decodes them after reading; the values derived from colours (CR's
    /// mirror, CT's opacity) are computed from the decoded colour, and
    /// CT's transmission is encoded back.
    AsTyped,
}

/// Where lowering reads from: which channel, how colours go, where image
/// files are, and the mapping that reads the surface afresh.
struct Ctx<'a> {
    channel: Channel,
    colors: Colors,
    base_dir: &'a Path,
    surface: TextureMapping,
}

/// A document lowered: the material, and the frames that belong to the
/// object rather than to its material.
#[derive(Debug, Clone, PartialEq)]
pub struct Lowered {
    pub material: Material,
    /// `ATX`: the polygon's (u, v) frame.
    pub polygon_frame: Option<UvFrame>,
    /// `APTX`: the plane's (u, v) frame.
    pub plane_frame: Option<UvFrame>,
}

pub fn uv_frame(f: &Frame) -> UvFrame {
    UvFrame {
        origin: Vec3::from(f.origin),
        u_axis: Vec3::from(f.u),
        v_axis: Vec3::from(f.v),
    }
}

/// The mapping `ATX3D` gives a tree: the 3D texture point is the surface
/// point's coordinates in the frame.
pub fn space_mapping(f: &Frame) -> TextureMapping {
    TextureMapping {
        frame: Some(uv_frame(f)),
        ..TextureMapping::default()
    }
}

/// Every attribute of `doc` lowered onto `base`, image files resolved
/// against `base_dir`.
pub fn lower_document(
    doc: &Document,
    base: &Material,
    base_dir: &Path,
) -> Result<Lowered, TxError> {
    let mut material = base.clone();
    for channel in Channel::ALL {
        *channel.texture_mut(&mut material) = lower_channel(
            doc,
            channel,
            channel.texture(base),
            base_dir,
            Colors::Linear,
        )?;
    }
    if sets(&doc.texture, Channel::Bump) {
        material.bump_height = BUMP_HEIGHT;
    }
    Ok(Lowered {
        material,
        polygon_frame: doc.polygon_frame.as_ref().map(uv_frame),
        plane_frame: doc.plane_frame.as_ref().map(uv_frame),
    })
}

/// One channel of `doc` lowered over `base` (its value wherever the text
/// does not set the channel).
pub fn lower_channel(
    doc: &Document,
    channel: Channel,
    base: &Texture,
    base_dir: &Path,
    colors: Colors,
) -> Result<Texture, TxError> {
    if !sets(&doc.texture, channel) {
        return Ok(base.clone());
    }
    let top = doc.space_frame.as_ref().map(space_mapping);
    let ctx = Ctx {
        channel,
        colors,
        base_dir,
        surface: top.unwrap_or_default(),
    };
    let below = match base.as_constant() {
        Some(value) => value.clone(),
        None => Child::Texture(Box::new(base.clone())),
    };
    // The text sets the channel, so the value is made by one of its
    // constructs, never `base` passed through whole: each node made is
    // within the depth a material holds, and a construct that would go
    // deeper is refused here, where the text wrote it.
    let mut texture = match lower(&doc.texture, &Made::Value(below), true, &ctx)? {
        Made::Value(child) => Texture::from(child),
        Made::TooDeep { construct, depth } => {
            let message = format!(
                "{} would nest the {} texture {depth} deep; a material's textures nest at most {} deep",
                construct.keyword(),
                channel.name(),
                Texture::MAX_DEPTH
            );
            return Err(match doc.place_of(construct) {
                Some((line, column)) => TxError::LowerAt {
                    line,
                    column,
                    message,
                },
                None => TxError::Lower(message),
            });
        }
    };
    if texture.mapping.is_none() && texture.pattern != Pattern::Constant {
        texture.mapping = top;
    }
    Ok(texture)
}

/// Whether `t` sets `channel` anywhere.
pub fn sets(t: &Tex, channel: Channel) -> bool {
    let attr = channel.attr();
    let has = |a: &super::ast::Attrs| attr.is_some_and(|attr| a.get(attr).is_some());
    match t {
        Tex::Uni(a) | Tex::Image { attrs: a, .. } => has(a),
        Tex::Quad { even, odd, .. } => sets(even, channel) || sets(odd, channel),
        Tex::Tuile { centre, mortar, .. } => {
            channel == Channel::Bump || has(mortar) || sets(centre, channel)
        }
        Tex::Mult(layers) => layers.iter().any(|l| sets(l, channel)),
        Tex::Decoupage {
            inside, outside, ..
        } => sets(inside, channel) || sets(outside, channel),
        Tex::Brique { brick, mortar, .. } => sets(brick, channel) || sets(mortar, channel),
        Tex::Noise { .. } | Tex::Turbulence { .. } | Tex::Bois { .. } | Tex::Marbre { .. } => {
            channel == Channel::Diffuse
        }
        Tex::Vague { .. } => channel == Channel::Bump,
    }
}

/// The value a typed coefficient gives the channel.
fn leaf(typed: Rgb, ctx: &Ctx) -> Child {
    let linear = ColorEncoding::Srgb.decode(Vec3::from(typed));
    let as_typed = ctx.colors == Colors::AsTyped;
    match ctx.channel {
        Channel::Mirror => Child::Scalar(linear.max_element()),
        Channel::Opacity => Child::Scalar(1.0 - linear.max_element()),
        Channel::Transmission => {
            let peak = linear.max_element();
            let tint = if peak > 0.0 { linear / peak } else { Vec3::ONE };
            Child::Color(if as_typed {
                ColorEncoding::Srgb.encode(tint)
            } else {
                tint
            })
        }
        _ if as_typed => Child::Color(Vec3::from(typed)),
        _ => Child::Color(linear),
    }
}

/// What lowering makes of a texture: its value, or the first construct
/// whose node would have nested the tree deeper than a material holds
/// ([`Texture::MAX_DEPTH`]), and how deep. That node is never built, so
/// no value lowering holds is deeper than the limit: each has at most
/// 2^MAX_DEPTH − 1 nodes of lowering's making, and each construct of the
/// text costs a few copies of one at most. (The depth used to be checked on the
/// finished tree, after each MULT layer over a DECOUPAGE or TUILE had
/// doubled it: 22 layers, two kilobytes of text, took 3 GB.) It is carried
/// rather than returned as an error at once because a later MULT layer may
/// cover it: a text whose final tree fits lowers as it did before.
#[derive(Clone)]
enum Made<'a> {
    Value(Child),
    TooDeep { construct: &'a Tex, depth: usize },
}

impl From<Child> for Made<'_> {
    fn from(child: Child) -> Self {
        Made::Value(child)
    }
}

/// `construct`'s `pattern` over two children; equal values make a value,
/// and a node deeper than a material holds is not made.
fn blend<'a>(
    construct: &'a Tex,
    pattern: Pattern,
    a: impl Into<Made<'a>>,
    b: impl Into<Made<'a>>,
) -> Made<'a> {
    let (a, b) = match (a.into(), b.into()) {
        (Made::Value(a), Made::Value(b)) => (a, b),
        (too_deep @ Made::TooDeep { .. }, _) | (_, too_deep @ Made::TooDeep { .. }) => {
            return too_deep;
        }
    };
    if a == b && !matches!(a, Child::Texture(_)) {
        return Made::Value(a);
    }
    let depth = 1 + [&a, &b]
        .into_iter()
        .filter_map(Child::texture)
        .map(Texture::depth)
        .max()
        .unwrap_or(0);
    if depth > Texture::MAX_DEPTH {
        return Made::TooDeep { construct, depth };
    }
    Made::Value(Child::Texture(Box::new(Texture::blend(pattern, a, b))))
}

/// What a cell's texture sees below it: a varying value from the surface's
/// space gets the surface's mapping back.
fn in_cell<'a>(below: &Made<'a>, surface: bool, ctx: &Ctx) -> Made<'a> {
    match below {
        Made::Value(Child::Texture(t)) if surface && t.mapping.is_none() => {
            Made::Value(Child::Texture(Box::new(Texture {
                mapping: Some(ctx.surface),
                ..(**t).clone()
            })))
        }
        other => other.clone(),
    }
}

fn positive(value: f32, what: &str) -> Result<f32, TxError> {
    if value > 0.0 {
        Ok(value)
    } else {
        Err(TxError::Lower(format!(
            "{what} must be positive, not {value}"
        )))
    }
}

fn level(value: f32, what: &str) -> Result<f32, TxError> {
    if (0.0..=1.0).contains(&value) {
        Ok(value)
    } else {
        Err(TxError::Lower(format!(
            "{what} is a level from 0 to 1 (a bump of {BUMP_HEIGHT} scene units at 1), not {value}"
        )))
    }
}

fn noise(octaves: f32, frequency: f32, amplitude: f32) -> NoiseSettings {
    NoiseSettings {
        fractal: FractalParams {
            octaves,
            frequency,
            amplitude,
            ..FractalParams::default()
        },
        ..NoiseSettings::default()
    }
}

/// NOISE: one octave of the lab's gradient noise (the report's noise
/// interpolates 8 lattice values).
pub fn noise_settings(frequency: f32, amplitude: f32) -> NoiseSettings {
    noise(1.0, frequency, amplitude)
}

/// TURBULENCE: five octaves of |gradient noise|.
pub fn turbulence_settings(frequency: f32, amplitude: f32) -> NoiseSettings {
    noise(5.0, frequency, amplitude)
}

/// BOIS's turbulence: four octaves at frequency 3 (the report gives none).
pub fn wood_settings() -> NoiseSettings {
    noise(4.0, 3.0, 1.0)
}

/// MARBRE's turbulence: four octaves at FREQTURB.
pub fn marble_settings(turbulence_frequency: f32) -> NoiseSettings {
    noise(4.0, turbulence_frequency, 1.0)
}

/// BRIQUE's joint for bricks of `size`.
pub fn brick_mortar(size: Vec2) -> f32 {
    BRIQUE_MORTAR_FRACTION * size.min_element()
}

/// `t` lowered for one channel over `below`; `surface` says whether the
/// coordinates here are the surface's (not a cell's).
fn lower<'a>(t: &'a Tex, below: &Made<'a>, surface: bool, ctx: &Ctx) -> Result<Made<'a>, TxError> {
    if !sets(t, ctx.channel) {
        return Ok(below.clone());
    }
    let attr = ctx.channel.attr();
    Ok(match t {
        Tex::Uni(a) => leaf(attr.and_then(|x| a.get(x)).unwrap_or_default(), ctx).into(),
        Tex::Quad {
            even,
            odd,
            gu,
            gv,
            phase,
        } => {
            let size = Vec2::new(
                positive(gu.unwrap_or(QUAD_DEFAULT_CELL), "QUAD's GU")?,
                positive(gv.unwrap_or(QUAD_DEFAULT_CELL), "QUAD's GV")?,
            );
            let inner = in_cell(below, surface, ctx);
            blend(
                t,
                Pattern::Checker2d {
                    size,
                    phase: phase.unwrap_or(0.0),
                },
                lower(even, &inner, false, ctx)?,
                lower(odd, &inner, false, ctx)?,
            )
        }
        Tex::Tuile {
            mortar_half_width,
            slope_width,
            level: niv3d,
            centre,
            mortar,
        } => {
            let pattern = Pattern::Tile {
                mortar_half_width: *mortar_half_width,
                bevel: slope_width.max(0.0),
            };
            if ctx.channel == Channel::Bump {
                blend(
                    t,
                    pattern,
                    Child::Scalar(0.0),
                    Child::Scalar(level(*niv3d, "TUILE's NIV3D")?),
                )
            } else {
                let joint = match attr.and_then(|x| mortar.get(x)) {
                    Some(c) => leaf(c, ctx).into(),
                    None => below.clone(),
                };
                blend(t, pattern, joint, lower(centre, below, surface, ctx)?)
            }
        }
        Tex::Mult(layers) => {
            let mut value = below.clone();
            for layer in layers {
                value = lower(layer, &value, surface, ctx)?;
            }
            value
        }
        Tex::Image { file, attrs } => {
            let typed = attr.and_then(|x| attrs.get(x)).unwrap_or_default();
            image(file, typed, ctx)?.into()
        }
        Tex::Decoupage {
            inside,
            outside,
            sides,
            radius,
        } => blend(
            t,
            Pattern::Cutout {
                sides: *sides,
                radius: radius.unwrap_or(DECOUPAGE_DEFAULT_RADIUS),
            },
            lower(outside, below, surface, ctx)?,
            lower(inside, below, surface, ctx)?,
        ),
        Tex::Noise {
            color,
            frequency,
            amplitude,
        } => blend(
            t,
            Pattern::Fbm {
                noise: noise_settings(*frequency, *amplitude),
            },
            Child::Color(Vec3::ZERO),
            leaf(*color, ctx),
        ),
        Tex::Turbulence {
            color,
            frequency,
            amplitude,
        } => blend(
            t,
            Pattern::Turbulence {
                noise: turbulence_settings(*frequency, *amplitude),
            },
            Child::Color(Vec3::ZERO),
            leaf(*color, ctx),
        ),
        Tex::Bois {
            dark,
            pale,
            ring_width,
            turbulence,
        } => blend(
            t,
            Pattern::Wood {
                noise: wood_settings(),
                ring_width: positive(
                    ring_width.unwrap_or(BOIS_DEFAULT_RING_WIDTH),
                    "BOIS's RAYON",
                )?,
                turbulence_amount: turbulence.unwrap_or(BOIS_DEFAULT_TURBULENCE),
            },
            leaf(*dark, ctx),
            leaf(*pale, ctx),
        ),
        Tex::Marbre {
            dominant,
            veins,
            frequency,
            turbulence,
            turbulence_frequency,
        } => blend(
            t,
            Pattern::Veins {
                noise: marble_settings(*turbulence_frequency),
                frequency: *frequency,
                turbulence_amount: *turbulence,
            },
            leaf(*dominant, ctx),
            leaf(*veins, ctx),
        ),
        Tex::Brique {
            brick,
            mortar,
            size_u,
            size_v,
        } => {
            let size = Vec2::new(
                positive(*size_u, "BRIQUE's width")?,
                positive(size_v.unwrap_or(*size_u), "BRIQUE's height")?,
            );
            let inner = in_cell(below, surface, ctx);
            blend(
                t,
                Pattern::Brick {
                    size,
                    mortar: brick_mortar(size),
                    row_offset: 0.5,
                },
                lower(mortar, &inner, false, ctx)?,
                lower(brick, &inner, false, ctx)?,
            )
        }
        Tex::Vague {
            frequency,
            amplitude,
        } => blend(
            t,
            Pattern::Waves {
                frequency: *frequency,
                direction: Vec2::X,
            },
            Child::Scalar(0.0),
            Child::Scalar(level(*amplitude, "VAGUE's amplitude")?),
        ),
    })
}

/// IMAGE: the file's colour times the coefficient, which must be a grey
/// (the tree scales a value; it has no colour product).
fn image(file: &str, typed: Rgb, ctx: &Ctx) -> Result<Child, TxError> {
    if matches!(ctx.channel, Channel::Opacity | Channel::Transmission) {
        return Err(TxError::Lower(format!(
            "IMAGE {}: CT through an image has no form in the material (opacity and tint from one picture)",
            shown(file)
        )));
    }
    if typed[0] != typed[1] || typed[1] != typed[2] {
        return Err(TxError::Lower(format!(
            "IMAGE {}: {} {} {} {} is not a grey; an image can only be scaled by a grey",
            shown(file),
            ctx.channel.attr().map_or("", Attr::keyword),
            typed[0],
            typed[1],
            typed[2]
        )));
    }
    let k = ColorEncoding::Srgb.decode(Vec3::splat(typed[0])).x;
    let path = Path::new(file);
    let mut texture = Texture {
        image: Some(ImageSource {
            path: if path.is_relative() {
                ctx.base_dir.join(path)
            } else {
                path.to_owned()
            },
            color_space: Default::default(),
        }),
        ..Texture::blend(
            Pattern::Image {
                filter: Default::default(),
                wrap: Default::default(),
            },
            0.0,
            0.0,
        )
    };
    if k != 1.0 {
        texture.ops.push(crate::scene::MathOp::Scale(k));
    }
    Ok(Child::Texture(Box::new(texture)))
}
