//! Materials: which texture drives which surface property.

use super::pattern::{MAX_SIGNALS, Pattern, Signal, SurfacePoint};
use super::texture_tree::Texture;
use crate::noise::NoiseSettings;
use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

/// A surface property a texture can drive. Colours use all three channels,
/// scalars the first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Property {
    Diffuse,
    Specular,
    Roughness,
    Mirror,
    Opacity,
    Transmission,
    Emission,
    DiffuseTransmission,
}

impl Property {
    /// In the order the generated shader returns them (`SurfaceTextures`).
    pub const ALL: [Property; 8] = [
        Property::Diffuse,
        Property::Specular,
        Property::Roughness,
        Property::Mirror,
        Property::Opacity,
        Property::Transmission,
        Property::Emission,
        Property::DiffuseTransmission,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Property::Diffuse => "diffuse",
            Property::Specular => "specular",
            Property::Roughness => "roughness",
            Property::Mirror => "mirror",
            Property::Opacity => "opacity",
            Property::Transmission => "transmission",
            Property::Emission => "emission",
            Property::DiffuseTransmission => "diffuse_transmission",
        }
    }

    /// How the panel names it: its preset field name, in words.
    pub fn label(self) -> &'static str {
        match self {
            Property::DiffuseTransmission => "diffuse transmission",
            p => p.name(),
        }
    }

    /// Whether the property is a colour (else a scalar, the first channel).
    pub fn is_color(self) -> bool {
        matches!(
            self,
            Property::Diffuse
                | Property::Specular
                | Property::Transmission
                | Property::Emission
                | Property::DiffuseTransmission
        )
    }
}

/// A Lambert diffuse lobe plus a GGX specular lobe, an optional perfect
/// mirror, a diffuse transmission lobe, opacity (holes, without
/// refraction), emission and bump. Every
/// property is a texture; in a preset a constant one may be written as its
/// value (`roughness: 0.4`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Material {
    #[serde(with = "property_serde::diffuse")]
    pub diffuse: Texture,
    #[serde(with = "property_serde::specular")]
    pub specular: Texture,
    /// GGX roughness (perceptual; α = roughness²), 0 (polished) to 1.
    #[serde(with = "property_serde::roughness")]
    pub roughness: Texture,
    /// Fraction of light reflected by a perfect mirror, 0 to 1.
    #[serde(with = "property_serde::mirror")]
    pub mirror: Texture,
    /// 1 is solid; below, a ray passes straight through with probability
    /// `1 - opacity` (a cutout's holes), and shadows thin accordingly.
    #[serde(with = "property_serde::opacity")]
    pub opacity: Texture,
    /// The colour of the light that passes through where opacity < 1 (MTL's
    /// `Tf`, N3D's transmission coefficients): white keeps it unchanged, a
    /// colour tints what is seen through the surface and its shadow.
    #[serde(with = "property_serde::transmission")]
    pub transmission: Texture,
    /// Emitted radiance is this colour times `emission_strength`.
    #[serde(with = "property_serde::emission")]
    pub emission: Texture,
    pub emission_strength: f32,
    /// N3D's diffuse transmission TD: a Lambert lobe on the other side of
    /// the surface, so light arriving on one side leaves the other side
    /// scattered diffusely with this reflectance (f = TD/π across the
    /// surface; a translucent sheet, a lampshade). Black (the default) is
    /// none. Diffuse + TD should stay ≤ 1 per channel for the surface to
    /// conserve energy: the renderer clamps each to [0, 1] but leaves their
    /// sum to the author.
    #[serde(with = "property_serde::diffuse_transmission")]
    pub diffuse_transmission: Texture,
    /// A height field over the surface (its first channel) that tilts the
    /// shading normal: bump mapping. Constant: no bump.
    #[serde(with = "property_serde::bump")]
    pub bump: Texture,
    /// The height, in scene units, of a bump value of 1.
    pub bump_height: f32,
    /// Applied in order over the properties above, each where its mask is.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub layers: Vec<Layer>,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            diffuse: Texture::color(Vec3::splat(0.7)),
            specular: Texture::color(Vec3::splat(0.04)),
            roughness: Texture::scalar(0.4),
            mirror: Texture::scalar(0.0),
            opacity: Texture::scalar(1.0),
            transmission: Texture::color(Vec3::ONE),
            emission: Texture::color(Vec3::ZERO),
            emission_strength: 1.0,
            diffuse_transmission: Texture::color(Vec3::ZERO),
            bump: Texture::scalar(0.0),
            bump_height: 0.0,
            layers: Vec::new(),
        }
    }
}

/// A layer of a material (Blender's mix of two shaders, one property at a
/// time): over the properties it defines, it replaces what lies below by
/// `mix(below, its value, mask)`; the properties it leaves out show through.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Layer {
    pub name: String,
    /// Where the layer lies, 0 to 1 (first channel).
    #[serde(with = "property_serde::mask")]
    pub mask: Texture,
    #[serde(
        with = "optional_property_serde",
        skip_serializing_if = "Option::is_none"
    )]
    pub diffuse: Option<Texture>,
    #[serde(
        with = "optional_property_serde",
        skip_serializing_if = "Option::is_none"
    )]
    pub specular: Option<Texture>,
    #[serde(
        with = "optional_property_serde",
        skip_serializing_if = "Option::is_none"
    )]
    pub roughness: Option<Texture>,
    #[serde(
        with = "optional_property_serde",
        skip_serializing_if = "Option::is_none"
    )]
    pub mirror: Option<Texture>,
    #[serde(
        with = "optional_property_serde",
        skip_serializing_if = "Option::is_none"
    )]
    pub opacity: Option<Texture>,
    #[serde(
        with = "optional_property_serde",
        skip_serializing_if = "Option::is_none"
    )]
    pub transmission: Option<Texture>,
    #[serde(
        with = "optional_property_serde",
        skip_serializing_if = "Option::is_none"
    )]
    pub emission: Option<Texture>,
    #[serde(
        with = "optional_property_serde",
        skip_serializing_if = "Option::is_none"
    )]
    pub diffuse_transmission: Option<Texture>,
}

impl Default for Layer {
    fn default() -> Self {
        Self {
            name: "layer".into(),
            mask: Texture::scalar(1.0),
            diffuse: None,
            specular: None,
            roughness: None,
            mirror: None,
            opacity: None,
            transmission: None,
            emission: None,
            diffuse_transmission: None,
        }
    }
}

impl Layer {
    pub fn texture(&self, property: Property) -> Option<&Texture> {
        self.slot(property).as_ref()
    }

    /// The layer's binding of `property`: None leaves it to the layers below.
    pub fn slot_mut(&mut self, property: Property) -> &mut Option<Texture> {
        match property {
            Property::Diffuse => &mut self.diffuse,
            Property::Specular => &mut self.specular,
            Property::Roughness => &mut self.roughness,
            Property::Mirror => &mut self.mirror,
            Property::Opacity => &mut self.opacity,
            Property::Transmission => &mut self.transmission,
            Property::Emission => &mut self.emission,
            Property::DiffuseTransmission => &mut self.diffuse_transmission,
        }
    }

    fn slot(&self, property: Property) -> &Option<Texture> {
        match property {
            Property::Diffuse => &self.diffuse,
            Property::Specular => &self.specular,
            Property::Roughness => &self.roughness,
            Property::Mirror => &self.mirror,
            Property::Opacity => &self.opacity,
            Property::Transmission => &self.transmission,
            Property::Emission => &self.emission,
            Property::DiffuseTransmission => &self.diffuse_transmission,
        }
    }

    /// The mask, then every property the layer defines.
    fn textures_mut(&mut self) -> Vec<&mut Texture> {
        let mut out = vec![&mut self.mask];
        out.extend(
            [
                &mut self.diffuse,
                &mut self.specular,
                &mut self.roughness,
                &mut self.mirror,
                &mut self.opacity,
                &mut self.transmission,
                &mut self.emission,
                &mut self.diffuse_transmission,
            ]
            .into_iter()
            .flatten(),
        );
        out
    }
}

impl Material {
    /// The brightest emission the panel reaches and a preset may hold: an
    /// emitter of 1e6 (the stability suite's hard case) and no further, so
    /// that a light's power stays far from f32 overflow.
    pub const MAX_EMISSION_STRENGTH: f32 = 1.0e6;
    /// The bump heights the panel's slider drags over, in scene units;
    /// any finite value may be typed or loaded (steep bumps are a hard case
    /// the shading-normal fallbacks handle).
    pub const BUMP_HEIGHT_DRAG_RANGE: f32 = 0.5;

    /// The base texture of `property` (before layers).
    pub fn texture(&self, property: Property) -> &Texture {
        match property {
            Property::Diffuse => &self.diffuse,
            Property::Specular => &self.specular,
            Property::Roughness => &self.roughness,
            Property::Mirror => &self.mirror,
            Property::Opacity => &self.opacity,
            Property::Transmission => &self.transmission,
            Property::Emission => &self.emission,
            Property::DiffuseTransmission => &self.diffuse_transmission,
        }
    }

    pub fn texture_mut(&mut self, property: Property) -> &mut Texture {
        match property {
            Property::Diffuse => &mut self.diffuse,
            Property::Specular => &mut self.specular,
            Property::Roughness => &mut self.roughness,
            Property::Mirror => &mut self.mirror,
            Property::Opacity => &mut self.opacity,
            Property::Transmission => &mut self.transmission,
            Property::Emission => &mut self.emission,
            Property::DiffuseTransmission => &mut self.diffuse_transmission,
        }
    }

    /// The value of `property` at a point whose object and world
    /// coordinates agree (the ground); see [`Material::value_at`].
    pub fn value(&self, property: Property, p: Vec3, uv: Vec2) -> Vec3 {
        self.value_at(property, &SurfacePoint::new(p, uv))
    }

    /// The value of `property` at a surface point, layers applied, before
    /// the renderer's clamping: the CPU reference of the generated shader.
    pub fn value_at(&self, property: Property, point: &SurfacePoint) -> Vec3 {
        let mut v = self.texture(property).eval_at(point);
        for layer in &self.layers {
            if let Some(t) = layer.texture(property) {
                let mask = layer.mask.eval_at(point).x.clamp(0.0, 1.0);
                v = v.lerp(t.eval_at(point), mask);
            }
        }
        if property == Property::Emission {
            v *= self.emission_strength;
        }
        v
    }

    /// Whether the bump texture varies: only then is bump code compiled in.
    pub fn has_bump(&self) -> bool {
        self.bump.pattern != Pattern::Constant
    }

    /// Whether any point may be less than fully opaque.
    pub fn has_opacity(&self) -> bool {
        self.bindings(Property::Opacity)
            .any(|t| !t.is_constant_value(Vec3::ONE))
    }

    /// Whether any point may emit.
    pub fn has_emission(&self) -> bool {
        self.emission_strength != 0.0
            && self
                .bindings(Property::Emission)
                .any(|t| !t.is_constant_value(Vec3::ZERO))
    }

    /// The base texture of `property` and the layers' bindings of it.
    fn bindings(&self, property: Property) -> impl Iterator<Item = &Texture> {
        std::iter::once(self.texture(property))
            .chain(self.layers.iter().filter_map(move |l| l.texture(property)))
    }

    /// Every texture the material holds: properties, bump, layers.
    pub fn all_textures(&self) -> Vec<&Texture> {
        let mut out: Vec<&Texture> = Property::ALL.iter().map(|&p| self.texture(p)).collect();
        out.push(&self.bump);
        for layer in &self.layers {
            out.push(&layer.mask);
            out.extend(Property::ALL.iter().filter_map(|&p| layer.texture(p)));
        }
        out
    }

    /// Calls `f` on every texture of the material, nested ones included.
    pub fn visit_textures_mut(&mut self, f: &mut dyn FnMut(&mut Texture)) {
        for property in Property::ALL {
            self.texture_mut(property).visit_mut(f);
        }
        self.bump.visit_mut(f);
        for layer in &mut self.layers {
            for texture in layer.textures_mut() {
                texture.visit_mut(f);
            }
        }
    }

    /// Calls `f` on every noise of the material's textures (properties, bump,
    /// layers' masks and properties, nested ones included): how the scene's
    /// time reaches each evolving noise (`Evolution::at`).
    pub fn for_each_noise_mut(&mut self, f: &mut dyn FnMut(&mut NoiseSettings)) {
        self.visit_textures_mut(&mut |t| {
            if let Some(n) = t.pattern.noise_mut() {
                f(n);
            }
        });
    }

    /// The material's distinct fractal sums, gradient noise first (the
    /// order `material_signals` in textures.wgsl expects), at most
    /// [`MAX_SIGNALS`] (`Scene::sanitize` keeps materials within it).
    pub fn signals(&self) -> Vec<Signal> {
        let mut signals = Vec::new();
        for signal in self.all_textures().iter().flat_map(|t| t.signals(None)) {
            if !signals.contains(&signal) {
                signals.push(signal);
            }
        }
        signals.truncate(MAX_SIGNALS);
        signals.sort_by_key(|s| s.noise.kind as u8);
        signals
    }

    /// For each fractal sum the textures read, in tree order, its slot in
    /// [`Material::signals`] (None past [`MAX_SIGNALS`]): the indices the
    /// generated code reads them at. Two materials whose sums are shared
    /// alike have equal slots.
    pub fn signal_slots(&self) -> Vec<Option<usize>> {
        let signals = self.signals();
        self.all_textures()
            .iter()
            .flat_map(|t| t.signals(None))
            .map(|s| signals.iter().position(|x| *x == s))
            .collect()
    }

    /// Every pattern of every texture, nested ones included.
    pub fn patterns(&self) -> Vec<&Pattern> {
        self.all_textures()
            .into_iter()
            .flat_map(Texture::patterns)
            .collect()
    }

    /// Replaces what the renderer cannot take (non-finite or negative
    /// values, signals past `MAX_SIGNALS`, trees too deep), naming each
    /// change in `notes` after `what`: `Scene::sanitize` and the soak's
    /// check of its own edits use it.
    pub fn sanitize(&mut self, what: &str, notes: &mut Vec<String>) {
        let mut textures: Vec<(String, &mut Texture)> = vec![
            (format!("{what} diffuse"), &mut self.diffuse),
            (format!("{what} specular"), &mut self.specular),
            (format!("{what} roughness"), &mut self.roughness),
            (format!("{what} mirror"), &mut self.mirror),
            (format!("{what} opacity"), &mut self.opacity),
            (format!("{what} transmission"), &mut self.transmission),
            (format!("{what} emission"), &mut self.emission),
            (
                format!("{what} diffuse transmission"),
                &mut self.diffuse_transmission,
            ),
            (format!("{what} bump"), &mut self.bump),
        ];
        for layer in &mut self.layers {
            let name = format!("{what} layer `{}`", layer.name);
            textures.extend(layer.textures_mut().into_iter().map(|t| (name.clone(), t)));
        }
        for (name, texture) in &mut textures {
            texture.sanitize(name, notes, 1);
        }
        let mut signals = Vec::new();
        for (_, texture) in &mut textures {
            texture.limit_signals(&mut signals, None, what, notes);
        }
        for (name, v) in [
            ("bump height", &mut self.bump_height),
            ("emission strength", &mut self.emission_strength),
        ] {
            if !v.is_finite() {
                notes.push(format!("{what}: non-finite {name} set to 0"));
                *v = 0.0;
            }
        }
        if self.emission_strength < 0.0 {
            notes.push(format!("{what}: negative emission strength set to 0"));
            self.emission_strength = 0.0;
        }
        if self.emission_strength > Self::MAX_EMISSION_STRENGTH {
            notes.push(format!(
                "{what}: emission strength {} clamped to {}",
                self.emission_strength,
                Self::MAX_EMISSION_STRENGTH
            ));
            self.emission_strength = Self::MAX_EMISSION_STRENGTH;
        }
    }
}

/// A property texture in a preset: a constant one is written as its value
/// (`0.4`, `(0.8, 0.1, 0.1)`), any other as a texture; both read back. A
/// property with a TX coefficient may also be written as TX text
/// (`diffuse: "TX QUAD … FTX"`): the property takes that coefficient's tree
/// over the default material's value (CD for diffuse, CT's opacity or
/// transmission, TUILE and VAGUE for the bump). Its colours are in the
/// preset's `colors` encoding and its image paths relative to the preset,
/// like the rest of the file. It is saved as a tree.
mod property_serde {
    use super::super::texture_tree::{Child, ChildVisitor, Texture};
    use serde::{Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(texture: &Texture, s: S) -> Result<S::Ok, S::Error> {
        match texture.as_constant() {
            Some(value) => value.serialize(s),
            None => texture.serialize(s),
        }
    }

    /// A property's value, or its text read by the preset's reader
    /// (`scene::text_property`: TX lowered onto the field's coefficient).
    fn deserialize_as<'de, D: Deserializer<'de>>(d: D, name: &str) -> Result<Texture, D::Error> {
        let read = |text: &str| {
            super::super::text_property::read(name, text).map(|t| Child::Texture(Box::new(t)))
        };
        Ok(Texture::from(
            d.deserialize_any(ChildVisitor { text: Some(&read) })?,
        ))
    }

    macro_rules! fields {
        ($($field:ident),* $(,)?) => {$(
            pub mod $field {
                pub use super::serialize;
                pub fn deserialize<'de, D: serde::Deserializer<'de>>(
                    d: D,
                ) -> Result<super::Texture, D::Error> {
                    super::deserialize_as(d, stringify!($field))
                }
            }
        )*};
    }

    fields! {
        diffuse,
        specular,
        roughness,
        mirror,
        opacity,
        transmission,
        emission,
        diffuse_transmission,
        bump,
        mask,
    }
}

/// [`property_serde`] for a layer's optional bindings: absent is None.
mod optional_property_serde {
    use super::super::texture_tree::{Child, Texture};
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(texture: &Option<Texture>, s: S) -> Result<S::Ok, S::Error> {
        match texture {
            Some(t) => super::property_serde::serialize(t, s),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Texture>, D::Error> {
        Ok(Some(Texture::from(Child::deserialize(d)?)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Child, MathOp};

    /// `for_each_noise_mut` reaches every noise: a property's, a nested
    /// child's, the bump's and a layer mask's, each once.
    #[test]
    fn every_noise_is_visited_once() {
        let noisy = |frequency: f32| {
            let mut noise = NoiseSettings::default();
            noise.fractal.frequency = frequency;
            Texture {
                pattern: Pattern::Fbm { noise },
                ..Texture::default()
            }
        };
        let mut m = Material::default();
        let mut diffuse = noisy(1.0);
        diffuse.b = Child::Texture(Box::new(noisy(2.0)));
        m.diffuse = diffuse;
        m.bump = noisy(3.0);
        m.layers.push(Layer {
            mask: noisy(4.0),
            ..Layer::default()
        });
        let mut seen = Vec::new();
        m.for_each_noise_mut(&mut |n| {
            seen.push(n.fractal.frequency);
            n.fractal.octaves = 2.0;
        });
        seen.sort_by(f32::total_cmp);
        assert_eq!(seen, [1.0, 2.0, 3.0, 4.0]);
        assert!(
            m.patterns()
                .iter()
                .filter_map(|p| p.noise())
                .all(|n| n.fractal.octaves == 2.0)
        );
    }

    /// An emission the panel cannot reach is clamped at load with a note
    /// that names the field; values it can reach (any finite bump height
    /// can be typed) are kept.
    #[test]
    fn emission_beyond_the_panel_is_clamped_with_a_note() {
        let mut m = Material {
            emission_strength: 5.0e7,
            ..Material::default()
        };
        let mut notes = Vec::new();
        m.sanitize("sphere 0", &mut notes);
        assert_eq!(m.emission_strength, Material::MAX_EMISSION_STRENGTH);
        assert!(
            notes.iter().any(|n| n.contains("emission strength")),
            "{notes:?}"
        );
        let mut reachable = Material {
            emission_strength: 1.0e6,
            bump_height: 1.0e38,
            ..Material::default()
        };
        let mut none = Vec::new();
        reachable.sanitize("sphere 1", &mut none);
        assert!(none.is_empty(), "{none:?}");
        assert_eq!(reachable.emission_strength, 1.0e6);
    }

    fn to_ron(m: &Material) -> String {
        ron::ser::to_string_pretty(m, ron::ser::PrettyConfig::default()).unwrap()
    }

    /// Constant properties are written as their values, textured ones as
    /// trees, and both read back to the same material.
    #[test]
    fn constant_properties_are_written_as_values_and_read_back() {
        let mut m = Material {
            diffuse: Texture::blend(
                Pattern::Checker { size: 0.5 },
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::ONE,
            ),
            ..Material::default()
        };
        m.layers.push(Layer {
            diffuse: Some(Texture::color(Vec3::Z)),
            ..Layer::default()
        });
        let text = to_ron(&m);
        assert!(text.contains("roughness: 0.4"), "{text}");
        assert!(text.contains("opacity: 1.0"), "{text}");
        assert!(
            text.contains("Checker(") && text.contains("size: 0.5"),
            "{text}"
        );
        assert!(!text.contains("specular: None"), "{text}");
        let back: Material = ron::from_str(&text).unwrap();
        assert_eq!(back, m);
    }

    /// Files from before properties were textures (`mirror: 0.25`, full
    /// constant trees) read unchanged, with the new properties defaulted.
    #[test]
    fn older_materials_read_unchanged() {
        let m: Material = ron::from_str(
            "(diffuse: (pattern: Constant, a: (0.8, 0.1, 0.1), b: (0.8, 0.1, 0.1)), roughness: (pattern: Constant, a: 0.3, b: 0.3), mirror: 0.25)",
        )
        .unwrap();
        assert_eq!(m.diffuse, Texture::color(Vec3::new(0.8, 0.1, 0.1)));
        assert_eq!(m.roughness, Texture::scalar(0.3));
        assert_eq!(m.mirror, Texture::scalar(0.25));
        assert_eq!(m.opacity, Texture::scalar(1.0));
        assert_eq!(m.diffuse_transmission, Texture::color(Vec3::ZERO));
        assert!(!m.has_opacity() && !m.has_emission());
    }

    /// A layer replaces what lies below where its mask is 1, keeps it where
    /// it is 0, and leaves the properties it does not set alone.
    #[test]
    fn layers_replace_only_what_they_set_where_their_mask_lies() {
        let red = Vec3::new(0.8, 0.0, 0.0);
        let blue = Vec3::new(0.0, 0.0, 0.8);
        let mut m = Material {
            diffuse: Texture::color(red),
            ..Material::default()
        };
        m.layers.push(Layer {
            mask: Texture::blend(
                Pattern::Checker2d {
                    size: Vec2::ONE,
                    phase: 0.0,
                },
                0.0,
                0.5,
            ),
            diffuse: Some(Texture::color(blue)),
            ..Layer::default()
        });
        let even = Vec2::new(0.5, 0.5);
        let odd = Vec2::new(1.5, 0.5);
        assert_eq!(m.value(Property::Diffuse, Vec3::ZERO, even), red);
        assert_eq!(
            m.value(Property::Diffuse, Vec3::ZERO, odd),
            red.lerp(blue, 0.5)
        );
        assert_eq!(
            m.value(Property::Roughness, Vec3::ZERO, odd),
            Vec3::splat(0.4)
        );
    }

    /// Each math step against its formula, applied in order after the
    /// blend; a mix takes t from its factor's first channel.
    #[test]
    fn math_steps_and_mix_follow_their_formulas() {
        let v = Vec3::new(-0.5, 0.25, 2.0);
        assert_eq!(MathOp::Scale(2.0).apply(v), Vec3::new(-1.0, 0.5, 4.0));
        assert_eq!(MathOp::Bias(0.5).apply(v), Vec3::new(0.0, 0.75, 2.5));
        assert_eq!(MathOp::Abs.apply(v), Vec3::new(0.5, 0.25, 2.0));
        assert_eq!(MathOp::Invert.apply(v), Vec3::new(1.5, 0.75, -1.0));
        assert_eq!(
            MathOp::Clamp { min: 0.0, max: 1.0 }.apply(v),
            Vec3::new(0.0, 0.25, 1.0)
        );
        assert_eq!(MathOp::Power(2.0).apply(v), Vec3::new(0.0, 0.0625, 4.0));

        let mut t = Texture::mix(Texture::scalar(0.25), Vec3::ZERO, Vec3::ONE);
        assert_eq!(t.eval(Vec3::ZERO, Vec2::ZERO), Vec3::splat(0.25));
        t.ops = vec![MathOp::Scale(2.0), MathOp::Invert];
        assert_eq!(t.eval(Vec3::ZERO, Vec2::ZERO), Vec3::splat(0.5));
    }

    /// Sanitising gives a mix without a factor one, drops a factor the
    /// pattern does not read, orders clamp bounds, and keeps exponents
    /// positive (0⁰ has no value on the GPU).
    #[test]
    fn sanitising_repairs_mix_and_math() {
        let mut m = Material {
            diffuse: Texture::blend(Pattern::Mix, Vec3::ZERO, Vec3::ONE),
            ..Material::default()
        };
        m.specular.factor = Some(Box::new(Texture::scalar(1.0)));
        m.roughness.ops = vec![MathOp::Power(0.0), MathOp::Clamp { min: 1.0, max: 0.0 }];
        let mut notes = Vec::new();
        m.sanitize("m", &mut notes);
        assert_eq!(m.diffuse.factor.as_deref(), Some(&Texture::scalar(0.5)));
        assert_eq!(m.specular.factor, None);
        assert_eq!(
            m.roughness.ops,
            vec![
                MathOp::Power(MathOp::MIN_EXPONENT),
                MathOp::Clamp { min: 0.0, max: 1.0 }
            ]
        );
        assert_eq!(notes.len(), 4, "{notes:?}");
    }

    #[test]
    fn opacity_and_emission_are_detected_from_the_bindings() {
        let mut m = Material::default();
        assert!(!m.has_opacity() && !m.has_emission());
        m.layers.push(Layer {
            opacity: Some(Texture::scalar(0.5)),
            ..Layer::default()
        });
        assert!(m.has_opacity());
        m.emission = Texture::from(Child::Color(Vec3::X));
        assert!(m.has_emission());
        m.emission_strength = 0.0;
        assert!(!m.has_emission());
    }
}
