//! The IFT528 report's TX examples (§2.3 and §3), copied verbatim: each
//! parses, prints back to an equal tree, and every truncation of it is
//! refused with a line, a column and the token expected.

use glam::{Vec2, Vec3};
use marbre_core::scene::{Child, ColorEncoding, Material, Pattern, Texture};
use marbre_core::tx::{self, Channel, Tex, TxError};
use std::path::Path;

/// (name, text) as the report prints them.
pub const EXAMPLES: [(&str, &str); 15] = [
    ("uni", "UNI CD 0.7 0.0 0.0 CS 0.7 0.0 0.0 FTX"),
    (
        "quad00",
        "QUAD UNI CD 0.8 0 0 FTX UNI CD 0 0 0.8 FTX GU 0.25 GV 0.25 FTX",
    ),
    (
        "quad01",
        "QUAD
  QUAD UNI CD 0.8 0 0 FTX  UNI CD 0.4 0.8 0 FTX GU 0.3333 GV 0.3333 FTX
  QUAD UNI CD 0 0 0.8 FTX  UNI CD 0.2 0.6 0.3 FTX GU 0.3333 GV 0.3333 FTX
  GU 0.25 GV 0.25
FTX",
    ),
    (
        "quad02",
        "QUAD
  UNI CD 0.8 0 0 FTX UNI CD 0 0 0.8 FTX
  GU 0.25 GV 0.25 DEPHASAGE 0.5
FTX",
    ),
    (
        "tuile00",
        "TUILE DMORTIER 0.02 DPENTE 0.01 NIV3D 0.4
      UNI CD 0.44 0.5 0.56 CS 0.44 0.5 0.56 FTX
      CD 0.74 0.74 0.74 CS 0.74 0.74 0.74
FTX",
    ),
    (
        "tuile01",
        "QUAD
  TUILE DMORTIER 0.02 DPENTE 0.01 NIV3D 0.4
      UNI CD 0.44 0.5 0.56 CS 0.44 0.5 0.56 FTX
      CD 0.74 0.74 0.74 CS 0.74 0.74 0.74
  FTX
  TUILE DMORTIER 0.02 DPENTE 0.01 NIV3D 0.4
      UNI CD 0.68 0.84 0.90 CS 0.68 0.84 0.90 FTX
      CD 0.74 0.74 0.74 CS 0.74 0.74 0.74
  FTX
  GU 0.25 GV 0.25
FTX",
    ),
    (
        "mult00",
        "TX MULT
    QUAD UNI CD 0 0.6 0 FTX UNI CD 0 0 0.6 FTX FTX
    DECOUPAGE UNI CD 0.9 0 0 FTX UNI FTX NBCOTE 5 RAYON 0.35 FTX
FTX",
    ),
    (
        "decoupage",
        "TX QUAD
  DECOUPAGE UNI CT 1 1 1 CD 0 0 0 FTX UNI CD 0.8 0.2 0.2 FTX NBCOTE 0 RAYON 0.4 FTX
  DECOUPAGE UNI CT 1 1 1 CD 0 0 0 FTX UNI CD 0.8 0.2 0.2 FTX NBCOTE 0 RAYON 0.4 FTX
  DEPHASAGE 0.5
FTX",
    ),
    ("image", "IMAGE udeslogo.ppm CD 1 1 1 FTX"),
    (
        "bois00",
        "BOIS FONCE 0.54 0.27 0.0742 PALE 0.59 0.40 0.20 RAYON 0.12 TURB 0.3 FTX",
    ),
    (
        "marbre",
        "MARBRE CD1 1 1 1 CD2 0 0 0 FREQ 1 TURB 15 FREQTURB 1 FTX",
    ),
    (
        "marbre04",
        "TX QUAD
  TUILE DMORTIER 0.02 DPENTE 0.02 NIV3D 1
     MARBRE CD1 0.53 0.80 0.92 CD2 0 0 0.60 FREQ 10 TURB 25 FREQTURB 3 FTX
     CD 0.74 0.74 0.74 CS 0.74 0.74 0.74
  FTX
  TUILE DMORTIER 0.02 DPENTE 0.02 NIV3D 1
     MARBRE CD1 0.55 0.73 0.56 CD2 0.18 0.54 0.34 FREQ 11 TURB 28 FREQTURB 3.1 FTX
     CD 0.74 0.74 0.74 CS 0.74 0.74 0.74
  FTX
  GU 0.25 GV 0.25
FTX",
    ),
    (
        "brique00",
        "TX BRIQUE
  TURBULENCE CD1 0.54 0.11 0.38 FREQ 14 AMPL 1 FTX
  UNI CD 0.54 0.54 0.48 FTX
  0.1 0.1
FTX",
    ),
    ("noise00", "TX NOISE CD1 0.9 0.2 0.3 FREQ 1 AMPL 1"),
    ("turbulence", "TX TURBULENCE CD1 0.9 0.2 0.3 FREQ 1 AMPL 1"),
];

fn example(name: &str) -> &'static str {
    EXAMPLES.iter().find(|(n, _)| *n == name).unwrap().1
}

#[test]
fn every_example_parses_and_prints_back_to_an_equal_tree() {
    for (name, text) in EXAMPLES {
        let doc = tx::parse(text).unwrap_or_else(|e| panic!("{name}: {e}"));
        let printed = tx::print(&doc);
        let back = tx::parse(&printed).unwrap_or_else(|e| panic!("{name}: {e}\n{printed}"));
        assert_eq!(back, doc, "{name}:\n{printed}");
    }
}

/// The text `text` cut just before its `k`-th token.
fn cut_before(text: &str, k: usize) -> String {
    let tokens = marbre_core::tx::lexer::tokenize(text);
    let Some(t) = tokens.get(k) else {
        return text.to_owned();
    };
    let mut out: Vec<&str> = text.lines().take(t.line - 1).collect();
    let line = text.lines().nth(t.line - 1).unwrap();
    let byte = line.char_indices().nth(t.column - 1).unwrap().0;
    out.push(&line[..byte]);
    out.join("\n")
}

#[test]
fn every_truncation_of_every_example_is_refused_where_it_ends() {
    let mut refused = 0;
    for (name, text) in EXAMPLES {
        let n = marbre_core::tx::lexer::tokenize(text).len();
        for k in 0..n {
            let cut = cut_before(text, k);
            match tx::parse(&cut) {
                Err(TxError::Syntax {
                    line,
                    column,
                    expected,
                    found,
                }) => {
                    let last = cut.lines().count().max(1);
                    assert!(
                        line <= last && column >= 1,
                        "{name} at {k}: {line}:{column}"
                    );
                    assert!(!expected.is_empty(), "{name} at {k}");
                    assert_eq!(found, "the end of the text", "{name} at {k}");
                    refused += 1;
                }
                Err(other) => panic!("{name} cut at token {k}: {other}"),
                Ok(doc) => panic!("{name} cut at token {k} parsed:\n{cut}\n{doc:?}"),
            }
        }
    }
    assert!(refused > 300, "{refused}");
}

fn decode(c: [f32; 3]) -> Vec3 {
    ColorEncoding::Srgb.decode(Vec3::from(c))
}

fn lower(name: &str, channel: Channel) -> Texture {
    let doc = tx::parse(example(name)).unwrap();
    let base = Material::default();
    tx::lower_channel(
        &doc,
        channel,
        channel.texture(&base),
        Path::new("/r"),
        tx::Colors::Linear,
    )
    .unwrap()
}

#[test]
fn the_4x4_checker_lowers_to_a_uv_checker_of_the_decoded_colours() {
    assert_eq!(
        lower("quad00", Channel::Diffuse),
        Texture::blend(
            Pattern::Checker2d {
                size: Vec2::splat(0.25),
                phase: 0.0
            },
            decode([0.8, 0.0, 0.0]),
            decode([0.0, 0.0, 0.8])
        )
    );
    // The text sets no other coefficient: the rest keep the material's.
    assert_eq!(
        lower("quad00", Channel::Specular),
        Material::default().specular
    );
}

/// The report's pentagon over a checker (MULT): the checker is the
/// cutout's outside, as presets/cutouts.ron writes it by hand.
#[test]
fn mult_layers_the_pentagon_over_the_checker() {
    let checker = Texture::blend(
        Pattern::Checker2d {
            size: Vec2::splat(0.125),
            phase: 0.0,
        },
        decode([0.0, 0.6, 0.0]),
        decode([0.0, 0.0, 0.6]),
    );
    assert_eq!(
        lower("mult00", Channel::Diffuse),
        Texture::blend(
            Pattern::Cutout {
                sides: 5,
                radius: 0.35
            },
            checker,
            decode([0.9, 0.0, 0.0])
        )
    );
}

/// The hole grid: CT 1 1 1 is a hole (opacity 0, white light through),
/// the rest keeps the material's opacity 1, as presets/cutouts.ron.
#[test]
fn the_hole_grid_lowers_ct_to_opacity_holes() {
    let disc = Texture::blend(
        Pattern::Cutout {
            sides: 0,
            radius: 0.4,
        },
        1.0,
        0.0,
    );
    assert_eq!(
        lower("decoupage", Channel::Opacity),
        Texture::blend(
            Pattern::Checker2d {
                size: Vec2::splat(0.125),
                phase: 0.5
            },
            disc.clone(),
            disc
        )
    );
    assert_eq!(
        lower("decoupage", Channel::Transmission),
        Texture::color(Vec3::ONE)
    );
    let diffuse = lower("decoupage", Channel::Diffuse);
    let Child::Texture(cell) = &diffuse.a else {
        panic!("{diffuse:?}")
    };
    assert_eq!(cell.a, Child::Color(decode([0.8, 0.2, 0.2])));
    assert_eq!(cell.b, Child::Color(Vec3::ZERO));
}

#[test]
fn the_tiles_raise_a_bump_of_their_level_and_the_marble_keeps_its_numbers() {
    let bump = lower("marbre04", Channel::Bump);
    let Pattern::Checker2d { size, .. } = bump.pattern else {
        panic!("{bump:?}")
    };
    assert_eq!(size, Vec2::splat(0.25));
    let tile = Texture::blend(
        Pattern::Tile {
            mortar_half_width: 0.02,
            bevel: 0.02,
        },
        0.0,
        1.0,
    );
    assert_eq!(bump.a, Child::Texture(Box::new(tile)));
    let diffuse = lower("marbre04", Channel::Diffuse);
    let Child::Texture(first) = &diffuse.a else {
        panic!()
    };
    let Child::Texture(marble) = &first.b else {
        panic!()
    };
    match marble.pattern {
        Pattern::Veins {
            noise,
            frequency,
            turbulence_amount,
        } => {
            assert_eq!((frequency, turbulence_amount), (10.0, 25.0));
            assert_eq!(noise.fractal.frequency, 3.0);
        }
        other => panic!("{other:?}"),
    }
    let doc = tx::parse(example("marbre04")).unwrap();
    let lowered = tx::lower_document(&doc, &Material::default(), Path::new(".")).unwrap();
    assert_eq!(lowered.material.bump_height, tx::lower::BUMP_HEIGHT);
}

#[test]
fn the_image_resolves_against_the_folder_of_its_text() {
    let t = lower("image", Channel::Diffuse);
    assert_eq!(t.image.as_ref().unwrap().path, Path::new("/r/udeslogo.ppm"));
    assert!(t.ops.is_empty(), "CD 1 1 1 scales by one: {:?}", t.ops);
    assert!(matches!(
        tx::parse(example("image")).unwrap().texture,
        Tex::Image { .. }
    ));
}

/// Every example's trees raise back to a text that lowers to the same
/// trees (within the sRGB round trip), property by property.
#[test]
fn lowered_examples_raise_and_lower_back() {
    use marbre_core::scene::Property;
    for (name, text) in EXAMPLES {
        let doc = tx::parse(text).unwrap();
        let m = tx::lower_document(&doc, &Material::default(), Path::new(""))
            .unwrap()
            .material;
        for p in [Property::Diffuse, Property::Specular, Property::Opacity] {
            let raised = tx::raise_property(&m, p).unwrap_or_else(|e| panic!("{name} {p:?}: {e}"));
            let mut back = Material::default();
            tx::apply_to_property(&mut back, p, &raised, Path::new(""))
                .unwrap_or_else(|e| panic!("{name} {p:?}: {e}\n{raised}"));
            assert!(
                approx_same(back.texture(p), m.texture(p)),
                "{name} {p:?}:\n{raised}\n{:?}\n{:?}",
                back.texture(p),
                m.texture(p)
            );
        }
    }
}

/// The same tree structure, values within 1e-5.
pub fn approx_same(a: &Texture, b: &Texture) -> bool {
    fn values(t: &Texture) -> (String, Vec<f32>) {
        let mut v = Vec::new();
        let mut shape = t.clone();
        shape.visit_mut(&mut |n| {
            for c in [&mut n.a, &mut n.b] {
                match c {
                    Child::Scalar(s) => {
                        v.push(*s);
                        *s = 0.0;
                    }
                    Child::Color(c) => {
                        v.extend(c.to_array());
                        *c = Vec3::ZERO;
                    }
                    Child::Texture(_) => {}
                }
            }
            for op in &mut n.ops {
                if let marbre_core::scene::MathOp::Scale(k) = op {
                    v.push(*k);
                    *k = 0.0;
                }
            }
        });
        (format!("{shape:?}"), v)
    }
    let (sa, va) = values(a);
    let (sb, vb) = values(b);
    sa == sb && va.len() == vb.len() && va.iter().zip(&vb).all(|(x, y)| (x - y).abs() <= 1e-5)
}

/// The report's examples also ship as presets (`presets/report/*.ron`), each
/// property written as its `.tx` text: every one loads without a note, and
/// each object's material and the polygon's frame are what lowering the
/// `.tx` file onto their neutral base gives, and the display is the
/// preview's, so the preset shows what `marbre tx` renders.
#[test]
fn the_report_presets_are_their_tx_files() {
    // Spelt without `..`: the preset loader normalises the paths it reads.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .unwrap();
    let dir = root.join("presets/report");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let tx_path = entry.unwrap().path();
        if tx_path.extension().is_none_or(|e| e != "tx") {
            continue;
        }
        let ron_path = tx_path.with_extension("ron");
        let loaded = marbre_core::preset::load(&ron_path)
            .unwrap_or_else(|e| panic!("{}: {e}", ron_path.display()));
        assert!(loaded.notes.is_empty(), "{:?}", loaded.notes);
        let doc = tx::parse(&std::fs::read_to_string(&tx_path).unwrap()).unwrap();
        // The presets' neutral base: the default material, a little rougher.
        let base = Material {
            roughness: Texture::scalar(0.45),
            ..Material::default()
        };
        let lowered = tx::lower_document(&doc, &base, &dir).unwrap();
        let scene = &loaded.preset.scene;
        for material in [
            &scene.spheres[0].material,
            &scene.cylinders[0].material,
            &scene.polygons[0].material,
        ] {
            for property in marbre_core::scene::Property::ALL {
                let (mine, theirs) = (
                    material.texture(property),
                    lowered.material.texture(property),
                );
                assert!(
                    approx_same(mine, theirs),
                    "{}: {}\n{mine:?}\n{theirs:?}",
                    ron_path.display(),
                    property.name()
                );
            }
            assert!(
                approx_same(&material.bump, &lowered.material.bump),
                "{}: bump",
                ron_path.display()
            );
            assert_eq!(material.bump_height, lowered.material.bump_height);
        }
        assert_eq!(scene.polygons[0].uv_frame, lowered.polygon_frame);
        let preview = marbre_core::tx_preview::preview_scene(&doc, &dir).unwrap();
        assert_eq!(
            scene.render.display,
            preview.render.display,
            "{}: the course display, as `marbre tx` shows it",
            ron_path.display()
        );
        count += 1;
    }
    assert_eq!(count, 20, "every example has its preset");
}
