//! The material editor: each property's texture tree, its layers, and the
//! tree operations (nest, unnest, copy a subtree, paste it over another).

use super::keying::number as keyed;
use super::swatches::{self, SwatchPlace};
use super::tx_ui::{has_tx_section, tx_ui};
use super::widgets::uv_frame_ui;
use super::{color_button, labelled_color, slider, vec3_ui};
use egui::{CollapsingHeader, ComboBox, Slider, SliderClamping, TextEdit, Ui};
use glam::Vec3;
use marbre_core::animation::ParamPath;
use marbre_core::bake::BakeProperty;
use marbre_core::noise::{
    Evolution, FractalParams, HashKind, NoiseKind, NoiseSettings, Progression,
};
use marbre_core::scene::MaterialKey;
use marbre_core::scene::texture_graph::{NodePath, Root, Socket};
use marbre_core::scene::{
    Child, Layer, MappingSpace, Material, MathOp, PATTERNS, Pattern, PatternKind, Property,
    Texture, TextureMapping, UvFrame,
};
use marbre_core::texture::{
    ColorSpace, ImageFilter, ImageSource, ImageWrap, MAX_RAMP_STOPS, RampStop,
};
use std::ops::RangeInclusive;
use std::path::PathBuf;

/// Every property's texture, the bump, the emission strength and layers;
/// returns the property whose Bake… button was pressed.
pub fn material_ui(ui: &mut Ui, key: MaterialKey, m: &mut Material) -> Option<BakeProperty> {
    let mut bake = None;
    let place = |root| SwatchPlace {
        key,
        path: NodePath::root(root),
    };
    let material = ParamPath::parse(&format!("{key}.material"))
        .expect("a material key prints as a parameter path");
    for property in Property::ALL {
        let (kind, hint) = property_ui_info(property);
        texture_ui(
            ui,
            property.label(),
            hint,
            m.texture_mut(property),
            kind,
            &place(Root::Property(property)),
        );
        let bakeable = BakeProperty::ALL
            .into_iter()
            .find(|b| b.material_property() == Some(property));
        bake = bake.or(bakeable.filter(|&b| bake_button(ui, b)));
        if has_tx_section(property) {
            ui.indent(("tx", property.name()), |ui| tx_ui(ui, m, property));
        }
        if property == Property::Emission {
            keyed(
                ui,
                &material.field("emission_strength"),
                &mut m.emission_strength,
                |ui, v| {
                    ui.add(
                        slider(
                            v,
                            0.0..=Material::MAX_EMISSION_STRENGTH,
                            "emission strength",
                        )
                        .logarithmic(true),
                    )
                },
            )
            .on_hover_text("Emitted radiance is the emission colour times this");
        }
    }
    texture_ui(
        ui,
        "bump",
        "A height field that tilts the shading normal (tiles with a bevel, waves, noise)",
        &mut m.bump,
        ValueKind::Scalar,
        &place(Root::Bump),
    );
    bake = bake.or(Some(BakeProperty::Bump).filter(|&b| bake_button(ui, b)));
    keyed(
        ui,
        &material.field("bump_height"),
        &mut m.bump_height,
        |ui, v| {
            ui.add(typed_beyond(slider(
                v,
                -Material::BUMP_HEIGHT_DRAG_RANGE..=Material::BUMP_HEIGHT_DRAG_RANGE,
                "bump height",
            )))
        },
    )
    .on_hover_text(
        "Height in scene units of a bump value of 1; 0 turns the bump off (drag within ±0.5, \
         or type any value: a steep bump bends shading normals away, and marbre falls back)",
    );
    layers_ui(ui, key, &mut m.layers);
    bake
}

/// Texels a side of a bake from the viewer (`marbre bake`'s default): the
/// Bake… button says it, `app::bake` writes it.
pub const BAKE_SIZE: u32 = 1024;

/// The Bake… button of a property: whether it was pressed.
fn bake_button(ui: &mut Ui, property: BakeProperty) -> bool {
    ui.small_button("Bake…")
        .on_hover_text(format!(
            "Write this {} to an image in the object's (u, v) square, {} texels a side, beside \
             the preset (as `marbre bake` does: {}), with its mapping in a .mapping.ron beside it",
            property.name(),
            BAKE_SIZE,
            if property.is_color() {
                "sRGB PNG"
            } else {
                "linear EXR"
            }
        ))
        .clicked()
}

/// What a property's values are, and its tooltip.
fn property_ui_info(property: Property) -> (ValueKind, &'static str) {
    let kind = if property.is_color() {
        ValueKind::Color
    } else {
        ValueKind::Scalar
    };
    let hint = match property {
        Property::Diffuse => "Lambert colour: the light scattered evenly in all directions",
        Property::Specular => {
            "GGX reflectance at normal incidence (about 0.04 for plastics and stone)"
        }
        Property::Roughness => "GGX roughness: 0 is polished, 1 is matte",
        Property::Mirror => "Fraction of the light reflected by a perfect mirror, on top of GGX",
        Property::Opacity => {
            "1 is solid; below, rays and shadows pass straight through (a cutout's holes)"
        }
        Property::Transmission => {
            "Colour of the light passing through where opacity < 1: tints the view through and the shadow"
        }
        Property::Emission => "Light the surface gives off (times the strength below)",
        Property::DiffuseTransmission => {
            "Diffuse transmission (N3D's TD): light reaching the other side leaves this side \
             scattered evenly, times this colour (a lampshade, paper); keep diffuse + this ≤ 1"
        }
    };
    (kind, hint)
}

/// The material's layers, each over everything before it: a mask and the
/// properties it sets.
fn layers_ui(ui: &mut Ui, key: MaterialKey, layers: &mut Vec<Layer>) {
    let place = |root| SwatchPlace {
        key,
        path: NodePath::root(root),
    };
    let mut remove = None;
    for (i, layer) in layers.iter_mut().enumerate() {
        ui.push_id(("layer", i), |ui| {
            CollapsingHeader::new(format!("layer “{}”", layer.name))
                .id_salt("layer")
                .show(ui, |ui| {
                    ui.horizontal(|ui| {
                        ui.text_edit_singleline(&mut layer.name)
                            .on_hover_text("The layer's name, shown in its header");
                        if ui
                            .small_button("remove layer")
                            .on_hover_text("Delete this layer")
                            .clicked()
                        {
                            remove = Some(i);
                        }
                    });
                    texture_ui(
                        ui,
                        "mask",
                        "Where the layer lies: 1 replaces what is below, 0 leaves it",
                        &mut layer.mask,
                        ValueKind::Scalar,
                        &place(Root::Mask(i)),
                    );
                    for property in Property::ALL {
                        let (kind, hint) = property_ui_info(property);
                        let slot = layer.slot_mut(property);
                        let mut set = slot.is_some();
                        if ui
                            .checkbox(&mut set, format!("sets {}", property.label()))
                            .on_hover_text("Ticked, the layer sets this property where its mask is")
                            .changed()
                        {
                            *slot = set.then(|| match kind {
                                ValueKind::Color => Texture::color(Vec3::splat(0.5)),
                                ValueKind::Scalar => Texture::scalar(0.5),
                            });
                        }
                        if let Some(texture) = slot {
                            texture_ui(
                                ui,
                                property.label(),
                                hint,
                                texture,
                                kind,
                                &place(Root::Layer(i, property)),
                            );
                        }
                    }
                });
        });
    }
    if let Some(i) = remove {
        layers.remove(i);
    }
    if ui
        .button("add layer")
        .on_hover_text("A layer over the material: a mask and the properties it sets")
        .clicked()
    {
        layers.push(Layer {
            name: format!("layer {}", layers.len() + 1),
            ..Layer::default()
        });
    }
}

/// What a property's values are: colours, or scalars (the first channel).
#[derive(Clone, Copy, PartialEq)]
enum ValueKind {
    Color,
    Scalar,
}

/// The subtree last copied from any texture's menu, for pasting elsewhere
/// (duplicating a subtree, or replacing one by another).
fn clipboard_id() -> egui::Id {
    egui::Id::NULL.with("texture clipboard")
}

/// A texture: its pattern, then its two children (a constant pattern only
/// uses the first), then its math steps. `place` is where it is in the
/// scene (a property's own texture is a root). Right-click the header to copy, paste over or reset the subtree.
fn texture_ui(
    ui: &mut Ui,
    title: &str,
    hint: &str,
    texture: &mut Texture,
    kind: ValueKind,
    place: &SwatchPlace,
) {
    ui.push_id(title, |ui| {
        let header = CollapsingHeader::new(title)
            .id_salt("texture")
            .default_open(place.path.steps.is_empty())
            .show(ui, |ui| {
                swatch_ui(ui, texture, place);
                let node = node_param_path(place);
                pattern_ui(ui, texture, &node.field("pattern"));
                if matches!(texture.pattern, Pattern::Image { .. }) {
                    image_source_ui(ui, &mut texture.image);
                }
                mapping_ui(ui, &mut texture.mapping, &node);
                if texture.pattern == Pattern::Mix {
                    let factor = texture
                        .factor
                        .get_or_insert_with(|| Box::new(Texture::scalar(0.5)));
                    texture_ui(
                        ui,
                        "factor",
                        "How much of b: its first channel, 0 to 1",
                        factor,
                        ValueKind::Scalar,
                        &place.child(Socket::Factor),
                    );
                }
                ramp_ui(ui, texture, &node);
                // An image gives its own colour: it has no children.
                let is_image = matches!(texture.pattern, Pattern::Image { .. });
                if texture.ramp.is_empty() && !is_image {
                    if texture.pattern == Pattern::Constant {
                        child_ui(ui, "value", &mut texture.a, kind, &place.child(Socket::A));
                    } else {
                        child_ui(
                            ui,
                            "a (t = 0)",
                            &mut texture.a,
                            kind,
                            &place.child(Socket::A),
                        );
                        child_ui(
                            ui,
                            "b (t = 1)",
                            &mut texture.b,
                            kind,
                            &place.child(Socket::B),
                        );
                    }
                }
                math_ui(ui, &mut texture.ops, &node);
            });
        header
            .header_response
            .on_hover_text(hint)
            .context_menu(|ui| {
                if ui
                    .button("copy subtree")
                    .on_hover_text("Copy this texture and everything nested in it")
                    .clicked()
                {
                    ui.ctx()
                        .data_mut(|d| d.insert_temp(clipboard_id(), texture.clone()));
                    ui.close();
                }
                let copied: Option<Texture> = ui.ctx().data(|d| d.get_temp(clipboard_id()));
                if ui
                    .add_enabled(copied.is_some(), egui::Button::new("paste over this"))
                    .on_hover_text("Replace this texture by the copied subtree")
                    .on_disabled_hover_text("Copy a subtree first")
                    .clicked()
                {
                    if let Some(copied) = copied {
                        *texture = copied;
                    }
                    ui.close();
                }
                if ui
                    .button("reset to a constant")
                    .on_hover_text("Replace this texture by its value at the origin")
                    .clicked()
                {
                    let value = texture.eval(Vec3::ZERO, glam::Vec2::ZERO);
                    *texture = match kind {
                        ValueKind::Color => Texture::color(value),
                        ValueKind::Scalar => Texture::scalar(value.x),
                    };
                    ui.close();
                }
            });
    });
}

/// The parameter path of the node at `place` (`spheres[0].material.diffuse.a`):
/// its numbers' key buttons name them under it.
fn node_param_path(place: &SwatchPlace) -> ParamPath {
    ParamPath::parse(&format!("{}.material.{}", place.key, place.path))
        .expect("a material key and a node path print as a parameter path")
}

/// Side of a node's preview swatch in the panel, in points.
const SWATCH_POINTS: f32 = 48.0;

/// The node's preview swatch, its output on a unit sphere, once the viewer
/// has rendered it; none for a constant, whose value shows as it is.
fn swatch_ui(ui: &mut Ui, texture: &Texture, place: &SwatchPlace) {
    if texture.as_constant().is_some() {
        return;
    }
    if let Some(id) = swatches::swatch(ui.ctx(), place.clone()) {
        ui.add(egui::Image::new((id, egui::Vec2::splat(SWATCH_POINTS))))
            .on_hover_text(
                "This node's output on the front of a unit sphere, point sampled (image nodes \
                 show grey); refreshed after each edit",
            );
    }
}

/// The octave count over the panel's width in quarter steps: egui's
/// default 100-px rail put 16 octaves in 100 px, ten of them in a 60-px
/// flick of the mouse.
pub(super) fn octaves_slider(ui: &mut Ui, octaves: &mut f32) -> egui::Response {
    ui.scope(|ui| {
        // Room for the value box, the label and a key button beside the
        // rail: a rail wider than the row would widen the panel, and the
        // next frame's rail with it.
        ui.spacing_mut().slider_width = (ui.available_width() - 160.0).max(120.0);
        ui.add(slider(octaves, FractalParams::OCTAVES, "octaves").step_by(0.25))
            .on_hover_text(
                "More octaves: finer detail, one noise evaluation each; a fractional part fades \
                 the last one in (in quarter steps)",
            )
    })
    .inner
}

/// The image file of an image node, and how its codes decode. The path is
/// applied on Enter or when the field loses focus (the viewer then loads
/// it), not at every keystroke.
pub(super) fn image_source_ui(ui: &mut Ui, image: &mut Option<ImageSource>) {
    let source = image.get_or_insert_with(|| ImageSource {
        path: PathBuf::new(),
        color_space: ColorSpace::Srgb,
    });
    let id = ui.scope_id().with("image path");
    let mut typed: String = ui
        .ctx()
        .data(|d| d.get_temp(id))
        .unwrap_or_else(|| source.path.display().to_string());
    let response = ui
        .add(TextEdit::singleline(&mut typed).hint_text("images/picture.png"))
        .on_hover_text(
            "PNG, JPEG, HDR, EXR, PPM or PGM; relative to the preset file. Enter applies",
        );
    if response.lost_focus() {
        source.path = PathBuf::from(typed.trim());
        ui.ctx().data_mut(|d| d.remove::<String>(id));
    } else {
        ui.ctx().data_mut(|d| d.insert_temp(id, typed));
    }
    ui.horizontal(|ui| {
        ui.selectable_value(&mut source.color_space, ColorSpace::Srgb, "sRGB colour")
            .on_hover_text("8-bit colour images: decoded from sRGB to linear");
        ui.selectable_value(&mut source.color_space, ColorSpace::Linear, "linear data")
            .on_hover_text("Roughness, height and other data: codes taken as they are");
    });
}

/// The texture's own mapping: ticked, it and its subtree read the surface's
/// coordinates (object or world for 3D patterns, the primitive's (u, v) for
/// 2D ones) through a transform.
/// `node`: the texture's parameter path, for the key buttons.
pub(super) fn mapping_ui(ui: &mut Ui, mapping: &mut Option<TextureMapping>, node: &ParamPath) {
    let mut on = mapping.is_some();
    if ui
        .checkbox(&mut on, "mapping")
        .on_hover_text("Place this texture with its own transform, in object or world space")
        .changed()
    {
        *mapping = on.then(TextureMapping::default);
    }
    let Some(m) = mapping else {
        return;
    };
    ui.horizontal(|ui| {
        ui.selectable_value(&mut m.space, MappingSpace::Object, "object")
            .on_hover_text("3D patterns move with the object");
        ui.selectable_value(&mut m.space, MappingSpace::World, "world")
            .on_hover_text("Objects move through the 3D pattern");
    });
    let at = node.field("mapping");
    uv_frame_ui(
        ui,
        &at.field("frame"),
        &mut m.frame,
        "3D frame",
        "The report's ATX3D: 3D patterns read the point's coordinates along an origin and \
         axes u, v (the third axis is their cross product, of length √(|u|·|v|)), before \
         the transform below",
        UvFrame {
            origin: Vec3::ZERO,
            u_axis: Vec3::X,
            v_axis: Vec3::Y,
        },
    );
    let t = &mut m.transform;
    vec3_ui(
        ui,
        &at.field("transform").field("translate"),
        "translate",
        &mut t.translate,
        0.01,
        "Where the texture's origin sits",
    );
    vec3_ui(
        ui,
        &at.field("transform").field("rotate_degrees"),
        "rotate °",
        &mut t.rotate_degrees,
        0.5,
        "Turns about x, then y, then z, in degrees",
    );
    vec3_ui(
        ui,
        &at.field("transform").field("scale"),
        "scale",
        &mut t.scale,
        0.01,
        "Size of the texture: 2 makes its features twice as large",
    );
}

/// The math steps after a texture: each a dropdown, its parameters, and a
/// remove button.
/// `node`: the texture's parameter path, for the key buttons.
pub(super) fn math_ui(ui: &mut Ui, ops: &mut Vec<MathOp>, node: &ParamPath) {
    let mut remove = None;
    for (i, op) in ops.iter_mut().enumerate() {
        let at = node.field("ops").index(i);
        ui.push_id(("op", i), |ui| {
            ui.horizontal(|ui| {
                let mut index = op.index();
                ComboBox::new("math", "")
                    .show_index(ui, &mut index, MathOp::NAMES.len(), |i| MathOp::NAMES[i])
                    .on_hover_text("A step applied to the texture's value, channel by channel");
                if index != op.index() {
                    *op = MathOp::with_index(index);
                }
                let drag = |ui: &mut Ui, path: &ParamPath, v: &mut f32, prefix: &str| {
                    keyed(ui, path, v, |ui, v| {
                        ui.add(egui::DragValue::new(v).speed(0.01).prefix(prefix))
                    })
                };
                match op {
                    MathOp::Scale(x) => {
                        drag(ui, &at, x, "× ").on_hover_text("Multiplies the value by this");
                    }
                    MathOp::Bias(x) => {
                        drag(ui, &at, x, "+ ").on_hover_text("Adds this to the value");
                    }
                    MathOp::Clamp { min, max } => {
                        drag(ui, &at.field("min"), min, "min ")
                            .on_hover_text("Values below this are raised to it");
                        drag(ui, &at.field("max"), max, "max ")
                            .on_hover_text("Values above this are lowered to it");
                    }
                    MathOp::Power(e) => {
                        keyed(ui, &at, e, |ui, e| {
                            ui.add(
                                egui::DragValue::new(e)
                                    .speed(0.01)
                                    .range(MathOp::MIN_EXPONENT..=100.0)
                                    .prefix("^ "),
                            )
                        })
                        .on_hover_text(format!(
                            "Raises the value (negatives taken as 0) to this exponent, at least {}",
                            MathOp::MIN_EXPONENT
                        ));
                    }
                    MathOp::Abs | MathOp::Invert => {}
                }
                if ui
                    .small_button("×")
                    .on_hover_text("Remove this step")
                    .clicked()
                {
                    remove = Some(i);
                }
            });
        });
    }
    if let Some(i) = remove {
        ops.remove(i);
    }
    if ops.len() < Texture::MAX_OPS
        && ui
            .small_button("add math step")
            .on_hover_text("Scale, bias, abs, invert, clamp or power the value")
            .clicked()
    {
        ops.push(MathOp::Scale(1.0));
    }
}

/// The colour ramp: ticked, the pattern's blend factor picks a colour from
/// the stops instead of blending `a` and `b` (which seed the first two).
/// `path`: the node's parameter path, for the stops' key buttons.
pub(super) fn ramp_ui(ui: &mut Ui, texture: &mut Texture, path: &ParamPath) {
    let mut on = !texture.ramp.is_empty();
    if ui
        .checkbox(&mut on, "colour ramp")
        .on_hover_text("Map the pattern's t through colour stops (like Blender's ColorRamp)")
        .changed()
    {
        texture.ramp = if on {
            let at = |c: &Child| c.eval(Vec3::ZERO, glam::Vec2::ZERO);
            vec![
                RampStop {
                    position: 0.0,
                    color: at(&texture.a),
                },
                RampStop {
                    position: 1.0,
                    color: at(&texture.b),
                },
            ]
        } else {
            Vec::new()
        };
    }
    let mut remove = None;
    for (i, stop) in texture.ramp.iter_mut().enumerate() {
        ui.push_id(("stop", i), |ui| {
            ui.horizontal(|ui| {
                let at = path.field("ramp").index(i);
                super::keying::vector(ui, &at.field("color"), &mut stop.color, |ui, c| {
                    color_button(ui, c).on_hover_text("This stop's colour")
                });
                keyed(ui, &at.field("position"), &mut stop.position, |ui, v| {
                    ui.add(slider(v, 0.0..=1.0, "at"))
                })
                .on_hover_text("The pattern's t at which this colour is reached, 0 to 1");
                if ui
                    .small_button("×")
                    .on_hover_text("Remove this stop")
                    .clicked()
                {
                    remove = Some(i);
                }
            });
        });
    }
    if let Some(i) = remove.filter(|_| texture.ramp.len() > 1) {
        texture.ramp.remove(i);
    }
    if !texture.ramp.is_empty()
        && texture.ramp.len() < MAX_RAMP_STOPS
        && ui
            .small_button("add stop")
            .on_hover_text(format!(
                "Another stop 0.1 after the last, in its colour (at most {MAX_RAMP_STOPS} stops)"
            ))
            .clicked()
    {
        let last = texture.ramp[texture.ramp.len() - 1];
        texture.ramp.push(RampStop {
            position: (last.position + 0.1).min(1.0),
            ..last
        });
    }
    // The shader interpolates neighbours: keep the stops in order.
    texture
        .ramp
        .sort_by(|x, y| x.position.total_cmp(&y.position));
}

/// One side of a blend: its value, or (ticked "texture") a nested texture
/// edited in place. Unticking keeps the nested texture's colour at the
/// origin as the value.
/// A child of a texture, at `place` (its socket's path).
fn child_ui(ui: &mut Ui, label: &str, child: &mut Child, kind: ValueKind, place: &SwatchPlace) {
    ui.push_id(label, |ui| {
        ui.horizontal(|ui| {
            let mut nested = matches!(child, Child::Texture(_));
            // The holder's depth (1 for a root) is the sockets down to here.
            let can_nest = place.path.steps.len() < Texture::MAX_DEPTH;
            if (can_nest || nested)
                && ui
                    .checkbox(&mut nested, "texture")
                    .on_hover_text(
                        "Nest a whole texture here (a checker of marbles, bricks of noise)",
                    )
                    .changed()
            {
                *child = if nested {
                    Child::Texture(Box::new(Texture::nesting(child)))
                } else {
                    let c = child.eval(Vec3::ZERO, glam::Vec2::ZERO);
                    match kind {
                        ValueKind::Color => Child::Color(c),
                        ValueKind::Scalar => Child::Scalar(c.x),
                    }
                };
            }
            let constant = match kind {
                ValueKind::Color => "A constant colour",
                ValueKind::Scalar => "A constant value, 0 to 1",
            };
            let hint = if can_nest {
                format!("{constant}; tick “texture” to nest a whole texture instead")
            } else {
                constant.to_owned()
            };
            let at = node_param_path(place);
            match child {
                Child::Color(c) if kind == ValueKind::Color => {
                    super::keying::vector(ui, &at, c, |ui, c| labelled_color(ui, c, label))
                        .on_hover_text(hint);
                }
                Child::Color(c) => {
                    keyed(ui, &at.index(0), &mut c.x, |ui, v| {
                        ui.add(slider(v, 0.0..=1.0, label))
                    })
                    .on_hover_text(hint);
                }
                Child::Scalar(v) => {
                    keyed(ui, &at, v, |ui, v| ui.add(slider(v, 0.0..=1.0, label)))
                        .on_hover_text(hint);
                }
                Child::Texture(_) => {}
            }
        });
        if let Child::Texture(t) = child {
            texture_ui(ui, label, "A nested texture", t, kind, place);
        }
    });
}

/// The pattern dropdown and the chosen pattern's parameters.
/// `path`: the pattern's parameter path (`….diffuse.pattern`), for the
/// key buttons.
pub(super) fn pattern_ui(ui: &mut Ui, texture: &mut Texture, path: &ParamPath) {
    let kind = texture.pattern.kind();
    let mut index = kind as usize;
    ComboBox::new("pattern", "pattern")
        .show_index(ui, &mut index, PATTERNS.len(), |i| PATTERNS[i].name)
        .on_hover_text(match kind.info().tx_keyword {
            Some(keyword) => {
                format!("What blends between the two values across the surface (TX: {keyword})")
            }
            None => "What blends between the two values across the surface".to_string(),
        });
    if let Some(chosen) = PatternKind::from_index(index)
        && chosen != kind
    {
        // `with_kind` carries the noise settings over, so tuning survives
        // (Massal's marble takes his recipe instead); a constant's one value
        // gets a contrasting second side, so the new pattern shows.
        *texture = texture.with_pattern_contrasting(texture.pattern.with_kind(chosen));
    }
    match &mut texture.pattern {
        Pattern::Constant | Pattern::Diagonal => {}
        Pattern::Checker { size } => {
            keyed(ui, &path.field("size"), size, |ui, v| {
                ui.add(slider(v, 0.01..=10.0, "cube size").logarithmic(true))
            })
            .on_hover_text("Side of the checkerboard's cubes, in scene units");
        }
        Pattern::Fbm { noise } | Pattern::Turbulence { noise } | Pattern::Ridged { noise } => {
            noise_ui(ui, noise, &path.field("noise"))
        }
        Pattern::Mix => {}
        Pattern::Image { filter, wrap } => {
            ComboBox::new("filter", "filter")
                .selected_text(format!("{filter:?}"))
                .show_ui(ui, |ui| {
                    for f in [
                        ImageFilter::Nearest,
                        ImageFilter::Bilinear,
                        ImageFilter::Trilinear,
                    ] {
                        ui.selectable_value(filter, f, format!("{f:?}"));
                    }
                })
                .response
                .on_hover_text(
                    "Nearest texel, bilinear between four, or trilinear between mip levels \
                     chosen by the pixel's footprint",
                );
            ComboBox::new("wrap", "wrap")
                .selected_text(format!("{wrap:?}"))
                .show_ui(ui, |ui| {
                    for w in [ImageWrap::Repeat, ImageWrap::Clamp, ImageWrap::Mirror] {
                        ui.selectable_value(wrap, w, format!("{w:?}"));
                    }
                })
                .response
                .on_hover_text("What the image shows outside its unit square of (u, v)");
        }
        Pattern::Marble {
            noise,
            stripe_frequency,
        } => {
            noise_ui(ui, noise, &path.field("noise"));
            keyed(
                ui,
                &path.field("stripe_frequency"),
                stripe_frequency,
                |ui, v| ui.add(slider(v, 0.0..=32.0, "stripe frequency")),
            )
            .on_hover_text(
                "t = 0.5 + 0.5·sin(x · stripe frequency + fBm): veins per 2π units along x",
            );
        }
        Pattern::Checker2d { size, phase } => {
            size_ui(
                ui,
                &path.field("size"),
                size,
                [
                    (
                        "cell width (u)",
                        "Width of a cell in (u, v): 0.125 gives 8 cells per unit",
                    ),
                    ("cell height (v)", "Height of a cell in (u, v)"),
                ],
            );
            keyed(ui, &path.field("phase"), phase, |ui, v| {
                ui.add(slider(v, 0.0..=1.0, "row phase"))
            })
            .on_hover_text("Shift of every other row, in cells: 0.5 lays them like bricks");
        }
        Pattern::Brick {
            size,
            mortar,
            row_offset,
        } => {
            size_ui(
                ui,
                &path.field("size"),
                size,
                [
                    (
                        "brick width (u)",
                        "Width of a brick and its joint, in (u, v) units",
                    ),
                    (
                        "brick height (v)",
                        "Height of a brick and its joint, in (u, v) units",
                    ),
                ],
            );
            keyed(ui, &path.field("mortar"), mortar, |ui, v| {
                ui.add(slider(v, 0.0..=0.2, "mortar width"))
            })
            .on_hover_text("Width of the joints, in (u, v) units; a is the mortar, b the bricks");
            keyed(ui, &path.field("row_offset"), row_offset, |ui, v| {
                ui.add(slider(v, 0.0..=1.0, "row offset"))
            })
            .on_hover_text("Shift of every other row, in bricks: 0.5 is the running bond");
        }
        Pattern::Tile {
            mortar_half_width,
            bevel,
        } => {
            keyed(
                ui,
                &path.field("mortar_half_width"),
                mortar_half_width,
                |ui, v| ui.add(slider(v, 0.0..=0.5, "mortar half-width")),
            )
            .on_hover_text(
                "Half the joint width, in (u, v) units; one tile per unit square, so lay it \
                     in a checker cell",
            );
            keyed(ui, &path.field("bevel"), bevel, |ui, v| {
                ui.add(slider(v, 0.0..=0.5, "bevel"))
            })
            .on_hover_text(
                "Width over which the tile rises from the mortar: bump it to raise the tiles",
            );
        }
        Pattern::Waves {
            frequency,
            direction,
        } => {
            keyed(ui, &path.field("frequency"), frequency, |ui, v| {
                ui.add(slider(v, 0.0..=64.0, "frequency"))
            })
            .on_hover_text("Crests per unit of (u, v) along the direction");
            let mut angle = direction.y.atan2(direction.x).to_degrees();
            if ui
                .add(slider(&mut angle, -180.0..=180.0, "direction (°)"))
                .on_hover_text("Angle from +u the waves travel along; the crests run across it")
                .changed()
            {
                let a = angle.to_radians();
                *direction = glam::Vec2::new(a.cos(), a.sin());
            }
        }
        Pattern::Cutout { sides, radius } => {
            ui.add(Slider::new(sides, 0..=12).text("sides"))
                .on_hover_text("A regular polygon; below 3, a disc. a is outside, b inside");
            keyed(ui, &path.field("radius"), radius, |ui, v| {
                ui.add(slider(v, 0.0..=0.71, "radius"))
            })
            .on_hover_text(
                "From the cell's centre to the polygon's corners (the disc's radius), in (u, v) \
                 units; 0.71 reaches the cell's corners",
            );
        }
        Pattern::Wood {
            noise,
            ring_width,
            turbulence_amount,
        } => {
            keyed(ui, &path.field("ring_width"), ring_width, |ui, v| {
                ui.add(slider(v, 0.01..=1.0, "ring width").logarithmic(true))
            })
            .on_hover_text("Width of each ring, in scene units: dark and pale alternate");
            keyed(
                ui,
                &path.field("turbulence_amount"),
                turbulence_amount,
                |ui, v| ui.add(slider(v, 0.0..=2.0, "turbulence")),
            )
            .on_hover_text("How far turbulence moves the rings; a dark, b pale");
            noise_ui(ui, noise, &path.field("noise"));
        }
        Pattern::Veins {
            noise,
            frequency,
            turbulence_amount,
        } => {
            keyed(ui, &path.field("frequency"), frequency, |ui, v| {
                ui.add(slider(v, 0.0..=32.0, "frequency"))
            })
            .on_hover_text(
                "t = max(0, sin(frequency · x + turbulence · T(p))): a dominant, b veins",
            );
            keyed(
                ui,
                &path.field("turbulence_amount"),
                turbulence_amount,
                |ui, v| ui.add(slider(v, 0.0..=40.0, "turbulence")),
            )
            .on_hover_text("How far turbulence bends the veins (times the fractal sum)");
            noise_ui(ui, noise, &path.field("noise"));
        }
        Pattern::MassalMarble {
            noise,
            stripe_frequency,
        } => {
            keyed(
                ui,
                &path.field("stripe_frequency"),
                stripe_frequency,
                |ui, v| ui.add(slider(v, 0.0..=32.0, "stripe frequency")),
            )
            .on_hover_text(
                "t = 0.5 + 0.5·sin((x + y) · stripe frequency + turbulence): Massal's \
                     marble, his stripe frequency equal to the noise's",
            );
            noise_ui(ui, noise, &path.field("noise"));
        }
    }
}

/// A cell's width and height in (u, v), each keyable (`path`: the
/// size's), with their labels and hints.
fn size_ui(ui: &mut Ui, path: &ParamPath, size: &mut glam::Vec2, labels: [(&str, &str); 2]) {
    for (i, (label, hint)) in labels.into_iter().enumerate() {
        keyed(ui, &path.index(i), &mut size[i], |ui, v| {
            ui.add(slider(v, 0.01..=4.0, label).logarithmic(true))
        })
        .on_hover_text(hint);
    }
}

/// The lattice noise, its hash and the fractal sum of a noise pattern.
fn noise_ui(ui: &mut Ui, noise: &mut NoiseSettings, path: &ParamPath) {
    ComboBox::new("noise kind", "noise")
        .selected_text(noise.kind.label())
        .show_ui(ui, |ui| {
            for kind in NoiseKind::ALL {
                ui.selectable_value(&mut noise.kind, kind, kind.label())
                    .on_hover_text(match kind {
                        NoiseKind::Gradient => {
                            "The lab's gradient noise: hashed corner gradients, smoothstep \
                             interpolation"
                        }
                        NoiseKind::Perlin => {
                            "Perlin's improved noise (2002): permutation table, 12 edge \
                             gradients, quintic fade"
                        }
                        NoiseKind::PerlinMassal => {
                            "Perlin's improved noise with the gradients of Massal's \
                             tutorial (his grad(), different at h = 13 and 14)"
                        }
                    });
            }
        })
        .response
        .on_hover_text("The lattice noise the fractal sum is built from");
    let hash_used = noise.kind != NoiseKind::Perlin;
    ui.add_enabled_ui(hash_used, |ui| {
        ComboBox::new("hash", "hash")
            .selected_text(noise.hash.label())
            .show_ui(ui, |ui| {
                for hash in HashKind::ALL {
                    ui.selectable_value(&mut noise.hash, hash, hash.label());
                }
            })
            .response
            .on_hover_text(
                "How gradient noise picks a corner's gradient: pcg3d agrees bit for bit \
                 on every GPU; tiled, it repeats every 256 cells, so a far offset is \
                 moved near the origin and stays sharp; fract(sin) is the lab's and \
                 drifts far from the origin",
            )
            .on_disabled_hover_text("Unused: Perlin noise hashes with its permutation table");
    });
    let f = &mut noise.fractal;
    let fractal = path.field("fractal");
    keyed(
        ui,
        &fractal.field("octaves"),
        &mut f.octaves,
        octaves_slider,
    );
    keyed(
        ui,
        &fractal.field("frequency"),
        &mut f.frequency,
        |ui, v| {
            ui.add(typed_beyond(
                slider(v, 0.01..=100.0, "frequency").logarithmic(true),
            ))
        },
    )
    .on_hover_text("Frequency of the first octave, in cycles per scene unit (type up to 1e6)");
    limit(&mut f.frequency, FractalParams::FREQUENCY);
    keyed(
        ui,
        &fractal.field("amplitude"),
        &mut f.amplitude,
        |ui, v| ui.add(typed_beyond(slider(v, 0.0..=2.0, "amplitude"))),
    )
    .on_hover_text("Amplitude of the first octave (type any value in ±100)");
    limit(&mut f.amplitude, FractalParams::AMPLITUDE);
    ComboBox::new("progression", "octaves progress")
        .selected_text(f.progression.label())
        .show_ui(ui, |ui| {
            for p in Progression::ALL {
                ui.selectable_value(&mut f.progression, p, p.label())
                    .on_hover_text(match p {
                        Progression::Geometric => {
                            "Octave i at frequency · lacunarityⁱ, weighted amplitude · \
                             persistenceⁱ"
                        }
                        Progression::Linear => {
                            "Massal's harmonics: level k at frequency · k, weighted \
                             amplitude / k (his turbulence: 9 levels of |noise|)"
                        }
                    });
            }
        })
        .response
        .on_hover_text("How each octave's frequency and weight follow from the first's");
    let geometric = f.progression == Progression::Geometric;
    ui.add_enabled_ui(geometric, |ui| {
        keyed(
            ui,
            &fractal.field("persistence"),
            &mut f.persistence,
            |ui, v| ui.add(slider(v, FractalParams::PERSISTENCE, "persistence")),
        )
        .on_hover_text(
            "Amplitude ratio between successive octaves (0.5: each half as strong; \
             above 1 the finest octaves dominate)",
        )
        .on_disabled_hover_text("Unused: linear levels are weighted 1/k");
        keyed(
            ui,
            &fractal.field("lacunarity"),
            &mut f.lacunarity,
            |ui, v| ui.add(typed_beyond(slider(v, 1.0..=4.0, "lacunarity"))),
        )
        .on_hover_text(
            "Frequency ratio between successive octaves (2: each twice as fine; type up to 8)",
        )
        .on_disabled_hover_text("Unused: linear level k is at frequency · k");
    });
    limit(&mut f.lacunarity, FractalParams::LACUNARITY);
    keyed(
        ui,
        &fractal.field("distortion"),
        &mut f.distortion,
        |ui, v| ui.add(typed_beyond(slider(v, 0.0..=4.0, "distortion"))),
    )
    .on_hover_text(
        "Domain warp: moves the point by noise before summing, three more noise evaluations \
         (0: none and free; type any value in ±100)",
    );
    limit(&mut f.distortion, FractalParams::DISTORTION);
    evolution_ui(ui, &mut noise.evolution, &path.field("evolution"));
}

/// Evolving noise (issue 29): the 4D noise whose w moves with the scene's
/// time, and a drift of its domain. Off is the 3D noise of before.
fn evolution_ui(ui: &mut Ui, evolution: &mut Option<Evolution>, path: &ParamPath) {
    let mut on = evolution.is_some();
    if ui
        .checkbox(&mut on, "Evolve (4D)")
        .on_hover_text(
            "Animate the noise: the 4D noise at a w that moves with time (as Blender's 4D \
             noise), its domain drifting. With the animation's loop on, w is periodic over \
             the loop, so the last frame meets the first",
        )
        .changed()
    {
        *evolution = on.then(Evolution::default);
    }
    let Some(e) = evolution else {
        return;
    };
    keyed(ui, &path.field("w"), &mut e.w, |ui, v| {
        ui.add(typed_beyond(slider(v, -4.0..=4.0, "w")))
    })
    .on_hover_text("The fourth coordinate at time 0, in cells of the first octave");
    limit(&mut e.w, Evolution::W);
    keyed(ui, &path.field("speed"), &mut e.speed, |ui, v| {
        ui.add(typed_beyond(slider(v, -4.0..=4.0, "speed")))
    })
    .on_hover_text("Cells of w per second (a loop rounds it to whole cells over its duration)");
    limit(&mut e.speed, Evolution::SPEED);
    ui.horizontal(|ui| {
        ui.label("drift").on_hover_text(
            "How far the noise moves per second, in its own units; a loop is seamless only \
             without drift",
        );
        for c in [&mut e.drift.x, &mut e.drift.y, &mut e.drift.z] {
            ui.add(egui::DragValue::new(c).speed(0.01));
            limit(c, Evolution::DRIFT);
        }
    });
}

/// A slider that drags over its useful range but keeps a typed value beyond
/// it; [`limit`] then holds it to what a preset may hold, so the panel
/// reaches exactly the values that load unchanged.
fn typed_beyond(slider: Slider<'_>) -> Slider<'_> {
    slider.clamping(SliderClamping::Never)
}

/// `value` clamped into the range a preset is clamped to at load.
fn limit(value: &mut f32, range: RangeInclusive<f32>) {
    *value = value.clamp(*range.start(), *range.end());
}
