//! The questions the viewer asks before it could lose work: unsaved edits
//! before another preset replaces them or the app quits, an outside change
//! to the preset file while there are unsaved edits, a file that a typed
//! Save as would replace, and a recovery file left by a run that did not
//! end cleanly. Each is a modal dialog; Esc or
//! a click outside it is the cautious answer (cancel, keep my edits, decide
//! later).

use super::recovery::RecoveryOffer;
use std::path::PathBuf;

/// What waits for the user's answer.
#[derive(Debug, Clone, PartialEq)]
pub enum Prompt {
    /// Load this preset, replacing a scene with unsaved edits.
    LoadPreset(PathBuf),
    /// Quit with unsaved edits.
    Quit,
    /// The preset file changed on disk while the scene has unsaved edits.
    ReloadFromDisk,
    /// Recover the scene a previous run autosaved.
    Recover(RecoveryOffer),
    /// Save as to a typed path where a file already is.
    Replace(PathBuf),
}

/// The user's answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Answer {
    /// Save the edits, then go on (load or quit).
    SaveFirst,
    /// Go on and lose the edits (load, quit, reload from disk, recover),
    /// or the file there (replace).
    Proceed,
    /// Do nothing: keep the scene as it is (and an offered recovery for
    /// the next start).
    Cancel,
    /// Throw the offered recovery away.
    Discard,
}

/// The dialog's width in points, its text wrapped to it.
const PROMPT_WIDTH: f32 = 420.0;

/// Draws `prompt` as a modal dialog; the answer once given.
pub fn show(ctx: &egui::Context, prompt: &Prompt, preset_name: &str) -> Option<Answer> {
    let (title, text, buttons): (&str, String, &[(&str, Answer)]) = match prompt {
        Prompt::LoadPreset(path) => (
            "Unsaved changes",
            format!(
                "{preset_name} has unsaved changes. Save them before opening {}?",
                path.display()
            ),
            &[
                ("Save", Answer::SaveFirst),
                ("Don't save", Answer::Proceed),
                ("Cancel", Answer::Cancel),
            ],
        ),
        Prompt::Quit => (
            "Unsaved changes",
            format!("{preset_name} has unsaved changes. Save them before quitting?"),
            &[
                ("Save", Answer::SaveFirst),
                ("Quit without saving", Answer::Proceed),
                ("Cancel", Answer::Cancel),
            ],
        ),
        Prompt::ReloadFromDisk => (
            "Preset changed on disk",
            format!(
                "{preset_name} was changed by another program, and the scene here has unsaved \
                 changes. Reload it from disk (your changes are lost), or keep yours (saving \
                 then overwrites the file)?"
            ),
            &[
                ("Reload from disk", Answer::Proceed),
                ("Keep my changes", Answer::Cancel),
            ],
        ),
        Prompt::Recover(offer) => (
            "Recover unsaved changes",
            format!(
                "marbre did not close cleanly while {} had unsaved changes; they were \
                 autosaved at {}. Recover them, as unsaved changes of that preset? (Later \
                 keeps them: they are offered again when it is next opened.)",
                offer.source.display(),
                offer.saved_at
            ),
            &[
                ("Recover", Answer::Proceed),
                ("Later", Answer::Cancel),
                ("Discard", Answer::Discard),
            ],
        ),
        // Cancel first, the default: Enter must not replace a file.
        Prompt::Replace(path) => (
            "Replace file?",
            format!(
                "{} already exists. Replace it with this scene? What it holds now is lost.",
                path.display()
            ),
            &[("Cancel", Answer::Cancel), ("Replace", Answer::Proceed)],
        ),
    };
    let mut answer = None;
    // No backdrop: it would cover the whole window, and the kept panel
    // layer would then be blended over all the image every frame rather
    // than over the box alone (`app/ui_layer.rs`). It still blocks the
    // widgets behind it.
    let response = egui::Modal::new(egui::Id::unique("marbre prompt"))
        .backdrop_color(egui::Color32::TRANSPARENT)
        .show(ctx, |ui| {
            // A fixed width: egui centres the dialog by the size it measured
            // the frame before, and a width that followed the content moved
            // it once measured (by about 35 px after the first frame).
            ui.set_width(PROMPT_WIDTH);
            ui.heading(title);
            ui.label(text);
            ui.separator();
            ui.horizontal(|ui| {
                let responses: Vec<egui::Response> = buttons
                    .iter()
                    .map(|(label, choice)| {
                        let response = ui.button(*label);
                        if response.clicked() {
                            answer = Some(*choice);
                        }
                        response
                    })
                    .collect();
                // The first button is the default, as in a native dialog: it
                // has the keyboard focus, so Enter chooses it (Esc cancels),
                // whatever had the focus when the prompt opened.
                if !responses.iter().any(egui::Response::has_focus) {
                    responses[0].request_focus();
                }
            });
        });
    if answer.is_none() && response.should_close() {
        answer = Some(Answer::Cancel);
    }
    answer
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Where the prompt's title is drawn in each of `frames` headless
    /// frames on a 1280x720 screen (None where it is not drawn).
    fn title_positions(prompt: &Prompt, frames: usize) -> Vec<Option<egui::Pos2>> {
        let ctx = egui::Context::default();
        let screen = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 720.0));
        (0..frames)
            .map(|_| {
                let input = egui::RawInput {
                    screen_rect: Some(screen),
                    ..Default::default()
                };
                let output = ctx.run_ui(input, |ui| {
                    show(ui.ctx(), prompt, "presets/default.ron");
                });
                let title = output
                    .shapes
                    .iter()
                    .find_map(|clipped| match &clipped.shape {
                        egui::Shape::Text(text) if text.galley.text() == "Unsaved changes" => {
                            Some(text.pos)
                        }
                        _ => None,
                    });
                output.drop_without_applying_deltas();
                title
            })
            .collect()
    }

    /// A prompt draws its box and nothing beyond it (no backdrop): the
    /// panel's kept layer is then blended over the image only there, and
    /// the scene keeps rendering under the prompt at its frame rate. A
    /// backdrop over the whole window made that blend, and egui's pass,
    /// cover the window (issue 28).
    #[test]
    fn a_prompt_covers_its_box_only() {
        // Every prompt is the same modal; the recovery offer's text is
        // the longest.
        for prompt in [Prompt::Quit, Prompt::Replace("copy.ron".into())] {
            let drawn = crate::panel::save_as::tests::modal_drawn(|ctx| {
                show(ctx, &prompt, "mine.ron");
            });
            assert!(
                drawn.width() < PROMPT_WIDTH + 60.0 && drawn.height() < 250.0,
                "{prompt:?} draws over {drawn:?}"
            );
        }
    }

    /// The prompt is drawn where it stays from its first frame on: it
    /// used to jump by about 35 px once egui had measured it.
    #[test]
    fn the_prompt_does_not_move_after_its_first_frame() {
        for prompt in [
            Prompt::Quit,
            Prompt::LoadPreset("presets/a/very/long/path/to/another/preset.ron".into()),
        ] {
            let positions = title_positions(&prompt, 4);
            let drawn: Vec<_> = positions.iter().flatten().collect();
            assert!(drawn.len() >= 3, "{positions:?}");
            assert!(drawn.iter().all(|p| *p == drawn[0]), "{positions:?}");
        }
    }
}
