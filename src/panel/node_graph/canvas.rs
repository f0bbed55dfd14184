//! Drawing the graph and what the pointer and keys do to it: a canvas that
//! pans (drag the background) and zooms (wheel, pinch) as `egui::Scene`
//! does, the material's node at the origin with a socket per tree, a node
//! per texture (its swatch, pattern, parameters and inputs), bezier links,
//! the link or node being dragged, a selected node, and the Add menu.
//!
//! Keys act on the canvas under the pointer, as in Blender's editors, and
//! never while a text field has the keyboard: Shift+A adds, X or Delete
//! deletes the selected node (its subtree becomes a constant), Shift+D
//! duplicates it onto the input nearest the pointer, Home frames all.

use super::Swatches;
use super::add_menu::{self, AddMenu};
use super::layout::{NODE_WIDTH, UNMEASURED_HEIGHT, auto_positions};
use crate::panel::keying;
use crate::panel::material_editor::{image_source_ui, mapping_ui, math_ui, pattern_ui, ramp_ui};
use crate::panel::widgets::{color_button, slider};
use egui::emath::TSTransform;
use egui::epaint::CubicBezierShape;
use egui::{
    CollapsingHeader, Color32, Frame, Id, Key, Label, Modifiers, Pos2, Rect, Sense, Shape, Stroke,
    Ui, UiBuilder, Vec2, pos2, vec2,
};
use marbre_core::animation::ParamPath;
use marbre_core::scene::texture_graph::{
    NodePath, Root, Socket, TextureGraph, add_node, detach, duplicate, move_subtree, roots,
    texture_at_mut,
};
use marbre_core::scene::{
    Child, GraphLayout, Material, MaterialKey, Pattern, PatternKind, Texture,
};

const SOCKET_RADIUS: f32 = 5.0;
/// How near the pointer must be to a socket to grab or drop on it.
const SOCKET_REACH: f32 = 12.0;
/// The material node's width.
const MATERIAL_WIDTH: f32 = 170.0;
/// How far the view zooms out and in.
const ZOOM: std::ops::RangeInclusive<f32> = 0.1..=2.0;
/// How much one notch of the wheel zooms.
const WHEEL_STEP: f32 = 1.2;
/// The space Home leaves around the nodes.
const FRAME_MARGIN: f32 = 30.0;

/// What the canvas keeps between frames (egui memory, not the scene): the
/// part of the graph shown, the link being dragged, the selected node, the
/// open Add menu and the last refused edit's reason.
#[derive(Clone, Default)]
pub(super) struct View {
    /// The graph-space rectangle the canvas shows (`egui::Scene`'s): pan
    /// and zoom.
    pub shown: Option<Rect>,
    dragging: Option<NodePath>,
    pub selected: Option<NodePath>,
    pub adding: Option<AddMenu>,
    message: Option<String>,
}

/// A change to the tree's shape or the layout, applied once everything
/// is drawn (parameters are edited in place while drawing).
enum Edit {
    Place(NodePath, glam::Vec2),
    Move {
        from: NodePath,
        to: NodePath,
    },
    Detach(NodePath),
    Add {
        at: NodePath,
        kind: PatternKind,
        place: glam::Vec2,
    },
    Duplicate {
        from: NodePath,
        at: NodePath,
        place: glam::Vec2,
    },
}

/// Where sockets were drawn this frame, in graph space.
#[derive(Default)]
struct Sockets {
    /// Each input that may take a link: the path a texture linked there has.
    inputs: Vec<(NodePath, Pos2)>,
}

impl Sockets {
    fn input(&self, path: &NodePath) -> Option<Pos2> {
        self.inputs
            .iter()
            .find(|(p, _)| p == path)
            .map(|(_, at)| *at)
    }

    /// The input nearest `at`, within `reach`.
    fn nearest(&self, at: Pos2, reach: f32) -> Option<&NodePath> {
        self.inputs
            .iter()
            .filter(|(_, p)| p.distance(at) <= reach)
            .min_by(|a, b| a.1.distance(at).total_cmp(&b.1.distance(at)))
            .map(|(p, _)| p)
    }
}

/// The canvas's id for `key`'s material: its view, its nodes' heights and
/// the nodes' ids are named under it.
pub(super) fn canvas_id(key: MaterialKey) -> Id {
    Id::NULL.with(("node canvas", key.to_string()))
}

/// The id a node's header and output are named under, from the canvas's
/// id and the node's path (tests find a node's header by it).
pub(super) fn node_id(canvas: Id, path: &NodePath) -> Id {
    canvas.with(("node", path.to_string()))
}

/// The canvas's view of `key`'s material as last drawn.
pub(super) fn view(ctx: &egui::Context, key: MaterialKey) -> View {
    ctx.data(|d| d.get_temp(canvas_id(key))).unwrap_or_default()
}

impl View {
    /// Closes the Add menu; whether it was open.
    pub fn close_menu(&mut self) -> bool {
        self.adding.take().is_some()
    }
}

/// What the keys asked of the canvas this frame.
#[derive(Default)]
struct Keys {
    add: bool,
    delete: bool,
    duplicate: bool,
    frame_all: bool,
}

impl Keys {
    /// The canvas's keys, taken only with the pointer over it and no text
    /// field holding the keyboard.
    fn read(ui: &Ui, over_canvas: bool) -> Keys {
        if !over_canvas || ui.ctx().memory(|m| m.focused().is_some()) {
            return Keys::default();
        }
        ui.input_mut(|i| Keys {
            add: i.consume_key(Modifiers::SHIFT, Key::A),
            delete: i.consume_key(Modifiers::NONE, Key::X)
                || i.consume_key(Modifiers::NONE, Key::Delete),
            duplicate: i.consume_key(Modifiers::SHIFT, Key::D),
            frame_all: i.consume_key(Modifiers::NONE, Key::Home),
        })
    }
}

pub(super) fn canvas(
    ui: &mut Ui,
    key: MaterialKey,
    material: &mut Material,
    layout: &mut GraphLayout,
    swatches: Swatches,
) {
    let id = canvas_id(key);
    let mut view = view(ui.ctx(), key);
    match &view.message {
        Some(message) => ui.colored_label(ui.visuals().error_fg_color, message),
        None => ui.weak(
            "Drag a header to move a node, the background to pan; the wheel zooms, Home frames \
             all. Shift+A or right-click adds a node on the input nearest the pointer; click a \
             header to select, X deletes (a constant stays), Shift+D duplicates. Drag a link's \
             end onto another input to move the subtree, onto nothing to leave a constant.",
        ),
    };
    let outer = ui.available_rect_before_wrap();
    ui.painter()
        .rect_filled(outer, 0.0, ui.visuals().extreme_bg_color);
    let over_canvas = ui.rect_contains_pointer(outer);
    let keys = Keys::read(ui, over_canvas);

    let graph = TextureGraph::of(material);
    let height_id = |path: &NodePath| id.with(("height", path.to_string()));
    let heights: Vec<f32> = graph
        .nodes
        .iter()
        .map(|n| ui.data(|d| d.get_temp(height_id(&n.path))))
        .map(|h| h.unwrap_or(UNMEASURED_HEIGHT))
        .collect();
    let root_ys_id = id.with("root ys");
    let root_ys: Vec<f32> = ui.data(|d| d.get_temp(root_ys_id)).unwrap_or_default();
    let auto = auto_positions(
        &graph,
        |i| heights[i],
        |k| root_ys.get(k).copied().unwrap_or(0.0),
    );
    let saved = layout.get(key);
    let positions: Vec<glam::Vec2> = graph
        .nodes
        .iter()
        .zip(&auto)
        .map(|(n, a)| saved.and_then(|l| l.position(&n.path)).unwrap_or(*a))
        .collect();

    // The material's node on the right, as the view opens.
    let shown = view.shown.get_or_insert(Rect::from_min_size(
        pos2(MATERIAL_WIDTH + 20.0 - outer.width(), -20.0),
        outer.size(),
    ));
    if keys.frame_all {
        let mut all = Rect::from_min_size(
            Pos2::ZERO,
            vec2(MATERIAL_WIDTH, 30.0 + 16.0 * root_ys.len() as f32),
        );
        for (p, h) in positions.iter().zip(&heights) {
            all = all.union(Rect::from_min_size(pos2(p.x, p.y), vec2(NODE_WIDTH, *h)));
        }
        *shown = all.expand(FRAME_MARGIN);
    }

    if over_canvas {
        wheel_zoom(ui, outer, shown);
    }

    let mut edits = Vec::new();
    let mut sockets = Sockets::default();
    let roots = roots(material);
    let scene = egui::Scene::new().zoom_range(ZOOM);
    let drawn = scene.show(ui, shown, |ui| {
        let links_slot = ui.painter().add(Shape::Noop);
        let from_global = ui
            .ctx()
            .layer_transform_from_global(ui.layer_id())
            .unwrap_or(TSTransform::IDENTITY);
        let pointer = ui
            .input(|i| i.pointer.latest_pos())
            .map(|p| from_global * p);

        let root_ys_now = material_node(ui, material, &roots, &mut sockets);
        if root_ys_now != root_ys {
            ui.data_mut(|d| d.insert_temp(root_ys_id, root_ys_now));
        }

        let mut outputs = Vec::with_capacity(graph.nodes.len());
        for (i, (node, position)) in graph.nodes.iter().zip(&positions).enumerate() {
            let Some(texture) = texture_at_mut(material, &node.path) else {
                continue;
            };
            let top_left = pos2(position.x, position.y);
            let swatch = swatches(key, &node.path, texture);
            let selected = view.selected.as_ref() == Some(&node.path);
            let drawn = texture_node(
                ui,
                (id, top_left, selected),
                (key, &node.path),
                texture,
                swatch,
                &mut sockets,
            );
            if drawn.header.dragged() && drawn.header.drag_delta() != Vec2::ZERO {
                let d = drawn.header.drag_delta();
                edits.push(Edit::Place(
                    node.path.clone(),
                    *position + glam::Vec2::new(d.x, d.y),
                ));
            }
            if drawn.header.clicked() || drawn.header.drag_started() {
                view.selected = Some(node.path.clone());
            }
            drawn.header.context_menu(|ui| {
                if ui.button("Duplicate (Shift+D)").clicked() {
                    let at = pointer.unwrap_or(top_left);
                    if let Some(to) = sockets.nearest(at, f32::INFINITY) {
                        edits.push(Edit::Duplicate {
                            from: node.path.clone(),
                            at: to.clone(),
                            place: glam::Vec2::new(at.x, at.y),
                        });
                    }
                }
                if ui.button("Delete (X): a constant stays").clicked() {
                    edits.push(Edit::Detach(node.path.clone()));
                }
            });
            if drawn.output.drag_started() {
                view.dragging = Some(node.path.clone());
            }
            if (drawn.height - heights[i]).abs() > 0.5 {
                ui.data_mut(|d| d.insert_temp(height_id(&node.path), drawn.height));
            }
            outputs.push((node.path.clone(), drawn.output.rect.center()));
        }

        // An input holding a texture gives up its link when dragged.
        for (path, at) in &sockets.inputs {
            let grab = ui.interact(
                Rect::from_center_size(*at, Vec2::splat(2.0 * SOCKET_REACH)),
                id.with(("input", path.to_string())),
                Sense::drag(),
            );
            if grab.drag_started() && outputs.iter().any(|(p, _)| p == path) {
                view.dragging = Some(path.clone());
            }
        }

        let mut links = Vec::new();
        for (path, from) in &outputs {
            let to = if view.dragging.as_ref() == Some(path) {
                pointer
            } else {
                sockets.input(path)
            };
            if let Some(to) = to {
                links.push(link(*from, to, link_color(ui, path)));
            }
        }
        ui.painter().set(links_slot, Shape::Vec(links));

        if ui.input(|i| i.pointer.any_released())
            && let Some(from) = view.dragging.take()
        {
            match pointer.and_then(|at| sockets.nearest(at, SOCKET_REACH)) {
                Some(to) if *to == from => {}
                Some(to) => edits.push(Edit::Move {
                    from,
                    to: to.clone(),
                }),
                None => edits.push(Edit::Detach(from)),
            }
        }
        pointer
    });
    let pointer = drawn.inner;
    let background = drawn.response;
    if background.clicked() {
        view.selected = None;
    }

    let nearest_input = |at: Pos2| sockets.nearest(at, f32::INFINITY).cloned();
    if (keys.add || background.secondary_clicked())
        && let Some(at) = pointer
        && let Some(input) = nearest_input(at)
    {
        view.adding = Some(AddMenu::new(
            input,
            at,
            ui.input(|i| i.pointer.latest_pos())
                .unwrap_or(outer.center()),
        ));
    }
    if keys.delete
        && let Some(selected) = view.selected.take()
    {
        edits.push(Edit::Detach(selected));
    }
    if keys.duplicate
        && let (Some(from), Some(at)) = (view.selected.clone(), pointer)
        && let Some(input) = nearest_input(at)
    {
        edits.push(Edit::Duplicate {
            from,
            at: input,
            place: glam::Vec2::new(at.x, at.y),
        });
    }
    if let Some(menu) = &mut view.adding {
        match add_menu::show(ui.ctx(), id.with("add menu"), menu) {
            add_menu::Outcome::Open => {}
            add_menu::Outcome::Closed => view.adding = None,
            add_menu::Outcome::Chosen(kind) => {
                edits.push(Edit::Add {
                    at: menu.input.clone(),
                    kind,
                    place: glam::Vec2::new(menu.place.x, menu.place.y),
                });
                view.adding = None;
            }
        }
    }

    for edit in edits {
        let result = layout.edit(key, |l| match &edit {
            Edit::Place(path, at) => {
                l.set(path, *at);
                Ok(())
            }
            Edit::Move { from, to } => move_subtree(material, l, from, to),
            Edit::Detach(from) => detach(material, l, from),
            Edit::Add { at, kind, place } => add_node(material, l, at, *kind).map(|()| {
                l.set(at, *place);
            }),
            Edit::Duplicate { from, at, place } => {
                duplicate(material, l, from, at).map(|()| l.set(at, *place))
            }
        });
        match &edit {
            Edit::Place(..) => {}
            Edit::Add { at, .. } | Edit::Duplicate { at, .. } if result.is_ok() => {
                view.selected = Some(at.clone());
                view.message = None;
            }
            _ => view.message = result.err().map(|e| e.to_string()),
        }
    }
    ui.data_mut(|d| d.insert_temp(id, view));
}

/// The wheel zooms about the pointer, [`WHEEL_STEP`] a notch (Blender's
/// wheel; `egui::Scene`'s own wheel zoom takes about 1.7× a notch). The
/// scroll is taken, so the scene does not pan with it too; a pinch is left
/// to the scene.
fn wheel_zoom(ui: &Ui, outer: Rect, shown: &mut Rect) {
    let scroll = ui
        .input_mut(|i| std::mem::take(&mut i.smooth_scroll_delta))
        .y;
    let Some(pointer) = ui.input(|i| i.pointer.latest_pos()) else {
        return;
    };
    if scroll == 0.0 || !shown.is_positive() {
        return;
    }
    let line = ui.ctx().options(|o| o.input_options.line_scroll_speed);
    // The scene fits `shown` in `outer` at one scale, centred.
    let scale = (outer.size() / shown.size()).min_elem();
    let wanted = scale * WHEEL_STEP.powf(scroll / line);
    let factor = ZOOM.start().max(wanted.min(*ZOOM.end())) / scale;
    let fixed = shown.center() + (pointer - outer.center()) / scale;
    *shown = Rect::from_min_max(
        fixed + (shown.min - fixed) / factor,
        fixed + (shown.max - fixed) / factor,
    );
}

/// A link from an output to an input, leaving and entering horizontally.
fn link(from: Pos2, to: Pos2, color: Color32) -> Shape {
    let dx = ((to.x - from.x).abs() * 0.5).max(40.0);
    Shape::CubicBezier(CubicBezierShape::from_points_stroke(
        [from, from + vec2(dx, 0.0), to - vec2(dx, 0.0), to],
        false,
        Color32::TRANSPARENT,
        Stroke::new(2.0, color),
    ))
}

/// Blender's colours: yellow for colours, grey for scalars.
fn link_color(ui: &Ui, path: &NodePath) -> Color32 {
    if path.is_color() {
        Color32::from_rgb(199, 199, 41)
    } else {
        ui.visuals().widgets.inactive.fg_stroke.color
    }
}

fn socket(ui: &Ui, at: Pos2, path: &NodePath, linked: bool) {
    let color = link_color(ui, path);
    let painter = ui.painter();
    if linked {
        painter.circle_filled(at, SOCKET_RADIUS, color);
    } else {
        painter.circle_stroke(at, SOCKET_RADIUS, Stroke::new(1.5, color));
    }
}

/// A node's box; the selected node's outline in the selection colour, as
/// Blender outlines the active node.
fn node_frame(ui: &Ui, selected: bool) -> Frame {
    let stroke = if selected {
        Stroke::new(2.0, ui.visuals().selection.stroke.color)
    } else {
        ui.visuals().window_stroke
    };
    Frame::new()
        .fill(ui.visuals().window_fill)
        .stroke(stroke)
        .corner_radius(4.0)
        .inner_margin(6.0)
}

/// A child Ui at `top_left` (graph space).
fn place(
    ui: &mut Ui,
    top_left: Pos2,
    width: f32,
    salt: impl std::hash::Hash + std::fmt::Debug,
) -> Ui {
    ui.new_child(
        UiBuilder::new()
            .id_salt(salt)
            .max_rect(Rect::from_min_size(top_left, vec2(width, 4000.0))),
    )
}

fn root_label(material: &Material, root: Root) -> String {
    let layer = |i: usize| material.layers.get(i).map_or("", |l| l.name.as_str());
    match root {
        Root::Property(p) => p.label().to_owned(),
        Root::Bump => "bump".to_owned(),
        Root::Mask(i) => format!("“{}” mask", layer(i)),
        Root::Layer(i, p) => format!("“{}” {}", layer(i), p.label()),
    }
}

/// The material's node at the graph's origin: a socket per tree. Returns
/// each socket's y, for the automatic layout.
fn material_node(
    ui: &mut Ui,
    material: &Material,
    roots: &[Root],
    sockets: &mut Sockets,
) -> Vec<f32> {
    let mut child = place(ui, Pos2::ZERO, MATERIAL_WIDTH, "material node");
    let mut ys = Vec::new();
    node_frame(&child, false).show(&mut child, |ui| {
        ui.set_width(MATERIAL_WIDTH - 12.0);
        ui.add(Label::new(egui::RichText::new("material").strong()).selectable(false));
        for &root in roots {
            let row = ui
                .add(Label::new(root_label(material, root)).selectable(false))
                .rect;
            let at = pos2(0.0, row.center().y);
            let path = NodePath::root(root);
            socket(ui, at, &path, true);
            sockets.inputs.push((path, at));
            ys.push(row.top());
        }
    });
    ys
}

/// What drawing a texture node gives back.
struct DrawnNode {
    header: egui::Response,
    output: egui::Response,
    height: f32,
}

/// A texture node: the header (swatch, pattern name; drag it to move the
/// node, click it to select; its output socket on the right), the pattern
/// and its parameters, the image, mapping, ramp and math steps folded, and
/// the inputs the pattern reads, each a socket with its value inline when
/// no texture is linked.
fn texture_node(
    ui: &mut Ui,
    (canvas_id, top_left, selected): (Id, Pos2, bool),
    (key, path): (MaterialKey, &NodePath),
    texture: &mut Texture,
    swatch: Option<egui::TextureId>,
    sockets: &mut Sockets,
) -> DrawnNode {
    let mut child = place(ui, top_left, NODE_WIDTH, ("node", path.to_string()));
    let id = node_id(canvas_id, path);
    let inner = node_frame(&child, selected).show(&mut child, |ui| {
        ui.set_width(NODE_WIDTH - 12.0);
        let header = ui
            .horizontal(|ui| {
                if let Some(swatch) = swatch {
                    ui.image((swatch, Vec2::splat(32.0)));
                }
                ui.add(
                    Label::new(egui::RichText::new(texture.pattern.info().name).strong())
                        .selectable(false),
                )
                .on_hover_text(path.to_string());
            })
            .response
            .rect;
        ui.separator();
        let node = ParamPath::parse(&format!("{key}.material.{path}"))
            .expect("a material key and a node path print as a parameter path");
        pattern_ui(ui, texture, &node.field("pattern"));
        if texture.pattern == Pattern::Mix && texture.factor.is_none() {
            // A pattern just switched to mix: the tree panel's default.
            texture.factor = Some(Box::new(Texture::scalar(0.5)));
        }
        CollapsingHeader::new("image, mapping, ramp, math")
            .id_salt("more")
            .show(ui, |ui| {
                if matches!(texture.pattern, Pattern::Image { .. }) {
                    image_source_ui(ui, &mut texture.image);
                }
                mapping_ui(ui, &mut texture.mapping, &node);
                ramp_ui(ui, texture, &node);
                math_ui(ui, &mut texture.ops, &node);
            });
        let reads_children =
            texture.ramp.is_empty() && !matches!(texture.pattern, Pattern::Image { .. });
        let constant = texture.pattern == Pattern::Constant;
        for (socket_kind, label) in [(Socket::A, "a"), (Socket::B, "b")] {
            let child = if socket_kind == Socket::A {
                &mut texture.a
            } else {
                &mut texture.b
            };
            let linked = matches!(child, Child::Texture(_));
            let read = reads_children && (socket_kind == Socket::A || !constant);
            if !(read || linked) {
                continue;
            }
            let label = if constant { "value" } else { label };
            let input = path.child(socket_kind);
            let row = ui
                .horizontal(|ui| {
                    let at = node.field(if socket_kind == Socket::A { "a" } else { "b" });
                    value_input(ui, &at, label, child, input.is_color())
                })
                .response
                .rect;
            input_socket(ui, top_left.x, row, input, linked, sockets);
        }
        if texture.pattern == Pattern::Mix || texture.factor.is_some() {
            let row = ui.add(Label::new("factor").selectable(false)).rect;
            input_socket(
                ui,
                top_left.x,
                row,
                path.child(Socket::Factor),
                true,
                sockets,
            );
        }
        header
    });
    let frame = inner.response.rect;
    // The whole top row grabs the node, not only its swatch and title.
    let header = Rect::from_x_y_ranges(frame.x_range(), inner.inner.y_range());
    let header = ui.interact(header, id.with("header"), Sense::click_and_drag());
    let output_at = pos2(frame.right(), inner.inner.center().y);
    socket(ui, output_at, path, true);
    let output = ui.interact(
        Rect::from_center_size(output_at, Vec2::splat(2.0 * SOCKET_REACH)),
        id.with("output"),
        Sense::drag(),
    );
    DrawnNode {
        header,
        output,
        height: frame.height(),
    }
}

fn input_socket(
    ui: &Ui,
    left: f32,
    row: Rect,
    path: NodePath,
    linked: bool,
    sockets: &mut Sockets,
) {
    let at = pos2(left, row.center().y);
    socket(ui, at, &path, linked);
    sockets.inputs.push((path, at));
}

/// An input's inline value (`path`: its parameter path, for the key
/// button), or its name alone when a texture is linked.
fn value_input(ui: &mut Ui, path: &ParamPath, label: &str, child: &mut Child, is_color: bool) {
    match child {
        Child::Texture(_) => {
            ui.add(Label::new(label).selectable(false));
        }
        Child::Color(c) if is_color => {
            keying::vector(ui, path, c, |ui, c| {
                let r = color_button(ui, c);
                ui.label(label);
                r
            });
        }
        Child::Color(c) => {
            keying::number(ui, &path.index(0), &mut c.x, |ui, v| {
                ui.add(slider(v, 0.0..=1.0, label))
            });
        }
        Child::Scalar(v) => {
            keying::number(ui, path, v, |ui, v| ui.add(slider(v, 0.0..=1.0, label)));
        }
    }
}
