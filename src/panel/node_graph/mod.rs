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

mod add_menu;
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

/// Closes the node editor's Add menu if it is open (Escape, which the
/// viewer's shortcuts take before the widgets); whether it was.
pub fn close_menu(ctx: &Context, open: Option<MaterialKey>) -> bool {
    let Some(key) = open else { return false };
    let mut view = canvas::view(ctx, key);
    let closed = view.close_menu();
    if closed {
        ctx.data_mut(|d| d.insert_temp(canvas::canvas_id(key), view));
    }
    closed
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
    use marbre_core::scene::texture_graph::texture_at;
    use marbre_core::scene::{Child, Ground, Pattern, PatternKind, Sphere, Texture};

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

    /// Where a node's part (`header`, `output`) was drawn last frame, on
    /// the screen (the canvas's layer is panned and zoomed).
    fn drawn_rect(ctx: &Context, key: MaterialKey, path: &str, part: &str) -> egui::Rect {
        let id = canvas::node_id(canvas::canvas_id(key), &path.parse().unwrap()).with(part);
        let response = ctx.read_response(id).expect("the node was drawn");
        let to_screen = ctx
            .layer_transform_to_global(response.layer_id)
            .unwrap_or_default();
        to_screen * response.rect
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
        // Within a point: the canvas's layer transform rounds.
        let moved_by = moved.min - header.min;
        assert!(
            (moved_by - egui::vec2(-60.0, 40.0)).length() <= 1.5,
            "{header:?} → {moved:?}"
        );
        assert_eq!(header_rect(&ctx, key, "diffuse").min, other.min);
        let layout = scene.graph_layout.get(key).expect("a position was saved");
        assert!(layout.position(&"diffuse.a".parse().unwrap()).is_some());
        assert!(layout.position(&"diffuse".parse().unwrap()).is_none());
    }

    fn key_event(key: egui::Key, modifiers: egui::Modifiers) -> egui::Event {
        egui::Event::Key {
            key,
            physical_key: None,
            pressed: true,
            repeat: false,
            modifiers,
        }
    }

    /// A context with `key`'s graph open and settled (egui sizes windows
    /// over the first frames).
    fn opened(scene: &mut Scene, key: MaterialKey) -> (Context, Option<MaterialKey>) {
        let ctx = Context::default();
        let mut open = Some(key);
        for _ in 0..3 {
            frame(&ctx, scene, &mut open, vec![]);
        }
        (ctx, open)
    }

    /// The wheel zooms about the pointer, as does a pinch: the nodes grow
    /// on screen and the graph shows less of itself.
    #[test]
    fn the_wheel_and_a_pinch_zoom_the_canvas() {
        let mut scene = scene();
        let key = MaterialKey::Sphere(0);
        let (ctx, mut open) = opened(&mut scene, key);
        let before = header_rect(&ctx, key, "diffuse").width();
        let shown = canvas::view(&ctx, key).shown.expect("a view").width();
        let at = header_rect(&ctx, key, "diffuse").center();
        frame(&ctx, &mut scene, &mut open, pointer(at, None));
        for _ in 0..10 {
            let wheel = egui::Event::MouseWheel {
                unit: egui::MouseWheelUnit::Line,
                delta: egui::vec2(0.0, 1.0),
                phase: egui::TouchPhase::Move,
                source: egui::MouseWheelSource::Unknown,
                modifiers: egui::Modifiers::NONE,
            };
            frame(&ctx, &mut scene, &mut open, vec![wheel]);
        }
        frame(&ctx, &mut scene, &mut open, vec![]);
        let wheeled = header_rect(&ctx, key, "diffuse").width();
        assert!(wheeled > 1.2 * before, "{before} → {wheeled}");
        assert!(canvas::view(&ctx, key).shown.unwrap().width() < shown / 1.2);
        frame(&ctx, &mut scene, &mut open, vec![egui::Event::Zoom(0.5)]);
        frame(&ctx, &mut scene, &mut open, vec![]);
        let pinched = header_rect(&ctx, key, "diffuse").width();
        assert!(pinched < 0.7 * wheeled, "{wheeled} → {pinched}");
        // Nothing in the scene moved: the view is not the scene's.
        assert_eq!(scene, self::scene());
    }

    /// Shift+A over the canvas opens the Add menu on the input nearest
    /// the pointer; typing filters it and Enter adds the first match
    /// there, nesting what the input held.
    #[test]
    fn shift_a_adds_the_searched_node_on_the_nearest_input() {
        let mut scene = scene();
        let key = MaterialKey::Sphere(0);
        let (ctx, mut open) = opened(&mut scene, key);
        // Just left of the diffuse node's `b` input: its header's left
        // edge, some rows down.
        let node = header_rect(&ctx, key, "diffuse");
        let near_b = egui::pos2(node.left() - 20.0, node.bottom() + 1.0);
        frame(&ctx, &mut scene, &mut open, pointer(near_b, None));
        let shift = egui::Modifiers::SHIFT;
        frame(
            &ctx,
            &mut scene,
            &mut open,
            vec![key_event(egui::Key::A, shift)],
        );
        let view = canvas::view(&ctx, key);
        let menu_input = view
            .adding
            .as_ref()
            .map(|m| &m.input)
            .expect("the menu opened")
            .to_string();
        frame(
            &ctx,
            &mut scene,
            &mut open,
            vec![egui::Event::Text("wave".into())],
        );
        frame(
            &ctx,
            &mut scene,
            &mut open,
            vec![key_event(egui::Key::Enter, egui::Modifiers::NONE)],
        );
        let added = texture_at(&scene.spheres[0].material, &menu_input.parse().unwrap())
            .expect("a node on the menu's input");
        assert_eq!(added.pattern.kind(), PatternKind::Waves);
        assert!(
            canvas::view(&ctx, key)
                .adding
                .as_ref()
                .map(|m| &m.input)
                .is_none()
        );
        assert_eq!(
            canvas::view(&ctx, key).selected.map(|p| p.to_string()),
            Some(menu_input)
        );
    }

    /// A click on a header selects the node; X deletes it, leaving a
    /// constant of its value in its place; Shift+D puts a copy of the
    /// selected node on the input nearest the pointer.
    #[test]
    fn x_deletes_the_selected_node_and_shift_d_duplicates_it() {
        let mut scene = scene();
        let key = MaterialKey::Sphere(0);
        let (ctx, mut open) = opened(&mut scene, key);
        let inner = header_rect(&ctx, key, "diffuse.a");
        let click_at = inner.center();
        frame(&ctx, &mut scene, &mut open, pointer(click_at, Some(true)));
        frame(&ctx, &mut scene, &mut open, pointer(click_at, Some(false)));
        assert_eq!(
            canvas::view(&ctx, key).selected.map(|p| p.to_string()),
            Some("diffuse.a".into())
        );
        // Duplicate with the pointer left of the roughness node.
        let roughness = header_rect(&ctx, key, "roughness");
        let at = egui::pos2(roughness.left() - 2.0, roughness.center().y);
        frame(&ctx, &mut scene, &mut open, pointer(at, None));
        frame(
            &ctx,
            &mut scene,
            &mut open,
            vec![key_event(egui::Key::D, egui::Modifiers::SHIFT)],
        );
        let checker = texture_at(&scene.spheres[0].material, &"diffuse.a".parse().unwrap())
            .unwrap()
            .clone();
        // The copy is selected, on an input near the pointer, outside the
        // original's tree.
        let copy = canvas::view(&ctx, key)
            .selected
            .expect("the copy is selected");
        assert!(!copy.to_string().starts_with("diffuse"), "{copy}");
        assert_eq!(
            texture_at(&scene.spheres[0].material, &copy),
            Some(&checker)
        );
        // Select the original again and delete it.
        frame(&ctx, &mut scene, &mut open, pointer(click_at, Some(true)));
        frame(&ctx, &mut scene, &mut open, pointer(click_at, Some(false)));
        frame(
            &ctx,
            &mut scene,
            &mut open,
            vec![key_event(egui::Key::X, egui::Modifiers::NONE)],
        );
        let m = &scene.spheres[0].material;
        assert!(texture_at(m, &"diffuse.a".parse().unwrap()).is_none());
        assert_eq!(
            m.diffuse.a,
            Child::Color(checker.eval(Vec3::ZERO, Vec2::ZERO))
        );
    }

    /// Home frames every node: the shown rectangle holds each node's
    /// place, and the nodes are all on screen.
    #[test]
    fn home_frames_all() {
        let mut scene = scene();
        let key = MaterialKey::Sphere(0);
        let (ctx, mut open) = opened(&mut scene, key);
        let window = ctx.read_response(egui::Id::NULL.with("node graph window"));
        let screen = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 720.0));
        let bump = header_rect(&ctx, key, "bump");
        assert!(!screen.contains_rect(bump), "bump at {bump:?} before");
        let inside = header_rect(&ctx, key, "diffuse").center();
        frame(&ctx, &mut scene, &mut open, pointer(inside, None));
        frame(
            &ctx,
            &mut scene,
            &mut open,
            vec![key_event(egui::Key::Home, egui::Modifiers::NONE)],
        );
        frame(&ctx, &mut scene, &mut open, vec![]);
        for path in [
            "diffuse",
            "diffuse.a",
            "roughness",
            "roughness.factor",
            "bump",
        ] {
            let r = header_rect(&ctx, key, path);
            assert!(
                screen.contains_rect(r),
                "{path} at {r:?}, window {window:?}"
            );
        }
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
