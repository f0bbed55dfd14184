//! The TX parser: recursive descent over the report's grammar (§4.1),
//! accepting what its examples (§2.3) write where the two differ; every
//! choice is listed in docs/VIEWER.md, section "TX".

use super::TxError;
use super::ast::{Attr, Attrs, Document, Frame, FrameKind, Rgb, Tex};
use super::lexer::{Tok, Token, tokenize};

/// The most sides a DECOUPAGE polygon may have: past this it is a disc to
/// any image, and f32 still holds every whole number up to it exactly.
const MAX_SIDES: f32 = 1e6;

/// What a message says is expected where a texture belongs.
const A_TEXTURE: &str = "a texture (UNI, QUAD, TUILE, MULT, IMAGE, DECOUPAGE, NOISE, TURBULENCE, BOIS, MARBRE, BRIQUE or VAGUE)";

/// Textures nest at most this deep in a text, far beyond what a material
/// holds, so that hostile input cannot overflow the stack.
const MAX_NESTING: usize = 64;

/// Parses a TX text: optional `ATX`, `APTX`, `ATX3D` frames, then `TX
/// texture FTX` (the `TX` may be left out, as in most of the report's
/// examples; the outermost texture's `FTX` closes the `TX` too, and after
/// NOISE or TURBULENCE may be left out at the very end, as in the report's
/// examples of those two).
pub fn parse(text: &str) -> Result<Document, TxError> {
    // A byte-order mark (Windows editors write one) is no part of the text:
    // read as a word, it made an error about an invisible character.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut p = Parser {
        toks: tokenize(text),
        pos: 0,
        end: end_position(text),
        places: Vec::new(),
    };
    let mut frames: Vec<(FrameKind, Frame)> = Vec::new();
    while let Some(kind) = p.peek_word().and_then(frame_kind) {
        if frames.iter().any(|(k, _)| *k == kind) {
            return Err(p.error_here(&format!(
                "each frame once ({} was given before)",
                kind.opening()
            )));
        }
        p.pos += 1;
        let frame = Frame {
            origin: p.rgb(&format!("the origin of {}", kind.opening()))?,
            u: p.rgb(&format!("the u vector of {}", kind.opening()))?,
            v: p.rgb(&format!("the v vector of {}", kind.opening()))?,
        };
        p.expect_word(
            kind.closing(),
            &format!("{} closing {}", kind.closing(), kind.opening()),
        )?;
        frames.push((kind, frame));
    }
    if p.peek_word() == Some("TX") {
        p.pos += 1;
    }
    let texture = p.texture(0)?;
    if let Some(t) = p.peek() {
        return Err(TxError::syntax(
            t.line,
            t.column,
            "the end of the text",
            &t.describe(),
        ));
    }
    let mut doc = Document {
        places: p.places,
        ..Document::new(texture)
    };
    for (kind, frame) in frames {
        *doc.frame_mut(kind) = Some(frame);
    }
    Ok(doc)
}

fn frame_kind(word: &str) -> Option<FrameKind> {
    FrameKind::ALL.into_iter().find(|k| k.opening() == word)
}

/// Where a message about the end of the text points: just after its last
/// character.
fn end_position(text: &str) -> (usize, usize) {
    match text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .last()
    {
        Some((i, l)) => (i + 1, l.trim_end().chars().count() + 1),
        None => (1, 1),
    }
}

struct Parser {
    toks: Vec<Token>,
    pos: usize,
    end: (usize, usize),
    /// Each texture's keyword's line and column, in pre-order
    /// ([`Document`]'s `places`).
    places: Vec<(usize, usize)>,
}

impl Parser {
    fn peek(&self) -> Option<&Token> {
        self.toks.get(self.pos)
    }

    fn peek_word(&self) -> Option<&str> {
        match self.peek().map(|t| &t.tok) {
            Some(Tok::Word(w)) => Some(w),
            _ => None,
        }
    }

    fn error_here(&self, expected: &str) -> TxError {
        match self.peek() {
            Some(t) => TxError::syntax(t.line, t.column, expected, &t.describe()),
            None => TxError::syntax(self.end.0, self.end.1, expected, "the end of the text"),
        }
    }

    fn expect_word(&mut self, word: &str, expected: &str) -> Result<(), TxError> {
        if self.peek_word() == Some(word) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.error_here(expected))
        }
    }

    fn number(&mut self, what: &str) -> Result<f32, TxError> {
        match self.peek().map(|t| &t.tok) {
            Some(Tok::Number(n)) => {
                let n = *n;
                self.pos += 1;
                Ok(n)
            }
            _ => Err(self.error_here(&format!("a number ({what})"))),
        }
    }

    fn rgb(&mut self, what: &str) -> Result<Rgb, TxError> {
        Ok([
            self.number(&format!("{what}, first of three"))?,
            self.number(&format!("{what}, second of three"))?,
            self.number(&format!("{what}, third of three"))?,
        ])
    }

    /// The `FTX` closing `name`. The report's NOISE and TURBULENCE
    /// examples end without it: after those two, whose parameters are all
    /// required (so a cut text cannot read as a whole one), the outermost
    /// `FTX` may be missing at the very end of the text.
    fn close(&mut self, name: &str, depth: usize) -> Result<(), TxError> {
        let unambiguous = name == "NOISE" || name == "TURBULENCE";
        if depth == 0 && unambiguous && self.peek().is_none() {
            return Ok(());
        }
        self.expect_word("FTX", &format!("FTX closing {name}"))
    }

    fn texture(&mut self, depth: usize) -> Result<Tex, TxError> {
        if depth >= MAX_NESTING {
            return Err(self.error_here(&format!(
                "at most {MAX_NESTING} nested textures, not another one"
            )));
        }
        let word = match self.toks.get(self.pos) {
            Some(Token {
                tok: Tok::Word(w),
                line,
                column,
            }) => {
                self.places.push((*line, *column));
                w.clone()
            }
            _ => return Err(self.error_here(A_TEXTURE)),
        };
        let inner = depth + 1;
        let parsed = match word.as_str() {
            "UNI" => {
                self.pos += 1;
                Tex::Uni(self.attrs()?)
            }
            "QUAD" => {
                self.pos += 1;
                let even = Box::new(self.texture(inner)?);
                let odd = Box::new(self.texture(inner)?);
                let [gu, gv, phase] = self.params("QUAD", &["GU", "GV", "DEPHASAGE"], &[])?;
                Tex::Quad {
                    even,
                    odd,
                    gu,
                    gv,
                    phase,
                }
            }
            "TUILE" => {
                self.pos += 1;
                let [m, s, l] =
                    self.params("TUILE", &["DMORTIER", "DPENTE", "NIV3D"], &[0, 1, 2])?;
                // The grammar writes the mortar's attributes first, the
                // examples the centre's texture first: both are read.
                let (mortar, centre) = if self.peek_is_attr_or_ftx() {
                    let mortar = self.attrs()?;
                    (mortar, self.texture(inner)?)
                } else {
                    let centre = self.texture(inner)?;
                    (self.attrs()?, centre)
                };
                Tex::Tuile {
                    mortar_half_width: m.unwrap_or_default(),
                    slope_width: s.unwrap_or_default(),
                    level: l.unwrap_or_default(),
                    centre: Box::new(centre),
                    mortar,
                }
            }
            "MULT" => {
                self.pos += 1;
                let mut layers = vec![self.texture(inner)?];
                while self.peek().is_some() && self.peek_word() != Some("FTX") {
                    layers.push(self.texture(inner)?);
                }
                Tex::Mult(layers)
            }
            "IMAGE" => {
                self.pos += 1;
                let file = match self.peek().map(|t| &t.tok) {
                    Some(Tok::Word(w)) if w != "FTX" && Attr::from_keyword(w).is_none() => {
                        w.clone()
                    }
                    _ => return Err(self.error_here("the image's file name (a .ppm or .pgm)")),
                };
                self.pos += 1;
                Tex::Image {
                    file,
                    attrs: self.attrs()?,
                }
            }
            "DECOUPAGE" => {
                self.pos += 1;
                let inside = Box::new(self.texture(inner)?);
                let outside = Box::new(self.texture(inner)?);
                let sides_at = self.peek().cloned();
                let [sides, radius] = self.params("DECOUPAGE", &["NBCOTE", "RAYON"], &[0])?;
                let sides = sides.unwrap_or_default();
                if sides < 0.0 || sides.fract() != 0.0 || sides > MAX_SIDES {
                    let at = sides_at.map_or(self.end, |t| (t.line, t.column));
                    // Numbers are read as f32: past 2^24 one may not be
                    // the one typed (16777217 reads 16777216), so a number
                    // over the limit is not echoed.
                    let found = if sides > MAX_SIDES {
                        format!("NBCOTE above {MAX_SIDES}")
                    } else {
                        format!("NBCOTE {sides}")
                    };
                    return Err(TxError::syntax(
                        at.0,
                        at.1,
                        &format!("NBCOTE followed by a whole number of sides, 0 to {MAX_SIDES}"),
                        &found,
                    ));
                }
                Tex::Decoupage {
                    inside,
                    outside,
                    sides: sides as u32,
                    radius,
                }
            }
            "NOISE" | "TURBULENCE" => {
                self.pos += 1;
                let (color, frequency, amplitude) = self.noise_params(&word)?;
                if word == "NOISE" {
                    Tex::Noise {
                        color,
                        frequency,
                        amplitude,
                    }
                } else {
                    Tex::Turbulence {
                        color,
                        frequency,
                        amplitude,
                    }
                }
            }
            "BOIS" => {
                self.pos += 1;
                let (dark, pale) = (
                    self.colour_param("FONCE", "BOIS")?,
                    self.colour_param("PALE", "BOIS")?,
                );
                let [ring_width, turbulence] = self.params("BOIS", &["RAYON", "TURB"], &[])?;
                Tex::Bois {
                    dark,
                    pale,
                    ring_width,
                    turbulence,
                }
            }
            "MARBRE" => {
                self.pos += 1;
                let dominant = self.colour_param("CD1", "MARBRE")?;
                let veins = self.colour_param("CD2", "MARBRE")?;
                let [f, t, ft] =
                    self.params("MARBRE", &["FREQ", "TURB", "FREQTURB"], &[0, 1, 2])?;
                Tex::Marbre {
                    dominant,
                    veins,
                    frequency: f.unwrap_or_default(),
                    turbulence: t.unwrap_or_default(),
                    turbulence_frequency: ft.unwrap_or_default(),
                }
            }
            "BRIQUE" => {
                self.pos += 1;
                let brick = Box::new(self.texture(inner)?);
                let mortar = Box::new(self.texture(inner)?);
                let size_u = self.number("the brick's width GrosseurU")?;
                let size_v = match self.peek().map(|t| &t.tok) {
                    Some(Tok::Number(_)) => Some(self.number("the brick's height")?),
                    _ => None,
                };
                Tex::Brique {
                    brick,
                    mortar,
                    size_u,
                    size_v,
                }
            }
            "VAGUE" => {
                self.pos += 1;
                Tex::Vague {
                    frequency: self.number("the waves' frequency")?,
                    amplitude: self.number("the waves' amplitude")?,
                }
            }
            _ => return Err(self.error_here(A_TEXTURE)),
        };
        self.close(&word, depth)?;
        Ok(parsed)
    }

    fn peek_is_attr_or_ftx(&self) -> bool {
        self.peek_word()
            .is_some_and(|w| w == "FTX" || Attr::from_keyword(w).is_some())
    }

    /// `BaseAttributs`: coefficients, each at most once.
    fn attrs(&mut self) -> Result<Attrs, TxError> {
        let mut out = Attrs::default();
        while let Some(attr) = self.peek_word().and_then(Attr::from_keyword) {
            if out.get(attr).is_some() {
                return Err(self.error_here(&format!(
                    "each coefficient once ({} was given before)",
                    attr.keyword()
                )));
            }
            self.pos += 1;
            let c = self.rgb(&format!("{}'s colour", attr.keyword()))?;
            out.0.push((attr, c));
        }
        Ok(out)
    }

    /// `keyword r g b`.
    fn colour_param(&mut self, keyword: &str, owner: &str) -> Result<Rgb, TxError> {
        self.expect_word(
            keyword,
            &format!("{keyword} (the colour {owner} needs next)"),
        )?;
        self.rgb(&format!("{owner}'s {keyword}"))
    }

    /// `CD1 r g b` then `FREQ f` and `AMPL a` in either order.
    fn noise_params(&mut self, owner: &str) -> Result<(Rgb, f32, f32), TxError> {
        let color = self.colour_param("CD1", owner)?;
        let [f, a] = self.params(owner, &["FREQ", "AMPL"], &[0, 1])?;
        Ok((color, f.unwrap_or_default(), a.unwrap_or_default()))
    }

    /// Keyword-number parameters in any order, each at most once; those
    /// whose index is in `required` must be there.
    fn params<const N: usize>(
        &mut self,
        owner: &str,
        names: &[&str; N],
        required: &[usize],
    ) -> Result<[Option<f32>; N], TxError> {
        let mut values = [None; N];
        while let Some(i) = self
            .peek_word()
            .and_then(|w| names.iter().position(|n| *n == w))
        {
            if values[i].is_some() {
                return Err(self.error_here(&format!(
                    "each parameter of {owner} once ({} was given before)",
                    names[i]
                )));
            }
            self.pos += 1;
            values[i] = Some(self.number(&format!("{owner}'s {}", names[i]))?);
        }
        if let Some(&missing) = required.iter().find(|&&i| values[i].is_none()) {
            let all: Vec<&str> = required.iter().map(|&i| names[i]).collect();
            return Err(self.error_here(&format!(
                "{} ({owner} needs {})",
                names[missing],
                all.join(", ")
            )));
        }
        Ok(values)
    }
}
