//! Materials and the procedural textures that drive their properties.
//!
//! A texture is a small tree: a pattern gives a blend factor `t` in [0, 1]
//! between two children, each a value or a whole texture of its own (a
//! checker of marbles, bricks of turbulence). Cell patterns (the 2D checker,
//! bricks) hand their children the point in the cell's own unit square, so
//! a texture nested in a cell repeats once per cell.

use crate::noise::{FractalParams, NoiseSettings, fbm, turbulence};
use crate::texture;
use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

/// The most distinct fractal sums (noise signals) one material's textures
/// may read: the shader evaluates each once per hit (`MAX_SIGNALS` in
/// shaders/scene.wgsl).
pub const MAX_SIGNALS: usize = 4;

/// What drives a property across a surface. Each pattern yields a blend
/// factor `t` in [0, 1] between the texture's two children: `a` where
/// `t = 0`, `b` where `t = 1`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum Pattern {
    /// `t = 0`: the first value everywhere.
    #[default]
    Constant,
    /// A 3D checkerboard of cubes of side `size`: `t` is 0 or 1.
    Checker { size: f32 },
    /// `t = 0.5 + 0.5 · fbm(p)`, clamped.
    Fbm { noise: NoiseSettings },
    /// `t = turbulence(p)` (a sum of |noise|), clamped.
    Turbulence { noise: NoiseSettings },
    /// `t = 0.5 + 0.5 · sin(p.x · stripe_frequency + fbm(p))`.
    Marble {
        noise: NoiseSettings,
        stripe_frequency: f32,
    },
    /// A board over the surface's (u, v) with cells of `size`, odd rows
    /// shifted by `phase` of a cell: `a` in even cells, `b` in odd ones, each
    /// seeing the cell as its whole (u, v) square.
    Checker2d { size: Vec2, phase: f32 },
    /// Bricks of `size` in (u, v), `mortar` wide joints, odd rows shifted by
    /// `row_offset`: `a` is the mortar, `b` the bricks (each brick its own
    /// unit square for a nested texture).
    Brick {
        size: Vec2,
        mortar: f32,
        row_offset: f32,
    },
    /// One tile per unit (u, v) square (lay it in a checker): `a` the mortar
    /// `mortar_half_width` wide along the edges, `b` the tile, which rises
    /// from the mortar over a `bevel` wide edge (0: a step). As a bump
    /// texture it raises the tiles.
    Tile {
        mortar_half_width: f32,
        #[serde(default)]
        bevel: f32,
    },
    /// Parallel waves across (u, v): `t = 0.5 + 0.5 · sin(2π · frequency ·
    /// direction·uv)`. As a bump texture it ripples the surface.
    Waves { frequency: f32, direction: Vec2 },
    /// A regular polygon of `sides` sides (a disc below 3) of circumradius
    /// `radius`, centred in every unit (u, v) square: `a` outside, `b` inside.
    Cutout { sides: u32, radius: f32 },
    /// Rings of `ring_width` around an axis tilted 15° from z, their radius
    /// perturbed by `turbulence_amount · turbulence(p)`: `a` dark, `b` pale.
    Wood {
        noise: NoiseSettings,
        ring_width: f32,
        turbulence_amount: f32,
    },
    /// The texture report's marble: `t = max(0, sin(frequency · x +
    /// turbulence_amount · turbulence(p)))`: `a` the dominant colour, `b` the
    /// veins.
    Veins {
        noise: NoiseSettings,
        frequency: f32,
        turbulence_amount: f32,
    },
}

impl Pattern {
    pub const NAMES: [&'static str; 12] = [
        "constant",
        "checker 3D",
        "fBm",
        "turbulence",
        "marble",
        "checker (uv)",
        "brick",
        "tile",
        "cutout",
        "wood",
        "veins",
        "waves",
    ];

    /// Index into [`Pattern::NAMES`]; also the pattern id in the shader.
    pub fn index(&self) -> usize {
        match self {
            Pattern::Constant => 0,
            Pattern::Checker { .. } => 1,
            Pattern::Fbm { .. } => 2,
            Pattern::Turbulence { .. } => 3,
            Pattern::Marble { .. } => 4,
            Pattern::Checker2d { .. } => 5,
            Pattern::Brick { .. } => 6,
            Pattern::Tile { .. } => 7,
            Pattern::Cutout { .. } => 8,
            Pattern::Wood { .. } => 9,
            Pattern::Veins { .. } => 10,
            Pattern::Waves { .. } => 11,
        }
    }

    /// The pattern with index `i`, keeping the noise settings of `self` where
    /// both have some, so switching the dropdown does not lose the tuning.
    pub fn with_index(&self, i: usize) -> Pattern {
        let noise = self.noise().copied().unwrap_or_default();
        match i {
            1 => Pattern::Checker { size: 1.0 },
            2 => Pattern::Fbm { noise },
            3 => Pattern::Turbulence { noise },
            4 => Pattern::Marble {
                noise,
                stripe_frequency: 4.0,
            },
            5 => Pattern::Checker2d {
                size: Vec2::splat(0.125),
                phase: 0.0,
            },
            6 => Pattern::Brick {
                size: Vec2::new(0.25, 0.1),
                mortar: 0.01,
                row_offset: 0.5,
            },
            7 => Pattern::Tile {
                mortar_half_width: 0.02,
                bevel: 0.02,
            },
            8 => Pattern::Cutout {
                sides: 0,
                radius: 0.4,
            },
            9 => Pattern::Wood {
                noise,
                ring_width: 0.12,
                turbulence_amount: 0.3,
            },
            10 => Pattern::Veins {
                noise,
                frequency: 10.0,
                turbulence_amount: 5.0,
            },
            11 => Pattern::Waves {
                frequency: 4.0,
                direction: Vec2::X,
            },
            _ => Pattern::Constant,
        }
    }

    pub fn noise(&self) -> Option<&NoiseSettings> {
        match self {
            Pattern::Fbm { noise }
            | Pattern::Turbulence { noise }
            | Pattern::Marble { noise, .. }
            | Pattern::Wood { noise, .. }
            | Pattern::Veins { noise, .. } => Some(noise),
            _ => None,
        }
    }

    pub fn noise_mut(&mut self) -> Option<&mut NoiseSettings> {
        match self {
            Pattern::Fbm { noise }
            | Pattern::Turbulence { noise }
            | Pattern::Marble { noise, .. }
            | Pattern::Wood { noise, .. }
            | Pattern::Veins { noise, .. } => Some(noise),
            _ => None,
        }
    }

    /// The fractal sum this pattern reads, as (settings, sums |noise|):
    /// the shader evaluates each distinct one once per hit (a signal).
    pub fn signal(&self) -> Option<(NoiseSettings, bool)> {
        let noise = *self.noise()?;
        let absolute = matches!(
            self,
            Pattern::Turbulence { .. } | Pattern::Wood { .. } | Pattern::Veins { .. }
        );
        Some((noise, absolute))
    }

    /// The blend factor at a point, given the pattern's signal value there,
    /// and the (u, v) its children see. CPU twin of the generated WGSL.
    fn blend(&self, p: Vec3, uv: Vec2, signal: f32) -> (f32, Vec2) {
        match *self {
            Pattern::Constant => (0.0, uv),
            Pattern::Checker { size } => (texture::checker_3d(p, Vec3::splat(size)), uv),
            Pattern::Fbm { .. } => ((0.5 + 0.5 * signal).clamp(0.0, 1.0), uv),
            Pattern::Turbulence { .. } => (signal.clamp(0.0, 1.0), uv),
            Pattern::Marble {
                stripe_frequency, ..
            } => (0.5 + 0.5 * (p.x * stripe_frequency + signal).sin(), uv),
            Pattern::Checker2d { size, phase } => {
                let cell = texture::checker_2d(uv, size, phase);
                (cell.select, cell.local)
            }
            Pattern::Brick {
                size,
                mortar,
                row_offset,
            } => {
                let cell = texture::brick(uv, size, mortar, row_offset);
                (cell.select, cell.local)
            }
            Pattern::Tile {
                mortar_half_width,
                bevel,
            } => (texture::tile_height(uv, mortar_half_width, bevel), uv),
            Pattern::Waves {
                frequency,
                direction,
            } => (texture::waves(uv, frequency, direction), uv),
            Pattern::Cutout { sides, radius } => (texture::cutout(uv, sides, radius), uv),
            Pattern::Wood {
                ring_width,
                turbulence_amount,
                ..
            } => (
                texture::wood::rings(
                    p,
                    texture::default_axis(),
                    ring_width,
                    turbulence_amount * signal,
                ),
                uv,
            ),
            Pattern::Veins {
                frequency,
                turbulence_amount,
                ..
            } => (
                (frequency * p.x + turbulence_amount * signal)
                    .sin()
                    .max(0.0),
                uv,
            ),
        }
    }

    fn sanitize(&mut self, what: &str, notes: &mut Vec<String>) {
        if let Pattern::Checker { size } = self
            && !(size.is_finite() && *size > 1e-4)
        {
            notes.push(format!("{what}: checker size {size} set to 1"));
            *size = 1.0;
        }
        if let Pattern::Marble {
            stripe_frequency, ..
        } = self
            && !stripe_frequency.is_finite()
        {
            notes.push(format!("{what}: marble stripe frequency reset"));
            *stripe_frequency = 4.0;
        }
        let mut positive = |name: &str, v: &mut f32, fallback: f32| {
            if !(v.is_finite() && *v > 1e-4) {
                notes.push(format!("{what}: {name} {v} set to {fallback}"));
                *v = fallback;
            }
        };
        match self {
            Pattern::Checker2d { size, .. } | Pattern::Brick { size, .. } => {
                positive("cell width", &mut size.x, 0.125);
                positive("cell height", &mut size.y, 0.125);
            }
            Pattern::Wood { ring_width, .. } => positive("ring width", ring_width, 0.12),
            _ => {}
        }
        let mut finite = |name: &str, v: &mut f32| {
            if !v.is_finite() {
                notes.push(format!("{what}: non-finite {name} set to 0"));
                *v = 0.0;
            }
        };
        match self {
            Pattern::Checker2d { phase, .. } => finite("phase", phase),
            Pattern::Brick {
                mortar, row_offset, ..
            } => {
                finite("mortar", mortar);
                finite("row offset", row_offset);
            }
            Pattern::Tile {
                mortar_half_width,
                bevel,
            } => {
                finite("mortar", mortar_half_width);
                finite("bevel", bevel);
                *bevel = bevel.max(0.0);
            }
            Pattern::Waves {
                frequency,
                direction,
            } => {
                finite("frequency", frequency);
                let d = direction.normalize_or(Vec2::X);
                if d != *direction {
                    notes.push(format!(
                        "{what}: wave direction {direction} made unit length"
                    ));
                    *direction = d;
                }
            }
            Pattern::Cutout { radius, .. } => finite("radius", radius),
            Pattern::Wood {
                turbulence_amount, ..
            } => finite("turbulence", turbulence_amount),
            Pattern::Veins {
                frequency,
                turbulence_amount,
                ..
            } => {
                finite("frequency", frequency);
                finite("turbulence", turbulence_amount);
            }
            _ => {}
        }
        if let Some(n) = self.noise_mut() {
            sanitize_fractal(&mut n.fractal, what, notes);
        }
    }
}

fn sanitize_fractal(f: &mut FractalParams, what: &str, notes: &mut Vec<String>) {
    let d = FractalParams::default();
    let mut clamp = |name: &str, v: &mut f32, lo: f32, hi: f32, fallback: f32| {
        let c = if v.is_finite() {
            v.clamp(lo, hi)
        } else {
            fallback
        };
        if c != *v {
            notes.push(format!("{what}: {name} {v} clamped to {c}"));
            *v = c;
        }
    };
    clamp(
        "octaves",
        &mut f.octaves,
        0.0,
        FractalParams::MAX_OCTAVES,
        d.octaves,
    );
    clamp("frequency", &mut f.frequency, 0.0, 1e6, d.frequency);
    clamp("amplitude", &mut f.amplitude, -100.0, 100.0, d.amplitude);
    clamp("persistence", &mut f.persistence, 0.0, 1.5, d.persistence);
    clamp("lacunarity", &mut f.lacunarity, 1.0, 8.0, d.lacunarity);
}

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
        struct ChildVisitor;
        impl<'de> serde::de::Visitor<'de> for ChildVisitor {
            type Value = Child;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number, an (r, g, b) colour, or a (pattern: …, a: …, b: …) texture")
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
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<Child, A::Error> {
                Vec3::deserialize(serde::de::value::SeqAccessDeserializer::new(seq))
                    .map(Child::Color)
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Child, A::Error> {
                Texture::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    .map(|t| Child::Texture(Box::new(t)))
            }
        }
        d.deserialize_any(ChildVisitor)
    }
}

impl Child {
    /// The child's colour at a point (a scalar is grey).
    pub fn eval(&self, p: Vec3, uv: Vec2) -> Vec3 {
        match self {
            Child::Scalar(v) => Vec3::splat(*v),
            Child::Color(c) => *c,
            Child::Texture(t) => t.eval(p, uv),
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

/// A property across a surface: `mix(a, b, t)` with `t` from the pattern,
/// or, when `ramp` has stops, the ramp's colour at `t` (Blender's
/// ColorRamp after a pattern: a noise mapped through chosen colours).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Texture {
    pub pattern: Pattern,
    pub a: Child,
    pub b: Child,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub ramp: Vec<texture::RampStop>,
}

impl Texture {
    /// The same colour everywhere.
    pub fn color(c: Vec3) -> Self {
        Self {
            pattern: Pattern::Constant,
            a: Child::Color(c),
            b: Child::Color(c),

            ramp: Vec::new(),
        }
    }

    /// The same value everywhere (a scalar property).
    pub fn scalar(v: f32) -> Self {
        Self {
            pattern: Pattern::Constant,
            a: Child::Scalar(v),
            b: Child::Scalar(v),

            ramp: Vec::new(),
        }
    }

    /// `pattern` blending two children.
    pub fn blend(pattern: Pattern, a: impl Into<Child>, b: impl Into<Child>) -> Self {
        Self {
            pattern,
            a: a.into(),
            b: b.into(),

            ramp: Vec::new(),
        }
    }

    /// The colour at a surface point `p` (texture space) with coordinates
    /// `uv`: the CPU reference of the shader code generated from this tree.
    /// A constant pattern never evaluates `b`.
    pub fn eval(&self, p: Vec3, uv: Vec2) -> Vec3 {
        let signal = self.pattern.signal().map_or(0.0, |(noise, absolute)| {
            if absolute {
                turbulence(p, &noise)
            } else {
                fbm(p, &noise)
            }
        });
        let (t, child_uv) = self.pattern.blend(p, uv, signal);
        if !self.ramp.is_empty() {
            return texture::ramp(&self.ramp, t);
        }
        let a = self.a.eval(p, child_uv);
        if self.pattern == Pattern::Constant {
            return a;
        }
        a.lerp(self.b.eval(p, child_uv), t)
    }

    /// Whether any texture in the tree maps its blend factor through a ramp.
    pub fn has_ramp(&self) -> bool {
        !self.ramp.is_empty()
            || [&self.a, &self.b]
                .iter()
                .filter_map(|c| c.texture())
                .any(Texture::has_ramp)
    }

    /// Every pattern in the tree, this one first.
    pub fn patterns(&self) -> Vec<&Pattern> {
        let mut out = vec![&self.pattern];
        for child in [&self.a, &self.b] {
            if let Some(t) = child.texture() {
                out.extend(t.patterns());
            }
        }
        out
    }

    /// How deep the tree goes: 1 for a texture with value children.
    pub fn depth(&self) -> usize {
        1 + [&self.a, &self.b]
            .iter()
            .filter_map(|c| c.texture())
            .map(Texture::depth)
            .max()
            .unwrap_or(0)
    }

    /// Clamps values into range: colours and scalars to [0, 1], each
    /// pattern's parameters to what its code handles. Trees deeper than
    /// [`Texture::MAX_DEPTH`] are cut there (the deepest textures become
    /// their `a` value).
    fn sanitize(&mut self, what: &str, notes: &mut Vec<String>, depth: usize) {
        self.pattern.sanitize(what, notes);
        self.sanitize_ramp(what, notes);
        for (name, child) in [("a", &mut self.a), ("b", &mut self.b)] {
            let path = format!("{what}.{name}");
            match child {
                Child::Scalar(v) => {
                    let s = if v.is_finite() {
                        v.clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    if s != *v {
                        notes.push(format!("{path}: {v} clamped to [0, 1]"));
                        *v = s;
                    }
                }
                Child::Color(c) => {
                    let s = if c.is_finite() {
                        c.clamp(Vec3::ZERO, Vec3::ONE)
                    } else {
                        Vec3::ZERO
                    };
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
    /// distinct ones (in `seen`) become constant, with a note.
    fn limit_signals(
        &mut self,
        seen: &mut Vec<(NoiseSettings, bool)>,
        what: &str,
        notes: &mut Vec<String>,
    ) {
        if let Some(signal) = self.pattern.signal()
            && !seen.contains(&signal)
        {
            if seen.len() < MAX_SIGNALS {
                seen.push(signal);
            } else {
                notes.push(format!(
                    "{what}: a material reads at most {MAX_SIGNALS} distinct noises; a {} pattern became constant",
                    Pattern::NAMES[self.pattern.index()]
                ));
                self.pattern = Pattern::Constant;
            }
        }
        for child in [&mut self.a, &mut self.b] {
            if let Child::Texture(t) = child {
                t.limit_signals(seen, what, notes);
            }
        }
    }

    /// The deepest nesting the panel and the shader generator accept.
    pub const MAX_DEPTH: usize = 6;
}

impl Default for Texture {
    fn default() -> Self {
        Self::color(Vec3::splat(0.5))
    }
}

/// A Lambert diffuse lobe plus a GGX specular lobe, and an optional perfect
/// mirror that takes a fraction `mirror` of the light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Material {
    pub diffuse: Texture,
    pub specular: Texture,
    /// GGX roughness (perceptual; α = roughness²), 0 (polished) to 1: the
    /// texture's first channel.
    pub roughness: Texture,
    /// Fraction of light reflected by a perfect mirror, 0 to 1.
    pub mirror: f32,
    /// A height field over the surface (its first channel) that tilts the
    /// shading normal: bump mapping. Constant: no bump.
    pub bump: Texture,
    /// The height, in scene units, of a bump value of 1.
    pub bump_height: f32,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            diffuse: Texture::color(Vec3::splat(0.7)),
            specular: Texture::color(Vec3::splat(0.04)),
            roughness: Texture::scalar(0.4),
            mirror: 0.0,
            bump: Texture::scalar(0.0),
            bump_height: 0.0,
        }
    }
}

impl Material {
    /// The material's colour and roughness textures, in shader order.
    pub fn textures(&self) -> [&Texture; 3] {
        [&self.diffuse, &self.specular, &self.roughness]
    }

    /// Whether the bump texture varies: only then is bump code compiled in.
    pub fn has_bump(&self) -> bool {
        self.bump.pattern != Pattern::Constant
    }

    /// Every pattern of every texture, bump and nested ones included.
    pub fn patterns(&self) -> Vec<&Pattern> {
        let mut out: Vec<&Pattern> = self.textures().iter().flat_map(|t| t.patterns()).collect();
        out.extend(self.bump.patterns());
        out
    }

    pub(crate) fn sanitize(&mut self, what: &str, notes: &mut Vec<String>) {
        self.diffuse.sanitize(&format!("{what} diffuse"), notes, 1);
        self.specular
            .sanitize(&format!("{what} specular"), notes, 1);
        self.roughness
            .sanitize(&format!("{what} roughness"), notes, 1);
        self.bump.sanitize(&format!("{what} bump"), notes, 1);
        let mut signals = Vec::new();
        for texture in [
            &mut self.diffuse,
            &mut self.specular,
            &mut self.roughness,
            &mut self.bump,
        ] {
            texture.limit_signals(&mut signals, what, notes);
        }
        if !self.bump_height.is_finite() {
            notes.push(format!("{what}: non-finite bump height set to 0"));
            self.bump_height = 0.0;
        }
        let s = if self.mirror.is_finite() {
            self.mirror.clamp(0.0, 1.0)
        } else {
            0.0
        };
        if s != self.mirror {
            notes.push(format!("{what}: mirror {} clamped to [0, 1]", self.mirror));
            self.mirror = s;
        }
    }
}
