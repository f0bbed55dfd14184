//! Small widgets every section uses: a collapsing section, sliders that
//! do not clamp what they show, colour buttons that write only on a change.

use egui::emath::Numeric;
use egui::{CollapsingHeader, DragValue, Response, Slider, SliderClamping, Ui};
use glam::Vec3;
use std::ops::RangeInclusive;

/// A top-level collapsible section, its open state keyed by its title.
pub(super) fn section(ui: &mut Ui, title: &str, default_open: bool, body: impl FnOnce(&mut Ui)) {
    CollapsingHeader::new(title)
        .id_salt(("section", title))
        .default_open(default_open)
        .show(ui, body);
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

/// Edits a linear RGB colour, writing it back only when the user changed it:
/// egui goes through HSVA, whose round trip is not bit-exact, and a spurious
/// change would restart the accumulation every frame.
pub(super) fn color_button(ui: &mut Ui, color: &mut Vec3) -> Response {
    let mut rgb = color.to_array();
    let response = ui.color_edit_button_rgb(&mut rgb);
    if response.changed() {
        *color = Vec3::from_array(rgb);
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

/// Three drag values for a point or direction, each with the same tooltip.
pub(super) fn vec3_ui(ui: &mut Ui, label: &str, v: &mut Vec3, speed: f32, hint: &str) {
    ui.horizontal(|ui| {
        for (prefix, c) in [("x ", &mut v.x), ("y ", &mut v.y), ("z ", &mut v.z)] {
            ui.add(DragValue::new(c).speed(speed).prefix(prefix))
                .on_hover_text(hint);
        }
        ui.label(label);
    });
}
