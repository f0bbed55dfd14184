//! A place in a material's texture trees: a root (a socket of the
//! material: a property, the bump, a layer's mask or property), then the
//! sockets (`a`, `b`, `factor`) followed down from it. One name for one
//! concept: the node editor's links and positions (`texture_graph`,
//! `graph_layout`) and the renderer's parameter plan (which node each
//! number of the generated code reads) all address nodes by it.

use super::material::Property;
use super::texture_tree::Child;
use glam::Vec3;
use std::fmt;
use std::str::FromStr;

/// Where a material's tree starts: a socket of the material itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Root {
    /// A base property.
    Property(Property),
    /// The bump height.
    Bump,
    /// The mask of layer `i`.
    Mask(usize),
    /// A property layer `i` sets.
    Layer(usize, Property),
}

impl Root {
    /// Whether the tree's values are colours (else scalars, the first
    /// channel).
    pub fn is_color(self) -> bool {
        match self {
            Root::Property(p) | Root::Layer(_, p) => p.is_color(),
            Root::Bump | Root::Mask(_) => false,
        }
    }
}

/// A texture's input that may hold a nested texture.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Socket {
    A,
    B,
    /// The mix pattern's blend factor.
    Factor,
}

impl Socket {
    pub const ALL: [Socket; 3] = [Socket::A, Socket::B, Socket::Factor];

    pub fn name(self) -> &'static str {
        match self {
            Socket::A => "a",
            Socket::B => "b",
            Socket::Factor => "factor",
        }
    }
}

/// A place in a material's trees: a root, then the sockets followed down
/// from it. It names a node (the texture there) and, equally, the input
/// that holds it: a link dropped on an input moves a subtree to that path.
///
/// Written as in the preset: `diffuse.a.factor`, `bump`,
/// `layers[0].mask`, `layers[1].roughness.b`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct NodePath {
    pub root: Root,
    pub steps: Vec<Socket>,
}

impl NodePath {
    pub fn root(root: Root) -> Self {
        Self {
            root,
            steps: Vec::new(),
        }
    }

    /// The path one socket further down.
    pub fn child(&self, socket: Socket) -> Self {
        let mut steps = self.steps.clone();
        steps.push(socket);
        Self {
            root: self.root,
            steps,
        }
    }

    /// The node holding this input and the socket, or None for a root.
    pub fn parent(&self) -> Option<(NodePath, Socket)> {
        let (&last, rest) = self.steps.split_last()?;
        Some((
            NodePath {
                root: self.root,
                steps: rest.to_vec(),
            },
            last,
        ))
    }

    /// Whether `self` is `other` or lies inside its subtree.
    pub fn starts_with(&self, other: &NodePath) -> bool {
        self.root == other.root && self.steps.starts_with(&other.steps)
    }

    /// `self` with its prefix `from` replaced by `to` (`self` must start
    /// with `from`): where a node goes when its subtree is moved.
    pub fn moved(&self, from: &NodePath, to: &NodePath) -> NodePath {
        let mut steps = to.steps.clone();
        steps.extend_from_slice(&self.steps[from.steps.len()..]);
        NodePath {
            root: to.root,
            steps,
        }
    }

    /// Whether a value held here is a colour: the root's kind, except
    /// below a mix factor, which is a scalar.
    pub fn is_color(&self) -> bool {
        self.root.is_color() && !self.steps.contains(&Socket::Factor)
    }

    /// The value a constant in this place has, from a colour.
    pub fn value(&self, c: Vec3) -> Child {
        if self.is_color() {
            Child::Color(c)
        } else {
            Child::Scalar(c.x)
        }
    }
}

impl fmt::Display for NodePath {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self.root {
            Root::Property(p) => f.write_str(p.name())?,
            Root::Bump => f.write_str("bump")?,
            Root::Mask(i) => write!(f, "layers[{i}].mask")?,
            Root::Layer(i, p) => write!(f, "layers[{i}].{}", p.name())?,
        }
        for s in &self.steps {
            write!(f, ".{}", s.name())?;
        }
        Ok(())
    }
}

impl FromStr for NodePath {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let bad = || format!("“{text}” is not a texture path (e.g. diffuse.a.factor)");
        let property = |name: &str| Property::ALL.into_iter().find(|p| p.name() == name);
        let mut words = text.split('.');
        let first = words.next().ok_or_else(bad)?;
        let root = if first == "bump" {
            Root::Bump
        } else if let Some(p) = property(first) {
            Root::Property(p)
        } else {
            let layer = first
                .strip_prefix("layers[")
                .and_then(|rest| rest.strip_suffix(']'))
                .and_then(|i| i.parse().ok())
                .ok_or_else(bad)?;
            match words.next().ok_or_else(bad)? {
                "mask" => Root::Mask(layer),
                name => Root::Layer(layer, property(name).ok_or_else(bad)?),
            }
        };
        let steps = words
            .map(|w| {
                Socket::ALL
                    .into_iter()
                    .find(|s| s.name() == w)
                    .ok_or_else(bad)
            })
            .collect::<Result<_, _>>()?;
        Ok(Self { root, steps })
    }
}
