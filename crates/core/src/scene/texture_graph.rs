//! A material's texture trees seen as a node graph (Blender's shader
//! editor): one node per [`Texture`], a link from each nested texture to
//! the socket of its parent that holds it (`a`, `b`, `factor`), and from
//! each property's texture to the material's socket for that property.
//! Scalar and colour children are no nodes: they stay on their socket as
//! an inline value, as Blender shows an unlinked input.
//!
//! The graph is a view of the tree, not a second model: the viewer's node
//! editor reads it, and edits the [`Material`] itself through the paths
//! here ([`texture_at_mut`], [`move_subtree`], [`detach`], [`add_node`],
//! [`duplicate`]), so the tree
//! panel and the graph always show one scene and share its undo history.

use super::graph_layout::MaterialLayout;
use super::material::{Material, Property};
pub use super::node_path::{NodePath, Root, Socket};
use super::pattern::Pattern;
use super::pattern_table::PatternKind;
use super::texture_tree::{Child, Texture};
use glam::{Vec2, Vec3};
use std::fmt;

/// Every root the material has, in the order the material's node lists
/// its sockets: the base properties, the bump, then each layer's mask and
/// the properties it sets.
pub fn roots(material: &Material) -> Vec<Root> {
    let mut out: Vec<Root> = Property::ALL.into_iter().map(Root::Property).collect();
    out.push(Root::Bump);
    for (i, layer) in material.layers.iter().enumerate() {
        out.push(Root::Mask(i));
        out.extend(
            Property::ALL
                .into_iter()
                .filter(|&p| layer.texture(p).is_some())
                .map(|p| Root::Layer(i, p)),
        );
    }
    out
}

fn root_texture(material: &Material, root: Root) -> Option<&Texture> {
    match root {
        Root::Property(p) => Some(material.texture(p)),
        Root::Bump => Some(&material.bump),
        Root::Mask(i) => material.layers.get(i).map(|l| &l.mask),
        Root::Layer(i, p) => material.layers.get(i)?.texture(p),
    }
}

fn root_texture_mut(material: &mut Material, root: Root) -> Option<&mut Texture> {
    match root {
        Root::Property(p) => Some(material.texture_mut(p)),
        Root::Bump => Some(&mut material.bump),
        Root::Mask(i) => material.layers.get_mut(i).map(|l| &mut l.mask),
        Root::Layer(i, p) => material.layers.get_mut(i)?.slot_mut(p).as_mut(),
    }
}

/// The texture node at `path`, if there is one (a value child is none).
pub fn texture_at<'a>(material: &'a Material, path: &NodePath) -> Option<&'a Texture> {
    path.steps
        .iter()
        .try_fold(root_texture(material, path.root)?, |t, s| match s {
            Socket::A => t.a.texture(),
            Socket::B => t.b.texture(),
            Socket::Factor => t.factor.as_deref(),
        })
}

/// The texture node at `path`, to edit its own settings in place.
pub fn texture_at_mut<'a>(material: &'a mut Material, path: &NodePath) -> Option<&'a mut Texture> {
    path.steps
        .iter()
        .try_fold(root_texture_mut(material, path.root)?, |t, s| match s {
            Socket::A => child_texture_mut(&mut t.a),
            Socket::B => child_texture_mut(&mut t.b),
            Socket::Factor => t.factor.as_deref_mut(),
        })
}

fn child_texture_mut(child: &mut Child) -> Option<&mut Texture> {
    match child {
        Child::Texture(t) => Some(t),
        _ => None,
    }
}

/// A node of the graph: where it sits in the tree and its own settings.
#[derive(Debug, Clone, PartialEq)]
pub struct GraphNode {
    pub path: NodePath,
    /// The texture with its nested textures taken out: a linked `a` or
    /// `b` is left as [`LINKED`], a linked factor as None. Value children
    /// stay: they are the node's inline inputs.
    pub texture: Texture,
}

/// What a linked child leaves in its node's [`GraphNode::texture`].
pub const LINKED: Child = Child::Scalar(0.0);

/// An input a link ends at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Input {
    /// The material's socket for a root.
    Root(Root),
    /// A socket of node `node` (an index into [`TextureGraph::nodes`]).
    Node { node: usize, socket: Socket },
}

/// A link from node `from`'s output to an input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Link {
    pub from: usize,
    pub to: Input,
}

/// A material's texture trees as nodes and links.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureGraph {
    /// Depth first, each root's tree in [`roots`] order, a node before its
    /// `a`, `b` and `factor` subtrees.
    pub nodes: Vec<GraphNode>,
    pub links: Vec<Link>,
}

impl TextureGraph {
    /// The graph of every tree of `material`.
    pub fn of(material: &Material) -> Self {
        let mut graph = Self {
            nodes: Vec::new(),
            links: Vec::new(),
        };
        for root in roots(material) {
            if let Some(t) = root_texture(material, root) {
                let node = graph.add(t, NodePath::root(root));
                graph.links.push(Link {
                    from: node,
                    to: Input::Root(root),
                });
            }
        }
        graph
    }

    fn add(&mut self, texture: &Texture, path: NodePath) -> usize {
        let index = self.nodes.len();
        let mut own = Texture {
            factor: None,
            ..texture.clone()
        };
        for child in [&mut own.a, &mut own.b] {
            if matches!(child, Child::Texture(_)) {
                *child = LINKED;
            }
        }
        self.nodes.push(GraphNode {
            path: path.clone(),
            texture: own,
        });
        let nested = [
            (Socket::A, texture.a.texture()),
            (Socket::B, texture.b.texture()),
            (Socket::Factor, texture.factor.as_deref()),
        ];
        for (socket, child) in nested {
            if let Some(child) = child {
                let from = self.add(child, path.child(socket));
                self.links.push(Link {
                    from,
                    to: Input::Node {
                        node: index,
                        socket,
                    },
                });
            }
        }
        index
    }

    /// The index of the node at `path`.
    pub fn node(&self, path: &NodePath) -> Option<usize> {
        self.nodes.iter().position(|n| n.path == *path)
    }

    /// The tree linked to each root, rebuilt from the nodes and links
    /// alone (not from the paths): the inverse of [`TextureGraph::of`].
    pub fn trees(&self) -> Vec<(Root, Texture)> {
        self.links
            .iter()
            .filter_map(|link| match link.to {
                Input::Root(root) => Some((root, self.tree(link.from))),
                Input::Node { .. } => None,
            })
            .collect()
    }

    fn tree(&self, node: usize) -> Texture {
        let mut t = self.nodes[node].texture.clone();
        for link in &self.links {
            if let Input::Node { node: n, socket } = link.to
                && n == node
            {
                let child = self.tree(link.from);
                match socket {
                    Socket::A => t.a = child.into(),
                    Socket::B => t.b = child.into(),
                    Socket::Factor => t.factor = Some(Box::new(child)),
                }
            }
        }
        t
    }

    /// `material` with its trees replaced by the graph's: the layers'
    /// properties the graph links to nothing are unset.
    pub fn apply_to(&self, material: &Material) -> Material {
        let mut out = material.clone();
        for layer in &mut out.layers {
            for p in Property::ALL {
                *layer.slot_mut(p) = None;
            }
        }
        for (root, tree) in self.trees() {
            match root {
                Root::Layer(i, p) => {
                    if let Some(layer) = out.layers.get_mut(i) {
                        *layer.slot_mut(p) = Some(tree);
                    }
                }
                _ => {
                    if let Some(t) = root_texture_mut(&mut out, root) {
                        *t = tree;
                    }
                }
            }
        }
        out
    }
}

/// Why a link edit was refused (the tree is left as it was).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum GraphEditError {
    /// No texture node at this path.
    NoNode(String),
    /// No input at this path (its node is missing, or a value's socket
    /// was asked for on a root that does not exist).
    NoInput(String),
    /// The input lies inside the subtree being moved.
    IntoItself,
    /// The move would nest textures deeper than [`Texture::MAX_DEPTH`].
    TooDeep,
}

impl fmt::Display for GraphEditError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            GraphEditError::NoNode(p) => write!(f, "no texture node at {p}"),
            GraphEditError::NoInput(p) => write!(f, "no input at {p}"),
            GraphEditError::IntoItself => f.write_str("a texture cannot be linked into itself"),
            GraphEditError::TooDeep => write!(
                f,
                "textures nest at most {} deep; this link would go deeper",
                Texture::MAX_DEPTH
            ),
        }
    }
}

impl std::error::Error for GraphEditError {}

/// What an input holds: a texture node, or a value.
#[derive(Debug, Clone, PartialEq)]
enum Content {
    Node(Box<Texture>),
    Value(Child),
}

impl Content {
    /// How deep it nests at `path` (0 for a value).
    fn depth_at(&self, path: &NodePath) -> usize {
        match self {
            Content::Node(t) => path.steps.len() + t.depth(),
            Content::Value(_) => 0,
        }
    }
}

fn read(material: &Material, path: &NodePath) -> Option<Content> {
    let Some((parent, socket)) = path.parent() else {
        return root_texture(material, path.root).map(|t| Content::Node(Box::new(t.clone())));
    };
    let parent = texture_at(material, &parent)?;
    Some(match socket {
        Socket::A => child_content(&parent.a),
        Socket::B => child_content(&parent.b),
        Socket::Factor => Content::Node(parent.factor.clone()?),
    })
}

fn child_content(child: &Child) -> Content {
    match child {
        Child::Texture(t) => Content::Node(t.clone()),
        value => Content::Value(value.clone()),
    }
}

/// Writes `content` into the input at `path`, which must exist: a value
/// written where a texture belongs (a root, a factor) becomes a constant
/// texture of it.
fn write(material: &mut Material, path: &NodePath, content: Content) {
    let as_texture = |content: Content| match content {
        Content::Node(t) => *t,
        Content::Value(v) => Texture::from(v),
    };
    let Some((parent, socket)) = path.parent() else {
        if let Some(t) = root_texture_mut(material, path.root) {
            *t = as_texture(content);
        }
        return;
    };
    let Some(parent) = texture_at_mut(material, &parent) else {
        return;
    };
    match socket {
        Socket::Factor => {
            parent.factor = Some(match content {
                Content::Node(t) => t,
                value => Box::new(as_texture(value)),
            })
        }
        Socket::A | Socket::B => {
            let child = match content {
                Content::Node(t) => Child::Texture(t),
                Content::Value(v) => v,
            };
            if socket == Socket::A {
                parent.a = child;
            } else {
                parent.b = child;
            }
        }
    }
}

/// Moves the texture at `from`, with its subtree, into the input `to` (a
/// link dragged from one socket to another). What `to` held takes the
/// place `from` leaves, so nothing is lost: a value there becomes the
/// value left behind, a subtree there is swapped with the moved one. When
/// `to` holds a texture the moved one is nested in, the moved one replaces
/// it whole. The layout follows: positions under `from` move to `to`
/// (and back, for a swap).
pub fn move_subtree(
    material: &mut Material,
    layout: &mut MaterialLayout,
    from: &NodePath,
    to: &NodePath,
) -> Result<(), GraphEditError> {
    let Some(Content::Node(moved)) = read(material, from) else {
        return Err(GraphEditError::NoNode(from.to_string()));
    };
    if to.starts_with(from) {
        return if to == from {
            Ok(())
        } else {
            Err(GraphEditError::IntoItself)
        };
    }
    let held = read(material, to).ok_or_else(|| GraphEditError::NoInput(to.to_string()))?;
    let moved = Content::Node(moved);
    let replaces_ancestor = from.starts_with(to);
    if moved.depth_at(to) > Texture::MAX_DEPTH
        || (!replaces_ancestor && held.depth_at(from) > Texture::MAX_DEPTH)
    {
        return Err(GraphEditError::TooDeep);
    }
    if !replaces_ancestor {
        write(material, from, held);
    }
    write(material, to, moved);
    layout.rename(|path| {
        if path.starts_with(from) {
            Some(path.moved(from, to))
        } else if path.starts_with(to) {
            (!replaces_ancestor).then(|| path.moved(to, from))
        } else {
            Some(path.clone())
        }
    });
    Ok(())
}

/// Replaces the texture at `from` by a constant (a link dragged off its
/// input and dropped on nothing): its value at the origin, as the tree
/// panel's "reset to a constant" does. The layout forgets the positions
/// of the nodes that are gone.
pub fn detach(
    material: &mut Material,
    layout: &mut MaterialLayout,
    from: &NodePath,
) -> Result<(), GraphEditError> {
    let Some(Content::Node(t)) = read(material, from) else {
        return Err(GraphEditError::NoNode(from.to_string()));
    };
    let value = from.value(t.eval(Vec3::ZERO, Vec2::ZERO));
    write(material, from, Content::Value(value));
    // A root or a factor keeps a node there: the constant.
    let keeps_node = texture_at(material, from).is_some();
    layout.rename(|path| {
        (!path.starts_with(from) || (path == from && keeps_node)).then(|| path.clone())
    });
    Ok(())
}

/// Puts a new node of `kind` on the input `at` (the node editor's Add
/// menu: a tree has no unlinked nodes, so a new one is linked where it is
/// added). What `at` held becomes the new node's `a`, so nothing is lost,
/// and its `b` a contrasting value (as a pattern switched from a constant
/// gets), so the new node shows at once. The layout moves the positions
/// under `at` one level down, to `at.a`.
pub fn add_node(
    material: &mut Material,
    layout: &mut MaterialLayout,
    at: &NodePath,
    kind: PatternKind,
) -> Result<(), GraphEditError> {
    let held = match read(material, at) {
        Some(Content::Node(t)) => Child::Texture(t),
        Some(Content::Value(v)) => v,
        None => return Err(GraphEditError::NoInput(at.to_string())),
    };
    let node = Texture::blend(Pattern::Constant, held.clone(), held)
        .with_pattern_contrasting(Pattern::fresh(kind, None));
    let node = Content::Node(Box::new(node));
    if node.depth_at(at) > Texture::MAX_DEPTH {
        return Err(GraphEditError::TooDeep);
    }
    write(material, at, node);
    let below = at.child(Socket::A);
    layout.rename(|path| {
        Some(if path.starts_with(at) {
            path.moved(at, &below)
        } else {
            path.clone()
        })
    });
    Ok(())
}

/// Puts a copy of the node at `from`, with its subtree, on the input `at`
/// (the node editor's Duplicate). What `at` held is replaced, and the
/// layout forgets its positions; `from` itself is left as it was.
pub fn duplicate(
    material: &mut Material,
    layout: &mut MaterialLayout,
    from: &NodePath,
    at: &NodePath,
) -> Result<(), GraphEditError> {
    let Some(copy @ Content::Node(_)) = read(material, from) else {
        return Err(GraphEditError::NoNode(from.to_string()));
    };
    if read(material, at).is_none() {
        return Err(GraphEditError::NoInput(at.to_string()));
    }
    if copy.depth_at(at) > Texture::MAX_DEPTH {
        return Err(GraphEditError::TooDeep);
    }
    write(material, at, copy);
    layout.rename(|path| (!path.starts_with(at)).then(|| path.clone()));
    Ok(())
}

#[cfg(test)]
mod tests;
