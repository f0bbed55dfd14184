//! Drawing the graph and what the pointer does to it: a pannable canvas,
//! the material's node on the right with a socket per tree, a node per
//! texture (its swatch slot, pattern, parameters and inputs), bezier links,
//! and the link or node being dragged.

use super::Swatches;
use super::layout::{NODE_WIDTH, UNMEASURED_HEIGHT, auto_positions};
use crate::panel::keying;
use crate::panel::material_editor::{image_source_ui, mapping_ui, math_ui, pattern_ui, ramp_ui};
use crate::panel::widgets::{color_button, slider};
use egui::epaint::CubicBezierShape;
use egui::{
    CollapsingHeader, Color32, Frame, Id, Label, Pos2, Rect, Sense, Shape, Stroke, Ui, UiBuilder,
    Vec2, pos2, vec2,
};
use marbre_core::animation::ParamPath;
use marbre_core::scene::texture_graph::{
    NodePath, Root, Socket, TextureGraph, detach, move_subtree, roots, texture_at_mut,
};
use marbre_core::scene::{Child, GraphLayout, Material, MaterialKey, Pattern, Texture};

const SOCKET_RADIUS: f32 = 5.0;
/// How near the pointer must be to a socket to grab or drop on it.
const SOCKET_REACH: f32 = 12.0;
/// The material node's width.
const MATERIAL_WIDTH: f32 = 170.0;

/// What the canvas keeps between frames (egui memory, not the scene): the
/// pan, the link being dragged and the last refused link's reason.
#[derive(Clone, Default)]
struct View {
    pan: Option<Vec2>,
    dragging: Option<NodePath>,
    message: Option<String>,
}

/// A change to the tree's shape or the layout, applied once everything
/// is drawn (parameters are edited in place while drawing).
enum Edit {
    Place(NodePath, glam::Vec2),
    Move { from: NodePath, to: NodePath },
    Detach(NodePath),
}

/// Where sockets were drawn this frame, in screen space.
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

    fn nearest(&self, at: Pos2) -> Option<&NodePath> {
        self.inputs
            .iter()
            .filter(|(_, p)| p.distance(at) <= SOCKET_REACH)
            .min_by(|a, b| a.1.distance(at).total_cmp(&b.1.distance(at)))
            .map(|(p, _)| p)
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
    let mut view: View = ui.data(|d| d.get_temp(id)).unwrap_or_default();
    match &view.message {
        Some(message) => ui.colored_label(ui.visuals().error_fg_color, message),
        None => ui.weak(
            "Drag a link's end onto another input to move the subtree (what the input held \
             takes its place), onto nothing to leave a constant; drag a header to move a node, \
             the background to pan.",
        ),
    };
    let (rect, background) = ui.allocate_exact_size(ui.available_size(), Sense::drag());
    let pan = view
        .pan
        .get_or_insert(vec2(rect.width() - MATERIAL_WIDTH - 20.0, 20.0));
    if background.dragged() {
        *pan += background.drag_delta();
    }
    let origin = rect.min + *pan;
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, ui.visuals().extreme_bg_color);
    let links_slot = painter.add(Shape::Noop);

    let mut sockets = Sockets::default();
    let roots = roots(material);
    let root_ys = material_node(ui, rect, origin, material, &roots, &mut sockets);

    let graph = TextureGraph::of(material);
    let height_id = |path: &NodePath| id.with(("height", path.to_string()));
    let heights: Vec<f32> = graph
        .nodes
        .iter()
        .map(|n| ui.data(|d| d.get_temp(height_id(&n.path))))
        .map(|h| h.unwrap_or(UNMEASURED_HEIGHT))
        .collect();
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

    let mut edits = Vec::new();
    let mut outputs = Vec::with_capacity(graph.nodes.len());
    for (node, position) in graph.nodes.iter().zip(&positions) {
        let Some(texture) = texture_at_mut(material, &node.path) else {
            continue;
        };
        let top_left = origin + vec2(position.x, position.y);
        let swatch = swatches(key, &node.path, texture);
        let drawn = texture_node(
            ui,
            (rect, id),
            top_left,
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
        if drawn.output.drag_started() {
            view.dragging = Some(node.path.clone());
        }
        if (drawn.height - heights[outputs.len()]).abs() > 0.5 {
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

    let pointer = ui.input(|i| i.pointer.latest_pos());
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
    ui.painter_at(rect).set(links_slot, Shape::Vec(links));

    if ui.input(|i| i.pointer.any_released())
        && let Some(from) = view.dragging.take()
    {
        match pointer.and_then(|at| sockets.nearest(at)) {
            Some(to) if *to == from => {}
            Some(to) => edits.push(Edit::Move {
                from,
                to: to.clone(),
            }),
            None => edits.push(Edit::Detach(from)),
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
        });
        if !matches!(edit, Edit::Place(..)) {
            view.message = result.err().map(|e| e.to_string());
        }
    }
    ui.data_mut(|d| d.insert_temp(id, view));
}

/// The canvas's id for `key`'s material: its view, its nodes' heights and
/// the nodes' ids are named under it.
pub(super) fn canvas_id(key: MaterialKey) -> Id {
    Id::NULL.with(("node canvas", key.to_string()))
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

fn node_frame(ui: &Ui) -> Frame {
    Frame::new()
        .fill(ui.visuals().window_fill)
        .stroke(ui.visuals().window_stroke)
        .corner_radius(4.0)
        .inner_margin(6.0)
}

/// A child Ui at `top_left`, clipped to the canvas.
fn place(
    ui: &mut Ui,
    canvas: Rect,
    top_left: Pos2,
    width: f32,
    salt: impl std::hash::Hash + std::fmt::Debug,
) -> Ui {
    let mut child = ui.new_child(
        UiBuilder::new()
            .id_salt(salt)
            .max_rect(Rect::from_min_size(top_left, vec2(width, 4000.0))),
    );
    child.set_clip_rect(canvas.intersect(ui.clip_rect()));
    child
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
/// each socket's y in graph space, for the automatic layout.
fn material_node(
    ui: &mut Ui,
    canvas: Rect,
    origin: Pos2,
    material: &Material,
    roots: &[Root],
    sockets: &mut Sockets,
) -> Vec<f32> {
    let mut child = place(ui, canvas, origin, MATERIAL_WIDTH, "material node");
    let mut ys = Vec::new();
    node_frame(&child).show(&mut child, |ui| {
        ui.set_width(MATERIAL_WIDTH - 12.0);
        ui.add(Label::new(egui::RichText::new("material").strong()).selectable(false));
        for &root in roots {
            let row = ui
                .add(Label::new(root_label(material, root)).selectable(false))
                .rect;
            let at = pos2(origin.x, row.center().y);
            let path = NodePath::root(root);
            socket(ui, at, &path, true);
            sockets.inputs.push((path, at));
            ys.push(row.top() - origin.y);
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

/// A texture node: the header (swatch slot, pattern name; drag it to move
/// the node; its output socket on the right), the pattern and its
/// parameters, the image, mapping, ramp and math steps folded, and the
/// inputs the pattern reads, each a socket with its value inline when no
/// texture is linked.
fn texture_node(
    ui: &mut Ui,
    (canvas, canvas_id): (Rect, Id),
    top_left: Pos2,
    (key, path): (MaterialKey, &NodePath),
    texture: &mut Texture,
    swatch: Option<egui::TextureId>,
    sockets: &mut Sockets,
) -> DrawnNode {
    let mut child = place(ui, canvas, top_left, NODE_WIDTH, ("node", path.to_string()));
    let id = node_id(canvas_id, path);
    let inner = node_frame(&child).show(&mut child, |ui| {
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
    let header = ui.interact(header, id.with("header"), Sense::drag());
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

/// The id a node's header and output are named under, from the canvas's
/// id and the node's path (tests find a node's header by it).
pub(super) fn node_id(canvas: Id, path: &NodePath) -> Id {
    canvas.with(("node", path.to_string()))
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
