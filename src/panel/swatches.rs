//! Preview swatches of texture nodes as the panels see them: a node asks
//! for the swatch of its place (a material and a node path) while it is
//! drawn and gets the latest one rendered (an earlier version's while an
//! edit's renders), never waiting. The viewer (`app/swatches.rs`) hands
//! the book each frame's [`Change`] with the scene: only when it touches
//! the materials (or shifts which material a key names) are the asked
//! places' subtrees read again, and those that changed are rendered on a
//! worker thread. The book travels in egui's memory, so a view needs no GPU
//! handle to ask, and without a viewer (tests) no swatch shows.
//!
//! The one call a view makes is [`swatch`]: the tree panel and the node
//! graph name the same place the same way, so they share a swatch.

use egui::{Context, Id, TextureHandle, TextureId};
use marbre_core::scene::texture_graph::{NodePath, Socket, texture_at};
use marbre_core::scene::{Change, MaterialKey, Scene, Texture};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// Frames a node may go unasked (its header closed, the node removed)
/// before its swatch is dropped.
const KEPT_UNASKED_FRAMES: u64 = 300;

/// Where a swatch's subtree is: a material of the scene and a node in it.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct SwatchPlace {
    pub key: MaterialKey,
    pub path: NodePath,
}

impl SwatchPlace {
    /// The place of the input `socket` of the node here.
    pub fn child(&self, socket: Socket) -> SwatchPlace {
        SwatchPlace {
            key: self.key,
            path: self.path.child(socket),
        }
    }
}

/// What a swatch shows: a subtree, and whether its property is a scalar
/// (shown as grey from the first channel, as the renderer reads it).
#[derive(Debug, Clone, PartialEq)]
pub struct SwatchRequest {
    pub place: SwatchPlace,
    pub texture: Texture,
    pub scalar: bool,
}

/// The book shared by the panels (which ask) and the viewer (which
/// renders).
pub type SharedSwatchBook = Arc<Mutex<SwatchBook>>;

#[derive(Default)]
pub struct SwatchBook {
    nodes: HashMap<SwatchPlace, Node>,
    frame: u64,
}

struct Node {
    /// The subtree at the place when the scene was last read; `None`
    /// before the first reading or where the place no longer exists.
    shows: Option<Texture>,
    /// Whether the scene was read since the node was first asked for.
    read: bool,
    /// Whether `shows` changed since it was last sent to render.
    unsent: bool,
    image: Option<TextureHandle>,
    /// The subtree `image` was rendered from, so that a subtree that
    /// moves to another place (a link dragged, an undo) takes its image
    /// along at once rather than wait for a render.
    image_of: Option<Texture>,
    /// The subtree last sent to render, which the next delivery shows.
    sent: Option<Texture>,
    last_asked: u64,
}

fn book_id() -> Id {
    Id::NULL.with("marbre swatch book")
}

/// Makes `book` the one [`swatch`] reads in `ctx`.
pub fn install(ctx: &Context, book: SharedSwatchBook) {
    ctx.data_mut(|d| d.insert_temp(book_id(), book));
}

/// The swatch of the node at `place`: the latest rendered, if any. The
/// request is noted; the book reads the subtree itself when it observes
/// the scene. `None` without a viewer.
pub fn swatch(ctx: &Context, place: SwatchPlace) -> Option<TextureId> {
    let book: SharedSwatchBook = ctx.data(|d| d.get_temp(book_id()))?;
    let mut book = book.lock().ok()?;
    let frame = book.frame;
    let node = book.nodes.entry(place).or_insert_with(|| Node {
        shows: None,
        read: false,
        unsent: false,
        image: None,
        image_of: None,
        sent: None,
        last_asked: frame,
    });
    node.last_asked = frame;
    node.image.as_ref().map(TextureHandle::id)
}

impl SwatchBook {
    /// After the frame's edits, with what they changed (worked out once,
    /// by the viewer): reads the subtree of each place asked for the first
    /// time, and of every place when `change` touches a material or moves
    /// the objects (a key may then name another material); a subtree that
    /// differs from what the node shows takes the image of a node that
    /// showed the same subtree before (of the same kind, colour or
    /// scalar), if there is one, or else is to be rendered.
    pub fn observe(&mut self, scene: &Scene, change: Change) {
        let materials_changed = change.intersects(
            Change::MATERIAL_PARAMETERS | Change::MATERIAL_STRUCTURE | Change::GEOMETRY,
        );
        if !materials_changed && self.nodes.values().all(|node| node.read) {
            // Most frames: nothing to read, so no images to gather either.
            return;
        }
        let rendered: Vec<(bool, Texture, TextureHandle)> = self
            .nodes
            .iter()
            .filter_map(|(place, node)| {
                Some((
                    place.path.is_color(),
                    node.image_of.clone()?,
                    node.image.clone()?,
                ))
            })
            .collect();
        for (place, node) in &mut self.nodes {
            if node.read && !materials_changed {
                continue;
            }
            node.read = true;
            let now = scene
                .material(place.key)
                .and_then(|material| texture_at(material, &place.path));
            if now == node.shows.as_ref() {
                continue;
            }
            node.shows = now.cloned();
            let same = rendered.iter().find(|(color, texture, _)| {
                *color == place.path.is_color() && Some(texture) == node.shows.as_ref()
            });
            match same {
                Some((_, texture, image)) => {
                    node.image = Some(image.clone());
                    node.image_of = Some(texture.clone());
                    node.unsent = false;
                }
                None => node.unsent = node.shows.is_some(),
            }
        }
    }

    /// Up to `max` nodes whose subtree changed since it was last sent,
    /// marked sent.
    pub fn take_requests(&mut self, max: usize) -> Vec<SwatchRequest> {
        let mut out = Vec::new();
        for (place, node) in &mut self.nodes {
            if out.len() == max {
                break;
            }
            if let (true, Some(texture)) = (node.unsent, &node.shows) {
                node.unsent = false;
                node.sent = Some(texture.clone());
                out.push(SwatchRequest {
                    place: place.clone(),
                    texture: texture.clone(),
                    scalar: !place.path.is_color(),
                });
            }
        }
        out
    }

    /// The new swatch of the node at `place` (ignored if the node was
    /// dropped meanwhile).
    pub fn deliver(&mut self, place: &SwatchPlace, image: TextureHandle) {
        if let Some(node) = self.nodes.get_mut(place) {
            node.image = Some(image);
            node.image_of = node.sent.clone();
        }
    }

    /// Ends a frame: nodes not asked for lately are dropped, with their
    /// images.
    pub fn end_frame(&mut self) {
        let frame = self.frame;
        self.nodes
            .retain(|_, node| frame - node.last_asked < KEPT_UNASKED_FRAMES);
        self.frame += 1;
    }

    /// How many nodes hold a swatch.
    pub fn shown(&self) -> usize {
        self.nodes.values().filter(|n| n.image.is_some()).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use marbre_core::scene::texture_graph::Root;
    use marbre_core::scene::{Pattern, Property};

    /// A node is read from the scene and sent once per version of its
    /// subtree; a version the book is not told of (an empty change) is not
    /// looked for; its swatch shows once delivered, an edit keeps showing
    /// it while the new one renders, and a node unasked long enough is
    /// dropped.
    #[test]
    fn a_node_is_rendered_once_per_version_and_dropped_when_unasked() {
        let ctx = Context::default();
        let book = SharedSwatchBook::default();
        install(&ctx, book.clone());
        let mut sphere = marbre_core::scene::Sphere::default();
        sphere.material.diffuse = Texture::color(Vec3::splat(0.5)).with_pattern_contrasting(
            Pattern::fresh(marbre_core::scene::PatternKind::Checker, None),
        );
        let mut scene = Scene {
            spheres: vec![sphere],
            ..Scene::default()
        };
        let place = SwatchPlace {
            key: MaterialKey::Sphere(0),
            path: NodePath::root(Root::Property(Property::Diffuse)),
        };
        let diffuse = |scene: &Scene| scene.spheres[0].material.diffuse.clone();
        assert_eq!(swatch(&ctx, place.clone()), None);
        book.lock().unwrap().observe(&scene, Change::empty());
        let sent = book.lock().unwrap().take_requests(8);
        assert_eq!(sent.len(), 1);
        assert_eq!(sent[0].texture, diffuse(&scene));
        assert!(!sent[0].scalar);
        // Asked again unchanged: nothing more to render.
        swatch(&ctx, place.clone());
        book.lock().unwrap().observe(&scene, Change::empty());
        assert!(book.lock().unwrap().take_requests(8).is_empty());
        let image = ctx.load_texture("s", egui::ColorImage::example(), Default::default());
        book.lock().unwrap().deliver(&place, image.clone());
        assert_eq!(swatch(&ctx, place.clone()), Some(image.id()));
        // An edit: the old swatch shows until the new one arrives, and the
        // book reads the subtree only when the change says a material moved.
        scene.spheres[0].material.diffuse.b = Vec3::ONE.into();
        assert_eq!(swatch(&ctx, place.clone()), Some(image.id()));
        book.lock().unwrap().observe(&scene, Change::CAMERA);
        assert!(book.lock().unwrap().take_requests(8).is_empty());
        book.lock()
            .unwrap()
            .observe(&scene, Change::MATERIAL_PARAMETERS);
        assert_eq!(
            book.lock().unwrap().take_requests(8)[0].texture,
            diffuse(&scene)
        );
        // The place gone (the sphere removed): nothing to render.
        scene.spheres.clear();
        book.lock().unwrap().observe(&scene, Change::GEOMETRY);
        assert!(book.lock().unwrap().take_requests(8).is_empty());
        for _ in 0..=KEPT_UNASKED_FRAMES {
            book.lock().unwrap().end_frame();
        }
        assert_eq!(book.lock().unwrap().shown(), 0);
    }

    /// A link dragged from one input to another swaps two subtrees: each
    /// node's swatch follows its subtree in the same frame, with nothing
    /// to render, where it used to show the old subtree until a render.
    #[test]
    fn swatches_follow_a_subtree_that_moves() {
        use marbre_core::scene::texture_graph::move_subtree;
        let ctx = Context::default();
        let book = SharedSwatchBook::default();
        install(&ctx, book.clone());
        let marble = Texture::blend(
            Pattern::fresh(marbre_core::scene::PatternKind::Marble, None),
            Vec3::ZERO,
            Vec3::ONE,
        );
        let mut sphere = marbre_core::scene::Sphere::default();
        sphere.material.diffuse = Texture::blend(
            Pattern::fresh(marbre_core::scene::PatternKind::Checker, None),
            marble,
            Texture::color(Vec3::X),
        );
        let mut scene = Scene {
            spheres: vec![sphere],
            ..Scene::default()
        };
        let key = MaterialKey::Sphere(0);
        let at = |text: &str| SwatchPlace {
            key,
            path: text.parse().unwrap(),
        };
        let (a, b) = (at("diffuse.a"), at("diffuse.b"));
        swatch(&ctx, a.clone());
        swatch(&ctx, b.clone());
        book.lock().unwrap().observe(&scene, Change::empty());
        let sent = book.lock().unwrap().take_requests(8);
        assert_eq!(sent.len(), 2);
        let images: Vec<_> = (0..2)
            .map(|i| {
                ctx.load_texture(
                    format!("s{i}"),
                    egui::ColorImage::example(),
                    Default::default(),
                )
            })
            .collect();
        for (request, image) in sent.iter().zip(&images) {
            book.lock().unwrap().deliver(&request.place, image.clone());
        }
        let before = (swatch(&ctx, a.clone()), swatch(&ctx, b.clone()));

        let (material, layout) = scene.material_and_layout_mut(key).unwrap();
        layout
            .edit(key, |l| move_subtree(material, l, &a.path, &b.path))
            .unwrap();
        book.lock()
            .unwrap()
            .observe(&scene, Change::MATERIAL_STRUCTURE);
        assert!(book.lock().unwrap().take_requests(8).is_empty());
        assert_eq!(
            (swatch(&ctx, a.clone()), swatch(&ctx, b.clone())),
            (before.1, before.0)
        );
    }
}
