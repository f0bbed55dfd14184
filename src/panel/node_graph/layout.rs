//! Where nodes go when the user has not put them anywhere: the material's
//! node at the origin, each tree growing to its left one column per level
//! (Blender's left-to-right flow), a node never above its parent and never
//! over the node before it in its column.

use glam::Vec2;
use marbre_core::scene::texture_graph::TextureGraph;

/// The width of every node, in points.
pub const NODE_WIDTH: f32 = 230.0;
/// From one column's left edge to the next.
pub const COLUMN: f32 = NODE_WIDTH + 70.0;
/// The space left between two nodes of a column.
const GAP: f32 = 16.0;
/// The height assumed for a node not drawn yet.
pub const UNMEASURED_HEIGHT: f32 = 90.0;

/// Each node's top-left corner (in graph space, the material's node at
/// the origin), in [`TextureGraph::nodes`] order. `height(i)` is node
/// `i`'s height as last drawn; `root_y(k)` where the material's node
/// draws its `k`-th socket, so that a root starts level with it.
pub fn auto_positions(
    graph: &TextureGraph,
    height: impl Fn(usize) -> f32,
    root_y: impl Fn(usize) -> f32,
) -> Vec<Vec2> {
    let mut out = vec![Vec2::ZERO; graph.nodes.len()];
    // The lowest free y of each column.
    let mut free: Vec<f32> = Vec::new();
    let mut roots = 0;
    // The nodes are depth first, parents before children: the parent's y
    // is known when a child is placed.
    for (i, node) in graph.nodes.iter().enumerate() {
        let column = node.path.steps.len();
        let wanted = match node.path.parent() {
            None => {
                roots += 1;
                root_y(roots - 1)
            }
            Some((parent, _)) => graph.node(&parent).map_or(0.0, |p| out[p].y),
        };
        if free.len() <= column {
            free.resize(column + 1, f32::MIN);
        }
        let y = wanted.max(free[column]);
        free[column] = y + height(i) + GAP;
        out[i] = Vec2::new(-COLUMN * (column + 1) as f32, y);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use marbre_core::scene::{Material, Pattern, Texture};

    #[test]
    fn trees_grow_left_and_nodes_never_overlap_in_a_column() {
        let checker = |a, b| Texture::blend(Pattern::Checker { size: 1.0 }, a, b);
        let material = Material {
            diffuse: checker(
                checker(Texture::scalar(0.1), Texture::scalar(0.9)),
                Texture::scalar(0.5),
            ),
            ..Material::default()
        };
        let graph = TextureGraph::of(&material);
        let at = auto_positions(&graph, |_| 100.0, |k| 20.0 * k as f32);
        for (node, p) in graph.nodes.iter().zip(&at) {
            assert_eq!(p.x, -COLUMN * (node.path.steps.len() + 1) as f32);
        }
        for (i, a) in at.iter().enumerate() {
            for b in &at[i + 1..] {
                assert!(a.x != b.x || (a.y - b.y).abs() >= 100.0 + GAP, "{a} {b}");
            }
        }
        // A child starts level with its parent when its column is free.
        let diffuse = graph.node(&"diffuse".parse().unwrap()).unwrap();
        let a = graph.node(&"diffuse.a".parse().unwrap()).unwrap();
        assert_eq!(at[a].y, at[diffuse].y);
        assert_eq!(at[diffuse].y, 0.0);
    }
}
