//! The TX module's unit tests: malformed texts refused where they go
//! wrong, printing and parsing random trees, and raising what lowering
//! makes.

use super::*;
use crate::scene::{Child, ColorEncoding, MathOp, Pattern, Texture};
use glam::{Vec2, Vec3};
use proptest::prelude::*;

/// (text, line, column, a phrase the expectation holds).
const MALFORMED: &[(&str, usize, usize, &str)] = &[
    ("", 1, 1, "a texture"),
    ("TX", 1, 3, "a texture"),
    ("TX FOO FTX", 1, 4, "a texture (UNI, QUAD"),
    ("TX uni FTX", 1, 4, "a texture"),
    ("QUAD 0.5 UNI FTX FTX", 1, 6, "a texture"),
    ("QUAD UNI FTX FTX", 1, 14, "a texture"),
    (
        "QUAD UNI CD 1 0 0 UNI CD 0 0 1 FTX FTX",
        1,
        19,
        "FTX closing UNI",
    ),
    (
        "QUAD UNI FTX UNI FTX GU 0.25 GV 0.25",
        1,
        37,
        "FTX closing QUAD",
    ),
    (
        "TX\nQUAD\n  UNI CD 1 0 0\n  UNI FTX\nFTX",
        4,
        3,
        "FTX closing UNI",
    ),
    ("UNI CD 0.5 0.5 FTX", 1, 16, "third of three"),
    ("UNI CD FTX", 1, 8, "CD's colour, first of three"),
    ("UNI CD 1 1 inf FTX", 1, 12, "a number"),
    ("UNI CD 1 1 1 CD 0 0 0 FTX", 1, 14, "each coefficient once"),
    ("UNI CD 1 1 1 FTX FTX", 1, 18, "the end of the text"),
    ("UNI CX 1 1 1 FTX", 1, 5, "FTX closing UNI"),
    ("QUAD UNI FTX UNI FTX GU FTX", 1, 25, "QUAD's GU"),
    (
        "QUAD UNI FTX UNI FTX GU 1 GU 2 FTX",
        1,
        27,
        "each parameter of QUAD once",
    ),
    ("MULT FTX", 1, 6, "a texture"),
    ("IMAGE CD 1 1 1 FTX", 1, 7, "file name"),
    ("IMAGE 12 FTX", 1, 7, "file name"),
    ("DECOUPAGE UNI FTX UNI FTX RAYON 0.4 FTX", 1, 37, "NBCOTE"),
    (
        "DECOUPAGE UNI FTX UNI FTX NBCOTE 2.5 FTX",
        1,
        27,
        "whole number",
    ),
    (
        "DECOUPAGE UNI FTX UNI FTX NBCOTE -1 FTX",
        1,
        27,
        "whole number",
    ),
    // Not echoed as the f32 it reads as (16777216).
    (
        "DECOUPAGE UNI FTX UNI FTX NBCOTE 16777217 FTX",
        1,
        27,
        "0 to 1000000",
    ),
    ("NOISE FREQ 1 AMPL 1 FTX", 1, 7, "CD1"),
    ("NOISE CD1 1 1 1 FREQ 1 FTX", 1, 24, "AMPL"),
    ("TURBULENCE CD1 1 1 1 AMPL 1", 1, 28, "FREQ"),
    ("BOIS PALE 1 1 1 FONCE 0 0 0 FTX", 1, 6, "FONCE"),
    ("BOIS FONCE 1 1 1 FTX", 1, 18, "PALE"),
    (
        "MARBRE CD1 1 1 1 CD2 0 0 0 FREQ 1 TURB 15 FTX",
        1,
        43,
        "FREQTURB",
    ),
    (
        "MARBRE CD2 0 0 0 CD1 1 1 1 FREQ 1 TURB 1 FREQTURB 1 FTX",
        1,
        8,
        "CD1",
    ),
    ("BRIQUE UNI FTX UNI FTX FTX", 1, 24, "the brick's width"),
    (
        "BRIQUE UNI FTX UNI FTX 0.1 0.1 0.1 FTX",
        1,
        32,
        "FTX closing BRIQUE",
    ),
    ("VAGUE 3 FTX", 1, 9, "amplitude"),
    ("VAGUE FTX", 1, 7, "frequency"),
    ("TUILE DPENTE 0.01 NIV3D 0.4 UNI FTX FTX", 1, 29, "DMORTIER"),
    (
        "TUILE DMORTIER 0.02 DPENTE 0.01 NIV3D 0.4 UNI FTX CD 1 1 FTX",
        1,
        58,
        "third of three",
    ),
    (
        "ATX 0 0 0 1 0 0 0 1 0 TX UNI FTX",
        1,
        23,
        "FATX closing ATX",
    ),
    ("ATX 0 0 0 1 0 0 TX UNI FTX", 1, 17, "the v vector of ATX"),
    (
        "APTX 0 0 0 1 0 0 0 1 0 FATX UNI FTX",
        1,
        24,
        "FAPTX closing APTX",
    ),
    (
        "ATX3D 0 0 0 1 0 0 0 1 0 FATX3D ATX3D 0 0 0 1 0 0 0 1 0 FATX3D UNI FTX",
        1,
        32,
        "each frame once",
    ),
    (
        "UNI FTX ATX 0 0 0 1 0 0 0 1 0 FATX",
        1,
        9,
        "the end of the text",
    ),
];

#[test]
fn malformed_texts_are_refused_where_they_go_wrong() {
    for &(text, line, column, phrase) in MALFORMED {
        match parse(text) {
            Err(TxError::Syntax {
                line: l,
                column: c,
                expected,
                found,
            }) => {
                assert_eq!(
                    (l, c),
                    (line, column),
                    "{text:?}: expected {expected}, found {found}"
                );
                assert!(expected.contains(phrase), "{text:?}: expected {expected}");
            }
            other => panic!("{text:?} gave {other:?}"),
        }
    }
}

#[test]
fn deep_nesting_is_refused_not_overflowed() {
    let text = format!("{}UNI FTX{}", "MULT ".repeat(10_000), " FTX".repeat(10_000));
    let e = parse(&text).unwrap_err();
    assert!(e.to_string().contains("at most 64 nested"), "{e}");
}

/// Issue 28's text: MULT layers of a tile whose centre is a cutout, each
/// holding the layer below twice and two levels deeper.
const LAYERS_HEAD: &str = "MULT UNI CD .5 .5 .5 FTX ";
const LAYER: &str =
    "TUILE DMORTIER 0.1 DPENTE 0 NIV3D 0 DECOUPAGE UNI CD 1 1 1 FTX UNI FTX NBCOTE 3 FTX FTX ";

fn layers(n: usize) -> String {
    format!("{LAYERS_HEAD}{}FTX", LAYER.repeat(n))
}

/// Each layer used to double the lowered tree, and its depth was checked
/// once the tree was whole: 22 layers took 3 GB, 40 would take 2^40 nodes.
/// Now no node deeper than a material holds is made: the fourth layer's
/// DECOUPAGE (depth 7) is refused where it is written, whatever follows.
#[test]
fn a_text_nesting_deeper_than_a_material_is_refused_where_it_goes_too_deep() {
    let base = crate::scene::Material::default();
    let fourth = LAYERS_HEAD.len() + 3 * LAYER.len() + LAYER.find("DECOUPAGE").unwrap() + 1;
    let message = "DECOUPAGE would nest the diffuse texture 7 deep; \
                   a material's textures nest at most 6 deep";
    assert_eq!(Texture::MAX_DEPTH, 6, "the message above names the limit");
    for n in [4, 22, 40] {
        let doc = parse(&layers(n)).unwrap();
        let want = TxError::LowerAt {
            line: 1,
            column: fourth,
            message: message.into(),
        };
        assert_eq!(
            lower_document(&doc, &base, Path::new("")).unwrap_err(),
            want,
            "{n} layers"
        );
        let mut m = base.clone();
        let e = apply_to_property(&mut m, Property::Diffuse, &layers(n), Path::new(""));
        assert_eq!(e.unwrap_err(), want, "{n} layers");
        assert_eq!(m, base);
    }
    assert_eq!(
        TxError::LowerAt {
            line: 1,
            column: fourth,
            message: message.into()
        }
        .to_string(),
        format!("TX line 1, column {fourth}: {message}")
    );
    // Three layers make a tree of exactly the depth a material holds.
    let three = lower_document(&parse(&layers(3)).unwrap(), &base, Path::new("")).unwrap();
    assert_eq!(three.material.diffuse.depth(), Texture::MAX_DEPTH);
    // A layer that would be too deep but that a later layer covers whole
    // is not in the tree: the text lowers, as it always did.
    let covered = format!("MULT {} UNI CD 1 0 0 FTX FTX", LAYER.repeat(22));
    let m = lower_document(&parse(&covered).unwrap(), &base, Path::new("")).unwrap();
    assert_eq!(m.material.diffuse, Texture::color(Vec3::X));
    // A document built in code, not read from text, has no place to name.
    let built = Document::new(parse(&layers(4)).unwrap().texture);
    let e = lower_document(&built, &base, Path::new(""));
    assert_eq!(e.unwrap_err(), TxError::Lower(message.into()));
}

/// A word of the text is echoed in messages with its control characters
/// escaped (a text must not clear the terminal that shows its error), its
/// accents as written.
#[test]
fn control_characters_in_a_text_are_escaped_in_its_messages() {
    let e = parse("UNI CD 1 1 1 \x1b[2J FTX").unwrap_err();
    let TxError::Syntax { found, .. } = &e else {
        panic!("{e:?}")
    };
    assert_eq!(found, "`\\u{1b}[2J`");
    let e = parse("UNI CD 1 1 1 Pâté FTX").unwrap_err();
    assert!(e.to_string().ends_with("found `Pâté`"), "{e}");
    let mut m = crate::scene::Material::default();
    let e = apply_to_property(
        &mut m,
        Property::Diffuse,
        "IMAGE \x1b]0;owned\x07é.ppm CD 1 0 0 FTX",
        Path::new(""),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("TX: IMAGE \\u{1b}]0;owned\\u{7}é.ppm: CD 1 0 0 is not a grey"),
        "{e}"
    );
    assert!(!e.chars().any(char::is_control), "{e:?}");
}

#[test]
fn the_grammar_order_of_tuile_and_one_brick_size_are_read_too() {
    let grammar =
        parse("TUILE DMORTIER 0.02 DPENTE 0.01 NIV3D 0.4 CD 1 1 1 UNI CD 0 0 0 FTX FTX").unwrap();
    let examples =
        parse("TUILE NIV3D 0.4 DPENTE 0.01 DMORTIER 0.02 UNI CD 0 0 0 FTX CD 1 1 1 FTX").unwrap();
    assert_eq!(grammar, examples);
    assert!(
        print(&grammar).contains("UNI CD 0 0 0 FTX\n  CD 1 1 1\nFTX"),
        "{}",
        print(&grammar)
    );
    let one = parse("BRIQUE UNI CD 1 0 0 FTX UNI FTX 0.2 FTX").unwrap();
    let m = lower_document(&one, &crate::scene::Material::default(), Path::new("")).unwrap();
    match m.material.diffuse.pattern {
        Pattern::Brick { size, .. } => assert_eq!(size, glam::Vec2::splat(0.2)),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_typed_tx_colour_lowers_to_its_linear_value() {
    let doc = parse("UNI CD 0.54 0.27 0.0742 FTX").unwrap();
    let base = crate::scene::Material::default();
    let t = lower_channel(
        &doc,
        Channel::Diffuse,
        &base.diffuse,
        Path::new(""),
        Colors::Linear,
    )
    .unwrap();
    let eotf = |c: f64| ((c + 0.055) / 1.055).powf(2.4);
    let want = Vec3::new(eotf(0.54) as f32, eotf(0.27) as f32, eotf(0.0742) as f32);
    let Some(Child::Color(got)) = t.as_constant() else {
        panic!("{t:?}")
    };
    assert!((*got - want).abs().max_element() < 1e-6, "{got} vs {want}");
    // As typed, for a preset that decodes its colours itself.
    let kept = lower_channel(
        &doc,
        Channel::Diffuse,
        &base.diffuse,
        Path::new(""),
        Colors::AsTyped,
    )
    .unwrap();
    assert_eq!(kept, Texture::color(Vec3::new(0.54, 0.27, 0.0742)));
}

/// Colours beyond 1 are clamped alike once the scene is sanitised: `CD 2`,
/// `CD 1e15` and `CD 1e20` (whose sRGB decoding overflows to infinity,
/// once made black) all render white, each with a note.
#[test]
fn large_tx_colours_all_clamp_to_white() {
    for text in [
        "UNI CD 2 2 2 FTX",
        "UNI CD 1e15 1e15 1e15 FTX",
        "UNI CD 1e20 1e20 1e20 FTX",
    ] {
        let doc = parse(text).unwrap();
        let base = crate::scene::Material::default();
        let mut t = lower_channel(
            &doc,
            Channel::Diffuse,
            &base.diffuse,
            Path::new(""),
            Colors::Linear,
        )
        .unwrap();
        let mut notes = Vec::new();
        t.sanitize("diffuse", &mut notes, 1);
        assert_eq!(t.eval(Vec3::ZERO, glam::Vec2::ZERO), Vec3::ONE, "{text}");
        assert!(!notes.is_empty(), "{text}: clamped without a note");
    }
}

/// A text saved with a byte-order mark reads as the same text.
#[test]
fn a_byte_order_mark_is_not_part_of_the_text() {
    let plain = "UNI CD 1 0 0 FTX";
    assert_eq!(
        parse(&format!("\u{feff}{plain}")).unwrap(),
        parse(plain).unwrap()
    );
}

#[test]
fn ct_splits_into_opacity_and_a_normalised_tint() {
    let mut m = crate::scene::Material::default();
    apply_to_property(
        &mut m,
        Property::Opacity,
        "UNI CT 0.5 0.25 0 FTX",
        Path::new(""),
    )
    .unwrap();
    let c = ColorEncoding::Srgb.decode(Vec3::new(0.5, 0.25, 0.0));
    assert_eq!(m.opacity, Texture::scalar(1.0 - c.x));
    assert_eq!(m.transmission, Texture::color(c / c.x));
    // What passes is the typed coefficient.
    let passing = m.transmission.eval(Vec3::ZERO, glam::Vec2::ZERO)
        * (1.0 - m.opacity.eval(Vec3::ZERO, glam::Vec2::ZERO).x);
    assert!((passing - c).abs().max_element() < 1e-6);
    let raised = raise_property(&m, Property::Transmission).unwrap();
    let Tex::Uni(attrs) = parse(&raised).unwrap().texture else {
        panic!("{raised}")
    };
    let typed = Vec3::from(attrs.get(Attr::Ct).unwrap());
    assert!(
        (typed - Vec3::new(0.5, 0.25, 0.0)).abs().max_element() < 1e-6,
        "{raised}"
    );
}

#[test]
fn errors_leave_the_material_untouched_and_name_what_has_no_form() {
    let mut m = crate::scene::Material::default();
    let before = m.clone();
    for text in [
        "UNI CD 1 1 FTX",
        "IMAGE a.ppm CD 1 0 0 FTX",
        "ATX 0 0 0 1 0 0 0 1 0 FATX UNI CD 1 1 1 FTX",
        "QUAD UNI FTX UNI CD 1 1 1 FTX GU 0 FTX",
    ] {
        assert!(
            apply_to_property(&mut m, Property::Diffuse, text, Path::new("")).is_err(),
            "{text}"
        );
        assert_eq!(m, before, "{text}");
    }
    assert!(apply_to_property(&mut m, Property::Roughness, "UNI FTX", Path::new("")).is_err());
    let cases: [(Texture, &str); 4] = [
        (
            Texture::blend(Pattern::Checker { size: 1.0 }, 0.0, 1.0),
            "checker 3D",
        ),
        (
            Texture {
                ops: vec![MathOp::Invert],
                ..Texture::blend(
                    Pattern::Cutout {
                        sides: 3,
                        radius: 0.4,
                    },
                    0.0,
                    1.0,
                )
            },
            "math step",
        ),
        (
            Texture::blend(
                Pattern::Fbm {
                    noise: Default::default(),
                },
                Vec3::ZERO,
                Vec3::ONE,
            ),
            "noise differs from NOISE",
        ),
        (Texture::mix(Texture::scalar(0.5), 0.0, 1.0), "mix"),
    ];
    for (texture, phrase) in cases {
        let m = crate::scene::Material {
            diffuse: texture,
            ..Default::default()
        };
        let e = raise_property(&m, Property::Diffuse)
            .unwrap_err()
            .to_string();
        assert!(e.contains(phrase) && e.contains("no TX form"), "{e}");
    }
    let e = raise_property(&crate::scene::Material::default(), Property::Emission).unwrap_err();
    assert!(
        e.to_string().contains("emission has no TX coefficient"),
        "{e}"
    );
}

/// A MULT layer whose texture varies, seen through a later QUAD's cell,
/// keeps the surface's coordinates (N3D computed it at the surface point).
#[test]
fn a_layer_below_a_cell_is_read_in_the_surface_space() {
    let doc = parse("MULT QUAD UNI CD 1 0 0 FTX UNI CD 0 0 1 FTX GU 0.1 GV 0.1 FTX QUAD UNI FTX UNI CD 0 1 0 FTX GU 0.5 GV 0.5 FTX FTX").unwrap();
    let m = lower_document(&doc, &crate::scene::Material::default(), Path::new(""))
        .unwrap()
        .material;
    let direct = parse("QUAD UNI CD 1 0 0 FTX UNI CD 0 0 1 FTX GU 0.1 GV 0.1 FTX").unwrap();
    let below = lower_document(&direct, &crate::scene::Material::default(), Path::new(""))
        .unwrap()
        .material;
    for (u, v) in [(0.05, 0.05), (0.15, 0.05), (0.25, 0.35), (0.45, 0.15)] {
        let uv = glam::Vec2::new(u, v);
        // Even cells of the 2 × 2 board show the first layer as it was.
        assert_eq!(
            m.diffuse.eval(Vec3::ZERO, uv),
            below.diffuse.eval(Vec3::ZERO, uv),
            "{uv}"
        );
    }
    assert_eq!(
        m.diffuse.eval(Vec3::ZERO, glam::Vec2::new(0.75, 0.25)),
        Vec3::Y
    );
}

fn number() -> impl Strategy<Value = f32> {
    prop_oneof![
        any::<f32>().prop_filter("finite", |x| x.is_finite()),
        (-1000i32..1000).prop_map(|i| i as f32 / 100.0),
    ]
}

fn rgb() -> impl Strategy<Value = Rgb> {
    [number(), number(), number()]
}

fn attrs() -> impl Strategy<Value = Attrs> {
    proptest::sample::subsequence(Attr::ALL.to_vec(), 0..=5)
        .prop_flat_map(|keys| {
            let n = keys.len();
            (Just(keys), proptest::collection::vec(rgb(), n))
        })
        .prop_map(|(keys, colours)| Attrs(keys.into_iter().zip(colours).collect()))
}

fn leaf() -> impl Strategy<Value = Tex> {
    prop_oneof![
        attrs().prop_map(Tex::Uni),
        ("[a-z]{1,8}\\.ppm", attrs()).prop_map(|(file, attrs)| Tex::Image { file, attrs }),
        (rgb(), number(), number()).prop_map(|(color, frequency, amplitude)| Tex::Noise {
            color,
            frequency,
            amplitude
        }),
        (rgb(), number(), number()).prop_map(|(color, frequency, amplitude)| Tex::Turbulence {
            color,
            frequency,
            amplitude
        }),
        (
            rgb(),
            rgb(),
            proptest::option::of(number()),
            proptest::option::of(number())
        )
            .prop_map(|(dark, pale, ring_width, turbulence)| Tex::Bois {
                dark,
                pale,
                ring_width,
                turbulence
            }),
        (rgb(), rgb(), number(), number(), number()).prop_map(
            |(dominant, veins, frequency, turbulence, turbulence_frequency)| Tex::Marbre {
                dominant,
                veins,
                frequency,
                turbulence,
                turbulence_frequency
            }
        ),
        (number(), number()).prop_map(|(frequency, amplitude)| Tex::Vague {
            frequency,
            amplitude
        }),
    ]
}

fn texture() -> impl Strategy<Value = Tex> {
    leaf().prop_recursive(4, 24, 4, |inner| {
        let boxed = inner.clone().prop_map(Box::new);
        prop_oneof![
            (
                boxed.clone(),
                boxed.clone(),
                proptest::option::of(number()),
                proptest::option::of(number()),
                proptest::option::of(number())
            )
                .prop_map(|(even, odd, gu, gv, phase)| Tex::Quad {
                    even,
                    odd,
                    gu,
                    gv,
                    phase
                }),
            (number(), number(), number(), boxed.clone(), attrs()).prop_map(
                |(m, s, l, centre, mortar)| Tex::Tuile {
                    mortar_half_width: m,
                    slope_width: s,
                    level: l,
                    centre,
                    mortar
                }
            ),
            proptest::collection::vec(inner, 1..4).prop_map(Tex::Mult),
            (
                boxed.clone(),
                boxed.clone(),
                0u32..12,
                proptest::option::of(number())
            )
                .prop_map(|(inside, outside, sides, radius)| Tex::Decoupage {
                    inside,
                    outside,
                    sides,
                    radius
                }),
            (
                boxed.clone(),
                boxed,
                number(),
                proptest::option::of(number())
            )
                .prop_map(|(brick, mortar, size_u, size_v)| Tex::Brique {
                    brick,
                    mortar,
                    size_u,
                    size_v
                }),
        ]
    })
}

fn frame() -> impl Strategy<Value = Option<Frame>> {
    proptest::option::of((rgb(), rgb(), rgb()).prop_map(|(origin, u, v)| Frame { origin, u, v }))
}

fn document() -> impl Strategy<Value = Document> {
    (frame(), frame(), frame(), texture()).prop_map(
        |(polygon_frame, plane_frame, space_frame, texture)| Document {
            polygon_frame,
            plane_frame,
            space_frame,
            ..Document::new(texture)
        },
    )
}

/// A texture whose lowering succeeds: colours and levels in range, sizes
/// positive.
fn lowerable() -> impl Strategy<Value = Tex> {
    let unit = || (0u8..=10).prop_map(|i| f32::from(i) / 10.0);
    let colour = move || [unit(), unit(), unit()];
    let size = || (1u8..=8).prop_map(|i| f32::from(i) / 8.0);
    let attrs = move || {
        proptest::sample::subsequence(
            vec![Attr::Cd, Attr::Cs, Attr::Cr, Attr::Ct, Attr::Td],
            0..=3,
        )
        .prop_flat_map(move |keys| {
            let n = keys.len();
            (Just(keys), proptest::collection::vec(colour(), n))
        })
        .prop_map(|(keys, colours)| Attrs(keys.into_iter().zip(colours).collect()))
    };
    let leaf = prop_oneof![
        attrs().prop_map(Tex::Uni),
        (colour(), size(), unit()).prop_map(|(color, frequency, amplitude)| Tex::Noise {
            color,
            frequency,
            amplitude
        }),
        (colour(), size(), unit()).prop_map(|(color, frequency, amplitude)| Tex::Turbulence {
            color,
            frequency,
            amplitude
        }),
        (colour(), colour(), size()).prop_map(|(dark, pale, r)| Tex::Bois {
            dark,
            pale,
            ring_width: Some(r),
            turbulence: None
        }),
        (colour(), colour(), size(), size(), size()).prop_map(
            |(dominant, veins, frequency, turbulence, turbulence_frequency)| Tex::Marbre {
                dominant,
                veins,
                frequency,
                turbulence,
                turbulence_frequency
            }
        ),
        (unit(), size()).prop_map(|(grey, _)| Tex::Image {
            file: "a.ppm".into(),
            attrs: Attrs(vec![(Attr::Cd, [grey; 3]), (Attr::Cs, [grey; 3])])
        }),
        (size(), unit()).prop_map(|(frequency, amplitude)| Tex::Vague {
            frequency,
            amplitude
        }),
    ];
    leaf.prop_recursive(3, 12, 3, move |inner| {
        let boxed = inner.clone().prop_map(Box::new);
        prop_oneof![
            (
                boxed.clone(),
                boxed.clone(),
                proptest::option::of(size()),
                proptest::option::of(size()),
                proptest::option::of(unit())
            )
                .prop_map(|(even, odd, gu, gv, phase)| Tex::Quad {
                    even,
                    odd,
                    gu,
                    gv,
                    phase
                }),
            (size(), size(), unit(), boxed.clone(), attrs()).prop_map(
                |(m, s, l, centre, mortar)| Tex::Tuile {
                    mortar_half_width: m / 10.0,
                    slope_width: s / 10.0,
                    level: l,
                    centre,
                    mortar
                }
            ),
            proptest::collection::vec(inner, 1..3).prop_map(Tex::Mult),
            (
                boxed.clone(),
                boxed.clone(),
                0u32..8,
                proptest::option::of(unit())
            )
                .prop_map(|(inside, outside, sides, radius)| Tex::Decoupage {
                    inside,
                    outside,
                    sides,
                    radius
                }),
            (boxed.clone(), boxed, size(), proptest::option::of(size())).prop_map(
                |(brick, mortar, size_u, size_v)| Tex::Brique {
                    brick,
                    mortar,
                    size_u,
                    size_v
                }
            ),
        ]
    })
}

/// The same structure, values within 1e-5 (the sRGB round trip).
fn approx_same(a: &Texture, b: &Texture) -> bool {
    fn split(t: &Texture) -> (Texture, Vec<f32>) {
        let mut values = Vec::new();
        let mut shape = t.clone();
        shape.visit_mut(&mut |n| {
            for c in [&mut n.a, &mut n.b] {
                match c {
                    Child::Scalar(s) => values.push(std::mem::take(s)),
                    Child::Color(c) => values.extend(std::mem::take(c).to_array()),
                    Child::Texture(_) => {}
                }
            }
            for op in &mut n.ops {
                if let MathOp::Scale(k) = op {
                    values.push(std::mem::take(k));
                }
            }
        });
        (shape, values)
    }
    let ((sa, va), (sb, vb)) = (split(a), split(b));
    sa == sb && va.len() == vb.len() && va.iter().zip(&vb).all(|(x, y)| (x - y).abs() <= 1e-5)
}

proptest! {
    #[test]
    fn printed_documents_parse_back_equal(doc in document()) {
        let text = print(&doc);
        prop_assert_eq!(parse(&text).map_err(|e| format!("{e}\n{text}")), Ok(doc));
    }

    /// Each texture of a text read back is placed at its own keyword (the
    /// parser's order of places is `Tex::children`'s).
    #[test]
    fn every_texture_is_placed_at_its_keyword(doc in document()) {
        fn all<'a>(t: &'a Tex, out: &mut Vec<&'a Tex>) {
            out.push(t);
            for c in t.children() {
                all(c, out);
            }
        }
        let text = print(&doc);
        let read = parse(&text).unwrap();
        let mut nodes = Vec::new();
        all(&read.texture, &mut nodes);
        for t in nodes {
            let (line, column) = read.place_of(t).unwrap();
            let at: String = text.lines().nth(line - 1).unwrap().chars().skip(column - 1).collect();
            prop_assert!(at.starts_with(t.keyword()), "{} at {}:{}: {}", t.keyword(), line, column, at);
        }
        prop_assert_eq!(doc.place_of(&doc.texture), None);
    }

    /// Lower(raise(t)) == t for the trees lowering makes, property by
    /// property; the only trees refused are named: a layer read through a
    /// cell, a tile whose mortar is a texture.
    #[test]
    fn raising_what_lowering_makes_lowers_back(t in lowerable()) {
        let doc = Document::new(t);
        let base = crate::scene::Material::default();
        let Ok(lowered) = lower_document(&doc, &base, Path::new("")) else {
            return Ok(());
        };
        let m = lowered.material;
        for p in [Property::Diffuse, Property::Specular, Property::Mirror, Property::Opacity, Property::DiffuseTransmission] {
            let raised = match raise_property(&m, p) {
                Ok(text) => text,
                Err(e) => {
                    let e = e.to_string();
                    prop_assert!(e.contains("its own mapping") || e.contains("mortar is a texture"), "{}", e);
                    continue;
                }
            };
            let mut back = crate::scene::Material::default();
            apply_to_property(&mut back, p, &raised, Path::new("")).map_err(|e| TestCaseError::fail(format!("{e}\n{raised}")))?;
            for q in if p == Property::Opacity { vec![Property::Opacity, Property::Transmission] } else { vec![p] } {
                prop_assert!(approx_same(back.texture(q), m.texture(q)), "{:?}\n{}\n{:?}\n{:?}", q, raised, back.texture(q), m.texture(q));
            }
        }
    }
}

fn preset_with(material: &str) -> String {
    format!("(format_version: 2, colors: Srgb, scene: (spheres: [(material: ({material}))]))")
}

/// A preset may write a property as TX text: the property takes that
/// coefficient's tree; colours follow the preset's `colors` (here display
/// values, decoded once) and images resolve against the preset's folder.
#[test]
fn a_preset_property_written_as_tx_lowers_like_the_text() {
    let text = preset_with(
        r#"diffuse: "TX QUAD UNI CD 0.8 0 0 FTX UNI CD 0 0 0.8 FTX GU 0.25 GV 0.25 FTX", specular: "IMAGE logo.ppm CS 1 1 1 FTX", opacity: "DECOUPAGE UNI CT 1 1 1 FTX UNI FTX NBCOTE 0 RAYON 0.4 FTX""#,
    );
    let loaded = crate::preset::parse(&text, Path::new("/presets/report/x.ron")).unwrap();
    let m = &loaded.preset.scene.spheres[0].material;
    let doc = parse("QUAD UNI CD 0.8 0 0 FTX UNI CD 0 0 0.8 FTX GU 0.25 GV 0.25 FTX").unwrap();
    let direct = lower_channel(
        &doc,
        Channel::Diffuse,
        &crate::scene::Material::default().diffuse,
        Path::new(""),
        Colors::Linear,
    )
    .unwrap();
    assert!(approx_same(&m.diffuse, &direct), "{:?}", m.diffuse);
    assert_eq!(
        m.specular.image.as_ref().unwrap().path,
        Path::new("/presets/report/logo.ppm")
    );
    assert_eq!(
        m.opacity,
        Texture::blend(
            Pattern::Cutout {
                sides: 0,
                radius: 0.4
            },
            1.0,
            0.0
        )
    );
}

/// TX colours are display values whatever the preset around them: in a
/// linear preset (no `colors` field) they are decoded as they are read, in
/// an sRGB one by the preset afterwards, never twice; the RON colour
/// beside them keeps its own preset's meaning.
#[test]
fn tx_colours_are_display_values_in_linear_and_srgb_presets_alike() {
    let material = r#"diffuse: "UNI CD 0.54 0.27 0.0742 FTX", specular: (0.5, 0.5, 0.5)"#;
    let srgb = crate::preset::parse(&preset_with(material), Path::new("s.ron")).unwrap();
    let linear_text = format!("(format_version: 2, scene: (spheres: [(material: ({material}))]))");
    let linear = crate::preset::parse(&linear_text, Path::new("l.ron")).unwrap();
    let eotf = |v: f64| ((v + 0.055) / 1.055).powf(2.4) as f32;
    let expected = Vec3::new(eotf(0.54), eotf(0.27), eotf(0.0742));
    for loaded in [&srgb, &linear] {
        let diffuse = loaded.preset.scene.spheres[0]
            .material
            .diffuse
            .eval(Vec3::ZERO, Vec2::ZERO);
        assert!((diffuse - expected).abs().max_element() < 1e-6, "{diffuse}");
    }
    let specular = |l: &crate::preset::Loaded| {
        l.preset.scene.spheres[0]
            .material
            .specular
            .eval(Vec3::ZERO, Vec2::ZERO)
            .x
    };
    assert_eq!(specular(&linear), 0.5);
    assert!((specular(&srgb) - eotf(0.5)).abs() < 1e-6);
}

#[test]
fn a_tx_error_in_a_preset_names_the_file_and_the_place_in_the_text() {
    let text = preset_with(r#"diffuse: "TX QUAD UNI CD 0.8 0 FTX UNI FTX FTX""#);
    let e = crate::preset::parse(&text, Path::new("presets/bad.ron"))
        .unwrap_err()
        .to_string();
    for part in [
        "presets/bad.ron",
        "diffuse",
        "TX line 1, column 22",
        "third of three",
        "`FTX`",
    ] {
        assert!(e.contains(part), "{part}: {e}");
    }
    let text = preset_with(r#"roughness: "UNI FTX""#);
    let e = crate::preset::parse(&text, Path::new("p.ron"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("roughness has no TX coefficient"), "{e}");
}

/// The pattern table's TX keywords are the parser's: each one opens a
/// texture (a text of it alone fails past the keyword, not at it), and the
/// parser's list of textures names each.
#[test]
fn the_pattern_tables_keywords_open_textures() {
    for row in crate::scene::PATTERNS.iter() {
        let Some(keyword) = row.tx_keyword else {
            continue;
        };
        let e = parse(&format!("TX {keyword}")).unwrap_err().to_string();
        assert!(!e.contains("column 4"), "{keyword}: {e}");
        let e = parse("TX").unwrap_err().to_string();
        assert!(e.contains(keyword), "{keyword} missing from {e}");
    }
}
