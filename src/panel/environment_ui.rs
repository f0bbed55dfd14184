//! The Environment section: the source (none, constant, lat-long map, cube
//! faces or cross), its fields and its rotation.

use super::keying;
use super::widgets::{enter_pressed, labelled_color, slider, typed_path};
use super::{PanelAction, PanelState};
use egui::{ComboBox, TextEdit, Ui};
use marbre_core::animation::ParamPath;
use marbre_core::scene::{EnvSource, Environment, LdrImages};

/// The environment sources in the order of the source dropdown.
pub(super) const ENV_SOURCE_NAMES: [&str; 5] = [
    "none",
    "constant",
    "lat-long map",
    "cube (6 faces)",
    "cube (cross)",
];

pub(super) fn environment_ui(
    ui: &mut Ui,
    env: &mut Environment,
    state: &mut PanelState,
    actions: &mut Vec<PanelAction>,
) {
    env_source_ui(ui, &mut env.source, state);
    if let Some(faces) = state.cube_pending {
        cube_source_ui(ui, &mut env.source, state, faces);
    } else {
        source_fields_ui(ui, &mut env.source, state, actions);
    }
    if env.source.is_map() {
        ldr_images_ui(ui, &mut env.ldr_images);
    }
    let at = |field: &str| {
        ParamPath::parse("environment")
            .expect("a path")
            .field(field)
    };
    keying::number(
        ui,
        &at("rotation_degrees"),
        &mut env.rotation_degrees,
        |ui, v| ui.add(slider(v, -180.0..=180.0, "rotation").suffix("°")),
    )
    .on_hover_text("Turns the environment about the vertical axis");
    keying::number(ui, &at("intensity"), &mut env.intensity, |ui, v| {
        ui.add(slider(v, 0.01..=100.0, "intensity").logarithmic(true))
    })
    .on_hover_text("Multiplies the environment's radiance");
    ui.checkbox(&mut env.background_visible, "background visible")
        .on_hover_text("Show the environment behind the scene; it lights the scene either way");
}

/// How a map's 8- and 16-bit files become radiance (the map reloads on a
/// change).
fn ldr_images_ui(ui: &mut Ui, ldr: &mut LdrImages) {
    ComboBox::from_label("8-bit images")
        .selected_text(match ldr {
            LdrImages::Srgb => "sRGB",
            LdrImages::Exposed => "exposed (Massal)",
        })
        .show_ui(ui, |ui| {
            ui.selectable_value(ldr, LdrImages::Srgb, "sRGB")
                .on_hover_text("The codes are sRGB, decoded to linear values in [0, 1]");
            ui.selectable_value(ldr, LdrImages::Exposed, "exposed (Massal)")
                .on_hover_text(
                    "Massal's LDR maps: stored after his exposure curve, read back \
                 by −ln(1.001 − c^2.2), white as 6.9; float files stay as they are",
                );
        });
}

/// The controls of the scene's current source.
pub(super) fn source_fields_ui(
    ui: &mut Ui,
    source: &mut EnvSource,
    state: &mut PanelState,
    actions: &mut Vec<PanelAction>,
) {
    match source {
        EnvSource::None => {}
        EnvSource::Constant { radiance } => {
            let path = ParamPath::parse("environment.source.radiance").expect("a path");
            keying::vector(ui, &path, radiance, |ui, c| labelled_color(ui, c, "colour"))
                .on_hover_text(
                    "Radiance arriving from every direction, times the intensity below \
                     (white at intensity 1 is the white-furnace test)",
                );
        }
        EnvSource::LatLong { path } => {
            ui.label(format!("current: {}", path.display()))
                .on_hover_text("The map the scene uses; relative to the preset file");
            ui.horizontal(|ui| {
                let field = ui
                    .add(TextEdit::singleline(&mut state.env_path).hint_text("map.exr"))
                    .on_hover_text(
                        "Latitude-longitude image: .exr, .hdr, .png or .jpg; Enter loads it",
                    );
                if std::mem::take(&mut state.focus_env_path) {
                    field.request_focus();
                }
                let typed = !state.env_path.trim().is_empty();
                let load = ui
                    .add_enabled(typed, egui::Button::new("Load"))
                    .on_hover_text("Load the map at this path")
                    .on_disabled_hover_text("Type a path first")
                    .clicked();
                if load || (typed && enter_pressed(ui, &field)) {
                    actions.push(PanelAction::LoadEnvironment(typed_path(&state.env_path)));
                }
            });
            ui.horizontal(|ui| {
                if ui
                    .button("Open…")
                    .on_hover_text("Pick a lat-long map in a file dialog")
                    .clicked()
                {
                    actions.push(PanelAction::BrowseEnvironment);
                }
                ui.weak("or drop a file on the window");
            });
        }
        EnvSource::CubeFaces { .. } => cube_source_ui(ui, source, state, true),
        EnvSource::CubeCross { .. } => cube_source_ui(ui, source, state, false),
    }
}

/// The path fields of a cube map (six faces, or a cross) and a Load button
/// that puts them in the scene: typing alone does not load half a path.
/// Enter in any of the fields loads too, once every path is typed; a
/// request to focus the environment path puts the keyboard in the first.
pub(super) fn cube_source_ui(
    ui: &mut Ui,
    source: &mut EnvSource,
    state: &mut PanelState,
    is_faces: bool,
) {
    let is_cube = matches!(
        source,
        EnvSource::CubeFaces { .. } | EnvSource::CubeCross { .. }
    );
    if is_cube && state.cube_seen.as_ref() != Some(source) {
        match source {
            EnvSource::CubeFaces { faces } => {
                state.cube_faces = faces.each_ref().map(|p| p.display().to_string());
            }
            EnvSource::CubeCross { path } => state.cube_cross = path.display().to_string(),
            _ => {}
        }
        state.cube_seen = Some(source.clone());
    }
    if is_cube {
        for path in source.paths() {
            ui.label(format!("current: {}", path.display()))
                .on_hover_text("A file the scene uses; relative to the preset file");
        }
    }
    let focus = std::mem::take(&mut state.focus_env_path);
    let mut entered = false;
    let ready = if is_faces {
        let names = ["+x", "-x", "+y", "-y", "+z", "-z"];
        let hints = ["px.exr", "nx.exr", "py.exr", "ny.exr", "pz.exr", "nz.exr"];
        for (i, ((name, hint), path)) in names
            .iter()
            .zip(hints)
            .zip(&mut state.cube_faces)
            .enumerate()
        {
            ui.horizontal(|ui| {
                ui.label(*name);
                let field = ui
                    .add(TextEdit::singleline(path).hint_text(hint))
                    .on_hover_text(
                        "A square face (.exr, .hdr, .png or .jpg), OpenGL orientation; \
                         all six the same size; Enter loads them",
                    );
                if focus && i == 0 {
                    field.request_focus();
                }
                entered |= enter_pressed(ui, &field);
            });
        }
        state.cube_faces.iter().all(|p| !p.trim().is_empty())
    } else {
        let field = ui
            .add(TextEdit::singleline(&mut state.cube_cross).hint_text("cross.exr"))
            .on_hover_text(
                "One image of 4x3 square faces: +y above +z; -x, +z, +x, -z across; -y below; \
                 Enter loads it",
            );
        if focus {
            field.request_focus();
        }
        entered = enter_pressed(ui, &field);
        !state.cube_cross.trim().is_empty()
    };
    let load = ui
        .add_enabled(ready, egui::Button::new("Load"))
        .on_hover_text("Load the cube map at these paths (resampled to lat-long)")
        .on_disabled_hover_text(if is_faces {
            "Type all six face paths first"
        } else {
            "Type the cross image's path first"
        })
        .clicked();
    if load || (ready && entered) {
        *source = cube_source_from(state, is_faces);
    }
}

/// A cube source with the paths typed in the panel.
pub(super) fn cube_source_from(state: &PanelState, faces: bool) -> EnvSource {
    if faces {
        EnvSource::CubeFaces {
            faces: state.cube_faces.each_ref().map(|p| typed_path(p)),
        }
    } else {
        EnvSource::CubeCross {
            path: typed_path(&state.cube_cross),
        }
    }
}

/// The source dropdown. Switching to constant restores the last colour;
/// switching to a map takes the path typed below, which the app then loads.
pub(super) fn env_source_ui(ui: &mut Ui, source: &mut EnvSource, state: &mut PanelState) {
    let current = match source {
        EnvSource::None => 0,
        EnvSource::Constant { radiance } => {
            state.last_radiance = *radiance;
            1
        }
        EnvSource::LatLong { .. } => 2,
        EnvSource::CubeFaces { .. } => 3,
        EnvSource::CubeCross { .. } => 4,
    };
    // A cube entry waiting for its paths shows as picked.
    let shown = match state.cube_pending {
        Some(faces) if current == if faces { 3 } else { 4 } => {
            state.cube_pending = None;
            current
        }
        Some(true) => 3,
        Some(false) => 4,
        None => current,
    };
    let mut index = shown;
    ComboBox::new("env source", "source")
        .show_index(ui, &mut index, ENV_SOURCE_NAMES.len(), |i| {
            ENV_SOURCE_NAMES[i]
        })
        .on_hover_text("What rays that leave the scene see");
    if index == shown {
        return;
    }
    state.cube_pending = None;
    if index == current {
        return;
    }
    let cube_typed = |faces: bool| {
        if faces {
            state.cube_faces.iter().all(|p| !p.trim().is_empty())
        } else {
            !state.cube_cross.trim().is_empty()
        }
    };
    if (index == 3 || index == 4) && !cube_typed(index == 3) {
        // Nothing to load yet: show the fields, keep the scene's source.
        state.cube_pending = Some(index == 3);
        return;
    }
    *source = match index {
        1 => EnvSource::Constant {
            radiance: state.last_radiance,
        },
        2 => EnvSource::LatLong {
            path: typed_path(&state.env_path),
        },
        3 => cube_source_from(state, true),
        4 => cube_source_from(state, false),
        _ => EnvSource::None,
    };
}
