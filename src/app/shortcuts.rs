//! The viewer's keyboard shortcuts, read from egui's input so that a key
//! typed into a text field edits the text instead (the table shown by F1
//! is `panel::help::SHORTCUTS`).
//!
//! They are read in two steps around the frame's widgets ([`Keys`]). The
//! function keys, Esc and the saves act even while typing, so they are
//! taken before any widget sees them. The others are read after the
//! widgets, and only if no widget had the keyboard when the frame began
//! or has it at its end: a click that gives a field the keyboard in the
//! same frame as the keys typed after it (a frame takes a second on a
//! software rasteriser) counts, and a key a widget consumed is gone. H,
//! the one plain letter, also needs the pointer over the image, so that a
//! click that missed a field, on the panel, does not turn the path typed
//! next into shortcuts (the "h" of ".hdr" hid the panel, issue 28); and
//! the saved views are Ctrl+digit, never a digit alone.

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
    /// Esc: close the help overlay or Save as, or cancel a question.
    Close,
    /// F12: save the image as PNG and EXR.
    Screenshot,
    /// Ctrl+R: open or close the Render dialog.
    RenderDialog,
    /// Ctrl+1 to Ctrl+9: go to the preset's saved view (0-based here).
    RecallView(usize),
    /// Space: play or pause the scene's time.
    PlayPause,
}

/// The digit keys of the saved views, in order.
const VIEW_KEYS: [Key; 9] = [
    Key::Num1,
    Key::Num2,
    Key::Num3,
    Key::Num4,
    Key::Num5,
    Key::Num6,
    Key::Num7,
    Key::Num8,
    Key::Num9,
];

/// One frame's shortcuts, between the two reads.
pub struct Keys {
    /// The ones taken before the widgets.
    pressed: Vec<Shortcut>,
    /// Whether a widget had the keyboard as the frame began.
    keyboard_was_taken: bool,
}

/// Takes the shortcuts `combos` lists that were pressed, in that order
/// (the shifted ones first: Ctrl+S would also match Ctrl+Shift+S).
fn take(i: &mut egui::InputState, combos: &[(Modifiers, Key, Shortcut)]) -> Vec<Shortcut> {
    combos
        .iter()
        .filter(|(modifiers, key, _)| i.consume_shortcut(&KeyboardShortcut::new(*modifiers, *key)))
        .map(|&(_, _, shortcut)| shortcut)
        .collect()
}

impl Keys {
    /// Before the widgets: the shortcuts that act even while typing,
    /// consumed so that no widget sees them. Ctrl is Cmd on macOS.
    pub fn before_widgets(ctx: &egui::Context) -> Self {
        let keyboard_was_taken = ctx.memory(|m| m.focused().is_some());
        let shift_command = Modifiers::COMMAND | Modifiers::SHIFT;
        let pressed = ctx.input_mut(|i| {
            take(
                i,
                &[
                    (Modifiers::NONE, Key::F1, Shortcut::Help),
                    (Modifiers::NONE, Key::F11, Shortcut::Fullscreen),
                    (Modifiers::NONE, Key::Escape, Shortcut::Close),
                    (Modifiers::NONE, Key::F12, Shortcut::Screenshot),
                    (shift_command, Key::S, Shortcut::SaveAs),
                    (Modifiers::COMMAND, Key::S, Shortcut::Save),
                ],
            )
        });
        Self {
            pressed,
            keyboard_was_taken,
        }
    }

    /// After the widgets: every shortcut pressed this frame. The ones that
    /// a text field would take as typing count only if no widget had the
    /// keyboard at the frame's start or has it now, and H only with the
    /// pointer over the image (`pointer_on_image`).
    pub fn after_widgets(mut self, ctx: &egui::Context, pointer_on_image: bool) -> Vec<Shortcut> {
        if self.keyboard_was_taken || ctx.memory(|m| m.focused().is_some()) {
            return self.pressed;
        }
        let shift_command = Modifiers::COMMAND | Modifiers::SHIFT;
        let mut combos = vec![
            (shift_command, Key::Z, Shortcut::Redo),
            (Modifiers::COMMAND, Key::Y, Shortcut::Redo),
            (Modifiers::COMMAND, Key::Z, Shortcut::Undo),
            (Modifiers::COMMAND, Key::O, Shortcut::Open),
            (Modifiers::COMMAND, Key::R, Shortcut::RenderDialog),
            (Modifiers::NONE, Key::Space, Shortcut::PlayPause),
        ];
        combos.extend(
            VIEW_KEYS
                .iter()
                .enumerate()
                .map(|(i, &key)| (Modifiers::COMMAND, key, Shortcut::RecallView(i))),
        );
        if pointer_on_image {
            combos.push((Modifiers::NONE, Key::H, Shortcut::HideUi));
        }
        self.pressed.extend(ctx.input_mut(|i| take(i, &combos)));
        self.pressed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(key: Key, modifiers: Modifiers) -> egui::Event {
        egui::Event::Key {
            key,
            physical_key: None,
            pressed: true,
            repeat: false,
            modifiers,
        }
    }

    /// A click of the primary button at `pos`: moved there, pressed,
    /// released.
    fn click(pos: egui::Pos2) -> Vec<egui::Event> {
        let button = |pressed| egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Modifiers::NONE,
        };
        vec![egui::Event::PointerMoved(pos), button(true), button(false)]
    }

    /// Runs one frame of a window with a text field at the top left and
    /// the image below it, `events` its input; returns the shortcuts read
    /// as the viewer reads them, and the field's text.
    fn frame(ctx: &egui::Context, events: Vec<egui::Event>, text: &mut String) -> Vec<Shortcut> {
        let input = egui::RawInput {
            events,
            screen_rect: Some(egui::Rect::from_min_size(
                egui::Pos2::ZERO,
                egui::vec2(800.0, 600.0),
            )),
            ..Default::default()
        };
        let mut pressed = Vec::new();
        ctx.run_ui(input, |ui| {
            let keys = Keys::before_widgets(ui.ctx());
            ui.add(egui::TextEdit::singleline(text).id_salt("field"));
            let image = egui::Rect::from_min_max(egui::pos2(0.0, 100.0), egui::pos2(800.0, 600.0));
            let on_image = ui
                .ctx()
                .pointer_hover_pos()
                .is_none_or(|p| image.contains(p));
            pressed = keys.after_widgets(ui.ctx(), on_image);
        })
        .drop_without_applying_deltas();
        pressed
    }

    fn press(modifiers: Modifiers, k: Key) -> Vec<Shortcut> {
        frame(
            &egui::Context::default(),
            vec![key(k, modifiers)],
            &mut String::new(),
        )
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
        assert_eq!(press(Modifiers::NONE, Key::Escape), [Shortcut::Close]);
        assert_eq!(
            press(Modifiers::COMMAND, Key::Num1),
            [Shortcut::RecallView(0)]
        );
        assert_eq!(
            press(Modifiers::COMMAND, Key::Num9),
            [Shortcut::RecallView(8)]
        );
        assert_eq!(press(Modifiers::NONE, Key::Z), []);
    }

    /// A digit alone is text, never a saved view.
    #[test]
    fn a_digit_alone_recalls_no_view() {
        for k in VIEW_KEYS {
            assert_eq!(press(Modifiers::NONE, k), [], "{k:?}");
        }
    }

    /// The click that gives a field the keyboard and the keys typed after
    /// it arrive in one frame: the field had no focus as the frame began,
    /// yet the keys are typing. Only the function keys act.
    #[test]
    fn keys_in_the_frame_a_click_focuses_a_field_are_typing() {
        let ctx = egui::Context::default();
        let mut text = String::new();
        // A first frame lays the field out, so that the click finds it.
        frame(&ctx, Vec::new(), &mut text);
        let mut events = click(egui::pos2(20.0, 10.0));
        events.extend([
            key(Key::H, Modifiers::NONE),
            egui::Event::Text("h".into()),
            key(Key::Num3, Modifiers::COMMAND),
            key(Key::Z, Modifiers::COMMAND),
            key(Key::F12, Modifiers::NONE),
        ]);
        let pressed = frame(&ctx, events, &mut text);
        assert_eq!(pressed, [Shortcut::Screenshot]);
        assert!(ctx.memory(|m| m.focused().is_some()), "the field has focus");
        // The next frame (the field focused from its start) no more.
        let pressed = frame(&ctx, vec![key(Key::H, Modifiers::NONE)], &mut text);
        assert_eq!(pressed, []);
    }

    /// A click that missed the field, on the panel beside it: no widget
    /// has the keyboard, but H is not for the panel, which the pointer is
    /// over. Over the image it hides the panel.
    #[test]
    fn h_acts_only_with_the_pointer_over_the_image() {
        let ctx = egui::Context::default();
        let mut text = String::new();
        frame(&ctx, Vec::new(), &mut text);
        let mut events = click(egui::pos2(700.0, 50.0));
        events.push(key(Key::H, Modifiers::NONE));
        assert_eq!(frame(&ctx, events, &mut text), []);
        let mut events = click(egui::pos2(400.0, 300.0));
        events.push(key(Key::H, Modifiers::NONE));
        assert_eq!(frame(&ctx, events, &mut text), [Shortcut::HideUi]);
    }

    /// A click on the image takes the keyboard from the field that had
    /// it: then H hides the panel.
    #[test]
    fn a_click_on_the_image_ends_typing() {
        let ctx = egui::Context::default();
        let mut text = String::new();
        frame(&ctx, Vec::new(), &mut text);
        frame(&ctx, click(egui::pos2(20.0, 10.0)), &mut text);
        assert!(ctx.memory(|m| m.focused().is_some()), "the field has focus");
        frame(&ctx, click(egui::pos2(400.0, 300.0)), &mut text);
        let pressed = frame(&ctx, vec![key(Key::H, Modifiers::NONE)], &mut text);
        assert_eq!(pressed, [Shortcut::HideUi]);
    }
}
