//! The key button beside each animatable number, and what it shows.
//!
//! A control names its number by its [`ParamPath`]. Unkeyed, it edits the
//! scene's number as ever. Keyed, it shows the number's value at the play
//! head (the traced scene's), tinted as Blender tints animated fields
//! (yellow on a key, green between keys), and an edit keys the new value
//! there, as Blender's auto-keying of keyed channels does; the scene's own
//! number under a track is not traced. The key button inserts a key at
//! the play head with the value shown.
//!
//! Like the swatch book, the frame's keying lives in egui's temporary data
//! for the frame, so that any section can draw a key button without the
//! panel passing it down; the viewer fills it before the panel runs and
//! applies the keys asked for after.

use egui::{Color32, Id, Response, Ui};
use marbre_core::animation::{Naming, ParamPath};
use marbre_core::scene::Scene;
use std::collections::HashMap;

#[derive(Debug, Clone, Default)]
struct Keying {
    time: f32,
    /// Each keyed path (as text): its value at the play head, and whether
    /// a key sits there.
    keyed: HashMap<String, (Vec<f32>, bool)>,
    /// Keys asked for this frame.
    requests: Vec<(ParamPath, Vec<f32>)>,
}

fn id() -> Id {
    Id::NULL.with("marbre keying")
}

/// Sets what the key buttons show this frame: the play head's `time`, and
/// each keyed parameter of `scene` there: its track's value, the number the
/// traced scene holds (read from the track, not from a scene traced for
/// the purpose, each frame).
pub fn begin_frame(ctx: &egui::Context, time: f32, scene: &Scene) {
    let mut keyed = HashMap::new();
    for track in scene.animation.iter().flat_map(|a| &a.tracks) {
        // The panel names a number by where its control sits (elements
        // by index); a track may name it by name.
        let Ok(path) = track
            .parsed_path()
            .and_then(|p| scene.parameter_name(&p, Naming::Indices))
        else {
            continue;
        };
        // A track whose path no longer names a number animates nothing
        // (the Time section lists it; `Animation::problems` says why).
        if let (Ok(_), Some(value)) = (scene.parameter(&path), track.value_at(time)) {
            let on_key = track.keys.iter().any(|k| (k.time - time).abs() < 1e-4);
            keyed.insert(path.to_string(), (value, on_key));
        }
    }
    ctx.data_mut(|d| {
        d.insert_temp(
            id(),
            Keying {
                time,
                keyed,
                requests: Vec::new(),
            },
        )
    });
}

/// The keys the panel asked for this frame, to insert at the play head.
pub fn take_requests(ctx: &egui::Context) -> Vec<(ParamPath, Vec<f32>)> {
    ctx.data_mut(|d| {
        d.get_temp_mut_or_default::<Keying>(id())
            .requests
            .drain(..)
            .collect()
    })
}

/// A keyable number: `widget` drawn on `value` (the scene's), or, when
/// keyed, on its value at the play head, then the key button.
pub fn number(
    ui: &mut Ui,
    path: &ParamPath,
    value: &mut f32,
    widget: impl FnOnce(&mut Ui, &mut f32) -> Response,
) -> Response {
    components(ui, path, std::slice::from_mut(value), |ui, v| {
        widget(ui, &mut v[0])
    })
}

/// A keyable vector or colour, as [`number`].
pub fn vector(
    ui: &mut Ui,
    path: &ParamPath,
    value: &mut glam::Vec3,
    widget: impl FnOnce(&mut Ui, &mut glam::Vec3) -> Response,
) -> Response {
    let mut v = value.to_array();
    let r = components(ui, path, &mut v, |ui, v| {
        let mut vec = glam::Vec3::from_slice(v);
        let r = widget(ui, &mut vec);
        v.copy_from_slice(&vec.to_array());
        r
    });
    *value = glam::Vec3::from_array(v);
    r
}

/// Blender's key button, a diamond: hollow on an unkeyed number, filled
/// and yellow on a key, green between keys (`keyed`: whether a key sits
/// at the play head). Drawn, not a glyph: egui's default fonts have none.
fn key_button(ui: &mut Ui, keyed: Option<bool>) -> Response {
    // Close to the control and narrow: a row with its button must fit the
    // panel's default width (a nested constant colour's row is the
    // widest), or the panel grows.
    ui.spacing_mut().item_spacing.x = 3.0;
    let size = egui::vec2(12.0, ui.spacing().interact_size.y);
    let (rect, response) = ui.allocate_exact_size(size, egui::Sense::click());
    let visuals = ui.style().interact(&response);
    let c = rect.center();
    let r = 5.0;
    let diamond = vec![
        egui::pos2(c.x, c.y - r),
        egui::pos2(c.x + r, c.y),
        egui::pos2(c.x, c.y + r),
        egui::pos2(c.x - r, c.y),
    ];
    let fill = match keyed {
        Some(true) => KEYED_HERE,
        Some(false) => KEYED_ELSEWHERE,
        None => Color32::TRANSPARENT,
    };
    ui.painter().add(egui::Shape::convex_polygon(
        diamond,
        fill,
        egui::Stroke::new(1.2, visuals.fg_stroke.color),
    ));
    response
}

/// Blender's tints: a key at the current frame, and an animated value
/// between keys.
const KEYED_HERE: Color32 = Color32::from_rgb(0xd8, 0xb0, 0x30);
const KEYED_ELSEWHERE: Color32 = Color32::from_rgb(0x60, 0xb0, 0x50);

fn components(
    ui: &mut Ui,
    path: &ParamPath,
    value: &mut [f32],
    widget: impl FnOnce(&mut Ui, &mut [f32]) -> Response,
) -> Response {
    let ctx = ui.ctx().clone();
    let text = path.to_string();
    let (time, keyed) = ctx.data_mut(|d| {
        let k = d.get_temp_mut_or_default::<Keying>(id());
        (k.time, k.keyed.get(&text).cloned())
    });
    let request = |v: Vec<f32>| {
        ctx.data_mut(|d| {
            d.get_temp_mut_or_default::<Keying>(id())
                .requests
                .push((path.clone(), v))
        })
    };
    ui.horizontal(|ui| {
        let response = match &keyed {
            Some((at_head, on_key)) => {
                let mut shown = at_head.clone();
                let r = widget(ui, &mut shown);
                if r.changed() {
                    request(shown.clone());
                }
                let tint = if *on_key { KEYED_HERE } else { KEYED_ELSEWHERE };
                ui.painter().rect_stroke(
                    r.rect.expand(1.0),
                    2.0,
                    egui::Stroke::new(1.5, tint),
                    egui::StrokeKind::Outside,
                );
                r
            }
            None => widget(ui, value),
        };
        let shown: Vec<f32> = keyed
            .as_ref()
            .map_or_else(|| value.to_vec(), |(v, _)| v.clone());
        let button = key_button(ui, keyed.as_ref().map(|(_, on_key)| *on_key))
            .on_hover_text(format!("Insert a key on {text} at {time:.2} s"));
        if button.clicked() {
            request(shown);
            // A key inserted is an edit to undo at once: the button keeps
            // no keyboard focus, which would hold Ctrl+Z back.
            button.surrender_focus();
        }
        response
    })
    .inner
}
