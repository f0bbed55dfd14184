//! Patterns: where a surface point falls between a texture's two children.
//!
//! A pattern turns a point (3D texture point and 2D (u, v)) into a blend
//! factor `t` in [0, 1], and for cell patterns the (u, v) the children see.
//! The functions themselves live in the texture library (`crate::texture`);
//! this is the scene's record of which one and with what parameters.

use super::pattern_table::{PatternInfo, PatternKind};
use super::uv_frame::UvFrame;
use crate::noise::{FractalParams, FractalShape, NoiseSettings, fractal_sum, rebase::rebase};
use crate::texture;
use glam::{Affine3A, Vec2, Vec3};
use serde::{Deserialize, Serialize};
use std::ops::RangeInclusive;

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
    /// `t = ridged(p)` (a sum of `(1 - |noise|)²`), clamped.
    Ridged { noise: NoiseSettings },
    /// `t` is the first channel of the texture's `factor` (Blender's Mix).
    Mix,
    /// The texture's `image` at (u, v), filtered and wrapped so: the value
    /// is the image's colour (or, with a ramp, its luminance mapped).
    Image {
        #[serde(default)]
        filter: texture::ImageFilter,
        #[serde(default)]
        wrap: texture::ImageWrap,
    },
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
    /// Massal's tutorial's marble: `t = 0.5 + 0.5 · sin((x + y) ·
    /// stripe_frequency + turbulence(p))`. His recipe is the default:
    /// his noise in 9 linear levels ([`NoiseSettings::massal`]), the stripe
    /// frequency equal to the noise's.
    MassalMarble {
        noise: NoiseSettings,
        stripe_frequency: f32,
    },
    /// The texture report's example of a new texture (§2.1, `MaTexture`):
    /// `a` where u < v, `b` elsewhere.
    Diagonal,
}

/// A fractal sum a pattern reads: the noise, what each octave adds, and
/// where it is taken (the mapping of the nearest mapped texture above it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Signal {
    pub noise: NoiseSettings,
    pub shape: FractalShape,
    pub mapping: Option<TextureMapping>,
}

impl Signal {
    /// The sum at a surface point given in object and world coordinates.
    pub fn eval(&self, point: &SurfacePoint) -> f32 {
        let p = match self.mapping {
            Some(m) => self
                .noise_space_map()
                .transform_point3(m.space_point(point)),
            None if self.drift() == Vec3::ZERO => point.object,
            None => self.noise_space_map().transform_point3(point.object),
        };
        fractal_sum(p, &self.noise, self.shape)
    }

    /// How far an evolving noise's domain has moved at the moment traced
    /// (`Evolution::offset_now`); zero for a still one.
    fn drift(&self) -> Vec3 {
        self.noise.evolution.map_or(Vec3::ZERO, |e| e.offset_now())
    }

    /// The map from surface to noise coordinates, less the evolving noise's
    /// drift (the noise is taken at `q − drift·t`, so its features move
    /// along +drift), its translation rebased by whole periods of the noise
    /// (`noise::rebase`): the same sum in exact arithmetic, taken near the
    /// origin where f32 resolves it. The rebase moves x, y and z alone:
    /// w keeps its loop's period.
    fn noise_space_map(&self) -> Affine3A {
        let mut m = self.mapping.unwrap_or_default().point_map();
        let translation = Vec3::from(m.translation) - self.drift();
        m.translation = rebase(translation, &self.noise).into();
        m
    }

    /// The rows of [`Signal::noise_space_map`], as the shader reads them.
    pub fn rows(&self) -> [[f32; 4]; 3] {
        affine_rows(&self.noise_space_map())
    }
}

/// Where a texture is evaluated: the surface point in the object's own
/// frame and in the world, and the primitive's (u, v).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub object: Vec3,
    pub world: Vec3,
    pub uv: Vec2,
}

impl SurfacePoint {
    /// A point whose object and world coordinates agree (the ground).
    pub fn new(p: Vec3, uv: Vec2) -> Self {
        Self {
            object: p,
            world: p,
            uv,
        }
    }
}

/// Which coordinates a mapped texture reads its 3D point from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum MappingSpace {
    /// The object's own frame: the texture moves with the object.
    #[default]
    Object,
    /// World coordinates: objects move through the texture.
    World,
}

/// Blender's Texture Coordinate and Mapping nodes in one: a texture with a
/// mapping, and its whole subtree, read the surface's coordinates afresh
/// (3D from `space`, then `frame`, 2D from the primitive) through
/// `transform`; (u, v) are transformed as the point (u, v, 0).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct TextureMapping {
    pub space: MappingSpace,
    /// The texture report's ATX3D: the 3D texture point is the coordinates
    /// (a, b, c) of the surface point in this frame,
    /// p = origin + a·u + b·v + c·w, before `transform`. The report gives only u and v; w is
    /// their normalised cross product scaled by √(|u|·|v|), so a frame
    /// whose axes have one length stays isotropic (a cube of the texture
    /// stays a cube) and an oblique or stretched one scales its third axis
    /// by the geometric mean. (u, v) are not affected. A degenerate frame
    /// is refused by `Scene::sanitize` (and reads as no frame meanwhile).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<UvFrame>,
    pub transform: texture::TextureTransform,
}

impl TextureMapping {
    pub fn point(&self, at: &SurfacePoint) -> Vec3 {
        self.point_map().transform_point3(self.space_point(at))
    }

    /// The map from the frame's coordinates (a, b, c) to space: the columns
    /// u, v, w and the origin. None for a frame that spans no volume.
    pub fn frame_to_space(frame: &UvFrame) -> Option<Affine3A> {
        if frame.problem().is_some() {
            return None;
        }
        let (u, v) = (frame.u_axis, frame.v_axis);
        let w = u.cross(v).normalize() * (u.length() * v.length()).sqrt();
        let m = Affine3A::from_cols(u.into(), v.into(), w.into(), frame.origin.into());
        (m.matrix3.determinant().is_finite()).then_some(m)
    }

    /// The affine map from surface points (in `space`) to 3D texture
    /// points: the frame's coordinates, then `transform`.
    pub fn point_map(&self) -> Affine3A {
        let into_frame = self
            .frame
            .as_ref()
            .and_then(Self::frame_to_space)
            .map_or(Affine3A::IDENTITY, |m| m.inverse());
        self.transform.to_texture() * into_frame
    }

    /// Refuses a frame that spans no volume (zero or parallel axes, a
    /// non-finite coordinate), with a note naming `what`.
    pub(crate) fn sanitize(&mut self, what: &str, notes: &mut Vec<String>) {
        if let Some(problem) = self.frame.as_ref().and_then(UvFrame::problem) {
            notes.push(format!(
                "{what}: mapping frame refused ({problem}); the surface point is read without it"
            ));
            self.frame = None;
        }
    }

    /// The surface point in the coordinates this mapping reads.
    fn space_point(&self, at: &SurfacePoint) -> Vec3 {
        match self.space {
            MappingSpace::Object => at.object,
            MappingSpace::World => at.world,
        }
    }

    pub fn uv(&self, at: &SurfacePoint) -> Vec2 {
        self.transform
            .to_texture()
            .transform_point3(at.uv.extend(0.0))
            .truncate()
    }

    /// How much the map enlarges a footprint: along u, along v (the map
    /// of (u, v, 0)) and in 3D (the frame included), each the longest
    /// image of a unit vector among the axes (a bound that never
    /// under-filters a uniform scale).
    pub fn footprint_scale(&self) -> [f32; 3] {
        let l = self.transform.to_texture().matrix3;
        let p = self.point_map().matrix3;
        [
            Vec3::from(l.x_axis).truncate().length(),
            Vec3::from(l.y_axis).truncate().length(),
            p.x_axis
                .length()
                .max(p.y_axis.length())
                .max(p.z_axis.length()),
        ]
    }

    /// The three rows of the 3D point's affine map, as the shader reads
    /// them: `p' = (dot(r0.xyz, p) + r0.w, …)`.
    pub fn rows(&self) -> [[f32; 4]; 3] {
        affine_rows(&self.point_map())
    }

    /// The rows of the (u, v) map: [`TextureMapping::rows`] unless a frame
    /// moves the 3D point alone.
    pub fn uv_rows(&self) -> [[f32; 4]; 3] {
        affine_rows(&self.transform.to_texture())
    }
}

/// The three rows `(dot(r.xyz, p) + r.w)` of an affine map.
fn affine_rows(m: &Affine3A) -> [[f32; 4]; 3] {
    let (l, t) = (m.matrix3, m.translation);
    [
        [l.x_axis.x, l.y_axis.x, l.z_axis.x, t.x],
        [l.x_axis.y, l.y_axis.y, l.z_axis.y, t.y],
        [l.x_axis.z, l.y_axis.z, l.z_axis.z, t.z],
    ]
}

impl Pattern {
    /// The frequency of Massal's marble when chosen in the panel: his 0.05
    /// was for spheres about 100 pixels in radius; scaled to marbre's unit
    /// spheres, a stripe about a radius wide.
    pub const MASSAL_MARBLE_FREQUENCY: f32 = 5.0;

    /// Which pattern this is, without its numbers: its row of
    /// [`PATTERNS`](super::pattern_table::PATTERNS).
    pub fn kind(&self) -> PatternKind {
        match self {
            Pattern::Constant => PatternKind::Constant,
            Pattern::Checker { .. } => PatternKind::Checker,
            Pattern::Fbm { .. } => PatternKind::Fbm,
            Pattern::Turbulence { .. } => PatternKind::Turbulence,
            Pattern::Marble { .. } => PatternKind::Marble,
            Pattern::Checker2d { .. } => PatternKind::Checker2d,
            Pattern::Brick { .. } => PatternKind::Brick,
            Pattern::Tile { .. } => PatternKind::Tile,
            Pattern::Cutout { .. } => PatternKind::Cutout,
            Pattern::Wood { .. } => PatternKind::Wood,
            Pattern::Veins { .. } => PatternKind::Veins,
            Pattern::Waves { .. } => PatternKind::Waves,
            Pattern::Ridged { .. } => PatternKind::Ridged,
            Pattern::Mix => PatternKind::Mix,
            Pattern::Image { .. } => PatternKind::Image,
            Pattern::MassalMarble { .. } => PatternKind::MassalMarble,
            Pattern::Diagonal => PatternKind::Diagonal,
        }
    }

    /// Its row of the pattern table.
    pub fn info(&self) -> &'static PatternInfo {
        self.kind().info()
    }

    /// Whether the two patterns compile to the same code: one kind, and
    /// the same choices the code holds (an image's filter and wrap, the
    /// noise kind and hash and whether it evolves, which pick functions);
    /// their numbers may differ.
    pub fn same_kind(&self, other: &Pattern) -> bool {
        let choices = |p: &Pattern| match p {
            Pattern::Image { filter, wrap } => Some((*filter as u8, *wrap as u8, false)),
            // An evolving noise's code is the 4D sum's (its w, period and
            // drift are numbers); a still one's is the 3D sum's.
            _ => p
                .noise()
                .map(|n| (n.kind as u8, n.hash as u8, n.evolution.is_some())),
        };
        self.kind() == other.kind() && choices(self) == choices(other)
    }

    /// The first octave's frequency of a pattern's noise when it had none:
    /// several features across a unit sphere.
    pub const FRESH_NOISE_FREQUENCY: f32 = 3.0;

    /// A fresh pattern of `kind`, reading `noise` where it has noise (so
    /// switching the panel's list keeps the tuning), else noise at
    /// [`Self::FRESH_NOISE_FREQUENCY`]. Fresh numbers show several features
    /// on a unit sphere (the 3D checker 4 cubes across it).
    pub fn fresh(kind: PatternKind, noise: Option<NoiseSettings>) -> Pattern {
        let noise = noise.unwrap_or_else(|| NoiseSettings {
            fractal: FractalParams {
                frequency: Self::FRESH_NOISE_FREQUENCY,
                ..FractalParams::default()
            },
            ..NoiseSettings::default()
        });
        match kind {
            PatternKind::Constant => Pattern::Constant,
            PatternKind::Checker => Pattern::Checker { size: 0.5 },
            PatternKind::Fbm => Pattern::Fbm { noise },
            PatternKind::Turbulence => Pattern::Turbulence { noise },
            PatternKind::Marble => Pattern::Marble {
                noise,
                stripe_frequency: 4.0,
            },
            PatternKind::Checker2d => Pattern::Checker2d {
                size: Vec2::splat(0.125),
                phase: 0.0,
            },
            PatternKind::Brick => Pattern::Brick {
                size: Vec2::new(0.25, 0.1),
                mortar: 0.01,
                row_offset: 0.5,
            },
            PatternKind::Tile => Pattern::Tile {
                mortar_half_width: 0.02,
                bevel: 0.02,
            },
            PatternKind::Cutout => Pattern::Cutout {
                sides: 0,
                radius: 0.4,
            },
            PatternKind::Wood => Pattern::Wood {
                noise,
                ring_width: 0.12,
                turbulence_amount: 0.3,
            },
            PatternKind::Veins => Pattern::Veins {
                noise,
                frequency: 10.0,
                turbulence_amount: 5.0,
            },
            PatternKind::Waves => Pattern::Waves {
                frequency: 4.0,
                direction: Vec2::X,
            },
            PatternKind::Ridged => Pattern::Ridged { noise },
            PatternKind::Mix => Pattern::Mix,
            PatternKind::Image => Pattern::Image {
                filter: Default::default(),
                wrap: Default::default(),
            },
            // His recipe, not the previous pattern's noise: the marble is
            // his only with his turbulence.
            PatternKind::MassalMarble => Pattern::MassalMarble {
                noise: NoiseSettings::massal(Self::MASSAL_MARBLE_FREQUENCY),
                stripe_frequency: Self::MASSAL_MARBLE_FREQUENCY,
            },
            PatternKind::Diagonal => Pattern::Diagonal,
        }
    }

    /// A fresh pattern of `kind` keeping this one's noise settings.
    pub fn with_kind(&self, kind: PatternKind) -> Pattern {
        Self::fresh(kind, self.noise().copied())
    }

    /// The numbers the generated code reads as one `vec4f` (`{q}` in the
    /// table's [`PatternCode`](super::pattern_table::PatternCode)); None
    /// for the patterns that read none (constant, noise sums, mix, image,
    /// diagonal).
    pub fn numbers(&self) -> Option<[f32; 4]> {
        Some(match *self {
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
            | Pattern::Image { .. }
            | Pattern::Diagonal => return None,
        })
    }

    pub fn noise(&self) -> Option<&NoiseSettings> {
        match self {
            Pattern::Fbm { noise }
            | Pattern::Turbulence { noise }
            | Pattern::Ridged { noise }
            | Pattern::Marble { noise, .. }
            | Pattern::Wood { noise, .. }
            | Pattern::Veins { noise, .. }
            | Pattern::MassalMarble { noise, .. } => Some(noise),
            _ => None,
        }
    }

    pub fn noise_mut(&mut self) -> Option<&mut NoiseSettings> {
        match self {
            Pattern::Fbm { noise }
            | Pattern::Turbulence { noise }
            | Pattern::Ridged { noise }
            | Pattern::Marble { noise, .. }
            | Pattern::Wood { noise, .. }
            | Pattern::Veins { noise, .. }
            | Pattern::MassalMarble { noise, .. } => Some(noise),
            _ => None,
        }
    }

    /// The fractal sum this pattern reads: the shader evaluates each
    /// distinct one once per hit (a signal).
    pub fn signal(&self) -> Option<Signal> {
        let noise = *self.noise()?;
        let shape = match self {
            Pattern::Turbulence { .. }
            | Pattern::Wood { .. }
            | Pattern::Veins { .. }
            | Pattern::MassalMarble { .. } => FractalShape::Absolute,
            Pattern::Ridged { .. } => FractalShape::Ridged,
            _ => FractalShape::Signed,
        };
        Some(Signal {
            noise,
            shape,
            mapping: None,
        })
    }

    /// The blend factor at a point, given the pattern's signal value there,
    /// and the (u, v) its children see. CPU twin of the generated WGSL.
    pub(crate) fn blend(&self, p: Vec3, uv: Vec2, signal: f32) -> (f32, Vec2) {
        match *self {
            Pattern::Constant => (0.0, uv),
            Pattern::Checker { size } => (texture::checker_3d(p, Vec3::splat(size)), uv),
            Pattern::Fbm { .. } => ((0.5 + 0.5 * signal).clamp(0.0, 1.0), uv),
            Pattern::Turbulence { .. } | Pattern::Ridged { .. } => (signal.clamp(0.0, 1.0), uv),
            // The texture tree takes t from the factor texture, and the
            // colour from the image.
            Pattern::Mix | Pattern::Image { .. } => (0.0, uv),
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
            Pattern::Diagonal => (texture::diagonal(uv), uv),
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
            Pattern::MassalMarble {
                stripe_frequency, ..
            } => (
                texture::massal_marble_stripes(p, stripe_frequency, signal),
                uv,
            ),
        }
    }

    pub(crate) fn sanitize(&mut self, what: &str, notes: &mut Vec<String>) {
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
        if let Pattern::MassalMarble {
            stripe_frequency, ..
        } = self
            && !stripe_frequency.is_finite()
        {
            notes.push(format!("{what}: Massal marble stripe frequency reset"));
            *stripe_frequency = Self::MASSAL_MARBLE_FREQUENCY;
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
            if let Some(e) = &mut n.evolution {
                let clean = e.sanitized();
                if clean != *e {
                    notes.push(format!(
                        "{what}: noise evolution {e:?} clamped to {clean:?}"
                    ));
                    *e = clean;
                }
            }
        }
    }
}

fn sanitize_fractal(f: &mut FractalParams, what: &str, notes: &mut Vec<String>) {
    let d = FractalParams::default();
    let mut clamp = |name: &str, v: &mut f32, range: RangeInclusive<f32>, fallback: f32| {
        let c = if v.is_finite() {
            v.clamp(*range.start(), *range.end())
        } else {
            fallback
        };
        if c != *v {
            notes.push(format!("{what}: {name} {v} clamped to {c}"));
            *v = c;
        }
    };
    clamp("octaves", &mut f.octaves, FractalParams::OCTAVES, d.octaves);
    clamp(
        "frequency",
        &mut f.frequency,
        FractalParams::FREQUENCY,
        d.frequency,
    );
    clamp(
        "amplitude",
        &mut f.amplitude,
        FractalParams::AMPLITUDE,
        d.amplitude,
    );
    clamp(
        "persistence",
        &mut f.persistence,
        FractalParams::PERSISTENCE,
        d.persistence,
    );
    clamp(
        "lacunarity",
        &mut f.lacunarity,
        FractalParams::LACUNARITY,
        d.lacunarity,
    );
    clamp(
        "distortion",
        &mut f.distortion,
        FractalParams::DISTORTION,
        d.distortion,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Scene, Sphere, Texture};

    fn frame() -> UvFrame {
        UvFrame {
            origin: Vec3::new(0.3, -0.2, 0.1),
            u_axis: Vec3::new(0.8, 0.3, 0.0),
            v_axis: Vec3::new(0.2, 1.2, 0.4),
        }
    }

    /// An evolving noise's drift moves its features along +drift: the
    /// signal at q + drift·t at time t is the signal at q at time 0 (w held
    /// still), through a mapping or none; the rows the shader reads carry
    /// the same shift.
    #[test]
    fn drift_moves_the_noise_along_itself() {
        use crate::noise::Evolution;
        let drift = Vec3::new(0.5, -0.25, 1.0);
        for mapping in [
            None,
            Some(TextureMapping {
                frame: Some(frame()),
                ..TextureMapping::default()
            }),
        ] {
            let mut signal = Signal {
                noise: NoiseSettings {
                    evolution: Some(Evolution {
                        speed: 0.0,
                        drift,
                        ..Evolution::default()
                    }),
                    ..NoiseSettings::default()
                },
                shape: FractalShape::Signed,
                mapping,
            };
            let still = signal;
            let t = 2.0;
            signal
                .noise
                .evolution
                .as_mut()
                .expect("evolving")
                .at(t, None);
            let to_noise = |s: &Signal, p: Vec3| {
                let [a, b, c] = s.rows();
                Vec3::new(
                    a[0] * p.x + a[1] * p.y + a[2] * p.z + a[3],
                    b[0] * p.x + b[1] * p.y + b[2] * p.z + b[3],
                    c[0] * p.x + c[1] * p.y + c[2] * p.z + c[3],
                )
            };
            for k in 0..50 {
                let q = Vec3::new(k as f32 * 0.13, 0.4 - k as f32 * 0.07, k as f32 * 0.031);
                let at = |p: Vec3| SurfacePoint::new(p, Vec2::ZERO);
                // The point whose noise-space image moved by drift·t.
                let m = mapping.unwrap_or_default().point_map();
                let moved = m
                    .inverse()
                    .transform_point3(m.transform_point3(q) + drift * t);
                let (now, then) = (signal.eval(&at(moved)), still.eval(&at(q)));
                assert!((now - then).abs() < 1e-4, "{q}: {now} vs {then}");
                let shift = to_noise(&signal, moved) - to_noise(&still, q);
                assert!(shift.abs().max_element() < 1e-4, "{shift}");
            }
        }
    }

    /// ATX3D: the texture point of origin + a·u + b·v + c·w is (a, b, c),
    /// w being u × v normalised to length √(|u|·|v|); the transform then
    /// applies to (a, b, c); (u, v) ignore the frame.
    #[test]
    fn a_mapping_frame_gives_the_coordinates_on_its_axes() {
        let f = frame();
        let w =
            f.u_axis.cross(f.v_axis).normalize() * (f.u_axis.length() * f.v_axis.length()).sqrt();
        let mut mapping = TextureMapping {
            frame: Some(f),
            ..TextureMapping::default()
        };
        let at = |p: Vec3| SurfacePoint::new(p, Vec2::new(0.25, 0.5));
        for abc in [
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::Z,
            Vec3::new(-1.5, 0.25, 2.0),
        ] {
            let p = f.origin + abc.x * f.u_axis + abc.y * f.v_axis + abc.z * w;
            let got = mapping.point(&at(p));
            assert!((got - abc).abs().max_element() < 1e-5, "{abc}: {got}");
        }
        mapping.transform.translate = Vec3::new(1.0, 2.0, 3.0);
        let p = f.origin + 0.5 * f.u_axis;
        let got = mapping.point(&at(p));
        assert!(
            (got - Vec3::new(-0.5, -2.0, -3.0)).abs().max_element() < 1e-5,
            "{got}"
        );
        assert_eq!(mapping.uv(&at(p)), Vec2::new(-0.75, -1.5));
    }

    /// Equal orthogonal axes keep the texture isotropic: the third axis
    /// has their length, so a cube of texture stays a cube.
    #[test]
    fn an_isotropic_frame_stays_isotropic() {
        let mapping = TextureMapping {
            frame: Some(UvFrame {
                origin: Vec3::ZERO,
                u_axis: Vec3::new(0.0, 0.0, 2.0),
                v_axis: Vec3::new(2.0, 0.0, 0.0),
            }),
            ..TextureMapping::default()
        };
        let m = mapping.point_map().matrix3;
        for axis in [m.x_axis, m.y_axis, m.z_axis] {
            assert!((axis.length() - 0.5).abs() < 1e-6, "{axis}");
        }
        assert_eq!(
            mapping
                .point(&SurfacePoint::new(Vec3::Y * 2.0, Vec2::ZERO))
                .z,
            1.0
        );
    }

    /// A frame that spans no volume is refused by `Scene::sanitize` with a
    /// note naming the texture, and until then reads as no frame: finite.
    #[test]
    fn a_degenerate_mapping_frame_is_refused_and_never_gives_nan() {
        for (u, v) in [
            (Vec3::X, Vec3::X * -2.0),
            (Vec3::ZERO, Vec3::Y),
            (Vec3::X, Vec3::splat(f32::INFINITY)),
            (Vec3::splat(1e30), Vec3::new(1e30, -1e30, 0.0)),
        ] {
            let degenerate = TextureMapping {
                frame: Some(UvFrame {
                    origin: Vec3::ZERO,
                    u_axis: u,
                    v_axis: v,
                }),
                ..TextureMapping::default()
            };
            let p = degenerate.point(&SurfacePoint::new(Vec3::new(1.0, 2.0, 3.0), Vec2::ZERO));
            assert_eq!(p, Vec3::new(1.0, 2.0, 3.0), "{u} {v}");
            assert!(degenerate.rows().iter().flatten().all(|x| x.is_finite()));
            let mut texture = Texture::blend(Pattern::Checker { size: 0.5 }, Vec3::ZERO, Vec3::ONE);
            texture.mapping = Some(degenerate);
            let mut sphere = Sphere::default();
            sphere.material.diffuse = texture;
            let mut scene = Scene {
                spheres: vec![sphere],
                ..Scene::default()
            };
            let notes = scene.sanitize();
            assert_eq!(
                scene.spheres[0].material.diffuse.mapping.unwrap().frame,
                None
            );
            assert!(
                notes.iter().any(|n| n.contains("sphere `sphere` diffuse")
                    && n.contains("mapping frame refused")),
                "{notes:?}"
            );
        }
    }
}
