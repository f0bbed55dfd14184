//! Small widgets every section uses: a collapsing section, sliders that
//! do not clamp what they show, colour buttons that write only on a change.

use super::keying;
use egui::emath::Numeric;
use egui::{CollapsingHeader, DragValue, Response, Slider, SliderClamping, Ui};
use glam::Vec3;
use marbre_core::animation::ParamPath;
use marbre_core::scene::UvFrame;
use marbre_core::scene::color_encoding::{srgb_decode, srgb_encode};
use std::ops::RangeInclusive;

/// A top-level collapsible section, its open state keyed by its title.
pub(super) fn section(ui: &mut Ui, title: &str, default_open: bool, body: impl FnOnce(&mut Ui)) {
    section_headed(ui, title, title, default_open, body);
}

/// A section whose header says more than its name (live figures): the
/// open state stays keyed by `name` as the header changes.
pub(super) fn section_headed(
    ui: &mut Ui,
    name: &str,
    header: impl Into<egui::WidgetText>,
    default_open: bool,
    body: impl FnOnce(&mut Ui),
) {
    CollapsingHeader::new(header)
        .id_salt(("section", name))
        .default_open(default_open)
        .show(ui, body);
}

/// The path typed in a field, tidied by its text (`bad/../envmaps/x.exr`
/// is `envmaps/x.exr`) so that the scene and every message name it
/// plainly; empty stays empty.
pub(super) fn typed_path(text: &str) -> std::path::PathBuf {
    let text = text.trim();
    if text.is_empty() {
        return std::path::PathBuf::new();
    }
    marbre_core::lexical_path::normalize(std::path::Path::new(text))
}

/// Whether Enter was pressed in the single-line text field `field` this
/// frame (egui takes the keyboard away from it then): every path field
/// loads on Enter, as its Load button does.
pub(super) fn enter_pressed(ui: &Ui, field: &Response) -> bool {
    field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter))
}

/// A slider that clamps what the user enters but leaves a value already out
/// of range (from a hand-written preset) alone: egui's default clamps and
/// rounds the value every frame, which would edit the scene by itself.
pub(super) fn slider<'a, Num: Numeric>(
    value: &'a mut Num,
    range: RangeInclusive<Num>,
    text: &str,
) -> Slider<'a> {
    Slider::new(value, range)
        .clamping(SliderClamping::Edits)
        .text(text)
}

/// Edits a linear RGB colour: egui's picker, then the three channels typed
/// as display (sRGB-encoded) values, the way the course documents and other
/// tools write colours (the report's brown wood is `0.54 0.27 0.0742`); the
/// scene keeps the linear value. Written back only when the user changed
/// it: egui goes through HSVA and the sRGB round trip is not bit-exact
/// either, and a spurious change would restart the accumulation every frame.
pub(super) fn color_button(ui: &mut Ui, color: &mut Vec3) -> Response {
    let mut rgb = color.to_array();
    let mut response = ui.color_edit_button_rgb(&mut rgb);
    if response.changed() {
        *color = Vec3::from_array(rgb);
    }
    let shown = color.map(srgb_encode);
    let mut typed = shown;
    // Narrow fields, so that a colour row keeps within the panel's width.
    ui.spacing_mut().interact_size.x = 30.0;
    ui.spacing_mut().item_spacing.x = 3.0;
    for (channel, c) in [
        ("red", &mut typed.x),
        ("green", &mut typed.y),
        ("blue", &mut typed.z),
    ] {
        response |= ui
            .add(
                DragValue::new(c)
                    .speed(0.005)
                    .range(0.0..=f32::MAX)
                    .max_decimals(3),
            )
            .on_hover_text(format!(
                "{channel}, as a display (sRGB) value, 0 to 1, the way the course documents \
                 write colours; the renderer uses its linear value"
            ));
    }
    if typed != shown {
        *color = typed.map(srgb_decode);
        response.mark_changed();
    }
    response
}

/// A colour button followed by its label, on one line.
pub(super) fn labelled_color(ui: &mut Ui, color: &mut Vec3, label: &str) -> Response {
    ui.horizontal(|ui| {
        let response = color_button(ui, color);
        ui.label(label);
        response
    })
    .inner
}

/// Three drag values for a point or direction, each with the same
/// tooltip, and the key button of the vector at `path`.
pub(super) fn vec3_ui(
    ui: &mut Ui,
    path: &ParamPath,
    label: &str,
    v: &mut Vec3,
    speed: f32,
    hint: &str,
) {
    keying::vector(ui, path, v, |ui, v| vec3_field(ui, label, v, speed, hint));
}

/// [`vec3_ui`], its three fields' response joined (changed if any is).
pub(super) fn vec3_field(
    ui: &mut Ui,
    label: &str,
    v: &mut Vec3,
    speed: f32,
    hint: &str,
) -> Response {
    ui.horizontal(|ui| {
        let mut joined: Option<Response> = None;
        for (prefix, c) in [("x ", &mut v.x), ("y ", &mut v.y), ("z ", &mut v.z)] {
            let r = ui
                .add(DragValue::new(c).speed(speed).prefix(prefix))
                .on_hover_text(hint);
            joined = Some(match joined {
                Some(j) => j | r,
                None => r,
            });
        }
        ui.label(label);
        joined.expect("three fields")
    })
    .inner
}

/// A texture frame (the report's ATX, APTX, ATX3D): ticked, its origin and
/// two axes as vector fields; unticked, None. A frame that spans no plane
/// is shown with the reason (the renderer reads it as no frame).
/// `path`: the frame's parameter path, for its vectors' key buttons.
pub(super) fn uv_frame_ui(
    ui: &mut Ui,
    path: &ParamPath,
    frame: &mut Option<UvFrame>,
    label: &str,
    hint: &str,
    default: UvFrame,
) {
    let mut on = frame.is_some();
    if ui.checkbox(&mut on, label).on_hover_text(hint).changed() {
        *frame = on.then_some(default);
    }
    let Some(f) = frame else {
        return;
    };
    vec3_ui(
        ui,
        &path.field("origin"),
        "origin",
        &mut f.origin,
        0.01,
        "The frame's origin: (0, 0)",
    );
    vec3_ui(
        ui,
        &path.field("u_axis"),
        "u axis",
        &mut f.u_axis,
        0.01,
        "The point at u = 1 lies this far from the origin",
    );
    vec3_ui(
        ui,
        &path.field("v_axis"),
        "v axis",
        &mut f.v_axis,
        0.01,
        "The point at v = 1 lies this far from the origin (oblique to u if you like)",
    );
    if let Some(problem) = f.problem() {
        ui.colored_label(
            ui.visuals().warn_fg_color,
            format!("unusable frame: {problem}"),
        );
    }
}
