//! The viewer's keyboard shortcuts, read from egui's input so that a key
//! typed into a text field edits the text instead, except for the function
//! keys, Esc and the saves (the table shown by F1
//! is `panel::help::SHORTCUTS`).

use egui::{Key, KeyboardShortcut, Modifiers};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shortcut {
    Undo,
    Redo,
    Save,
    SaveAs,
    Open,
    Help,
    Fullscreen,
    HideUi,
    /// Esc: close the help overlay.
    Close,
    /// F12: save the image as PNG and EXR.
    Screenshot,
    /// Ctrl+R: open or close the Render dialog.
    RenderDialog,
}

/// The shortcuts pressed this frame, consumed so no widget sees them.
/// Ctrl is Cmd on macOS.
pub fn pressed(ctx: &egui::Context) -> Vec<Shortcut> {
    let typing = ctx.egui_wants_keyboard_input();
    ctx.input_mut(|i| {
        let mut pressed = Vec::new();
        let mut take = |modifiers: Modifiers, key: Key, shortcut: Shortcut| {
            if i.consume_shortcut(&KeyboardShortcut::new(modifiers, key)) {
                pressed.push(shortcut);
            }
        };
        // Function keys and Esc work even while typing.
        take(Modifiers::NONE, Key::F1, Shortcut::Help);
        take(Modifiers::NONE, Key::F11, Shortcut::Fullscreen);
        take(Modifiers::NONE, Key::Escape, Shortcut::Close);
        take(Modifiers::NONE, Key::F12, Shortcut::Screenshot);
        // The shifted shortcuts first: Ctrl+S would also match Ctrl+Shift+S.
        take(
            Modifiers::COMMAND | Modifiers::SHIFT,
            Key::S,
            Shortcut::SaveAs,
        );
        take(Modifiers::COMMAND, Key::S, Shortcut::Save);
        if typing {
            return pressed;
        }
        take(
            Modifiers::COMMAND | Modifiers::SHIFT,
            Key::Z,
            Shortcut::Redo,
        );
        take(Modifiers::COMMAND, Key::Y, Shortcut::Redo);
        take(Modifiers::COMMAND, Key::Z, Shortcut::Undo);
        take(Modifiers::COMMAND, Key::O, Shortcut::Open);
        take(Modifiers::COMMAND, Key::R, Shortcut::RenderDialog);
        take(Modifiers::NONE, Key::H, Shortcut::HideUi);
        pressed
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn press(modifiers: Modifiers, key: Key) -> Vec<Shortcut> {
        let ctx = egui::Context::default();
        let input = egui::RawInput {
            events: vec![egui::Event::Key {
                key,
                physical_key: None,
                pressed: true,
                repeat: false,
                modifiers,
            }],
            ..Default::default()
        };
        let mut pressed = Vec::new();
        ctx.run_ui(input, |ui| pressed = self::pressed(ui.ctx()))
            .drop_without_applying_deltas();
        pressed
    }

    #[test]
    fn each_key_maps_to_its_shortcut() {
        let shift_command = Modifiers::COMMAND | Modifiers::SHIFT;
        assert_eq!(press(Modifiers::COMMAND, Key::Z), [Shortcut::Undo]);
        assert_eq!(press(shift_command, Key::Z), [Shortcut::Redo]);
        assert_eq!(press(Modifiers::COMMAND, Key::Y), [Shortcut::Redo]);
        assert_eq!(press(Modifiers::COMMAND, Key::S), [Shortcut::Save]);
        assert_eq!(press(shift_command, Key::S), [Shortcut::SaveAs]);
        assert_eq!(press(Modifiers::COMMAND, Key::O), [Shortcut::Open]);
        assert_eq!(press(Modifiers::COMMAND, Key::R), [Shortcut::RenderDialog]);
        assert_eq!(press(Modifiers::NONE, Key::F1), [Shortcut::Help]);
        assert_eq!(press(Modifiers::NONE, Key::F11), [Shortcut::Fullscreen]);
        assert_eq!(press(Modifiers::NONE, Key::H), [Shortcut::HideUi]);
        assert_eq!(press(Modifiers::NONE, Key::F12), [Shortcut::Screenshot]);
        assert_eq!(press(Modifiers::NONE, Key::Z), []);
    }
}
