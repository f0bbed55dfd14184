//! A material property shown and edited as the texture report's TX text
//! (`TX QUAD UNI CD 0.8 0 0 FTX UNI CD 0 0 0.8 FTX FTX`), beside its tree.
//! The text follows the tree while the user has not typed in it; Apply
//! lowers it onto the material, and a text that does not parse leaves the
//! material untouched with the line, column and token expected shown.

use egui::{Button, CollapsingHeader, Key, TextEdit, Ui};
use marbre_core::scene::{Material, Property};
use marbre_core::tx;
use std::path::Path;

/// The properties with a TX coefficient, each shown once: CT drives opacity
/// and transmission together, so it sits under opacity.
pub(super) fn has_tx_section(property: Property) -> bool {
    tx::Channel::for_property(property).is_some() && property != Property::Transmission
}

/// What the TX field of one property holds between frames.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct TxEdit {
    /// The text in the field.
    pub text: String,
    /// The tree's own TX text when last seen (its raise).
    pub shown: String,
    /// Whether `text` holds typing not yet applied: the tree's changes
    /// then leave it alone.
    pub edited: bool,
    /// Why the last Apply failed.
    pub error: Option<String>,
}

impl TxEdit {
    /// Follows the tree's text `raised` (or its reason for having none)
    /// unless the user is typing.
    pub fn sync(&mut self, raised: &Result<String, tx::TxError>) {
        let current = match raised {
            Ok(text) => text.clone(),
            Err(_) => String::new(),
        };
        if current != self.shown {
            if !self.edited {
                self.text = current.clone();
            }
            self.shown = current;
        }
    }

    /// Lowers the text onto `property` of `material`; on an error the
    /// material is unchanged and the error kept for display. Image paths
    /// resolve against `base_dir`.
    pub fn apply(&mut self, material: &mut Material, property: Property, base_dir: &Path) {
        match tx::apply_to_property(material, property, &self.text, base_dir) {
            Ok(()) => {
                self.edited = false;
                self.error = None;
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }
}

/// The rows the TX box shows; a longer text scrolls in it.
const TX_ROWS: usize = 5;

/// The "as TX" section of `property`, folded by default.
pub(super) fn tx_ui(ui: &mut Ui, material: &mut Material, property: Property) {
    let title = if property == Property::Opacity {
        "opacity and transmission as TX (CT)"
    } else {
        "as TX"
    };
    CollapsingHeader::new(title)
        .id_salt(("tx", property.name()))
        .default_open(false)
        .show(ui, |ui| {
            let id = ui.scope_id().with("tx-edit");
            let mut state: TxEdit = ui.data_mut(|d| d.get_temp(id)).unwrap_or_default();
            let raised = tx::raise_property(material, property);
            state.sync(&raised);
            if let Err(e) = &raised {
                ui.label(egui::RichText::new(format!("no TX form: {e}")).weak());
            }
            // A box of a fixed height that scrolls: typing a line more does
            // not push Apply down under the pointer.
            let rows = TX_ROWS as f32;
            let height = rows * ui.text_style_height(&egui::TextStyle::Monospace)
                + 2.0 * ui.spacing().button_padding.y;
            let field = egui::ScrollArea::vertical()
                .id_salt("tx-scroll")
                .max_height(height)
                .show(ui, |ui| {
                    ui.add(
                        TextEdit::multiline(&mut state.text)
                            .code_editor()
                            .desired_rows(TX_ROWS)
                            .desired_width(f32::INFINITY),
                    )
                })
                .inner;
            if field.changed() {
                state.edited = state.text != state.shown;
                state.error = None;
            }
            let ctrl_enter =
                field.has_focus() && ui.input(|i| i.modifiers.command && i.key_pressed(Key::Enter));
            ui.horizontal(|ui| {
                let apply = ui
                    .button("apply")
                    .on_hover_text("Replace the tree by this text (Ctrl+Enter in the field)");
                if apply.clicked() || ctrl_enter {
                    // Image paths typed here are relative to the working
                    // folder, like the panel's other path fields.
                    let base = std::env::current_dir().unwrap_or_default();
                    state.apply(material, property, &base);
                }
                if ui
                    .add_enabled(state.edited, Button::new("revert"))
                    .on_hover_text("Back to the tree's own text")
                    .clicked()
                {
                    state.text = state.shown.clone();
                    state.edited = false;
                    state.error = None;
                }
            });
            if let Some(e) = &state.error {
                ui.colored_label(ui.visuals().error_fg_color, e);
            }
            ui.data_mut(|d| d.insert_temp(id, state));
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec3};
    use marbre_core::scene::Pattern;

    fn srgb_decode(v: f32) -> f32 {
        marbre_core::scene::color_encoding::srgb_decode(v)
    }

    /// The report's 4×4 board typed in the panel becomes the diffuse tree:
    /// its colours decoded from display values, the tree's text then
    /// shown in place of the typing.
    #[test]
    fn applying_the_report_quad_sets_the_diffuse_tree() {
        let mut material = Material::default();
        let mut edit = TxEdit::default();
        edit.sync(&tx::raise_property(&material, Property::Diffuse));
        assert!(edit.text.contains("CD"), "{}", edit.text);
        edit.text = "TX QUAD UNI CD 0.8 0 0 FTX UNI CD 0 0 0.8 FTX GU 0.25 GV 0.25 FTX".into();
        edit.edited = true;
        edit.apply(&mut material, Property::Diffuse, Path::new("."));
        assert_eq!(edit.error, None);
        assert!(matches!(
            material.diffuse.pattern,
            Pattern::Checker2d { size, .. } if size == Vec2::splat(0.25)
        ));
        let even = material.diffuse.eval(Vec3::ZERO, Vec2::new(0.1, 0.1));
        assert!(
            (even - Vec3::new(srgb_decode(0.8), 0.0, 0.0))
                .abs()
                .max_element()
                < 1e-6
        );
        edit.sync(&tx::raise_property(&material, Property::Diffuse));
        assert!(edit.text.contains("QUAD"), "{}", edit.text);
        assert!(!edit.edited);
    }

    /// A text that does not parse leaves the tree as it was and says where
    /// and what was expected; the typing survives a change of the tree.
    #[test]
    fn a_bad_text_leaves_the_tree_and_names_the_place() {
        let mut material = Material::default();
        let before = material.clone();
        let mut edit = TxEdit {
            text: "QUAD UNI CD 0.8 0 FTX UNI FTX FTX".into(),
            edited: true,
            ..TxEdit::default()
        };
        edit.apply(&mut material, Property::Diffuse, Path::new("."));
        assert_eq!(material, before);
        let error = edit.error.clone().unwrap();
        assert!(error.contains("line 1, column"), "{error}");
        assert!(error.contains("expected"), "{error}");
        material.diffuse = marbre_core::scene::Texture::color(Vec3::ONE);
        edit.sync(&tx::raise_property(&material, Property::Diffuse));
        assert_eq!(edit.text, "QUAD UNI CD 0.8 0 FTX UNI FTX FTX");
    }

    #[test]
    fn ct_is_shown_once_and_roughness_not_at_all() {
        assert!(has_tx_section(Property::Opacity));
        assert!(!has_tx_section(Property::Transmission));
        assert!(!has_tx_section(Property::Roughness));
        assert!(has_tx_section(Property::Diffuse));
    }
}
