//! Tiles of an image (issue 30): the rectangle of pixels one farm task or
//! one pass of a large render traces, as `render --tile X0,Y0,X1,Y1` or
//! `--tiles CxR --tile-index I` names it, and the checks that a set of
//! tiles covers an image once. A tile is traced with the whole image's
//! camera and per-pixel samples (`shaders/scene.wgsl`'s crop), so the
//! tiles of an image assemble to its render exactly.

use serde::{Deserialize, Serialize};
use std::fmt;

/// The most columns or rows a grid may have: an image's largest side
/// (`render --size`), so that a grid's tile count fits a `u32`.
pub const MAX_GRID_SIDE: u32 = 16384;

/// The pixels [x0, x1) × [y0, y1) of an image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Tile {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Tile {
    /// The whole of an image of `size`.
    pub fn whole(size: (u32, u32)) -> Self {
        Self {
            x0: 0,
            y0: 0,
            x1: size.0,
            y1: size.1,
        }
    }

    pub fn size(&self) -> (u32, u32) {
        (self.x1 - self.x0, self.y1 - self.y0)
    }

    pub fn pixels(&self) -> u64 {
        u64::from(self.x1 - self.x0) * u64::from(self.y1 - self.y0)
    }

    /// `X0,Y0,X1,Y1` (the ends excluded, as Blender's border and pbrt's
    /// crop window in pixels), not yet checked against an image.
    pub fn parse(s: &str) -> Result<Self, String> {
        let numbers: Vec<u32> = s
            .split(',')
            .map(|v| v.trim().parse::<u32>())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("`{s}` is not X0,Y0,X1,Y1 (four whole numbers of pixels)"))?;
        let [x0, y0, x1, y1] = numbers[..] else {
            return Err(format!(
                "`{s}` is not X0,Y0,X1,Y1 (four whole numbers of pixels)"
            ));
        };
        if x1 <= x0 || y1 <= y0 {
            return Err(format!(
                "the tile `{s}` is empty: X1 must be greater than X0 and Y1 than Y0"
            ));
        }
        Ok(Self { x0, y0, x1, y1 })
    }

    /// An error unless the tile lies within an image of `size`.
    pub fn check_within(&self, size: (u32, u32)) -> Result<(), String> {
        if self.x1 > size.0 || self.y1 > size.1 {
            return Err(format!(
                "the tile {self} reaches outside the {} × {} image",
                size.0, size.1
            ));
        }
        Ok(())
    }

    fn overlaps(&self, other: &Tile) -> bool {
        self.x0 < other.x1 && other.x0 < self.x1 && self.y0 < other.y1 && other.y0 < self.y1
    }
}

impl fmt::Display for Tile {
    /// As `--tile` takes it.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.y0, self.x1, self.y1)
    }
}

/// A grid of `columns` × `rows` tiles (`--tiles CxR`), numbered row by
/// row from the top left. Edges fall at ⌊i·W/C⌋, so tiles of a size the
/// grid does not divide differ by a pixel at most.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct TileGrid {
    pub columns: u32,
    pub rows: u32,
}

impl TileGrid {
    /// `CxR`, each from 1 to [`MAX_GRID_SIDE`].
    pub fn parse(s: &str) -> Result<Self, String> {
        let (c, r) = s
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("`{s}` is not COLUMNSxROWS, like 4x4"))?;
        let count = |v: &str| {
            v.trim()
                .parse::<u32>()
                .ok()
                .filter(|&n| (1..=MAX_GRID_SIDE).contains(&n))
                .ok_or_else(|| {
                    format!("`{s}` is not COLUMNSxROWS of whole numbers from 1 to {MAX_GRID_SIDE}")
                })
        };
        Ok(Self {
            columns: count(c)?,
            rows: count(r)?,
        })
    }

    pub fn count(&self) -> u32 {
        self.columns * self.rows
    }

    /// Tile `index` of an image of `size`; an error if the index is past
    /// the last tile or the grid has more columns or rows than the image
    /// has pixels (some tiles would be empty).
    pub fn tile(&self, size: (u32, u32), index: u32) -> Result<Tile, String> {
        if self.columns > size.0 || self.rows > size.1 {
            return Err(format!(
                "a {}x{} grid does not divide a {} × {} image: a tile would hold no pixel",
                self.columns, self.rows, size.0, size.1
            ));
        }
        if index >= self.count() {
            return Err(format!(
                "tile index {index} is out of range: a {}x{} grid has tiles 0 to {}",
                self.columns,
                self.rows,
                self.count() - 1
            ));
        }
        let edge = |i: u32, n: u32, len: u32| (u64::from(i) * u64::from(len) / u64::from(n)) as u32;
        let (c, r) = (index % self.columns, index / self.columns);
        Ok(Tile {
            x0: edge(c, self.columns, size.0),
            x1: edge(c + 1, self.columns, size.0),
            y0: edge(r, self.rows, size.1),
            y1: edge(r + 1, self.rows, size.1),
        })
    }

    /// Every tile of an image of `size`, in index order.
    pub fn tiles(&self, size: (u32, u32)) -> Result<Vec<Tile>, String> {
        (0..self.count()).map(|i| self.tile(size, i)).collect()
    }
}

/// The pieces `region` is traced in when one set of targets for it would
/// exceed what a GPU holds: pieces at most `max_side` pixels on a side (a
/// texture's largest size) and, as far as whole rows allow, of at most
/// `max_pixels` (the targets take about 160 bytes a pixel); as few as
/// those allow, in rows from the top, all of the first's size but for the
/// last row and column of pieces, which are smaller (so the renderer's
/// targets, sized for the first, fit every piece); `region` itself when it
/// fits.
pub fn split(region: Tile, max_side: u32, max_pixels: u64) -> Vec<Tile> {
    let (w, h) = region.size();
    let max_side = max_side.max(1);
    let piece_width = w.div_ceil(w.div_ceil(max_side));
    let piece_height =
        (max_pixels / u64::from(piece_width)).clamp(1, u64::from(max_side.min(h))) as u32;
    let starts = |len: u32, step: u32| (0..len.div_ceil(step)).map(move |i| i * step);
    starts(h, piece_height)
        .flat_map(|y| {
            starts(w, piece_width).map(move |x| Tile {
                x0: region.x0 + x,
                x1: region.x0 + (x + piece_width).min(w),
                y0: region.y0 + y,
                y1: region.y0 + (y + piece_height).min(h),
            })
        })
        .collect()
}

/// An error naming what is wrong if `tiles` (each with a name, its file)
/// do not cover an image of `size` exactly once: the first two that
/// overlap, or how many pixels none covers and the first of them.
pub fn check_cover(size: (u32, u32), tiles: &[(String, Tile)]) -> Result<(), String> {
    for (name, tile) in tiles {
        tile.check_within(size)
            .map_err(|e| format!("{name}: {e}"))?;
    }
    for (i, (a_name, a)) in tiles.iter().enumerate() {
        if let Some((b_name, b)) = tiles[i + 1..].iter().find(|(_, b)| a.overlaps(b)) {
            return Err(format!(
                "{a_name} (tile {a}) and {b_name} (tile {b}) overlap: a pixel would be written twice"
            ));
        }
    }
    let covered: u64 = tiles.iter().map(|(_, t)| t.pixels()).sum();
    let total = u64::from(size.0) * u64::from(size.1);
    if covered < total {
        let (x, y) = first_uncovered(size, tiles).unwrap_or((0, 0));
        return Err(format!(
            "the tiles leave {} of the {} × {} image's pixels out, the first at ({x}, {y}): \
             a tile is missing",
            total - covered,
            size.0,
            size.1,
        ));
    }
    Ok(())
}

/// The first pixel, row by row, that no tile covers: each row's tiles
/// sorted by their left edge and walked once (not every pixel against
/// every tile: a 16384² image has 2²⁸ pixels).
fn first_uncovered(size: (u32, u32), tiles: &[(String, Tile)]) -> Option<(u32, u32)> {
    (0..size.1).find_map(|y| {
        let mut spans: Vec<(u32, u32)> = tiles
            .iter()
            .filter(|(_, t)| (t.y0..t.y1).contains(&y))
            .map(|(_, t)| (t.x0, t.x1))
            .collect();
        spans.sort_unstable();
        let mut x = 0;
        for (x0, x1) in spans {
            if x0 > x {
                break;
            }
            x = x.max(x1);
        }
        (x < size.0).then_some((x, y))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4x3 grid of a 10 × 7 image: edges at ⌊i·10/4⌋ = 0, 2, 5, 7, 10
    /// and ⌊j·7/3⌋ = 0, 2, 4, 7; the tiles cover the image once.
    #[test]
    fn a_grid_splits_an_image_at_floor_edges() {
        let grid = TileGrid::parse("4x3").unwrap();
        let tiles = grid.tiles((10, 7)).unwrap();
        assert_eq!(tiles.len(), 12);
        assert_eq!(tiles[0], Tile::parse("0,0,2,2").unwrap());
        assert_eq!(tiles[1], Tile::parse("2,0,5,2").unwrap());
        assert_eq!(tiles[11], Tile::parse("7,4,10,7").unwrap());
        let named: Vec<_> = tiles.iter().map(|t| (t.to_string(), *t)).collect();
        assert_eq!(check_cover((10, 7), &named), Ok(()));
    }

    #[test]
    fn bad_tiles_and_grids_are_refused_with_their_cause() {
        assert!(Tile::parse("0,0,4").unwrap_err().contains("X0,Y0,X1,Y1"));
        assert!(Tile::parse("4,0,4,4").unwrap_err().contains("empty"));
        let e = Tile::parse("0,0,9,4")
            .unwrap()
            .check_within((8, 8))
            .unwrap_err();
        assert!(e.contains("0,0,9,4") && e.contains("8 × 8"), "{e}");
        assert!(TileGrid::parse("4").unwrap_err().contains("COLUMNSxROWS"));
        assert!(TileGrid::parse("0x2").is_err());
        assert!(TileGrid::parse("16385x1").unwrap_err().contains("16384"));
        let grid = TileGrid::parse("2x2").unwrap();
        assert!(grid.tile((8, 8), 4).unwrap_err().contains("0 to 3"));
        let e = TileGrid::parse("9x1").unwrap().tile((8, 8), 0).unwrap_err();
        assert!(e.contains("does not divide"), "{e}");
    }

    /// A missing tile is found with its first pixel; an overlap names both
    /// files.
    #[test]
    fn a_cover_with_a_hole_or_an_overlap_is_refused() {
        let tiles = TileGrid {
            columns: 2,
            rows: 2,
        }
        .tiles((8, 6))
        .unwrap();
        let named = |t: &[Tile]| -> Vec<(String, Tile)> {
            t.iter()
                .enumerate()
                .map(|(i, t)| (format!("t{i}.exr"), *t))
                .collect()
        };
        let e = check_cover((8, 6), &named(&tiles[..3])).unwrap_err();
        assert!(e.contains("12 of the 8 × 6") && e.contains("(4, 3)"), "{e}");
        let mut twice = tiles.clone();
        twice[3] = Tile::parse("3,3,8,6").unwrap();
        let e = check_cover((8, 6), &named(&twice)).unwrap_err();
        assert!(
            e.contains("t2.exr") && e.contains("t3.exr") && e.contains("overlap"),
            "{e}"
        );
    }

    /// A region that fits is one piece; a larger one is cut into pieces
    /// within both limits, none larger than the first, covering it once.
    #[test]
    fn pieces_stay_within_the_limits() {
        let whole = Tile::whole((100, 50));
        assert_eq!(split(whole, 4096, 1 << 20), vec![whole]);
        let pieces = split(whole, 4096, 1000);
        assert_eq!(pieces.len(), 5);
        assert_eq!(pieces[4], Tile::parse("0,40,100,50").unwrap());
        let rows = split(Tile::whole((16384, 16384)), 16384, 3840 * 2160);
        assert_eq!(
            (rows.len(), rows[0].size(), rows[32].size()),
            (33, (16384, 506), (16384, 192))
        );
        let region = Tile::parse("10,20,110,70").unwrap();
        for (max_side, max_pixels) in [(4096, 1000), (30, 1 << 20), (7, 20), (1, 1), (64, 64)] {
            let pieces = split(region, max_side, max_pixels);
            let (w0, h0) = pieces[0].size();
            for p in &pieces {
                let (w, h) = p.size();
                assert!(w <= max_side && h <= max_side, "{p}");
                assert!(p.pixels() <= max_pixels.max(u64::from(w)), "{p}");
                assert!(w <= w0 && h <= h0, "{p} is larger than the first piece");
            }
            let shifted: Vec<_> = pieces
                .iter()
                .map(|t| {
                    let t = Tile {
                        x0: t.x0 - 10,
                        x1: t.x1 - 10,
                        y0: t.y0 - 20,
                        y1: t.y1 - 20,
                    };
                    (t.to_string(), t)
                })
                .collect();
            assert_eq!(
                check_cover((100, 50), &shifted),
                Ok(()),
                "{max_side} {max_pixels}"
            );
        }
    }
}
