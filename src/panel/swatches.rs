//! Preview swatches of texture nodes as the panels see them: a node asks
//! for the swatch of its subtree while it is drawn and gets the latest one
//! rendered (an earlier version's while an edit's renders), never waiting.
//! The viewer (`app/swatches.rs`) renders what was asked on a worker thread
//! and hands the images back. The book travels in egui's memory, so a view
//! needs no GPU handle to ask, and without a viewer (tests) no swatch shows.
//!
//! The one call a view makes is [`swatch`]: the tree panel passes its
//! node's header id; another view (the node graph) passes its own node ids.

use egui::{Context, Id, TextureHandle, TextureId};
use marbre_core::scene::Texture;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// Frames a node may go unasked (its header closed, the node removed)
/// before its swatch is dropped.
const KEPT_UNASKED_FRAMES: u64 = 300;

/// What a swatch shows: a subtree, and whether its property is a scalar
/// (shown as grey from the first channel, as the renderer reads it).
#[derive(Debug, Clone, PartialEq)]
pub struct SwatchRequest {
    pub id: Id,
    pub texture: Texture,
    pub scalar: bool,
}

/// The book shared by the panels (which ask) and the viewer (which
/// renders).
pub type SharedSwatchBook = Arc<Mutex<SwatchBook>>;

#[derive(Default)]
pub struct SwatchBook {
    nodes: HashMap<Id, Node>,
    frame: u64,
}

struct Node {
    /// What the node shows now.
    asked: (Texture, bool),
    /// What was last handed to the viewer to render.
    sent: Option<(Texture, bool)>,
    image: Option<TextureHandle>,
    last_asked: u64,
}

fn book_id() -> Id {
    Id::NULL.with("marbre swatch book")
}

/// Makes `book` the one [`swatch`] reads in `ctx`.
pub fn install(ctx: &Context, book: SharedSwatchBook) {
    ctx.data_mut(|d| d.insert_temp(book_id(), book));
}

/// The swatch of node `id`, which shows `texture` (`scalar`: a scalar
/// property's): the latest rendered, if any; the request is noted, and a
/// changed subtree is rendered again. `None` without a viewer.
pub fn swatch(ctx: &Context, id: Id, texture: &Texture, scalar: bool) -> Option<TextureId> {
    let book: SharedSwatchBook = ctx.data(|d| d.get_temp(book_id()))?;
    let mut book = book.lock().ok()?;
    let frame = book.frame;
    let node = book.nodes.entry(id).or_insert_with(|| Node {
        asked: (texture.clone(), scalar),
        sent: None,
        image: None,
        last_asked: frame,
    });
    node.last_asked = frame;
    if node.asked.0 != *texture || node.asked.1 != scalar {
        node.asked = (texture.clone(), scalar);
    }
    node.image.as_ref().map(TextureHandle::id)
}

impl SwatchBook {
    /// Up to `max` nodes whose subtree changed since it was last sent,
    /// marked sent.
    pub fn take_requests(&mut self, max: usize) -> Vec<SwatchRequest> {
        let mut out = Vec::new();
        for (id, node) in &mut self.nodes {
            if out.len() == max {
                break;
            }
            if node.sent.as_ref() != Some(&node.asked) {
                node.sent = Some(node.asked.clone());
                out.push(SwatchRequest {
                    id: *id,
                    texture: node.asked.0.clone(),
                    scalar: node.asked.1,
                });
            }
        }
        out
    }

    /// Node `id`'s new swatch (ignored if the node was dropped meanwhile).
    pub fn deliver(&mut self, id: Id, image: TextureHandle) {
        if let Some(node) = self.nodes.get_mut(&id) {
            node.image = Some(image);
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
    use marbre_core::scene::Pattern;

    /// A node is sent once per version of its subtree; its swatch shows
    /// once delivered, an edit keeps showing it while the new one renders,
    /// and a node unasked long enough is dropped.
    #[test]
    fn a_node_is_rendered_once_per_version_and_dropped_when_unasked() {
        let ctx = Context::default();
        let book = SharedSwatchBook::default();
        install(&ctx, book.clone());
        let id = Id::NULL.with("node");
        let mut t = Texture::color(Vec3::splat(0.5)).with_pattern_contrasting(Pattern::fresh(
            marbre_core::scene::PatternKind::Checker,
            None,
        ));
        assert_eq!(swatch(&ctx, id, &t, false), None);
        let sent = book.lock().unwrap().take_requests(8);
        assert_eq!(sent.len(), 1);
        assert_eq!(sent[0].texture, t);
        // Asked again unchanged: nothing more to render.
        swatch(&ctx, id, &t, false);
        assert!(book.lock().unwrap().take_requests(8).is_empty());
        let image = ctx.load_texture("s", egui::ColorImage::example(), Default::default());
        book.lock().unwrap().deliver(id, image.clone());
        assert_eq!(swatch(&ctx, id, &t, false), Some(image.id()));
        // An edit: the old swatch shows until the new one arrives.
        t.b = Vec3::ONE.into();
        assert_eq!(swatch(&ctx, id, &t, false), Some(image.id()));
        assert_eq!(book.lock().unwrap().take_requests(8)[0].texture, t);
        for _ in 0..=KEPT_UNASKED_FRAMES {
            book.lock().unwrap().end_frame();
        }
        assert_eq!(book.lock().unwrap().shown(), 0);
    }
}
