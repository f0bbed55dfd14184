//! The node editor: a material's texture trees as a node graph in a
//! window beside the panel (Blender's shader editor). Each texture is a
//! node with its pattern and parameters, value children are inline inputs,
//! and links run from a nested texture to its parent's socket and from each
//! tree to the material's socket for its property. Dragging a link's end
//! onto another input moves the subtree there (`texture_graph::move_subtree`),
//! dropping it on nothing leaves a constant (`texture_graph::detach`);
//! dragging a node's header moves the node (`Scene::graph_layout`).
//!
//! Every edit goes straight to the [`Scene`] the tree panel edits, so the
//! two always agree and the app's history records graph edits like any
//! other (one step per gesture).
//!
//! Written here rather than taken from a crate: none of the egui node-graph
//! crates builds with egui 0.37 (checked 2026-12 with `cargo info -v`:
//! egui-snarl 0.12.0 needs egui 0.36, egui-graph-edit 0.9.1 egui 0.35,
//! egui_node_graph2 0.7.0 egui 0.29), and a tree needs little of them.

mod canvas;
mod layout;

use egui::{Context, TextureId, Ui};
use marbre_core::scene::texture_graph::NodePath;
use marbre_core::scene::{MaterialKey, Scene, Texture};

/// A preview image of the texture at a node (the node's path and its
/// subtree), if one is at hand; the node draws it in its header.
pub type Swatches<'a> = &'a dyn Fn(MaterialKey, &NodePath, &Texture) -> Option<TextureId>;

/// A button that opens the node editor on `key`'s material (or closes it).
pub fn toggle(ui: &mut Ui, open: &mut Option<MaterialKey>, key: MaterialKey) {
    let mut shown = *open == Some(key);
    if ui
        .toggle_value(&mut shown, "node graph")
        .on_hover_text(
            "Show this material's texture trees as nodes and links in a window: \
             drag a link's end to another input to move the subtree, onto nothing \
             to leave a constant; drag a header to move a node",
        )
        .changed()
    {
        *open = shown.then_some(key);
    }
}

/// The node editor's window for the material `open` names, if any; closing
/// the window (or the material disappearing) clears `open`.
pub fn window(
    ctx: &Context,
    scene: &mut Scene,
    open: &mut Option<MaterialKey>,
    swatches: Swatches,
) {
    let Some(key) = *open else { return };
    let title = scene.material_title(key).unwrap_or_else(|| key.to_string());
    let Some((material, layout)) = scene.material_and_layout_mut(key) else {
        *open = None;
        return;
    };
    let mut keep = true;
    egui::Window::new(format!("node graph: {title}"))
        .id(egui::Id::NULL.with("node graph window"))
        .open(&mut keep)
        .default_size([900.0, 560.0])
        .resizable(true)
        .show(ctx, |ui| {
            canvas::canvas(ui, key, material, layout, swatches);
        });
    if !keep {
        *open = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec3};
    use marbre_core::scene::{Child, Ground, Pattern, Sphere, Texture};

    fn scene() -> Scene {
        let checker = |a: Child, b: Child| {
            Texture::blend(
                Pattern::Checker2d {
                    size: Vec2::splat(0.25),
                    phase: 0.5,
                },
                a,
                b,
            )
        };
        let mut sphere = Sphere::default();
        sphere.material.diffuse = checker(
            checker(Vec3::X.into(), Vec3::Y.into()).into(),
            Vec3::Z.into(),
        );
        sphere.material.roughness = Texture::mix(
            Texture::blend(
                Pattern::fresh(marbre_core::scene::PatternKind::Fbm, None),
                0.0,
                1.0,
            ),
            0.2,
            0.8,
        );
        Scene {
            spheres: vec![sphere],
            ground: Some(Ground::default()),
            ..Scene::default()
        }
    }

    /// Drawing the window, several frames (egui sizes windows on the
    /// first), edits nothing: no parameter, no position.
    #[test]
    fn drawing_the_graph_without_input_changes_nothing() {
        let mut scene = scene();
        let before = scene.clone();
        let ctx = Context::default();
        for key in [MaterialKey::Sphere(0), MaterialKey::Ground] {
            let mut open = Some(key);
            for _ in 0..3 {
                ctx.run_ui(egui::RawInput::default(), |ui| {
                    window(ui.ctx(), &mut scene, &mut open, &|_, _, _| None);
                })
                .drop_without_applying_deltas();
            }
            assert_eq!(open, Some(key));
            assert_eq!(scene, before);
            // The nodes were drawn: each measured its height.
            let drawn: Option<f32> = ctx.data(|d| {
                d.get_temp(
                    egui::Id::NULL
                        .with(("node canvas", key.to_string()))
                        .with(("height", "diffuse".to_string())),
                )
            });
            assert!(drawn.is_some_and(|h| h > 40.0), "{drawn:?}");
        }
    }

    /// Runs one frame of the window with `events` as input.
    fn frame(
        ctx: &Context,
        scene: &mut Scene,
        open: &mut Option<MaterialKey>,
        events: Vec<egui::Event>,
    ) {
        let input = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(
                egui::Pos2::ZERO,
                egui::vec2(1280.0, 720.0),
            )),
            events,
            ..Default::default()
        };
        ctx.run_ui(input, |ui| {
            window(ui.ctx(), scene, open, &|_, _, _| {
                Some(egui::TextureId::Managed(0))
            });
        })
        .drop_without_applying_deltas();
    }

    fn pointer(pos: egui::Pos2, pressed: Option<bool>) -> Vec<egui::Event> {
        let mut events = vec![egui::Event::PointerMoved(pos)];
        if let Some(pressed) = pressed {
            events.push(egui::Event::PointerButton {
                pos,
                button: egui::PointerButton::Primary,
                pressed,
                modifiers: egui::Modifiers::NONE,
            });
        }
        events
    }

    /// A press at `from`, moves in steps to `to`, a release there.
    fn drag(
        ctx: &Context,
        scene: &mut Scene,
        open: &mut Option<MaterialKey>,
        from: egui::Pos2,
        to: egui::Pos2,
    ) {
        frame(ctx, scene, open, pointer(from, None));
        frame(ctx, scene, open, pointer(from, Some(true)));
        for k in 1..=5 {
            let at = from + (to - from) * (k as f32 / 5.0);
            frame(ctx, scene, open, pointer(at, None));
        }
        frame(ctx, scene, open, pointer(to, Some(false)));
        frame(ctx, scene, open, vec![]);
    }

    /// Where a node's part (`header`, `output`) was drawn last frame.
    fn drawn_rect(ctx: &Context, key: MaterialKey, path: &str, part: &str) -> egui::Rect {
        let id = canvas::node_id(canvas::canvas_id(key), &path.parse().unwrap()).with(part);
        ctx.read_response(id).expect("the node was drawn").rect
    }

    fn header_rect(ctx: &Context, key: MaterialKey, path: &str) -> egui::Rect {
        drawn_rect(ctx, key, path, "header")
    }

    /// Dragging a node's header, anywhere along its top row, moves that
    /// node by the drag and nothing else: not the other nodes, not the
    /// view.
    #[test]
    fn dragging_a_header_moves_its_node_alone() {
        let mut scene = scene();
        let key = MaterialKey::Sphere(0);
        let mut open = Some(key);
        let ctx = Context::default();
        for _ in 0..3 {
            frame(&ctx, &mut scene, &mut open, vec![]);
        }
        let header = header_rect(&ctx, key, "diffuse.a");
        let other = header_rect(&ctx, key, "diffuse");
        // Right of the title, where the row is empty, short of the output
        // socket at the node's right edge.
        let output = drawn_rect(&ctx, key, "diffuse.a", "output");
        let from = egui::pos2(output.center().x - 40.0, header.center().y);
        drag(
            &ctx,
            &mut scene,
            &mut open,
            from,
            from + egui::vec2(-60.0, 40.0),
        );
        let moved = header_rect(&ctx, key, "diffuse.a");
        assert_eq!(
            moved.min - header.min,
            egui::vec2(-60.0, 40.0),
            "{header:?} → {moved:?}"
        );
        assert_eq!(header_rect(&ctx, key, "diffuse"), other);
        let layout = scene.graph_layout.get(key).expect("a position was saved");
        assert!(layout.position(&"diffuse.a".parse().unwrap()).is_some());
        assert!(layout.position(&"diffuse".parse().unwrap()).is_none());
    }

    /// A material that is gone closes the window rather than panicking.
    #[test]
    fn a_missing_material_closes_the_window() {
        let mut scene = scene();
        let mut open = Some(MaterialKey::Cylinder(3));
        let ctx = Context::default();
        ctx.run_ui(egui::RawInput::default(), |ui| {
            window(ui.ctx(), &mut scene, &mut open, &|_, _, _| None);
        })
        .drop_without_applying_deltas();
        assert_eq!(open, None);
    }
}
