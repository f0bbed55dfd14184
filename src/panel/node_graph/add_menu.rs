//! The node editor's Add menu (Blender's Shift+A): a search field over
//! the pattern list, opened at the pointer. Typing filters the list by
//! name (and by the report's TX keyword), Enter takes the first match, a
//! click takes any, Escape or a click elsewhere closes it.

use egui::{Area, Context, Frame, Id, Key, Order, Pos2, TextEdit};
use marbre_core::scene::texture_graph::NodePath;
use marbre_core::scene::{PATTERNS, PatternInfo, PatternKind};

/// An open Add menu: the input its node goes on, where in the graph the
/// node is put, where on screen the menu shows, and the search text.
#[derive(Clone, Debug)]
pub(super) struct AddMenu {
    pub input: NodePath,
    pub place: Pos2,
    screen: Pos2,
    search: String,
    focused: bool,
}

impl AddMenu {
    pub fn new(input: NodePath, place: Pos2, screen: Pos2) -> Self {
        Self {
            input,
            place,
            screen,
            search: String::new(),
            focused: false,
        }
    }
}

/// What the menu did this frame.
pub(super) enum Outcome {
    Open,
    Closed,
    Chosen(PatternKind),
}

/// The patterns whose name or TX keyword contains `search` (case
/// ignored), in the panel's order.
pub(super) fn matches(search: &str) -> Vec<&'static PatternInfo> {
    let search = search.trim().to_lowercase();
    PATTERNS
        .iter()
        .filter(|p| {
            p.name.to_lowercase().contains(&search)
                || p.tx_keyword
                    .is_some_and(|k| k.to_lowercase().contains(&search))
        })
        .collect()
}

pub(super) fn show(ctx: &Context, id: Id, menu: &mut AddMenu) -> Outcome {
    let mut outcome = Outcome::Open;
    let area = Area::new(id)
        .order(Order::Foreground)
        .fixed_pos(menu.screen)
        .show(ctx, |ui| {
            Frame::menu(ui.style()).show(ui, |ui| {
                ui.set_width(220.0);
                ui.strong(format!("Add on {}", menu.input));
                let field = ui.add(
                    TextEdit::singleline(&mut menu.search)
                        .hint_text("search")
                        .desired_width(f32::INFINITY),
                );
                if !menu.focused {
                    field.request_focus();
                    menu.focused = true;
                }
                let found = matches(&menu.search);
                if ui.input(|i| i.key_pressed(Key::Enter))
                    && let Some(first) = found.first()
                {
                    outcome = Outcome::Chosen(first.kind);
                }
                if ui.input(|i| i.key_pressed(Key::Escape)) {
                    outcome = Outcome::Closed;
                }
                egui::ScrollArea::vertical()
                    .max_height(320.0)
                    .show(ui, |ui| {
                        for info in found {
                            if ui.selectable_label(false, info.name).clicked() {
                                outcome = Outcome::Chosen(info.kind);
                            }
                        }
                    });
            });
        });
    let clicked_elsewhere = ctx.input(|i| i.pointer.any_pressed())
        && !ctx
            .input(|i| i.pointer.interact_pos())
            .is_some_and(|p| area.response.rect.contains(p));
    if clicked_elsewhere && matches!(outcome, Outcome::Open) && menu.focused {
        outcome = Outcome::Closed;
    }
    outcome
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_search_filters_by_name_and_tx_keyword() {
        assert_eq!(matches("").len(), PATTERNS.len());
        let marble: Vec<_> = matches("MARB").iter().map(|p| p.kind).collect();
        assert!(marble.contains(&PatternKind::Marble), "{marble:?}");
        assert!(marble.contains(&PatternKind::MassalMarble), "{marble:?}");
        assert!(!marble.contains(&PatternKind::Checker));
        // The report's keyword for a brick wall.
        let brick: Vec<_> = matches("brique").iter().map(|p| p.kind).collect();
        assert_eq!(brick, [PatternKind::Brick]);
        assert!(matches("no such pattern").is_empty());
    }
}
