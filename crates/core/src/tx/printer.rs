//! The TX printer: a document written the way the report's examples are,
//! `TX` first, composite textures one child a line, indented by two
//! spaces, their parameters on the line before their `FTX`; simple
//! textures on one line. Numbers are written in Rust's shortest form that
//! reads back to the same f32, so `parse(print(d)) == d`.

use super::ast::{Attrs, Document, Rgb, Tex};
use std::fmt::Write;

pub fn print(doc: &Document) -> String {
    let mut out = String::new();
    for kind in super::ast::FrameKind::ALL {
        if let Some(f) = doc.frame(kind) {
            let _ = writeln!(
                out,
                "{} {} {} {} {}",
                kind.opening(),
                rgb(&f.origin),
                rgb(&f.u),
                rgb(&f.v),
                kind.closing()
            );
        }
    }
    out.push_str("TX ");
    texture(&mut out, &doc.texture, 0);
    out.push('\n');
    out
}

/// `n` as the shortest text that reads back to it.
pub fn number(n: f32) -> String {
    format!("{n}")
}

fn rgb(c: &Rgb) -> String {
    format!("{} {} {}", number(c[0]), number(c[1]), number(c[2]))
}

fn attrs(a: &Attrs) -> String {
    a.0.iter()
        .map(|(attr, c)| format!("{} {}", attr.keyword(), rgb(c)))
        .collect::<Vec<_>>()
        .join(" ")
}

/// `keyword value` for each present parameter.
fn optional(params: &[(&str, Option<f32>)]) -> String {
    params
        .iter()
        .filter_map(|(k, v)| v.map(|v| format!("{k} {}", number(v))))
        .collect::<Vec<_>>()
        .join(" ")
}

fn simple(out: &mut String, body: String) {
    out.push_str(&body);
    out.push_str(" FTX");
}

/// A texture with children: its keyword, each child and then the
/// parameters on lines of their own, one level deeper, and its `FTX`.
fn composite(out: &mut String, keyword: &str, children: &[&Tex], params: String, indent: usize) {
    let pad = "  ".repeat(indent + 1);
    out.push_str(keyword);
    for child in children {
        out.push('\n');
        out.push_str(&pad);
        texture(out, child, indent + 1);
    }
    if !params.is_empty() {
        out.push('\n');
        out.push_str(&pad);
        out.push_str(&params);
    }
    out.push('\n');
    out.push_str(&"  ".repeat(indent));
    out.push_str("FTX");
}

fn texture(out: &mut String, t: &Tex, indent: usize) {
    match t {
        Tex::Uni(a) if a.0.is_empty() => out.push_str("UNI FTX"),
        Tex::Uni(a) => simple(out, format!("UNI {}", attrs(a))),
        Tex::Quad {
            even,
            odd,
            gu,
            gv,
            phase,
        } => composite(
            out,
            "QUAD",
            &[even, odd],
            optional(&[("GU", *gu), ("GV", *gv), ("DEPHASAGE", *phase)]),
            indent,
        ),
        Tex::Tuile {
            mortar_half_width,
            slope_width,
            level,
            centre,
            mortar,
        } => {
            let head = format!(
                "TUILE DMORTIER {} DPENTE {} NIV3D {}",
                number(*mortar_half_width),
                number(*slope_width),
                number(*level)
            );
            composite(out, &head, &[centre], attrs(mortar), indent);
        }
        Tex::Mult(layers) => {
            let children: Vec<&Tex> = layers.iter().collect();
            composite(out, "MULT", &children, String::new(), indent);
        }
        Tex::Image { file, attrs: a } if a.0.is_empty() => simple(out, format!("IMAGE {file}")),
        Tex::Image { file, attrs: a } => simple(out, format!("IMAGE {file} {}", attrs(a))),
        Tex::Decoupage {
            inside,
            outside,
            sides,
            radius,
        } => {
            let mut params = format!("NBCOTE {sides}");
            if let Some(r) = radius {
                let _ = write!(params, " RAYON {}", number(*r));
            }
            composite(out, "DECOUPAGE", &[inside, outside], params, indent);
        }
        Tex::Noise {
            color,
            frequency,
            amplitude,
        } => simple(
            out,
            format!(
                "NOISE CD1 {} FREQ {} AMPL {}",
                rgb(color),
                number(*frequency),
                number(*amplitude)
            ),
        ),
        Tex::Turbulence {
            color,
            frequency,
            amplitude,
        } => simple(
            out,
            format!(
                "TURBULENCE CD1 {} FREQ {} AMPL {}",
                rgb(color),
                number(*frequency),
                number(*amplitude)
            ),
        ),
        Tex::Bois {
            dark,
            pale,
            ring_width,
            turbulence,
        } => {
            let rest = optional(&[("RAYON", *ring_width), ("TURB", *turbulence)]);
            let mut body = format!("BOIS FONCE {} PALE {}", rgb(dark), rgb(pale));
            if !rest.is_empty() {
                body = format!("{body} {rest}");
            }
            simple(out, body);
        }
        Tex::Marbre {
            dominant,
            veins,
            frequency,
            turbulence,
            turbulence_frequency,
        } => simple(
            out,
            format!(
                "MARBRE CD1 {} CD2 {} FREQ {} TURB {} FREQTURB {}",
                rgb(dominant),
                rgb(veins),
                number(*frequency),
                number(*turbulence),
                number(*turbulence_frequency)
            ),
        ),
        Tex::Brique {
            brick,
            mortar,
            size_u,
            size_v,
        } => {
            let mut params = number(*size_u);
            if let Some(v) = size_v {
                let _ = write!(params, " {}", number(*v));
            }
            composite(out, "BRIQUE", &[brick, mortar], params, indent);
        }
        Tex::Vague {
            frequency,
            amplitude,
        } => simple(
            out,
            format!("VAGUE {} {}", number(*frequency), number(*amplitude)),
        ),
    }
}
