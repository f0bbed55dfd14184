//! Raising: a property's texture tree written back as TX, the inverse of
//! lowering for the trees lowering makes. A tree with no TX form (a ramp,
//! math steps, a mix, fBm of several octaves, a mapping inside the tree…)
//! gives a message naming the construct.

use super::TxError;
use super::ast::{Attr, Attrs, Document, Frame, Rgb, Tex};
use super::lower::{
    Channel, brick_mortar, marble_settings, noise_settings, turbulence_settings, wood_settings,
};
use crate::scene::{Child, ColorEncoding, MathOp, Pattern, Texture, TextureMapping};
use glam::Vec3;

fn no_form(what: &str) -> TxError {
    TxError::Raise(format!("{what} has no TX form"))
}

/// The tree of `channel` as a TX document (frames only for ATX3D).
pub fn raise_channel(texture: &Texture, channel: Channel) -> Result<Document, TxError> {
    let Some(attr) = channel.attr() else {
        return Err(no_form("the bump, alone,"));
    };
    let (space_frame, top) = match texture.mapping {
        None => (None, texture.clone()),
        Some(TextureMapping {
            frame: Some(f),
            space: crate::scene::MappingSpace::Object,
            transform,
        }) if transform == Default::default() => (
            Some(Frame {
                origin: f.origin.to_array(),
                u: f.u_axis.to_array(),
                v: f.v_axis.to_array(),
            }),
            Texture {
                mapping: None,
                ..texture.clone()
            },
        ),
        Some(_) => {
            return Err(no_form(
                "a mapping other than an ATX3D frame (a transform, world space)",
            ));
        }
    };
    let raiser = Raiser { attr, channel };
    Ok(Document {
        space_frame,
        ..Document::new(raiser.node(&top)?)
    })
}

/// CT's trees, opacity and transmission, as one tree of the coefficient
/// `c = transmission · (1 − opacity)` they were lowered from: the two must
/// have the same patterns where both vary.
pub fn combine_transmission(opacity: &Texture, transmission: &Texture) -> Result<Texture, TxError> {
    let o = Child::Texture(Box::new(opacity.clone()));
    let t = Child::Texture(Box::new(transmission.clone()));
    Ok(Texture::from(zip(&o, &t)?))
}

fn zip(o: &Child, t: &Child) -> Result<Child, TxError> {
    let value = |c: &Child| match c {
        Child::Scalar(v) => Some(Vec3::splat(*v)),
        Child::Color(c) => Some(*c),
        Child::Texture(_) => None,
    };
    if let (Some(o), Some(t)) = (value(o), value(t)) {
        return Ok(Child::Color(t * (1.0 - o.x)));
    }
    let rebuilt = |node: &Texture, a: Child, b: Child| {
        Child::Texture(Box::new(Texture {
            a,
            b,
            ..node.clone()
        }))
    };
    match (o, t) {
        (Child::Texture(x), Child::Texture(y)) => {
            let same_shape = x.pattern == y.pattern
                && x.mapping == y.mapping
                && x.image == y.image
                && x.ops == y.ops
                && x.ramp == y.ramp
                && x.factor == y.factor;
            if x.pattern == Pattern::Constant {
                return zip(&x.a, t);
            }
            if y.pattern == Pattern::Constant {
                return zip(o, &y.a);
            }
            if !same_shape {
                return Err(no_form(
                    "an opacity and a transmission with different patterns (CT drives both)",
                ));
            }
            Ok(rebuilt(x, zip(&x.a, &y.a)?, zip(&x.b, &y.b)?))
        }
        (Child::Texture(x), v) => {
            if x.pattern == Pattern::Constant {
                return zip(&x.a, v);
            }
            Ok(rebuilt(x, zip(&x.a, v)?, zip(&x.b, v)?))
        }
        (v, Child::Texture(y)) => {
            if y.pattern == Pattern::Constant {
                return zip(v, &y.a);
            }
            Ok(rebuilt(y, zip(v, &y.a)?, zip(v, &y.b)?))
        }
        _ => unreachable!("two values are zipped above"),
    }
}

struct Raiser {
    attr: Attr,
    channel: Channel,
}

impl Raiser {
    /// A value as the coefficient that lowers to it.
    fn typed(&self, c: &Child) -> Option<Rgb> {
        let linear = match c {
            Child::Scalar(v) => Vec3::splat(*v),
            Child::Color(c) => *c,
            Child::Texture(_) => return None,
        };
        Some(ColorEncoding::Srgb.encode(linear).to_array())
    }

    fn uni(&self, c: Rgb) -> Tex {
        Tex::Uni(Attrs(vec![(self.attr, c)]))
    }

    fn child(&self, c: &Child) -> Result<Tex, TxError> {
        match self.typed(c) {
            Some(rgb) => Ok(self.uni(rgb)),
            None => match c {
                Child::Texture(t) if t.mapping.is_some() => Err(no_form(
                    "a texture with its own mapping inside another (what a MULT layer seen through a QUAD or BRIQUE cell lowers to)",
                )),
                Child::Texture(t) => self.node(t),
                _ => unreachable!("values are typed above"),
            },
        }
    }

    /// The colour of a 3D texture, which drives CD only.
    fn colour(&self, c: &Child, texture: &str) -> Result<Rgb, TxError> {
        if self.channel != Channel::Diffuse {
            return Err(no_form(&format!(
                "{texture} on {} ({texture} sets CD only)",
                self.channel.name()
            )));
        }
        self.typed(c)
            .ok_or_else(|| no_form(&format!("{texture} with a texture for a colour")))
    }

    fn node(&self, t: &Texture) -> Result<Tex, TxError> {
        if !t.ramp.is_empty() {
            return Err(no_form("a colour ramp"));
        }
        let image_scale = matches!(t.pattern, Pattern::Image { .. })
            && matches!(t.ops.as_slice(), [] | [MathOp::Scale(_)]);
        if !t.ops.is_empty() && !image_scale {
            return Err(no_form(
                "a math step (scale, bias, abs, invert, clamp, power)",
            ));
        }
        let name = t.pattern.info().name;
        let same = |a: &crate::noise::NoiseSettings, b: crate::noise::NoiseSettings, what: &str| {
            if *a == b {
                Ok(())
            } else {
                Err(no_form(&format!(
                    "a {name} pattern whose noise differs from {what}'s ({b:?})"
                )))
            }
        };
        Ok(match t.pattern {
            Pattern::Constant => self.child(&t.a)?,
            Pattern::Checker2d { size, phase } => Tex::Quad {
                even: Box::new(self.child(&t.a)?),
                odd: Box::new(self.child(&t.b)?),
                gu: Some(size.x),
                gv: Some(size.y),
                phase: (phase != 0.0).then_some(phase),
            },
            Pattern::Tile {
                mortar_half_width,
                bevel,
            } => {
                let mortar = self.typed(&t.a).ok_or_else(|| {
                    no_form("a tile whose mortar is a texture (TUILE's mortar is coefficients)")
                })?;
                Tex::Tuile {
                    mortar_half_width,
                    slope_width: bevel,
                    level: 0.0,
                    centre: Box::new(self.child(&t.b)?),
                    mortar: Attrs(vec![(self.attr, mortar)]),
                }
            }
            Pattern::Cutout { sides, radius } => Tex::Decoupage {
                inside: Box::new(self.child(&t.b)?),
                outside: Box::new(self.child(&t.a)?),
                sides,
                radius: Some(radius),
            },
            Pattern::Brick {
                size,
                mortar,
                row_offset,
            } => {
                if row_offset != 0.5 || mortar != brick_mortar(size) {
                    return Err(no_form(&format!(
                        "a brick with a row offset other than 0.5 or a joint other than {} of its smaller side",
                        super::lower::BRIQUE_MORTAR_FRACTION
                    )));
                }
                Tex::Brique {
                    brick: Box::new(self.child(&t.b)?),
                    mortar: Box::new(self.child(&t.a)?),
                    size_u: size.x,
                    size_v: Some(size.y),
                }
            }
            Pattern::Wood {
                noise,
                ring_width,
                turbulence_amount,
            } => {
                same(&noise, wood_settings(), "BOIS")?;
                Tex::Bois {
                    dark: self.colour(&t.a, "BOIS")?,
                    pale: self.colour(&t.b, "BOIS")?,
                    ring_width: Some(ring_width),
                    turbulence: Some(turbulence_amount),
                }
            }
            Pattern::Veins {
                noise,
                frequency,
                turbulence_amount,
            } => {
                same(&noise, marble_settings(noise.fractal.frequency), "MARBRE")?;
                Tex::Marbre {
                    dominant: self.colour(&t.a, "MARBRE")?,
                    veins: self.colour(&t.b, "MARBRE")?,
                    frequency,
                    turbulence: turbulence_amount,
                    turbulence_frequency: noise.fractal.frequency,
                }
            }
            Pattern::Fbm { noise } | Pattern::Turbulence { noise } => {
                let (f, a) = (noise.fractal.frequency, noise.fractal.amplitude);
                let fbm = matches!(t.pattern, Pattern::Fbm { .. });
                let keyword = if fbm { "NOISE" } else { "TURBULENCE" };
                let expected = if fbm {
                    noise_settings(f, a)
                } else {
                    turbulence_settings(f, a)
                };
                same(&noise, expected, keyword)?;
                if t.a != Child::Color(Vec3::ZERO) {
                    return Err(no_form(&format!(
                        "a {name} pattern not starting from black ({keyword} blends black to CD1)"
                    )));
                }
                let color = self.colour(&t.b, keyword)?;
                if fbm {
                    Tex::Noise {
                        color,
                        frequency: f,
                        amplitude: a,
                    }
                } else {
                    Tex::Turbulence {
                        color,
                        frequency: f,
                        amplitude: a,
                    }
                }
            }
            Pattern::Image { filter, wrap } => {
                let source = t
                    .image
                    .as_ref()
                    .ok_or_else(|| no_form("an image without a file"))?;
                let file = source.path.to_string_lossy().into_owned();
                if filter != Default::default()
                    || wrap != Default::default()
                    || source.color_space != Default::default()
                    || file.is_empty()
                    || file.contains(char::is_whitespace)
                {
                    return Err(no_form(
                        "an image filtered or wrapped otherwise than bilinear and repeated, read as linear data, or whose path holds a blank",
                    ));
                }
                if matches!(self.channel, Channel::Opacity | Channel::Transmission) {
                    return Err(no_form("an image on opacity or transmission"));
                }
                let k = match t.ops.as_slice() {
                    [MathOp::Scale(k)] => *k,
                    _ => 1.0,
                };
                let grey = ColorEncoding::Srgb.encode(Vec3::splat(k)).x;
                Tex::Image {
                    file,
                    attrs: Attrs(vec![(self.attr, [grey; 3])]),
                }
            }
            Pattern::Checker { .. }
            | Pattern::Ridged { .. }
            | Pattern::Marble { .. }
            | Pattern::MassalMarble { .. }
            | Pattern::Waves { .. }
            | Pattern::Mix
            | Pattern::Diagonal => {
                return Err(no_form(&format!(
                    "the {name} pattern (on {}; VAGUE waves only bump)",
                    self.channel.name()
                )));
            }
        })
    }
}
