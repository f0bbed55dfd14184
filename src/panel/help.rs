//! The F1 help overlay: the keyboard shortcuts and the mouse controls.
//!
//! The shortcuts live in one table so that the overlay, and anything else
//! that lists them, cannot disagree with each other; the viewer binds the
//! keys themselves.

/// One row of the help: the keys, as the user types them, and what they do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shortcut {
    /// One or more key combinations separated by [`ALTERNATIVE`].
    pub keys: &'static str,
    pub action: &'static str,
}

/// Separates key combinations that do the same thing in [`Shortcut::keys`].
pub const ALTERNATIVE: &str = " / ";

/// Every keyboard shortcut of the viewer, in the order the overlay lists
/// them.
pub const SHORTCUTS: &[Shortcut] = &[
    Shortcut {
        keys: "F1",
        action: "Show or hide this help",
    },
    Shortcut {
        keys: "F11",
        action: "Fullscreen on or off",
    },
    Shortcut {
        keys: "H",
        action: "Hide or show the UI panels (with the pointer over the image)",
    },
    Shortcut {
        keys: "F12",
        action: "Screenshot without the UI: PNG and EXR into screenshots/",
    },
    Shortcut {
        keys: "Ctrl+R",
        action: "Open the Render dialog: a final render to PNG or EXR, in the background",
    },
    Shortcut {
        keys: "Ctrl+Z",
        action: "Undo the last edit",
    },
    Shortcut {
        keys: "Ctrl+Shift+Z / Ctrl+Y",
        action: "Redo what was undone",
    },
    Shortcut {
        keys: "Ctrl+S",
        action: "Save the preset",
    },
    Shortcut {
        keys: "Ctrl+Shift+S",
        action: "Save the preset as a new file",
    },
    Shortcut {
        keys: "Ctrl+O",
        action: "Open a preset",
    },
    Shortcut {
        keys: "Space",
        action: "Play or pause the scene's time (Time section)",
    },
    Shortcut {
        keys: "Ctrl+1–9",
        action: "Go to saved view 1 to 9 (Camera section)",
    },
    Shortcut {
        keys: "Esc",
        action: "Close this help, Save as, the node editor's Add menu, or a question (its cautious answer)",
    },
    Shortcut {
        keys: "Shift+A",
        action: "Node editor (pointer over it): add a node, searched by name, on the nearest input",
    },
    Shortcut {
        keys: "X / Delete",
        action: "Node editor: delete the selected node (a constant of its value stays)",
    },
    Shortcut {
        keys: "Shift+D",
        action: "Node editor: put a copy of the selected node on the input nearest the pointer",
    },
    Shortcut {
        keys: "Home",
        action: "Node editor: frame every node",
    },
];

/// What the mouse does over the image (see `app::camera_input`).
const MOUSE_CONTROLS: &str = "Mouse over the image: left drag orbits, right or middle drag pans, \
     the wheel zooms. In the node editor: drag a header to move a node, the background to pan; \
     the wheel or a pinch zooms; right-click adds a node.";

/// Why some keys do nothing at times (see `app::shortcuts`).
const TYPING_NOTE: &str = "While a text field has the keyboard, only the F keys, Esc and the \
     saves act: the other keys are typing.";

/// The window's title.
const TITLE: &str = "Keyboard shortcuts (F1)";

/// The window's egui id, named rather than derived from the title so that
/// its remembered position can be looked up.
fn window_id() -> egui::Id {
    egui::Id::unique("help overlay")
}

/// Draws the help window, centred, while `open` is true; its close button
/// sets `open` to false.
pub fn draw_help_overlay(ctx: &egui::Context, open: &mut bool) {
    egui::Window::new(TITLE)
        .id(window_id())
        .open(open)
        .collapsible(false)
        .resizable(false)
        .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
        .show(ctx, |ui| {
            egui::Grid::new("shortcuts")
                .num_columns(2)
                .striped(true)
                .show(ui, |ui| {
                    for shortcut in SHORTCUTS {
                        ui.strong(shortcut.keys);
                        ui.label(shortcut.action);
                        ui.end_row();
                    }
                });
            ui.separator();
            ui.label(MOUSE_CONTROLS);
            ui.label(TYPING_NOTE);
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    #[test]
    fn key_combinations_are_distinct_and_actions_are_named() {
        let mut seen = BTreeSet::new();
        for shortcut in SHORTCUTS {
            assert!(
                !shortcut.action.trim().is_empty(),
                "{shortcut:?} has no action"
            );
            for combination in shortcut.keys.split(ALTERNATIVE) {
                let combination = combination.trim();
                assert!(!combination.is_empty(), "{shortcut:?} has an empty key");
                assert!(
                    seen.insert(combination.to_lowercase()),
                    "{combination} is in the table twice"
                );
            }
        }
        // Redo's and delete's two combinations count separately.
        assert_eq!(seen.len(), SHORTCUTS.len() + 2);
    }

    /// The text of every text shape in a frame's output.
    fn drawn_texts(output: &egui::FullOutput) -> Vec<String> {
        output
            .shapes
            .iter()
            .filter_map(|clipped| match &clipped.shape {
                egui::Shape::Text(text) => Some(text.galley.text().to_owned()),
                _ => None,
            })
            .collect()
    }

    /// Runs headless frames of the overlay and returns the last one's texts.
    fn run_frames(ctx: &egui::Context, open: &mut bool) -> Vec<String> {
        let mut texts = Vec::new();
        // A window's first frame only measures it (nothing is drawn), and it
        // is placed with the size measured a frame earlier: by the third
        // frame its size has settled and it sits centred.
        for _ in 0..3 {
            let output = ctx.run_ui(egui::RawInput::default(), |ui| {
                draw_help_overlay(ui.ctx(), open);
            });
            texts = drawn_texts(&output);
            output.drop_without_applying_deltas();
        }
        texts
    }

    #[test]
    fn open_overlay_shows_every_shortcut_and_stays_open() {
        let ctx = egui::Context::default();
        let mut open = true;
        let texts = run_frames(&ctx, &mut open);
        assert!(open, "nothing asked the overlay to close");
        for wanted in SHORTCUTS.iter().flat_map(|s| [s.keys, s.action]).chain([
            TITLE,
            MOUSE_CONTROLS,
            TYPING_NOTE,
        ]) {
            assert!(
                texts.iter().any(|t| t == wanted),
                "{wanted:?} not drawn; drawn: {texts:?}"
            );
        }
        let window = ctx
            .memory(|m| m.area_rect(window_id()))
            .expect("the window was laid out");
        let screen = ctx.content_rect();
        assert!(
            (window.center() - screen.center()).length() < 1.0,
            "window {window:?} is not centred on {screen:?}"
        );
    }

    #[test]
    fn closed_overlay_draws_nothing() {
        let ctx = egui::Context::default();
        let mut open = false;
        let texts = run_frames(&ctx, &mut open);
        assert!(!open);
        assert!(texts.is_empty(), "drawn: {texts:?}");
    }
}
