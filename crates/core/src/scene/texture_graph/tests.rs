use super::*;
use crate::preset::{self, Preset};
use crate::scene::{Layer, MaterialKey, MathOp, PATTERNS, Pattern, PatternKind, Scene, Sphere};
use glam::Vec2;
use proptest::prelude::*;
use std::path::Path;

fn path(text: &str) -> NodePath {
    text.parse().unwrap()
}

fn checker(a: impl Into<Child>, b: impl Into<Child>) -> Texture {
    Texture::blend(
        Pattern::Checker2d {
            size: Vec2::splat(0.25),
            phase: 0.0,
        },
        a,
        b,
    )
}

/// diffuse = checker(marble(red, white), blue), roughness = mix(factor:
/// fbm, 0.2, 0.8), a layer with a mask.
fn material() -> Material {
    let marble = Texture::blend(
        Pattern::fresh(PatternKind::Marble, None),
        Vec3::X,
        Vec3::ONE,
    );
    let fbm = Texture::blend(Pattern::fresh(PatternKind::Fbm, None), 0.0, 1.0);
    Material {
        diffuse: checker(marble, Vec3::Z),
        roughness: Texture::mix(fbm, 0.2, 0.8),
        layers: vec![Layer {
            mask: checker(0.0, 1.0),
            diffuse: Some(Texture::color(Vec3::Y)),
            ..Layer::default()
        }],
        ..Material::default()
    }
}

#[test]
fn paths_print_and_parse_back() {
    for text in [
        "diffuse",
        "bump",
        "diffuse_transmission.a.b.factor",
        "layers[0].mask",
        "layers[3].roughness.b",
    ] {
        assert_eq!(path(text).to_string(), text);
    }
    for bad in [
        "",
        "diffuse.c",
        "colour",
        "layers[x].mask",
        "layers[0]",
        "layers[0].paint",
    ] {
        assert!(bad.parse::<NodePath>().is_err(), "{bad}");
    }
}

#[test]
fn the_graph_has_a_node_per_texture_and_a_link_per_nesting() {
    let m = material();
    let g = TextureGraph::of(&m);
    // 8 properties + bump + mask + the layer's diffuse are roots; the
    // marble, the fbm factor are nested.
    assert_eq!(g.nodes.len(), 13);
    assert_eq!(g.links.len(), 13);
    let diffuse = g.node(&path("diffuse")).unwrap();
    let marble = g.node(&path("diffuse.a")).unwrap();
    assert!(g.links.contains(&Link {
        from: marble,
        to: Input::Node {
            node: diffuse,
            socket: Socket::A
        }
    }));
    assert!(g.links.contains(&Link {
        from: diffuse,
        to: Input::Root(Root::Property(Property::Diffuse))
    }));
    // A value child stays inline; a linked one is a placeholder.
    assert_eq!(g.nodes[diffuse].texture.a, LINKED);
    assert_eq!(g.nodes[diffuse].texture.b, Child::Color(Vec3::Z));
    assert!(g.node(&path("roughness.factor")).is_some());
    assert!(g.node(&path("layers[0].diffuse")).is_some());
    assert!(g.node(&path("layers[0].specular")).is_none());
    assert_eq!(g.apply_to(&m), m);
}

/// An edit made through the graph's path is an edit of the tree, and the
/// graph rebuilt from an edited tree shows the edit.
#[test]
fn graph_edits_are_tree_edits_and_back() {
    let mut m = material();
    let Pattern::Marble {
        stripe_frequency, ..
    } = &mut texture_at_mut(&mut m, &path("diffuse.a")).unwrap().pattern
    else {
        panic!("the diffuse's a is the marble")
    };
    *stripe_frequency = 7.5;
    let Child::Texture(marble) = &m.diffuse.a else {
        panic!("still nested")
    };
    assert!(matches!(
        marble.pattern,
        Pattern::Marble { stripe_frequency, .. } if stripe_frequency == 7.5
    ));

    // The tree edited as the tree panel does: the graph shows it.
    m.diffuse.b = Child::Texture(Box::new(checker(0.1, 0.9)));
    let g = TextureGraph::of(&m);
    let b = g.node(&path("diffuse.b")).unwrap();
    assert_eq!(g.nodes[b].texture, checker(0.1, 0.9));
}

#[test]
fn a_link_moved_onto_a_value_swaps_the_value_in() {
    let mut m = material();
    let mut layout = MaterialLayout::default();
    layout.set(&path("diffuse.a"), Vec2::new(-300.0, 10.0));
    let marble = texture_at(&m, &path("diffuse.a")).unwrap().clone();
    move_subtree(&mut m, &mut layout, &path("diffuse.a"), &path("diffuse.b")).unwrap();
    assert_eq!(m.diffuse.a, Child::Color(Vec3::Z));
    assert_eq!(m.diffuse.b, Child::Texture(Box::new(marble)));
    assert_eq!(
        layout.position(&path("diffuse.b")),
        Some(Vec2::new(-300.0, 10.0))
    );
    assert_eq!(layout.position(&path("diffuse.a")), None);
}

#[test]
fn a_link_moved_onto_a_texture_swaps_the_subtrees() {
    let mut m = material();
    let mut layout = MaterialLayout::default();
    layout.set(&path("roughness"), Vec2::new(1.0, 1.0));
    layout.set(&path("roughness.factor"), Vec2::new(2.0, 2.0));
    layout.set(&path("diffuse.a"), Vec2::new(3.0, 3.0));
    let (marble, mix) = (m.diffuse.a.texture().unwrap().clone(), m.roughness.clone());
    move_subtree(&mut m, &mut layout, &path("diffuse.a"), &path("roughness")).unwrap();
    assert_eq!(m.roughness, marble);
    assert_eq!(m.diffuse.a, Child::Texture(Box::new(mix)));
    assert_eq!(layout.position(&path("roughness")), Some(Vec2::splat(3.0)));
    assert_eq!(layout.position(&path("diffuse.a")), Some(Vec2::ONE));
    assert_eq!(
        layout.position(&path("diffuse.a.factor")),
        Some(Vec2::splat(2.0))
    );
}

/// Linked to an input of a texture it is nested in, the subtree replaces
/// that texture (Blender's link past intermediate nodes).
#[test]
fn a_link_moved_up_replaces_the_ancestor() {
    let mut m = material();
    let marble = m.diffuse.a.texture().unwrap().clone();
    move_subtree(
        &mut m,
        &mut MaterialLayout::default(),
        &path("diffuse.a"),
        &path("diffuse"),
    )
    .unwrap();
    assert_eq!(m.diffuse, marble);
}

#[test]
fn refused_links_leave_the_tree() {
    let before = material();
    let mut m = before.clone();
    let mut layout = MaterialLayout::default();
    let refused = [
        ("diffuse", "diffuse.a", GraphEditError::IntoItself),
        (
            "diffuse.b",
            "roughness",
            GraphEditError::NoNode("diffuse.b".into()),
        ),
        ("diffuse.a", "diffuse.a.a.a", GraphEditError::IntoItself),
        (
            "diffuse.a",
            "layers[0].specular",
            GraphEditError::NoInput("layers[0].specular".into()),
        ),
        (
            "diffuse.a",
            "specular.factor",
            GraphEditError::NoInput("specular.factor".into()),
        ),
    ];
    for (from, to, error) in refused {
        assert_eq!(
            move_subtree(&mut m, &mut layout, &path(from), &path(to)),
            Err(error),
            "{from} → {to}"
        );
        assert_eq!(m, before);
    }
}

#[test]
fn a_link_that_nests_too_deep_is_refused() {
    let mut deep = Texture::scalar(0.5);
    for _ in 1..Texture::MAX_DEPTH {
        deep = checker(deep, 1.0);
    }
    let mut m = Material {
        roughness: deep,
        bump: checker(0.0, 1.0),
        ..Material::default()
    };
    let before = m.clone();
    let err = move_subtree(
        &mut m,
        &mut MaterialLayout::default(),
        &path("roughness"),
        &path("bump.a"),
    );
    assert_eq!(err, Err(GraphEditError::TooDeep));
    assert_eq!(m, before);
}

#[test]
fn a_detached_link_leaves_the_value_at_the_origin() {
    let mut m = material();
    let mut layout = MaterialLayout::default();
    layout.set(&path("diffuse.a"), Vec2::ONE);
    let at_origin = m.diffuse.a.texture().unwrap().eval(Vec3::ZERO, Vec2::ZERO);
    detach(&mut m, &mut layout, &path("diffuse.a")).unwrap();
    assert_eq!(m.diffuse.a, Child::Color(at_origin));
    assert!(layout.is_empty());
    // A factor is a texture socket: it keeps a constant node, scalar.
    let factor = m
        .roughness
        .factor
        .as_deref()
        .unwrap()
        .eval(Vec3::ZERO, Vec2::ZERO);
    detach(&mut m, &mut layout, &path("roughness.factor")).unwrap();
    assert_eq!(
        m.roughness.factor.as_deref(),
        Some(&Texture::scalar(factor.x))
    );
    assert_eq!(
        detach(&mut m, &mut layout, &path("diffuse.b")),
        Err(GraphEditError::NoNode("diffuse.b".into()))
    );
}

#[test]
fn the_layout_round_trips_through_a_preset_and_is_not_traced() {
    let mut scene = Scene {
        spheres: vec![Sphere::default()],
        ..Scene::default()
    };
    let (_, layout) = scene
        .material_and_layout_mut(MaterialKey::Sphere(0))
        .unwrap();
    layout.edit(MaterialKey::Sphere(0), |l| {
        l.set(&path("diffuse"), Vec2::new(-250.0, 40.5))
    });
    let preset = Preset {
        scene: scene.clone(),
        ..Preset::default()
    };
    let text = preset::to_text(&preset, Path::new("g.ron")).unwrap();
    assert!(text.contains("graph_layout"), "{text}");
    let back = preset::parse(&text, Path::new("g.ron")).unwrap();
    assert_eq!(back.preset.scene, scene);
    assert!(back.notes.is_empty(), "{:?}", back.notes);
    let unlaid = Scene {
        graph_layout: Default::default(),
        ..scene.clone()
    };
    assert_eq!(
        scene.changes_from(&unlaid),
        crate::scene::Change::ANNOTATIONS,
        "the layout is saved but not traced"
    );
    assert_ne!(
        scene,
        Scene {
            graph_layout: Default::default(),
            ..scene.clone()
        }
    );
}

#[test]
fn a_preset_without_a_layout_reads_an_empty_one() {
    let text = preset::to_text(&Preset::default(), Path::new("old.ron")).unwrap();
    assert!(!text.contains("graph_layout"));
    let back = preset::parse(
        "(format_version: 2, scene: (spheres: [()]))",
        Path::new("old.ron"),
    )
    .unwrap();
    assert!(back.preset.scene.graph_layout.is_empty());
    assert!(back.notes.is_empty(), "{:?}", back.notes);
}

fn value() -> impl Strategy<Value = Child> {
    prop_oneof![
        (0.0f32..=1.0).prop_map(Child::Scalar),
        (0.0f32..=1.0, 0.0f32..=1.0, 0.0f32..=1.0)
            .prop_map(|(r, g, b)| Child::Color(Vec3::new(r, g, b))),
    ]
}

/// A random tree: any pattern with its default parameters, value or
/// texture children, a factor under a mix, math steps.
fn tree() -> impl Strategy<Value = Texture> {
    let leaf = (0..PATTERNS.len(), value(), value()).prop_map(|(i, a, b)| {
        let pattern = Pattern::fresh(PATTERNS[i].kind, None);
        let factor = (pattern == Pattern::Mix).then(|| Box::new(Texture::scalar(0.5)));
        Texture {
            factor,
            ..Texture::blend(pattern, a, b)
        }
    });
    leaf.prop_recursive(4, 24, 3, |inner| {
        let child = prop_oneof![value(), inner.clone().prop_map(Child::from)];
        (
            0..PATTERNS.len(),
            child.clone(),
            child,
            inner,
            proptest::collection::vec(0..MathOp::NAMES.len(), 0..3),
        )
            .prop_map(|(i, a, b, factor, ops)| {
                let pattern = Pattern::fresh(PATTERNS[i].kind, None);
                Texture {
                    factor: (pattern == Pattern::Mix).then(|| Box::new(factor)),
                    ops: ops.into_iter().map(MathOp::with_index).collect(),
                    ..Texture::blend(pattern, a, b)
                }
            })
    })
}

proptest! {
    #[test]
    fn tree_to_graph_to_tree_is_the_identity(
        diffuse in tree(),
        bump in tree(),
        mask in tree(),
        layer_roughness in proptest::option::of(tree()),
    ) {
        let m = Material {
            diffuse,
            bump,
            layers: vec![Layer {
                mask,
                roughness: layer_roughness,
                ..Layer::default()
            }],
            ..Material::default()
        };
        let g = TextureGraph::of(&m);
        prop_assert_eq!(g.apply_to(&m), m.clone());
        // Every node's path leads to its texture, its own settings equal.
        for node in &g.nodes {
            let t = texture_at(&m, &node.path).unwrap();
            prop_assert_eq!(node.texture.pattern, t.pattern);
            prop_assert_eq!(&node.texture.ops, &t.ops);
        }
    }
}

/// A node added on a linked input takes the subtree there as its `a`
/// (nothing is lost), with a contrasting `b`, and the positions below
/// move one level down with it.
#[test]
fn an_added_node_nests_what_its_input_held() {
    let mut m = material();
    let mut layout = MaterialLayout::default();
    layout.set(&path("diffuse.a"), Vec2::new(-600.0, 0.0));
    let marble = m.diffuse.a.clone();
    add_node(&mut m, &mut layout, &path("diffuse.a"), PatternKind::Waves).unwrap();
    let added = texture_at(&m, &path("diffuse.a")).unwrap();
    assert_eq!(added.pattern.kind(), PatternKind::Waves);
    assert_eq!(added.a, marble);
    assert!(matches!(added.b, Child::Color(_)), "{:?}", added.b);
    assert_eq!(
        layout.position(&path("diffuse.a.a")),
        Some(Vec2::new(-600.0, 0.0))
    );
    assert_eq!(layout.position(&path("diffuse.a")), None);
    // The rest of the tree is as it was.
    assert_eq!(m.diffuse.b, Child::Color(Vec3::Z));
    assert_eq!(m.roughness, material().roughness);
}

/// On a value input the value becomes the new node's `a`; on a root the
/// property's whole tree does.
#[test]
fn an_added_node_on_a_value_or_a_root_keeps_it() {
    let mut m = material();
    let mut layout = MaterialLayout::default();
    add_node(
        &mut m,
        &mut layout,
        &path("diffuse.b"),
        PatternKind::Checker,
    )
    .unwrap();
    let added = texture_at(&m, &path("diffuse.b")).unwrap();
    assert_eq!(added.a, Child::Color(Vec3::Z));
    assert_ne!(added.b, added.a);
    let roughness = m.roughness.clone();
    add_node(&mut m, &mut layout, &path("roughness"), PatternKind::Fbm).unwrap();
    assert_eq!(m.roughness.a, Child::Texture(Box::new(roughness)));
}

#[test]
fn an_added_node_is_refused_past_the_depth_limit_or_on_no_input() {
    let before = material();
    let mut m = before.clone();
    let mut layout = MaterialLayout::default();
    let mut deep = path("diffuse");
    for _ in 0..Texture::MAX_DEPTH {
        deep = deep.child(Socket::A);
    }
    assert_eq!(
        add_node(&mut m, &mut layout, &deep, PatternKind::Fbm),
        Err(GraphEditError::NoInput(deep.to_string()))
    );
    // Nest until the limit refuses, then the tree holds at the limit.
    let mut refused = None;
    for _ in 0..=Texture::MAX_DEPTH {
        if let Err(e) = add_node(&mut m, &mut layout, &path("diffuse"), PatternKind::Fbm) {
            refused = Some(e);
            break;
        }
    }
    assert_eq!(refused, Some(GraphEditError::TooDeep));
    assert_eq!(m.diffuse.depth(), Texture::MAX_DEPTH);
}

/// A duplicate is a copy: the original stays, the input it lands on
/// holds an equal subtree, and that input's old positions are forgotten.
#[test]
fn a_duplicate_copies_the_subtree_onto_the_input() {
    let mut m = material();
    let mut layout = MaterialLayout::default();
    layout.set(&path("roughness.factor"), Vec2::new(5.0, 5.0));
    let marble = texture_at(&m, &path("diffuse.a")).unwrap().clone();
    duplicate(&mut m, &mut layout, &path("diffuse.a"), &path("roughness")).unwrap();
    assert_eq!(texture_at(&m, &path("diffuse.a")), Some(&marble));
    assert_eq!(m.roughness, marble);
    assert_eq!(layout.position(&path("roughness.factor")), None);
    assert_eq!(
        duplicate(&mut m, &mut layout, &path("diffuse.b"), &path("roughness")),
        Err(GraphEditError::NoNode("diffuse.b".into()))
    );
}
