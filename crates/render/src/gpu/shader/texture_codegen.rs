//! Generates the WGSL that evaluates a scene's texture trees.
//!
//! Each material's three property textures become straight-line WGSL
//! functions whose structure (pattern kinds, nesting) is fixed in the code
//! and whose numbers (colours, cell sizes, frequencies) are read at constant
//! indices from the `texture_params` uniform. So a parameter edit rewrites a
//! buffer and the next frame shows it; only a structural edit (a new
//! pattern, a nested texture) changes the code and rebuilds the pipeline.
//! Constant indices matter on lavapipe: a uniform read at an index that
//! differs between lanes costs eight scalar loads, one at a constant index a
//! single broadcast.
//!
//! The fractal sums the patterns read are the material's noise signals,
//! evaluated once per hit by `material_signals` (textures.wgsl); the
//! generated code reads them from `signals`.

use anyhow::{Result, ensure};
use marbre_core::scene::{
    Child, MappingSpace, Material, MathOp, Pattern, PatternCode, Property, Scene, Signal, Texture,
    TextureMapping,
};
use marbre_core::texture::{ImageFilter, ImageSet, ImageWrap};
use std::fmt::Write;

use crate::gpu::texture_params::{Field, Place, Slot};
pub use crate::gpu::texture_params::{MAX_TEXTURE_PARAMS, ParamPlan};
use marbre_core::scene::node_path::{NodePath, Root, Socket};

/// The generated code and the parameters it reads.
#[derive(Debug, Clone, PartialEq)]
pub struct GeneratedTextures {
    /// WGSL defining `surface_textures`; identical for two scenes whose
    /// textures differ only in their numbers.
    pub wgsl: String,
    /// The `texture_params` values, padded to [`MAX_TEXTURE_PARAMS`].
    pub params: Vec<[f32; 4]>,
    /// Where each of `params` comes from: fills them for another scene of
    /// the same structure without generating the code.
    pub plan: ParamPlan,
}

/// The code and parameters for every material of `scene`, in GPU order:
/// `surface_textures`, and `surface_height` for the bump textures.
pub fn generate(scene: &Scene, images: &ImageSet) -> Result<GeneratedTextures> {
    let mut generator = Generator::new(images);
    let mut dispatch = String::new();
    let mut transmittances = String::new();
    let mut emissions = String::new();
    let mut heights = String::new();
    for (index, material) in scene.materials().enumerate() {
        let cases = generator.material(index, material);
        writeln!(
            dispatch,
            "        case {index}u: {{\n{}        }}",
            cases.textures
        )?;
        writeln!(
            transmittances,
            "        case {index}u: {{\n{}        }}",
            cases.transmittance
        )?;
        writeln!(
            emissions,
            "        case {index}u: {{\n{}        }}",
            cases.emission
        )?;
        if material.has_bump() {
            let name = format!("texture_{index}_bump");
            generator.function(
                &name,
                (index, Root::Bump),
                &material.bump,
                &material.signals(),
            );
            writeln!(
                heights,
                "        case {index}u: {{\n            return {name}(p, pw, uv, fp, signals).x;\n        }}"
            )?;
        }
    }
    let (mut wgsl, params, plan) = generator.finish(
        "// Generated from the scene's texture trees (gpu::texture_codegen).\n\n",
        "the scene's textures",
    )?;
    write!(
        wgsl,
        "fn surface_textures(material: u32, p: vec3f, pw: vec3f, uv: vec2f, fp: Footprint, signals: vec4f) -> SurfaceTextures {{\n    var out = SurfaceTextures(vec3f(0.0), vec3f(0.0), 0.0, 0.0, 1.0, vec3f(1.0), vec3f(0.0), vec3f(0.0));\n    switch material {{\n{dispatch}        default: {{}}\n    }}\n    return out;\n}}\n"
    )?;
    // Shadow rays read opacity and transmission alone, light samples
    // emission alone; each evaluates the noise signals only if one of its
    // textures reads one.
    let signals_for = |properties: &[Property]| {
        let reads_noise = scene.materials().any(|m| {
            properties.iter().any(|&property| {
                std::iter::once(m.texture(property))
                    .chain(
                        m.layers
                            .iter()
                            .flat_map(|l| [Some(&l.mask), l.texture(property)])
                            .flatten(),
                    )
                    .flat_map(Texture::patterns)
                    .any(|p| p.signal().is_some())
            })
        });
        if reads_noise {
            "material_signals(material, p, pw, 0.0)"
        } else {
            "vec4f(0.0)"
        }
    };
    let signals = signals_for(&[Property::Opacity, Property::Transmission]);
    write!(
        wgsl,
        "\n// The fraction of light a material lets straight through, per channel:\n// (1 - opacity) tinted by the transmission colour, for shadow rays.\nfn surface_transmittance(material: u32, p: vec3f, pw: vec3f, uv: vec2f) -> vec3f {{\n    let signals = {signals};\n    let fp = Footprint(vec2f(0.0), 0.0, vec3f(0.0));\n    switch material {{\n{transmittances}        default: {{}}\n    }}\n    return vec3f(0.0);\n}}\n"
    )?;
    let signals = signals_for(&[Property::Emission]);
    write!(
        wgsl,
        "\n// A material's emitted radiance alone, for points sampled on lights.\nfn surface_emission(material: u32, p: vec3f, pw: vec3f, uv: vec2f) -> vec3f {{\n    let signals = {signals};\n    let fp = Footprint(vec2f(0.0), 0.0, vec3f(0.0));\n    switch material {{\n{emissions}        default: {{}}\n    }}\n    return vec3f(0.0);\n}}\n"
    )?;
    let bump_reads_noise = scene
        .materials()
        .filter(|m| m.has_bump())
        .flat_map(|m| m.bump.patterns())
        .any(|p| p.signal().is_some());
    write!(
        wgsl,
        "\n// Whether a bump height reads noise (bump_mapping.wgsl then evaluates the\n// signals at its offset points).\nconst BUMP_READS_NOISE: bool = {bump_reads_noise};\n"
    )?;
    // Always defined, so that a shader with the bump feature forced on (the
    // uber shader) builds for any scene.
    write!(
        wgsl,
        "\n// The bump height of a material (0 for those without bump).\nfn surface_height(material: u32, p: vec3f, pw: vec3f, uv: vec2f, fp: Footprint, signals: vec4f) -> f32 {{\n    switch material {{\n{heights}        default: {{}}\n    }}\n    return 0.0;\n}}\n"
    )?;
    Ok(GeneratedTextures { wgsl, params, plan })
}

/// The code and parameters evaluating each of `textures` alone (the
/// panel's preview swatches, `gpu::swatch`): `swatch_texture(index, …)`
/// returns texture `index`'s colour, its noise signals read from
/// `signals`, which `material_signals(index, …)` evaluates from the
/// materials [`swatch_material`] makes. The same generator as
/// [`generate`], so a swatch shows what the renderer would.
pub fn generate_swatches(textures: &[Texture], images: &ImageSet) -> Result<GeneratedTextures> {
    let mut generator = Generator::new(images);
    let mut dispatch = String::new();
    for (index, texture) in textures.iter().enumerate() {
        let name = format!("swatch_{index}");
        generator.function(
            &name,
            // A swatch's texture is its material's diffuse (`swatch_material`).
            (index, Root::Property(Property::Diffuse)),
            texture,
            &swatch_material(texture).signals(),
        );
        writeln!(
            dispatch,
            "        case {index}u: {{\n            return {name}(p, pw, uv, fp, signals);\n        }}"
        )?;
    }
    let (mut wgsl, params, plan) = generator.finish(
        "// Generated from texture trees for swatches (gpu::texture_codegen).\n\n",
        "the swatches' textures",
    )?;
    write!(
        wgsl,
        "fn swatch_texture(index: u32, p: vec3f, pw: vec3f, uv: vec2f, fp: Footprint, signals: vec4f) -> vec3f {{\n    switch index {{\n{dispatch}        default: {{}}\n    }}\n    return vec3f(0.0);\n}}\n"
    )?;
    Ok(GeneratedTextures { wgsl, params, plan })
}

/// The material a swatch of `texture` reads its noise signals through: a
/// default one whose diffuse colour is the texture.
pub fn swatch_material(texture: &Texture) -> Material {
    let mut material = Material::default();
    *material.texture_mut(Property::Diffuse) = texture.clone();
    material
}

/// Where a texture node is evaluated: the WGSL expressions of its 3D point
/// and (u, v), and the mapping they came through (which its noise signals
/// are taken through too).
#[derive(Clone)]
struct Site {
    p: String,
    uv: String,
    /// A `Footprint`: the sample's extent around `p` and `uv`.
    footprint: String,
    mapping: Option<TextureMapping>,
}

/// What [`Generator::material`] returns: a material's statements in the
/// two dispatch functions.
struct MaterialCases {
    textures: String,
    /// The statements of `surface_transmittance`.
    transmittance: String,
    /// The statements of `surface_emission`.
    emission: String,
}

struct Generator<'a> {
    /// Where each image lies in the atlas (image nodes read it).
    images: &'a ImageSet,
    code: String,
    params: Vec<[f32; 4]>,
    /// Where each of `params` comes from.
    slots: Vec<Slot>,
    /// The material of the function being generated, and the path of the
    /// node being generated.
    owner: usize,
    path: NodePath,
    /// Numbers the local variables of the function being generated.
    next: usize,
}

impl<'a> Generator<'a> {
    fn new(images: &'a ImageSet) -> Self {
        Self {
            images,
            code: String::new(),
            params: Vec::new(),
            slots: Vec::new(),
            owner: 0,
            path: NodePath::root(Root::Bump),
            next: 0,
        }
    }

    /// The generated functions after `header`, the parameters padded to
    /// the uniform array's size, and their plan; refused when they do not
    /// fit (`what` names whose they are).
    fn finish(self, header: &str, what: &str) -> Result<(String, Vec<[f32; 4]>, ParamPlan)> {
        ensure!(
            self.params.len() <= MAX_TEXTURE_PARAMS,
            "{what} need {} parameter slots; the renderer holds {MAX_TEXTURE_PARAMS}",
            self.params.len()
        );
        let mut params = self.params;
        params.resize(MAX_TEXTURE_PARAMS, [0.0; 4]);
        let plan = ParamPlan { slots: self.slots };
        Ok((format!("{header}{}", self.code), params, plan))
    }

    /// Generates the functions of material `index`'s textures and returns
    /// the statements of its case in `surface_textures` (each property's
    /// base texture, then each layer over it where its mask lies) and in
    /// `surface_opacity` (the same for opacity alone).
    fn material(&mut self, index: usize, material: &Material) -> MaterialCases {
        let signals = material.signals();
        let mut masks = Vec::new();
        for (l, layer) in material.layers.iter().enumerate() {
            let name = format!("texture_{index}_layer{l}_mask");
            self.function(&name, (index, Root::Mask(l)), &layer.mask, &signals);
            masks.push(format!(
                "            let mask{l} = clamp({name}(p, pw, uv, fp, signals).x, 0.0, 1.0);\n"
            ));
        }
        let mut cases = MaterialCases {
            textures: masks.concat(),
            transmittance: String::new(),
            emission: String::new(),
        };
        let strength = self.emission_strength_slot(index, material);
        // The layer masks the transmittance reads (each declared once).
        let mut transmittance_masks = std::collections::BTreeSet::new();
        let mut transmittance = String::new();
        for property in Property::ALL {
            let value = property.name();
            let name = format!("texture_{index}_{value}");
            let tree = (index, Root::Property(property));
            self.function(&name, tree, material.texture(property), &signals);
            let mut statements =
                format!("            var {value} = {name}(p, pw, uv, fp, signals);\n");
            let mut masks_read = Vec::new();
            for (l, layer) in material.layers.iter().enumerate() {
                if let Some(texture) = layer.texture(property) {
                    let name = format!("texture_{index}_layer{l}_{value}");
                    let tree = (index, Root::Layer(l, property));
                    self.function(&name, tree, texture, &signals);
                    let _ = writeln!(
                        statements,
                        "            {value} = mix({value}, {name}(p, pw, uv, fp, signals), mask{l});"
                    );
                    masks_read.push(l);
                }
            }
            cases.textures.push_str(&statements);
            match property {
                Property::Opacity | Property::Transmission => {
                    transmittance_masks.extend(masks_read);
                    transmittance.push_str(&statements);
                }
                Property::Emission => {
                    let masks_read: String =
                        masks_read.iter().map(|&l| masks[l].as_str()).collect();
                    cases.emission = format!(
                        "{masks_read}{statements}            return emission * {strength}.x;\n"
                    );
                }
                _ => {}
            }
        }
        cases.transmittance = transmittance_masks
            .iter()
            .map(|&l| masks[l].as_str())
            .collect::<String>()
            + &transmittance
            + "            return (1.0 - clamp(opacity.x, 0.0, 1.0)) * clamp(transmission, vec3f(0.0), vec3f(1.0));\n";
        let _ = writeln!(
            cases.textures,
            "            out = SurfaceTextures(diffuse, specular, roughness.x, mirror.x, opacity.x, transmission, emission * {strength}.x, diffuse_transmission);"
        );
        cases
    }

    /// Generates function `name` evaluating `texture`, the tree at `root`
    /// of material (or swatch) `owner`.
    fn function(
        &mut self,
        name: &str,
        (owner, root): (usize, Root),
        texture: &Texture,
        signals: &[Signal],
    ) {
        self.owner = owner;
        self.path = NodePath::root(root);
        self.next = 0;
        let mut body = String::new();
        let site = Site {
            p: "p".into(),
            uv: "uv".into(),
            footprint: "fp".into(),
            mapping: None,
        };
        let value = self.texture(texture, &site, signals, &mut body);
        let _ = write!(
            self.code,
            "fn {name}(p: vec3f, pw: vec3f, uv: vec2f, fp: Footprint, signals: vec4f) -> vec3f {{\n{body}    return {value};\n}}\n\n"
        );
    }

    /// Reserves a parameter slot for `field` of `node` (the node at the
    /// current path) and returns the WGSL that reads it.
    fn slot(&mut self, node: &Texture, field: Field) -> String {
        let value = field
            .value(node, self.images)
            .expect("the generator reads only the numbers a node has");
        self.push(value, Place::Node(self.path.clone(), field))
    }

    /// The slot of material `owner`'s emission strength.
    fn emission_strength_slot(&mut self, owner: usize, material: &Material) -> String {
        self.owner = owner;
        self.push(
            [material.emission_strength, 0.0, 0.0, 0.0],
            Place::EmissionStrength,
        )
    }

    fn push(&mut self, value: [f32; 4], place: Place) -> String {
        self.params.push(value);
        self.slots.push(Slot {
            owner: self.owner,
            place,
        });
        format!("texture_params[{}]", self.params.len() - 1)
    }

    /// `node`'s child `child`, in its socket `a` or `b`: a constant's
    /// slot, or the nested texture's statements.
    fn child(
        &mut self,
        node: &Texture,
        (socket, child): (Socket, &Child),
        site: &Site,
        signals: &[Signal],
        body: &mut String,
    ) -> String {
        match child {
            Child::Scalar(_) | Child::Color(_) => {
                format!("{}.xyz", self.slot(node, Field::Constant(socket)))
            }
            Child::Texture(t) => self.nested(t, socket, site, signals, body),
        }
    }

    /// [`Generator::texture`] of the node in the current one's `socket`.
    fn nested(
        &mut self,
        texture: &Texture,
        socket: Socket,
        site: &Site,
        signals: &[Signal],
        body: &mut String,
    ) -> String {
        self.path.steps.push(socket);
        let value = self.texture(texture, site, signals, body);
        self.path.steps.pop();
        value
    }

    /// The ramp of texture `k` at its blend factor `t{k}`, unrolled stop by
    /// stop (twin of `texture::ramp`): before the first stop its colour, then
    /// each pair of neighbours takes over past its first position.
    fn ramp(&mut self, texture: &Texture, k: usize, body: &mut String) -> String {
        let slots: Vec<String> = (0..texture.ramp.len())
            .map(|i| self.slot(texture, Field::RampStop(i)))
            .collect();
        let _ = writeln!(body, "    var ramp{k} = {}.xyz;", slots[0]);
        for pair in slots.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            let _ = writeln!(
                body,
                "    ramp{k} = select(ramp{k}, mix({a}.xyz, {b}.xyz, clamp(select(1.0, (t{k} - {a}.w) / ({b}.w - {a}.w), {b}.w > {a}.w), 0.0, 1.0)), t{k} > {a}.w);"
            );
        }
        format!("ramp{k}")
    }

    /// An image node: its colour from the atlas (or, with a ramp, its
    /// luminance mapped). An image not loaded shows the CPU reference's
    /// stand-in colour.
    fn image(
        &mut self,
        texture: &Texture,
        k: usize,
        filter: ImageFilter,
        wrap: ImageWrap,
        site: &Site,
        body: &mut String,
    ) -> String {
        let rect = texture.image.as_ref().and_then(|s| self.images.rect(s));
        let color = match rect {
            Some(_) => {
                let rect = self.slot(texture, Field::ImageRect);
                let (uv, wrap) = (&site.uv, wrap.id());
                match filter {
                    ImageFilter::Nearest => format!("image_nearest({rect}, {uv}, {wrap}u).xyz"),
                    ImageFilter::Bilinear => {
                        format!("image_bilinear({rect}, 0, {uv}, {wrap}u).xyz")
                    }
                    ImageFilter::Trilinear => {
                        // The level whose texels are as wide as the footprint.
                        let fp = &site.footprint;
                        format!(
                            "image_trilinear({rect}, {uv}, {wrap}u, log2(max(max({fp}.uv.x * {rect}.z, {fp}.uv.y * {rect}.w), 1e-8))).xyz"
                        )
                    }
                }
            }
            None => format!("{}.xyz", self.slot(texture, Field::ImageUnavailable)),
        };
        let _ = writeln!(body, "    let c{k} = {color};");
        if texture.ramp.is_empty() {
            return format!("c{k}");
        }
        let _ = writeln!(body, "    let t{k} = luminance(c{k});");
        self.ramp(texture, k, body)
    }

    /// Appends the statements evaluating `texture` at `site` to `body` and
    /// returns the expression holding its colour. A mapped texture reads the
    /// surface's coordinates (the function's `p` or `pw`, and `uv`) afresh
    /// through its map, whose rows are parameters.
    fn texture(
        &mut self,
        texture: &Texture,
        site: &Site,
        signals: &[Signal],
        body: &mut String,
    ) -> String {
        let k = self.next;
        self.next += 1;
        let mapped;
        let site = match &texture.mapping {
            Some(mapping) => {
                let [r0, r1, r2] = [0, 1, 2].map(|i| self.slot(texture, Field::MappingRow(i)));
                // A frame moves the 3D point alone: (u, v) then read the
                // transform's own rows.
                let [u0, u1, u2] = if mapping.frame.is_some() {
                    [0, 1, 2].map(|i| self.slot(texture, Field::UvRow(i)))
                } else {
                    [r0.clone(), r1.clone(), r2.clone()]
                };
                let point = match mapping.space {
                    MappingSpace::Object => "p",
                    MappingSpace::World => "pw",
                };
                let scale = self.slot(texture, Field::FootprintScale);
                let _ = writeln!(
                    body,
                    "    let p{k} = affine_rows({point}, {r0}, {r1}, {r2});\n    let uv{k} = affine_rows(vec3f(uv, 0.0), {u0}, {u1}, {u2}).xy;\n    let fp{k} = Footprint(fp.uv * {scale}.xy, fp.p * {scale}.z, fp.axes * {scale}.z);"
                );
                mapped = Site {
                    p: format!("p{k}"),
                    uv: format!("uv{k}"),
                    footprint: format!("fp{k}"),
                    mapping: Some(*mapping),
                };
                &mapped
            }
            None => site,
        };
        let value = self.blended(texture, k, site, signals, body);
        if texture.ops.is_empty() {
            return value;
        }
        let _ = writeln!(body, "    var r{k} = {value};");
        for (i, op) in texture.ops.iter().enumerate() {
            let r = format!("r{k}");
            let expression = match op {
                MathOp::Abs => format!("abs({r})"),
                MathOp::Invert => format!("1.0 - {r}"),
                MathOp::Scale(_) => format!("{r} * {}.x", self.slot(texture, Field::Op(i))),
                MathOp::Bias(_) => format!("{r} + {}.x", self.slot(texture, Field::Op(i))),
                MathOp::Clamp { .. } => {
                    let q = self.slot(texture, Field::Op(i));
                    format!("min(max({r}, vec3f({q}.x)), vec3f({q}.y))")
                }
                MathOp::Power(_) => {
                    let q = self.slot(texture, Field::Op(i));
                    format!("pow(max({r}, vec3f(0.0)), vec3f({q}.x))")
                }
            };
            let _ = writeln!(body, "    {r} = {expression};");
        }
        format!("r{k}")
    }

    /// [`Generator::texture`] before the math steps: texture number `k`'s
    /// blend of its children (or ramp).
    fn blended(
        &mut self,
        texture: &Texture,
        k: usize,
        site: &Site,
        signals: &[Signal],
        body: &mut String,
    ) -> String {
        if texture.pattern == Pattern::Constant && texture.ramp.is_empty() {
            return self.child(texture, (Socket::A, &texture.a), site, signals, body);
        }
        if let Pattern::Image { filter, wrap } = texture.pattern {
            return self.image(texture, k, filter, wrap, site, body);
        }
        let (p, uv, fp) = (site.p.as_str(), site.uv.as_str(), site.footprint.as_str());
        let signal = texture
            .pattern
            .signal()
            .map(|s| Signal {
                mapping: site.mapping,
                ..s
            })
            .and_then(|s| signals.iter().position(|x| *x == s))
            .map_or_else(|| "0.0".to_string(), |i| format!("signals[{i}]"));
        let mut child_uv = uv.to_string();
        let mut child_footprint = fp.to_string();
        // The pattern's own numbers, one slot (those that have any).
        let q = match texture.pattern.numbers() {
            Some(_) => self.slot(texture, Field::Pattern),
            None => String::new(),
        };
        let cell = format!("cell{k}");
        let fill = |code: &str| {
            code.replace("{p}", p)
                .replace("{uv}", uv)
                .replace("{fp}", fp)
                .replace("{q}", &q)
                .replace("{signal}", &signal)
                .replace("{cell}", &cell)
        };
        let t = match texture.pattern.info().code {
            PatternCode::First => "0.0".to_string(),
            PatternCode::Blend(t) => fill(t),
            PatternCode::Cell { cell: cell_code, t } => {
                let _ = writeln!(body, "    let {cell} = {};", fill(cell_code));
                child_uv = format!("{cell}.local");
                child_footprint = format!("Footprint({fp}.uv / {q}.xy, {fp}.p, {fp}.axes)");
                fill(t)
            }
            PatternCode::Factor => match &texture.factor {
                Some(factor) => {
                    let f = self.nested(factor, Socket::Factor, site, signals, body);
                    format!("clamp({f}.x, 0.0, 1.0)")
                }
                None => "0.0".to_string(),
            },
            PatternCode::Image => unreachable!("image nodes are generated by `image`"),
        };
        let _ = writeln!(body, "    let t{k} = {t};");
        if !texture.ramp.is_empty() {
            return self.ramp(texture, k, body);
        }
        let child_site = Site {
            uv: child_uv,
            footprint: child_footprint,
            ..site.clone()
        };
        let a = self.child(texture, (Socket::A, &texture.a), &child_site, signals, body);
        let b = self.child(texture, (Socket::B, &texture.b), &child_site, signals, body);
        let _ = writeln!(body, "    let v{k} = mix({a}, {b}, t{k});");
        format!("v{k}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec3};
    use marbre_core::scene::{Ground, Sphere};

    fn generate_plain(scene: &Scene) -> Result<GeneratedTextures> {
        generate(scene, &ImageSet::empty())
    }

    fn nested() -> Texture {
        let inner = Texture::blend(
            Pattern::Checker2d {
                size: Vec2::splat(1.0 / 3.0),
                phase: 0.0,
            },
            Vec3::new(0.8, 0.0, 0.0),
            Vec3::new(0.4, 0.8, 0.0),
        );
        Texture::blend(
            Pattern::Checker2d {
                size: Vec2::splat(0.25),
                phase: 0.0,
            },
            inner,
            Vec3::new(0.0, 0.0, 0.8),
        )
    }

    fn scene_with(texture: Texture) -> Scene {
        let mut ground = Ground::default();
        ground.material.diffuse = texture;
        Scene {
            spheres: vec![Sphere::default()],
            ground: Some(ground),
            ..Scene::default()
        }
    }

    /// A colour typed as the texture report writes it, in a preset marked
    /// `colors: Srgb`, reaches the shader's parameters as its linear value
    /// (the sRGB EOTF of IEC 61966-2-1, evaluated here in f64).
    #[test]
    fn a_typed_srgb_colour_reaches_the_shader_linear() {
        let text =
            "(colors: Srgb, scene: (spheres: [(material: (diffuse: (0.54, 0.27, 0.0742)))]))";
        let preset = marbre_core::preset::parse(text, std::path::Path::new("typed.ron"))
            .unwrap()
            .preset;
        let params = generate_plain(&preset.scene).unwrap().params;
        let eotf = |v: f64| ((v + 0.055) / 1.055).powf(2.4);
        let expected = [eotf(0.54), eotf(0.27), eotf(0.0742)];
        let found = params
            .iter()
            .any(|p| (0..3).all(|i| (f64::from(p[i]) - expected[i]).abs() < 1e-6));
        assert!(found, "{expected:?} not among {:?}", &params[..4]);
    }

    /// Numbers live in the parameter buffer: editing them keeps the code,
    /// so the pipeline is not rebuilt; a structural edit changes it.
    #[test]
    fn parameter_edits_keep_the_code_and_structural_edits_change_it() {
        let base = generate_plain(&scene_with(nested())).unwrap();
        let mut edited = nested();
        edited.pattern = Pattern::Checker2d {
            size: Vec2::splat(0.1),
            phase: 0.5,
        };
        edited.b = Child::Color(Vec3::ONE);
        let numbers = generate_plain(&scene_with(edited.clone())).unwrap();
        assert_eq!(numbers.wgsl, base.wgsl);
        assert_ne!(numbers.params, base.params);
        assert!(numbers.params.contains(&[0.1, 0.1, 0.5, 0.0]));

        edited.pattern = Pattern::Cutout {
            sides: 5,
            radius: 0.3,
        };
        let structure = generate_plain(&scene_with(edited)).unwrap();
        assert_ne!(structure.wgsl, base.wgsl);
        assert!(structure.wgsl.contains("cutout("));
    }

    /// Nested cell patterns hand their children the cell's local (u, v).
    #[test]
    fn nested_cells_read_the_parent_cell_coordinates() {
        let code = generate_plain(&scene_with(nested())).unwrap().wgsl;
        assert!(code.contains("checker_2d(uv,"), "{code}");
        assert!(
            code.contains("checker_2d(cell1.local,") || code.contains("checker_2d(cell0.local,"),
            "{code}"
        );
    }

    /// The CPU reference of the same tree: a 4×4 board whose even cells
    /// hold 3×3 boards.
    #[test]
    fn cpu_reference_of_a_nested_checker() {
        let t = nested();
        let red = Vec3::new(0.8, 0.0, 0.0);
        let green = Vec3::new(0.4, 0.8, 0.0);
        let blue = Vec3::new(0.0, 0.0, 0.8);
        // Outer cell (0, 0) is even: the inner board, whose cell (0, 0) is red
        // and (1, 0) green.
        assert_eq!(t.eval(Vec3::ZERO, Vec2::new(0.01, 0.01)), red);
        assert_eq!(t.eval(Vec3::ZERO, Vec2::new(0.12, 0.01)), green);
        // Outer cell (1, 0) is odd: blue.
        assert_eq!(t.eval(Vec3::ZERO, Vec2::new(0.3, 0.1)), blue);
    }

    /// With a ramp, the pattern's t picks a stop colour: the children are
    /// neither generated nor evaluated, and each stop is one parameter.
    #[test]
    fn a_ramp_replaces_the_blend_of_the_children() {
        use marbre_core::texture::RampStop;
        let mut t = nested();
        t.ramp = vec![
            RampStop {
                position: 0.0,
                color: Vec3::X,
            },
            RampStop {
                position: 1.0,
                color: Vec3::Y,
            },
        ];
        let generated = generate_plain(&scene_with(t.clone())).unwrap();
        assert!(generated.wgsl.contains("var ramp0"), "{}", generated.wgsl);
        assert!(!generated.wgsl.contains("cell1"), "children were generated");
        assert!(generated.params.contains(&[0.0, 1.0, 0.0, 1.0]));
        // Outer cell (1, 0) is odd: t = 1, the last stop.
        assert_eq!(t.eval(Vec3::ZERO, Vec2::new(0.3, 0.1)), Vec3::Y);
        assert_eq!(t.eval(Vec3::ZERO, Vec2::new(0.1, 0.1)), Vec3::X);
    }

    /// Shadow rays evaluate the noise signals only when an opacity texture
    /// reads one; layers' opacity bindings count. A layer that sets both
    /// opacity and transmission declares its mask once.
    #[test]
    fn surface_transmittance_reads_noise_only_when_opacity_does() {
        let mut scene = scene_with(nested());
        scene.spheres[0].material.diffuse = Texture::blend(
            Pattern::Fbm {
                noise: Default::default(),
            },
            0.0,
            1.0,
        );
        let code = generate_plain(&scene).unwrap().wgsl;
        assert!(code.contains("fn surface_transmittance"), "{code}");
        assert!(!code.contains("let signals = material_signals"), "{code}");
        scene.spheres[0]
            .material
            .layers
            .push(marbre_core::scene::Layer {
                opacity: Some(Texture::blend(
                    Pattern::Turbulence {
                        noise: Default::default(),
                    },
                    0.0,
                    1.0,
                )),
                transmission: Some(Texture::color(Vec3::X)),
                ..Default::default()
            });
        let code = generate_plain(&scene).unwrap().wgsl;
        assert!(code.contains("let signals = material_signals"), "{code}");
        let transmittance = &code[code.find("fn surface_transmittance").unwrap()..];
        let transmittance = &transmittance[..transmittance.find("\n}\n").unwrap()];
        assert_eq!(transmittance.matches("let mask0").count(), 1, "{code}");
        assert!(
            code.contains("opacity = mix(opacity, texture_0_layer0_opacity"),
            "{code}"
        );
    }

    /// The anti-aliasing switches are override constants: toggling them
    /// changes neither the generated code nor the feature set, so the
    /// module is the same and only the pipeline's constants differ.
    #[test]
    fn anti_aliasing_switches_leave_the_module_alone() {
        let on = scene_with(nested());
        let mut off = on.clone();
        off.render.filter_checkers = false;
        off.render.clamp_octaves = false;
        assert_eq!(generate_plain(&on).unwrap(), generate_plain(&off).unwrap());
        let features = crate::gpu::FeatureSet::for_scene;
        assert_eq!(features(&on), features(&off));
        assert!(
            generate_plain(&on)
                .unwrap()
                .wgsl
                .contains("filter_checkers)")
        );
    }

    #[test]
    fn every_material_has_a_case() {
        let scene = scene_with(nested());
        let code = generate_plain(&scene).unwrap().wgsl;
        for i in 0..scene.materials().count() {
            assert!(code.contains(&format!("case {i}u:")), "{code}");
        }
    }
}
