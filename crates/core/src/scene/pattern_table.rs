//! Every pattern described once: the table the panel's list, the shader's
//! features and code generation, the soak's edits and TX's keywords read.
//!
//! pbrt-v4 describes a texture once (one class, one tagged-pointer list,
//! one name switch); marbre's equivalent is this table. Adding a pattern
//! takes a variant of [`crate::scene::Pattern`] (its numbers, its defaults
//! in `Pattern::fresh`, its CPU blend), its function in the texture library
//! (`crate::texture`, Rust and `patterns.wgsl`), and a row here; the list
//! of files is in docs/ARCHITECTURE.md ("Adding a pattern").

/// Which pattern, without its numbers: the row of [`PATTERNS`] (and the
/// position in the panel's list) is `kind as usize`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum PatternKind {
    Constant,
    Checker,
    Fbm,
    Turbulence,
    Marble,
    Checker2d,
    Brick,
    Tile,
    Cutout,
    Wood,
    Veins,
    Waves,
    Ridged,
    Mix,
    Image,
    MassalMarble,
    Diagonal,
}

/// How the generated WGSL finds a pattern's blend factor `t`. In the
/// expressions, `{p}` is the 3D texture point, `{uv}` the (u, v), `{fp}`
/// the `Footprint`, `{q}` the pattern's numbers (one `vec4f` of the
/// parameter buffer, `texture_params::pattern_params`), `{signal}` its
/// fractal sum and `{cell}` the cell's variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PatternCode {
    /// `t = 0`: the first child alone.
    First,
    /// `t` is this expression.
    Blend(&'static str),
    /// A board of cells: `cell` (a `Cell`) is computed once, `t` read from
    /// it, and the children see the cell's own (u, v) square
    /// (`{cell}.local`), their footprint scaled by the cell size (`{q}.xy`).
    Cell { cell: &'static str, t: &'static str },
    /// `t` is the first channel of the texture's factor (Blender's Mix).
    Factor,
    /// The colour is the texture's image (`texture_codegen` samples it).
    Image,
}

/// One row of [`PATTERNS`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatternInfo {
    pub kind: PatternKind,
    /// Shown in the panel's list and on the node editor's nodes.
    pub name: &'static str,
    /// The `#if` name that compiles the pattern's code in; None when it
    /// needs none.
    pub define: Option<&'static str>,
    /// Whether it reads the surface's (u, v) (the shader then computes them:
    /// `TEXTURE_UV`).
    pub reads_uv: bool,
    /// Whether its code calls the texture library (`texture/patterns.wgsl`).
    pub uses_library: bool,
    /// Whether its footprint filters it (the box-filtered checkers); noise
    /// patterns clamp their octaves by it whatever this says.
    pub filtered: bool,
    pub code: PatternCode,
    /// The texture report's TX keyword that lowers to it, if any.
    pub tx_keyword: Option<&'static str>,
}

const fn row(kind: PatternKind, name: &'static str, code: PatternCode) -> PatternInfo {
    PatternInfo {
        kind,
        name,
        define: None,
        reads_uv: false,
        uses_library: false,
        filtered: false,
        code,
        tx_keyword: None,
    }
}

impl PatternInfo {
    const fn define(self, define: &'static str) -> Self {
        Self {
            define: Some(define),
            ..self
        }
    }
    const fn uv(self) -> Self {
        Self {
            reads_uv: true,
            ..self
        }
    }
    const fn library(self) -> Self {
        Self {
            uses_library: true,
            ..self
        }
    }
    const fn filtered(self) -> Self {
        Self {
            filtered: true,
            ..self
        }
    }
    const fn tx(self, keyword: &'static str) -> Self {
        Self {
            tx_keyword: Some(keyword),
            ..self
        }
    }
}

use PatternCode::{Blend, Cell, Factor, First, Image};
use PatternKind as K;

/// Every pattern, in [`PatternKind`] order.
pub const PATTERNS: [PatternInfo; 17] = [
    row(K::Constant, "constant", First).tx("UNI"),
    row(
        K::Checker,
        "checker 3D",
        Blend(
            "select(checker_3d({p}, {q}.xyz), filtered_checker_3d({p}, {q}.xyz, 0.5 * {fp}.axes), filter_checkers)",
        ),
    )
    .define("PATTERN_CHECKER")
    .filtered(),
    row(K::Fbm, "fBm", Blend("clamp(0.5 + 0.5 * {signal}, 0.0, 1.0)"))
        .define("PATTERN_FBM")
        .tx("NOISE"),
    row(K::Turbulence, "turbulence", Blend("clamp({signal}, 0.0, 1.0)"))
        .define("PATTERN_TURBULENCE")
        .tx("TURBULENCE"),
    row(
        K::Marble,
        "marble",
        Blend("0.5 + 0.5 * marble_stripes({p}.x, {signal}, {q}.x)"),
    )
    .define("PATTERN_MARBLE"),
    row(
        K::Checker2d,
        "checker (uv)",
        Cell {
            cell: "checker_2d({uv}, {q}.xy, {q}.z)",
            t: "select({cell}.select, filtered_checker_2d({uv}, {q}.xy, {q}.z, 0.5 * {fp}.uv), filter_checkers)",
        },
    )
    .define("PATTERN_CHECKER_2D")
    .uv()
    .library()
    .filtered()
    .tx("QUAD"),
    row(
        K::Brick,
        "brick",
        Cell {
            cell: "brick({uv}, {q}.xy, {q}.z, {q}.w)",
            t: "{cell}.select",
        },
    )
    .define("PATTERN_BRICK")
    .uv()
    .library()
    .tx("BRIQUE"),
    row(K::Tile, "tile", Blend("tile_height({uv}, {q}.x, {q}.y)"))
        .define("PATTERN_TILE")
        .uv()
        .library()
        .tx("TUILE"),
    row(K::Cutout, "cutout", Blend("cutout({uv}, u32({q}.y), {q}.x)"))
        .define("PATTERN_CUTOUT")
        .uv()
        .library()
        .tx("DECOUPAGE"),
    row(
        K::Wood,
        "wood",
        Blend("wood_rings({p}, WOOD_AXIS, {q}.x, {q}.y * {signal})"),
    )
    .define("PATTERN_WOOD")
    .library()
    .tx("BOIS"),
    row(
        K::Veins,
        "veins",
        Blend("max(sin({q}.x * {p}.x + {q}.y * {signal}), 0.0)"),
    )
    .define("PATTERN_VEINS")
    .library()
    .tx("MARBRE"),
    row(K::Waves, "waves", Blend("waves({uv}, {q}.x, {q}.yz)"))
        .define("PATTERN_WAVES")
        .uv()
        .library()
        .tx("VAGUE"),
    row(K::Ridged, "ridged", Blend("clamp({signal}, 0.0, 1.0)")).define("PATTERN_RIDGED"),
    row(K::Mix, "mix", Factor).define("PATTERN_MIX"),
    row(K::Image, "image", Image)
        .define("IMAGE")
        .uv()
        .library()
        .tx("IMAGE"),
    row(
        K::MassalMarble,
        "marble (Massal)",
        Blend("massal_marble({p}, {q}.x, {signal})"),
    )
    .define("PATTERN_MASSAL_MARBLE")
    .library(),
    row(K::Diagonal, "diagonal (u < v)", Blend("diagonal({uv})"))
        .define("PATTERN_DIAGONAL")
        .uv()
        .library(),
];

impl PatternKind {
    /// Every kind, in the table's order.
    pub fn all() -> impl Iterator<Item = PatternKind> {
        PATTERNS.iter().map(|row| row.kind)
    }

    /// Its row of [`PATTERNS`].
    pub fn info(self) -> &'static PatternInfo {
        &PATTERNS[self as usize]
    }

    /// The kind at `index` in the panel's list; None past its end.
    pub fn from_index(index: usize) -> Option<PatternKind> {
        PATTERNS.get(index).map(|row| row.kind)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Pattern;
    use std::collections::BTreeSet;

    /// Row `i` describes kind `i`, and the fresh pattern of each kind is of
    /// that kind: the table, the enum and `Pattern::fresh` agree.
    #[test]
    fn each_row_describes_its_kind() {
        for (i, row) in PATTERNS.iter().enumerate() {
            assert_eq!(row.kind as usize, i, "{}", row.name);
            assert_eq!(PatternKind::from_index(i), Some(row.kind));
            assert_eq!(Pattern::fresh(row.kind, None).kind(), row.kind);
        }
        assert_eq!(PatternKind::from_index(PATTERNS.len()), None);
    }

    /// Names, defines and keywords are each unique, and defines are what
    /// the WGSL's `#if` reads (upper case words).
    #[test]
    fn names_defines_and_keywords_are_unique() {
        let unique = |items: Vec<&str>| items.len() == items.iter().collect::<BTreeSet<_>>().len();
        assert!(unique(PATTERNS.iter().map(|r| r.name).collect()));
        let defines: Vec<&str> = PATTERNS.iter().filter_map(|r| r.define).collect();
        assert!(unique(defines.clone()));
        assert!(defines.iter().all(|d| {
            d.chars()
                .all(|c| c.is_ascii_uppercase() || c == '_' || c.is_ascii_digit())
        }));
        assert!(unique(
            PATTERNS.iter().filter_map(|r| r.tx_keyword).collect()
        ));
    }

    /// A pattern that compiles code has a define; one whose code reads
    /// (u, v) or a cell says it reads (u, v); every placeholder is one the
    /// generator fills.
    #[test]
    fn the_code_column_agrees_with_the_flags() {
        for row in &PATTERNS {
            let expressions: Vec<&str> = match row.code {
                First => vec![],
                Blend(t) => vec![t],
                Cell { cell, t } => vec![cell, t],
                Factor | Image => vec![],
            };
            assert_eq!(row.define.is_none(), row.code == First, "{}", row.name);
            if !expressions.is_empty() {
                assert_eq!(
                    expressions.iter().any(|e| e.contains("{uv}")),
                    row.reads_uv,
                    "{}: reads (u, v) as its flag says",
                    row.name
                );
            }
            for e in &expressions {
                let mut rest = *e;
                while let Some(open) = rest.find('{') {
                    let close = rest[open..].find('}').expect("closed placeholder") + open;
                    let name = &rest[open + 1..close];
                    assert!(
                        ["p", "uv", "fp", "q", "signal", "cell"].contains(&name),
                        "{}: unknown placeholder {{{name}}}",
                        row.name
                    );
                    rest = &rest[close + 1..];
                }
            }
            let noise = Pattern::fresh(row.kind, None).noise().is_some();
            assert_eq!(
                expressions.iter().any(|e| e.contains("{signal}")),
                noise,
                "{}: reads a signal exactly when it has noise",
                row.name
            );
        }
    }
}
