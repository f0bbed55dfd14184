//! Save as where no file dialog can open (no desktop portal and no
//! zenity, as under a bare X server or over SSH): a small dialog of its
//! own asks where to save, and its Enter saves there.
//!
//! The typed path once went to the Preset field, whose Enter *opens* what
//! it names: the viewer then asked to save the unsaved changes before
//! opening, and the default answer, Save, wrote them over the original
//! preset (issue 28). Here Enter (or Save) asks the app to save to the
//! typed path, and the dialog stays until that save is done (the app
//! closes it), so that a path that cannot be written is corrected in
//! place; Cancel, Esc or a click beside it close it.

use super::PanelAction;
use super::widgets::{enter_pressed, typed_path};
use egui::text::CCursorRange;
use egui::{Button, TextEdit};

/// Save as waiting for a path.
#[derive(Debug, Clone, PartialEq)]
pub struct SaveAs {
    /// The path being typed.
    pub path: String,
    /// The dialog has just opened: its field takes the keyboard with the
    /// suggestion selected, so that typing replaces it.
    opening: bool,
}

impl SaveAs {
    /// Save as, its field holding `suggestion`.
    pub fn new(suggestion: String) -> Self {
        Self {
            path: suggestion,
            opening: true,
        }
    }
}

/// The dialog's width in points.
const WIDTH: f32 = 480.0;

/// Draws Save as while `state` holds it; `on_top` is false while a
/// question drawn over it (a file to replace) has the keyboard. Cancel
/// empties `state`; Enter or Save pushes [`PanelAction::SavePresetAs`].
pub fn show(
    ctx: &egui::Context,
    state: &mut Option<SaveAs>,
    on_top: bool,
    actions: &mut Vec<PanelAction>,
) {
    let Some(save_as) = state else {
        return;
    };
    let mut close = false;
    // No backdrop: it would cover the whole window, and the kept panel
    // layer would then be blended over all the image every frame rather
    // than over the box alone (`app/ui_layer.rs`). It still blocks the
    // widgets behind it.
    let response = egui::Modal::new(egui::Id::unique("marbre save as"))
        .backdrop_color(egui::Color32::TRANSPARENT)
        .show(ctx, |ui| {
            ui.set_width(WIDTH);
            ui.heading("Save preset as");
            ui.label(
                "No file dialog can open here: type where to save the scene (a .ron file) and \
             press Enter. A file already there is replaced only once you confirm.",
            );
            let egui::text_edit::TextEditOutput {
                response: field,
                galley,
                mut state,
                ..
            } = TextEdit::singleline(&mut save_as.path)
                .id_salt("save as path")
                .hint_text("presets/scene.ron")
                .desired_width(f32::INFINITY)
                .show(ui);
            let field = field.response;
            if std::mem::take(&mut save_as.opening) {
                state
                    .cursor
                    .set_char_range(Some(CCursorRange::select_all(&galley)));
                state.store(ui.ctx(), field.id);
                field.request_focus();
            }
            let path = typed_path(&save_as.path);
            let typed = !path.as_os_str().is_empty();
            let mut save = typed && enter_pressed(ui, &field);
            ui.horizontal(|ui| {
                save |= ui
                    .add_enabled(typed, Button::new("Save"))
                    .on_disabled_hover_text("Type a path first")
                    .clicked();
                close |= ui.button("Cancel").clicked();
            });
            if save {
                actions.push(PanelAction::SavePresetAs(path));
            }
            // The keyboard stays in the field (Enter saves) unless a question
            // over the dialog has it.
            if on_top && ctx.memory(|m| m.focused().is_none()) {
                field.request_focus();
            }
        });
    if close || response.should_close() {
        *state = None;
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The rectangle around all that a modal drawn by `show_modal` paints
    /// on a 1280x720 screen, once settled (three frames).
    pub(crate) fn modal_drawn(show_modal: impl Fn(&egui::Context)) -> egui::Rect {
        let ctx = egui::Context::default();
        let screen = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 720.0));
        let mut drawn = egui::Rect::NOTHING;
        for _ in 0..3 {
            let input = egui::RawInput {
                screen_rect: Some(screen),
                ..Default::default()
            };
            let mut output = ctx.run_ui(input, |ui| show_modal(ui.ctx()));
            let jobs = ctx.tessellate(std::mem::take(&mut output.shapes), 1.0);
            drawn = jobs
                .iter()
                .filter_map(|job| match &job.primitive {
                    egui::epaint::Primitive::Mesh(mesh) => {
                        Some(mesh.calc_bounds().intersect(job.clip_rect))
                    }
                    egui::epaint::Primitive::Callback(_) => None,
                })
                .filter(|r| r.is_positive())
                .fold(egui::Rect::NOTHING, |a, b| a.union(b));
            output.drop_without_applying_deltas();
        }
        assert!(drawn.is_positive(), "the modal draws nothing");
        drawn
    }

    fn key(key: egui::Key) -> egui::Event {
        egui::Event::Key {
            key,
            physical_key: None,
            pressed: true,
            repeat: false,
            modifiers: egui::Modifiers::NONE,
        }
    }

    /// Runs the dialog for a frame per entry of `frames` (each that
    /// frame's input events); returns the actions and the state left.
    fn run(
        mut state: Option<SaveAs>,
        frames: Vec<Vec<egui::Event>>,
    ) -> (Vec<PanelAction>, Option<SaveAs>) {
        let ctx = egui::Context::default();
        let mut actions = Vec::new();
        for events in frames {
            let input = egui::RawInput {
                events,
                screen_rect: Some(egui::Rect::from_min_size(
                    egui::Pos2::ZERO,
                    egui::vec2(1280.0, 720.0),
                )),
                ..Default::default()
            };
            ctx.run_ui(input, |ui| show(ui.ctx(), &mut state, true, &mut actions))
                .drop_without_applying_deltas();
        }
        (actions, state)
    }

    /// The path typed over the suggestion (which it replaces, selected),
    /// then Enter: saved there, and the dialog waits for the app to say
    /// the save is done.
    #[test]
    fn enter_saves_to_the_typed_path() {
        let state = Some(SaveAs::new("presets/mine.ron".into()));
        let (actions, state) = run(
            state,
            vec![
                vec![],
                vec![egui::Event::Text("copies/./copy.ron ".into())],
                vec![key(egui::Key::Enter)],
            ],
        );
        assert_eq!(
            actions,
            [PanelAction::SavePresetAs("copies/copy.ron".into())]
        );
        assert_eq!(state.map(|s| s.path), Some("copies/./copy.ron ".into()));
    }

    /// Enter with the suggestion kept saves to the suggestion; nothing is
    /// ever a load.
    #[test]
    fn enter_on_the_suggestion_saves_there() {
        let state = Some(SaveAs::new("presets/mine.ron".into()));
        let (actions, _) = run(state, vec![vec![], vec![key(egui::Key::Enter)]]);
        assert_eq!(
            actions,
            [PanelAction::SavePresetAs("presets/mine.ron".into())]
        );
    }

    /// An empty field saves nothing.
    #[test]
    fn an_empty_path_saves_nothing() {
        let state = Some(SaveAs::new("  ".into()));
        let (actions, state) = run(state, vec![vec![], vec![key(egui::Key::Enter)]]);
        assert_eq!(actions, []);
        assert!(state.is_some());
    }

    /// Save as draws its box and nothing beyond it (no backdrop over the
    /// image), as the prompts do: the scene keeps rendering under it.
    #[test]
    fn save_as_covers_its_box_only() {
        let drawn = modal_drawn(|ctx| {
            let mut state = Some(SaveAs::new("presets/mine.ron".into()));
            show(ctx, &mut state, true, &mut Vec::new());
        });
        assert!(
            drawn.width() < WIDTH + 60.0 && drawn.height() < 250.0,
            "{drawn:?}"
        );
    }

    /// A click beside the dialog closes it, saving nothing.
    #[test]
    fn a_click_beside_it_cancels() {
        let state = Some(SaveAs::new("presets/mine.ron".into()));
        let at = egui::pos2(5.0, 5.0);
        let button = |pressed| egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        };
        let (actions, state) = run(
            state,
            vec![
                vec![],
                vec![egui::Event::PointerMoved(at)],
                vec![button(true), button(false)],
            ],
        );
        assert_eq!(actions, []);
        assert_eq!(state, None);
    }
}
