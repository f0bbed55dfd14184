//! Texture trees: a pattern blending two children, each a value or a whole
//! nested texture (a checker of marbles, bricks of turbulence). Cell
//! patterns (the 2D checker, bricks) hand their children the point in the
//! cell's own unit square, so a texture nested in a cell repeats once per
//! cell.

use super::pattern::{MAX_SIGNALS, Pattern, Signal, SurfacePoint, TextureMapping};
use crate::texture;
use crate::texture::{ImageSet, ImageSource};
use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

/// What a texture node reads while the tree is evaluated: the surface point
/// (for mappings below, which start afresh from it), the current 3D point
/// and (u, v), and the mapping they came through.
#[derive(Debug, Clone, Copy)]
struct Coordinates<'a> {
    surface: SurfacePoint,
    p: Vec3,
    uv: Vec2,
    mapping: Option<TextureMapping>,
    /// The loaded images, if the caller has them.
    images: Option<&'a ImageSet>,
}

impl<'a> Coordinates<'a> {
    fn surface(point: &SurfacePoint, images: Option<&'a ImageSet>) -> Self {
        Self {
            surface: *point,
            p: point.object,
            uv: point.uv,
            mapping: None,
            images,
        }
    }
}

/// What an image node shows when its image is not at hand (the CPU
/// reference evaluated without an [`ImageSet`]).
pub const IMAGE_UNAVAILABLE: Vec3 = Vec3::splat(0.5);

/// One side of a blend: a scalar, a colour, or a whole nested texture.
///
/// In a preset it is written as what it is: `0.3`, `(0.8, 0.1, 0.1)`, or
/// `(pattern: …, a: …, b: …)`, so files from before nesting existed read
/// unchanged.
#[derive(Debug, Clone, PartialEq)]
pub enum Child {
    Scalar(f32),
    Color(Vec3),
    Texture(Box<Texture>),
}

impl From<f32> for Child {
    fn from(v: f32) -> Self {
        Child::Scalar(v)
    }
}

impl From<Vec3> for Child {
    fn from(c: Vec3) -> Self {
        Child::Color(c)
    }
}

impl From<Texture> for Child {
    fn from(t: Texture) -> Self {
        Child::Texture(Box::new(t))
    }
}

impl Serialize for Child {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Child::Scalar(v) => v.serialize(s),
            Child::Color(c) => c.serialize(s),
            Child::Texture(t) => t.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Child {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ChildVisitor { text: None })
    }
}

/// Reads TX text where a property's texture may be written as it (see
/// `scene::material`): the text → the child, or a message.
pub(crate) type TextReader<'a> = &'a dyn Fn(&str) -> Result<Child, String>;

/// Reads a [`Child`] in any of its forms, and TX text where `text` is set.
pub(crate) struct ChildVisitor<'a> {
    pub text: Option<TextReader<'a>>,
}

impl<'de> serde::de::Visitor<'de> for ChildVisitor<'_> {
    type Value = Child;
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a number, an (r, g, b) colour, or a (pattern: …, a: …, b: …) texture")?;
        if self.text.is_some() {
            f.write_str(", or TX text (\"TX … FTX\")")?;
        }
        Ok(())
    }
    fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Child, E> {
        Ok(Child::Scalar(v as f32))
    }
    fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Child, E> {
        Ok(Child::Scalar(v as f32))
    }
    fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Child, E> {
        Ok(Child::Scalar(v as f32))
    }
    fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Child, E> {
        match self.text {
            Some(read) => read(v).map_err(E::custom),
            None => Err(E::invalid_type(serde::de::Unexpected::Str(v), &self)),
        }
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<Child, A::Error> {
        Vec3::deserialize(serde::de::value::SeqAccessDeserializer::new(seq)).map(Child::Color)
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Child, A::Error> {
        Texture::deserialize(serde::de::value::MapAccessDeserializer::new(map))
            .map(|t| Child::Texture(Box::new(t)))
    }
}

impl Child {
    /// The child's colour at a point (a scalar is grey).
    pub fn eval(&self, p: Vec3, uv: Vec2) -> Vec3 {
        self.eval_in(&Coordinates::surface(&SurfacePoint::new(p, uv), None))
    }

    fn eval_in(&self, at: &Coordinates) -> Vec3 {
        match self {
            Child::Scalar(v) => Vec3::splat(*v),
            Child::Color(c) => *c,
            Child::Texture(t) => t.eval_in(at),
        }
    }

    /// The nested texture, if any.
    pub fn texture(&self) -> Option<&Texture> {
        match self {
            Child::Texture(t) => Some(t),
            _ => None,
        }
    }
}

/// A step applied to a texture's value, channel by channel (Blender's Math
/// node on the texture's output).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum MathOp {
    /// `v · factor`.
    Scale(f32),
    /// `v + offset`.
    Bias(f32),
    /// `|v|`.
    Abs,
    /// `1 - v`.
    Invert,
    /// `clamp(v, min, max)`.
    Clamp { min: f32, max: f32 },
    /// `max(v, 0)^exponent`, exponent at least [`MathOp::MIN_EXPONENT`].
    Power(f32),
}

impl MathOp {
    pub const NAMES: [&'static str; 6] = ["scale", "bias", "abs", "invert", "clamp", "power"];

    /// The smallest exponent of `Power`: `0^0` has no value.
    pub const MIN_EXPONENT: f32 = 1e-3;

    pub fn index(&self) -> usize {
        match self {
            MathOp::Scale(_) => 0,
            MathOp::Bias(_) => 1,
            MathOp::Abs => 2,
            MathOp::Invert => 3,
            MathOp::Clamp { .. } => 4,
            MathOp::Power(_) => 5,
        }
    }

    /// The operation with index `i`, with its neutral parameters.
    pub fn with_index(i: usize) -> MathOp {
        match i {
            0 => MathOp::Scale(1.0),
            1 => MathOp::Bias(0.0),
            2 => MathOp::Abs,
            3 => MathOp::Invert,
            4 => MathOp::Clamp { min: 0.0, max: 1.0 },
            _ => MathOp::Power(1.0),
        }
    }

    pub fn apply(&self, v: Vec3) -> Vec3 {
        match *self {
            MathOp::Scale(factor) => v * factor,
            MathOp::Bias(offset) => v + offset,
            MathOp::Abs => v.abs(),
            MathOp::Invert => 1.0 - v,
            MathOp::Clamp { min, max } => v.max(Vec3::splat(min)).min(Vec3::splat(max)),
            MathOp::Power(exponent) => v.max(Vec3::ZERO).powf(exponent),
        }
    }

    /// Its numbers, as the shader reads them.
    pub fn params(&self) -> [f32; 4] {
        match *self {
            MathOp::Scale(x) | MathOp::Bias(x) | MathOp::Power(x) => [x, 0.0, 0.0, 0.0],
            MathOp::Clamp { min, max } => [min, max, 0.0, 0.0],
            MathOp::Abs | MathOp::Invert => [0.0; 4],
        }
    }

    fn sanitize(&mut self, what: &str, notes: &mut Vec<String>) {
        let before = *self;
        match self {
            MathOp::Scale(x) | MathOp::Bias(x) => {
                if !x.is_finite() {
                    *x = 0.0;
                }
            }
            MathOp::Clamp { min, max } => {
                if !(min.is_finite() && max.is_finite()) {
                    (*min, *max) = (0.0, 1.0);
                }
                // WGSL leaves clamp with crossed bounds undefined.
                if *min > *max {
                    std::mem::swap(min, max);
                }
            }
            MathOp::Power(e) => {
                *e = if e.is_finite() {
                    e.clamp(Self::MIN_EXPONENT, 1e3)
                } else {
                    1.0
                };
            }
            MathOp::Abs | MathOp::Invert => {}
        }
        if *self != before {
            notes.push(format!("{what}: math step {before:?} set to {self:?}"));
        }
    }
}

/// A property across a surface: `mix(a, b, t)` with `t` from the pattern
/// (for the mix pattern, from the `factor` texture), or, when `ramp` has
/// stops, the ramp's colour at `t` (Blender's ColorRamp after a pattern: a
/// noise mapped through chosen colours); then the `ops`, in order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Texture {
    pub pattern: Pattern,
    pub a: Child,
    pub b: Child,
    /// The blend factor of [`Pattern::Mix`]: this texture's first channel.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub factor: Option<Box<Texture>>,
    /// The file [`Pattern::Image`] shows.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub image: Option<ImageSource>,
    /// Set, this texture and its subtree read the surface's coordinates
    /// through it; unset, they read what the texture above them reads.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mapping: Option<TextureMapping>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub ramp: Vec<texture::RampStop>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub ops: Vec<MathOp>,
}

impl From<Child> for Texture {
    fn from(child: Child) -> Self {
        match child {
            Child::Scalar(v) => Texture::scalar(v),
            Child::Color(c) => Texture::color(c),
            Child::Texture(t) => *t,
        }
    }
}

impl Texture {
    /// The same colour everywhere.
    pub fn color(c: Vec3) -> Self {
        Self::blend(Pattern::Constant, c, c)
    }

    /// The same value everywhere (a scalar property).
    pub fn scalar(v: f32) -> Self {
        Self::blend(Pattern::Constant, v, v)
    }

    /// `pattern` blending two children.
    pub fn blend(pattern: Pattern, a: impl Into<Child>, b: impl Into<Child>) -> Self {
        Self {
            pattern,
            a: a.into(),
            b: b.into(),
            factor: None,
            image: None,
            mapping: None,
            ramp: Vec::new(),
            ops: Vec::new(),
        }
    }

    /// `a` and `b` mixed by the first channel of `factor`.
    pub fn mix(factor: Texture, a: impl Into<Child>, b: impl Into<Child>) -> Self {
        Self {
            factor: Some(Box::new(factor)),
            ..Self::blend(Pattern::Mix, a, b)
        }
    }

    /// The plain value of a texture that is one everywhere (what
    /// [`Texture::color`] and [`Texture::scalar`] make), if it is one.
    pub fn as_constant(&self) -> Option<&Child> {
        let plain = self.pattern == Pattern::Constant
            && self.ramp.is_empty()
            && self.ops.is_empty()
            && self.factor.is_none()
            && self.mapping.is_none()
            && self.image.is_none()
            && self.a == self.b;
        (plain && !matches!(self.a, Child::Texture(_))).then_some(&self.a)
    }

    /// Whether the texture is `value` everywhere, as far as its structure
    /// shows (a constant pattern, no steps after it).
    pub fn is_constant_value(&self, value: Vec3) -> bool {
        self.pattern == Pattern::Constant
            && self.ramp.is_empty()
            && self.ops.is_empty()
            && match &self.a {
                Child::Scalar(v) => Vec3::splat(*v) == value,
                Child::Color(c) => *c == value,
                Child::Texture(t) => t.is_constant_value(value),
            }
    }

    /// The colour at a surface point `p` with coordinates `uv`, object and
    /// world coordinates being the same (the ground).
    pub fn eval(&self, p: Vec3, uv: Vec2) -> Vec3 {
        self.eval_at(&SurfacePoint::new(p, uv))
    }

    /// The colour at a surface point: the CPU reference of the shader code
    /// generated from this tree. A constant pattern never evaluates `b`.
    pub fn eval_at(&self, point: &SurfacePoint) -> Vec3 {
        self.eval_in(&Coordinates::surface(point, None))
    }

    /// [`Texture::eval_at`] with the scene's images loaded (image nodes
    /// otherwise show [`IMAGE_UNAVAILABLE`]). Images are sampled at their
    /// finest level: the CPU reference has no pixel footprint.
    pub fn eval_with(&self, point: &SurfacePoint, images: &ImageSet) -> Vec3 {
        self.eval_in(&Coordinates::surface(point, Some(images)))
    }

    fn eval_in(&self, at: &Coordinates) -> Vec3 {
        let mapped;
        let at = match &self.mapping {
            Some(m) => {
                mapped = Coordinates {
                    p: m.point(&at.surface),
                    uv: m.uv(&at.surface),
                    mapping: Some(*m),
                    ..*at
                };
                &mapped
            }
            None => at,
        };
        let value = self.blended(at);
        self.ops.iter().fold(value, |v, op| op.apply(v))
    }

    /// The value before the `ops`.
    fn blended(&self, at: &Coordinates) -> Vec3 {
        if let Pattern::Image { filter, wrap } = self.pattern {
            let color = at
                .images
                .zip(self.image.as_ref())
                .and_then(|(images, source)| images.sample(source, at.uv, filter, wrap, 0.0))
                .map_or(IMAGE_UNAVAILABLE, |c| c.truncate());
            if self.ramp.is_empty() {
                return color;
            }
            return texture::ramp(&self.ramp, texture::luminance(color));
        }
        let (t, child_uv) = match (&self.pattern, &self.factor) {
            (Pattern::Mix, Some(factor)) => (factor.eval_in(at).x.clamp(0.0, 1.0), at.uv),
            (Pattern::Mix, None) => (0.0, at.uv),
            (pattern, _) => {
                let signal = pattern.signal().map_or(0.0, |signal| {
                    Signal {
                        mapping: at.mapping,
                        ..signal
                    }
                    .eval(&at.surface)
                });
                pattern.blend(at.p, at.uv, signal)
            }
        };
        if !self.ramp.is_empty() {
            return texture::ramp(&self.ramp, t);
        }
        let child_at = Coordinates {
            uv: child_uv,
            ..*at
        };
        let a = self.a.eval_in(&child_at);
        if self.pattern == Pattern::Constant {
            return a;
        }
        a.lerp(self.b.eval_in(&child_at), t)
    }

    /// The fractal sums the tree reads, each with the mapping it is taken
    /// through (the nearest above it, from `inherited` on), in tree order,
    /// repeats included.
    pub fn signals(&self, inherited: Option<TextureMapping>) -> Vec<Signal> {
        let mapping = self.mapping.or(inherited);
        let mut out: Vec<Signal> = self
            .pattern
            .signal()
            .map(|s| Signal { mapping, ..s })
            .into_iter()
            .collect();
        for t in self.subtrees() {
            out.extend(t.signals(mapping));
        }
        out
    }

    /// The nested textures: the children's, then the mix factor.
    fn subtrees(&self) -> impl Iterator<Item = &Texture> {
        [&self.a, &self.b]
            .into_iter()
            .filter_map(Child::texture)
            .chain(self.factor.as_deref())
    }

    /// Calls `f` on every texture of the tree, this one first.
    pub fn visit(&self, f: &mut dyn FnMut(&Texture)) {
        f(self);
        for t in self.subtrees() {
            t.visit(f);
        }
    }

    /// Calls `f` on every texture of the tree, this one first.
    pub fn visit_mut(&mut self, f: &mut dyn FnMut(&mut Texture)) {
        f(self);
        for child in [&mut self.a, &mut self.b] {
            if let Child::Texture(t) = child {
                t.visit_mut(f);
            }
        }
        if let Some(factor) = &mut self.factor {
            factor.visit_mut(f);
        }
    }

    /// Whether any texture in the tree maps its blend factor through a ramp.
    pub fn has_ramp(&self) -> bool {
        !self.ramp.is_empty() || self.subtrees().any(Texture::has_ramp)
    }

    /// Every pattern in the tree, this one first.
    pub fn patterns(&self) -> Vec<&Pattern> {
        let mut out = vec![&self.pattern];
        for t in self.subtrees() {
            out.extend(t.patterns());
        }
        out
    }

    /// How deep the tree goes: 1 for a texture with value children.
    pub fn depth(&self) -> usize {
        1 + self.subtrees().map(Texture::depth).max().unwrap_or(0)
    }

    /// Clamps values into range: colours and scalars to [0, 1], each
    /// pattern's parameters to what its code handles. Trees deeper than
    /// [`Texture::MAX_DEPTH`] are cut there (the deepest textures become
    /// their `a` value).
    pub(crate) fn sanitize(&mut self, what: &str, notes: &mut Vec<String>, depth: usize) {
        self.pattern.sanitize(what, notes);
        if let Some(mapping) = &mut self.mapping {
            mapping.sanitize(what, notes);
        }
        self.sanitize_ramp(what, notes);
        for (name, child) in [("a", &mut self.a), ("b", &mut self.b)] {
            let path = format!("{what}.{name}");
            match child {
                // An infinite value clamps like a large finite one (a TX
                // `CD 1e20` whose lowering overflows is white, as `CD 2`
                // is); only NaN, which has no side, becomes 0.
                Child::Scalar(v) => {
                    let s = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
                    if s != *v {
                        notes.push(format!("{path}: {v} clamped to [0, 1]"));
                        *v = s;
                    }
                }
                Child::Color(c) => {
                    let s = Vec3::from_array(
                        c.to_array()
                            .map(|x| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) }),
                    );
                    if s != *c {
                        notes.push(format!("{path}: colour {c} clamped to [0, 1]"));
                        *c = s;
                    }
                }
                Child::Texture(t) if depth >= Self::MAX_DEPTH => {
                    notes.push(format!(
                        "{path}: textures nest at most {} deep; this one is cut",
                        Self::MAX_DEPTH
                    ));
                    *child = Child::Color(t.eval(Vec3::ZERO, Vec2::ZERO));
                }
                Child::Texture(t) => t.sanitize(&path, notes, depth + 1),
            }
        }
        match (&self.pattern, &mut self.factor) {
            (Pattern::Mix, None) => {
                notes.push(format!(
                    "{what}: a mix without a factor mixes half and half"
                ));
                self.factor = Some(Box::new(Texture::scalar(0.5)));
            }
            (Pattern::Mix, Some(factor)) if depth >= Self::MAX_DEPTH => {
                notes.push(format!(
                    "{what}.factor: textures nest at most {} deep; this one is cut",
                    Self::MAX_DEPTH
                ));
                let v = factor.eval(Vec3::ZERO, Vec2::ZERO).x;
                **factor = Texture::scalar(v);
            }
            (Pattern::Mix, Some(factor)) => {
                factor.sanitize(&format!("{what}.factor"), notes, depth + 1)
            }
            (_, factor @ Some(_)) => {
                notes.push(format!(
                    "{what}: a factor is only read by the mix pattern; dropped"
                ));
                *factor = None;
            }
            (_, None) => {}
        }
        if self.ops.len() > Self::MAX_OPS {
            notes.push(format!(
                "{what}: at most {} math steps; the rest are dropped",
                Self::MAX_OPS
            ));
            self.ops.truncate(Self::MAX_OPS);
        }
        for op in &mut self.ops {
            op.sanitize(what, notes);
        }
    }

    /// Ramp stops: at most [`texture::MAX_RAMP_STOPS`], finite, colours in
    /// [0, 1], sorted by position (the shader interpolates neighbours).
    fn sanitize_ramp(&mut self, what: &str, notes: &mut Vec<String>) {
        if self.ramp.len() > texture::MAX_RAMP_STOPS {
            notes.push(format!(
                "{what}: a ramp holds at most {} stops; the rest are dropped",
                texture::MAX_RAMP_STOPS
            ));
            self.ramp.truncate(texture::MAX_RAMP_STOPS);
        }
        for stop in &mut self.ramp {
            if !stop.position.is_finite() || !stop.color.is_finite() {
                notes.push(format!("{what}: a non-finite ramp stop set to 0"));
                *stop = texture::RampStop {
                    position: 0.0,
                    color: Vec3::ZERO,
                };
            }
            stop.color = stop.color.clamp(Vec3::ZERO, Vec3::ONE);
        }
        if !self.ramp.is_sorted_by(|x, y| x.position <= y.position) {
            notes.push(format!("{what}: ramp stops sorted by position"));
            self.ramp.sort_by(|x, y| x.position.total_cmp(&y.position));
        }
    }

    /// Patterns reading a fractal sum beyond the first [`MAX_SIGNALS`]
    /// distinct ones (in `seen`) become constant, with a note. `inherited`
    /// is the mapping the texture above reads through.
    pub(crate) fn limit_signals(
        &mut self,
        seen: &mut Vec<Signal>,
        inherited: Option<TextureMapping>,
        what: &str,
        notes: &mut Vec<String>,
    ) {
        let mapping = self.mapping.or(inherited);
        if let Some(signal) = self.pattern.signal().map(|s| Signal { mapping, ..s })
            && !seen.contains(&signal)
        {
            if seen.len() < MAX_SIGNALS {
                seen.push(signal);
            } else {
                notes.push(format!(
                    "{what}: a material reads at most {MAX_SIGNALS} distinct noises; a {} pattern became constant",
                    self.pattern.info().name
                ));
                self.pattern = Pattern::Constant;
            }
        }
        for child in [&mut self.a, &mut self.b] {
            if let Child::Texture(t) = child {
                t.limit_signals(seen, mapping, what, notes);
            }
        }
        if let Some(factor) = &mut self.factor {
            factor.limit_signals(seen, mapping, what, notes);
        }
    }

    /// The deepest nesting the panel and the shader generator accept.
    pub const MAX_DEPTH: usize = 6;

    /// The most math steps after one texture.
    pub const MAX_OPS: usize = 8;
}

impl Default for Texture {
    fn default() -> Self {
        Self::color(Vec3::splat(0.5))
    }
}
