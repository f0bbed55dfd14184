//! The Preset section: the preset's path (typed, or picked in a native
//! dialog), Open, Save, Save as, the recent files, undo and redo, whether
//! there are unsaved changes, and the latest messages.
//!
//! The typed path stays for systems with no file dialog (no desktop
//! portal, no zenity): Ctrl+O there focuses this field instead, and Enter
//! in it loads the preset. Save as… there asks for its path in a dialog of
//! its own (`save_as`), never in this field, whose Enter opens.

use super::widgets::{enter_pressed, typed_path};
use super::{PanelAction, PanelState, SHOWN_MESSAGES};
use egui::{Button, TextEdit, Ui};

pub fn preset_ui(ui: &mut Ui, state: &mut PanelState, actions: &mut Vec<PanelAction>) {
    let field = ui
        .add(
            TextEdit::singleline(&mut state.preset_path)
                .id_salt("preset path")
                .hint_text("presets/scene.ron")
                .desired_width(f32::INFINITY),
        )
        .on_hover_text("Preset file (RON) used by Load and Save as; Enter loads it (an .obj opens as a new scene)");
    if std::mem::take(&mut state.focus_preset_path) {
        field.request_focus();
    }
    let path = typed_path(&state.preset_path);
    if enter_pressed(ui, &field) {
        actions.push(PanelAction::LoadPreset(path.clone()));
    }
    ui.horizontal(|ui| {
        if ui
            .button("Load")
            .on_hover_text("Replace the scene with the preset at the path above")
            .clicked()
        {
            actions.push(PanelAction::LoadPreset(path.clone()));
        }
        if ui
            .button("Open…")
            .on_hover_text(
                "Pick a preset, or an OBJ file to open as a new scene, in a file dialog (Ctrl+O)",
            )
            .clicked()
        {
            actions.push(PanelAction::BrowsePreset);
        }
        recent_menu(ui, state, actions);
    });
    ui.horizontal(|ui| {
        if ui
            .button("Save")
            .on_hover_text(
                "Overwrite the preset file the scene was loaded from or last saved to (Ctrl+S); a scene opened from an OBJ file asks where",
            )
            .clicked()
        {
            actions.push(PanelAction::SavePreset);
        }
        if ui
            .button("Save as")
            .on_hover_text("Write the scene to the path above (a file already there is replaced only once you confirm)")
            .clicked()
        {
            actions.push(PanelAction::SavePresetAs(path));
        }
        if ui
            .button("Save as…")
            .on_hover_text(
                "Pick where to save in a file dialog, or type it where none can open (Ctrl+Shift+S)",
            )
            .clicked()
        {
            actions.push(PanelAction::BrowseSavePresetAs);
        }
        if state.shares_links
            && ui
                .button("Share")
                .on_hover_text(
                    "Put the scene in the page's address and copy the link: opening it \
                     shows this scene (files you dropped on the page are not in it)",
                )
                .clicked()
        {
            actions.push(PanelAction::ShareLink);
        }
    });
    ui.horizontal(|ui| {
        let undo = ui
            .add_enabled(state.can_undo, Button::new("Undo"))
            .on_hover_text("Undo the last edit (Ctrl+Z); a whole slider drag is one edit")
            .on_disabled_hover_text("Nothing to undo");
        if undo.clicked() {
            actions.push(PanelAction::Undo);
        }
        let redo = ui
            .add_enabled(state.can_redo, Button::new("Redo"))
            .on_hover_text("Redo what was undone (Ctrl+Shift+Z or Ctrl+Y)")
            .on_disabled_hover_text("Nothing to redo");
        if redo.clicked() {
            actions.push(PanelAction::Redo);
        }
        if state.unsaved {
            ui.colored_label(ui.visuals().warn_fg_color, "unsaved changes")
                .on_hover_text(
                    "The scene differs from its preset file (camera aside); autosaved for \
                     recovery every 20 s, and you are asked before anything replaces it",
                );
        }
    });
    if let Some((stage, fraction)) = &state.progress {
        ui.add(
            egui::ProgressBar::new(*fraction)
                .text(stage.as_str())
                .animate(true),
        )
        .on_hover_text("The scene on screen stays until the new one has loaded");
    }
    messages_ui(ui, state);
}

/// The latest messages, each with its time; the older ones kept fold
/// under them, and Clear empties the list.
fn messages_ui(ui: &mut Ui, state: &mut PanelState) {
    if state.messages.is_empty() {
        return;
    }
    let first = state.messages.len().saturating_sub(SHOWN_MESSAGES);
    if first > 0 {
        egui::CollapsingHeader::new(format!("{first} earlier messages"))
            .id_salt("earlier messages")
            .show(ui, |ui| {
                egui::ScrollArea::vertical()
                    .id_salt("earlier messages scroll")
                    .max_height(200.0)
                    .show(ui, |ui| {
                        for message in &state.messages[..first] {
                            message_label(ui, message);
                        }
                    });
            });
    }
    for message in &state.messages[first..] {
        message_label(ui, message);
    }
    if ui
        .small_button("Clear messages")
        .on_hover_text("Empty the message list")
        .clicked()
    {
        state.messages.clear();
    }
}

fn message_label(ui: &mut Ui, message: &super::Message) {
    // A message of several lines is a compiler's diagnostic or a report:
    // monospace keeps its carets under the columns they point at, and
    // egui's monospace font (Hack) has the box-drawing glyphs naga frames
    // source lines with, which the proportional one lacks. The time goes
    // on a line of its own there, so as not to shift the first line.
    let separator = if message.text.contains('\n') {
        '\n'
    } else {
        ' '
    };
    let mut text = egui::RichText::new(format!("{}{separator}{}", message.time, message.text));
    if message.text.contains('\n') {
        text = text.monospace();
    }
    if message.is_error {
        text = text.color(ui.visuals().error_fg_color);
    }
    ui.label(text);
}

/// The recent presets and environment maps, newest first.
fn recent_menu(ui: &mut Ui, state: &PanelState, actions: &mut Vec<PanelAction>) {
    ui.add_enabled_ui(!state.recent_files.is_empty(), |ui| {
        ui.menu_button("Recent", |ui| {
            for path in &state.recent_files {
                let name = path.file_name().map_or_else(
                    || path.display().to_string(),
                    |n| n.to_string_lossy().into(),
                );
                if ui
                    .button(name)
                    .on_hover_text(path.display().to_string())
                    .clicked()
                {
                    actions.push(PanelAction::OpenRecent(path.clone()));
                    ui.close();
                }
            }
        })
        .response
        .on_hover_text("Presets and environment maps opened or saved lately")
        .on_disabled_hover_text("Nothing opened yet");
    });
}
