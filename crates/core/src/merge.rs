//! The merge of a farm's sample batches (issue 30): renders of disjoint
//! samples of one scene's one long render (`render --sample-offset`),
//! averaged weighted by their samples, as pbrt-v4's `imgtool average` and
//! Cycles' sample subsets do. The spread between the batches estimates the
//! merged image's error, as the Quality strip's does from a render's
//! frames: the merge says how far it probably is from converged. Tiles
//! of one image (`render --tile`) are put in their place, each the mean
//! of its own batches, as pbrt-v4's `imgtool assemble` and Flamenco's
//! tile merge do.

use crate::render_record::RenderRecord;
use crate::shown::shown;
use crate::tile::{Tile, check_cover};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// One input: a file's linear radiance and its render's record.
#[derive(Debug, Clone)]
pub struct Batch {
    pub path: PathBuf,
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
    /// Each pixel's estimated variance of its mean, when the file has the
    /// layer (`render --moments`).
    pub variance: Option<Vec<[f32; 3]>>,
    /// The denoiser's guides, when the file has them (`render --guides`).
    pub guides: Option<Guides>,
    pub record: RenderRecord,
    /// What reading the file changed or could not check, each line naming
    /// the file (NaN and infinite values set to 0, a record without a
    /// seal): the merge passes them on.
    pub notes: Vec<String>,
}

/// A denoiser's guides: per pixel, the mean of its samples' first-hit
/// albedo (plus emission) and shading normal.
#[derive(Debug, Clone, PartialEq)]
pub struct Guides {
    pub albedo: Vec<[f32; 3]>,
    pub normal: Vec<[f32; 3]>,
}

/// The merged image and its estimated error.
#[derive(Debug, Clone)]
pub struct Merged {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
    /// The record of the merged render: all the samples, from the first,
    /// of the whole image.
    pub record: RenderRecord,
    /// Each pixel's estimated variance of its merged mean, when every tile
    /// has one: from the files' variance layers, Σ (n_i / N)² v_i over its
    /// batches, else from the spread between its batches (two or more).
    pub variance: Option<Vec<[f32; 3]>>,
    /// The guides' means weighted as the radiance's, when every file has
    /// them.
    pub guides: Option<Guides>,
    /// The error of the merged mean, from the files' variance layers
    /// where every batch of a tile has one, else from the spread between
    /// the batches of a tile; `None` when no tile has either.
    pub error: Option<MergeError>,
    /// How many tiles were assembled (1: batches of the whole image).
    pub tiles: usize,
    /// How many of them have an estimated variance, which `error`
    /// covers.
    pub measured_tiles: usize,
    /// The batches' notes, in their order, for the user.
    pub notes: Vec<String>,
}

/// An estimate of a merged image's error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MergeError {
    /// √ of the mean over channels of the merged mean's variance.
    pub rmse: f64,
    /// √relMSE: the same relative to mean² + 0.01, as the Quality strip
    /// and the benchmarks measure it.
    pub relative: f64,
}

/// The relMSE's ε (`shaders/error_meter.wgsl`'s `REL_EPSILON`).
const REL_EPSILON: f64 = 0.01;

/// Assembles `batches` into one image: the batches of each tile averaged
/// weighted by their samples, the tiles put in their place. Refused,
/// naming the files: fewer than two, another image size, scene, frame or
/// moment, a file whose pixels are not its tile's, a batch of no samples,
/// samples counted twice (overlapping sample ranges), tiles that overlap
/// or leave pixels out, tiles of different sample counts, and more
/// samples than a record holds.
///
/// What the records say is checked against each other and against the
/// pixels' size here; whether a record's samples are the pixels' own
/// (an `spp` edited after the render) cannot be seen in the pixels, and
/// is checked by the record's seal as the file is read
/// ([`crate::render_record::check_seal`]).
pub fn merge(batches: &[Batch]) -> Result<Merged, String> {
    let [first, rest @ ..] = batches else {
        return Err("a merge needs two files or more (got none)".into());
    };
    if rest.is_empty() {
        return Err(format!(
            "a merge needs two files or more (got only {})",
            shown(&first.path.display().to_string())
        ));
    }
    let name = |b: &Batch| shown(&b.path.display().to_string());
    let image = first.record.image;
    for b in batches {
        // A batch of no samples has no mean: its weight would be 0 (or
        // every weight 0/0), and the spread would call the merge exact.
        if b.record.spp == 0 {
            return Err(format!(
                "{} holds no samples (its record says spp=0): a batch of no samples has \
                 nothing to merge",
                name(b)
            ));
        }
        if !b.record.time.is_finite() {
            return Err(format!(
                "{}: its record's time is {}, not a moment of an animation",
                name(b),
                b.record.time
            ));
        }
        if b.record.tile.size() != (b.width, b.height) {
            return Err(format!(
                "{} is {}×{}, but its record says it holds the tile {}: the file was changed \
                 after the render",
                name(b),
                b.width,
                b.height,
                b.record.tile
            ));
        }
    }
    for b in rest {
        if b.record.image != image {
            return Err(format!(
                "{} is part of a {}×{} image, but {} of a {}×{} one: batches and tiles of one \
                 render have its size",
                name(b),
                b.record.image.0,
                b.record.image.1,
                name(first),
                image.0,
                image.1
            ));
        }
        if b.record.scene != first.record.scene {
            return Err(format!(
                "{} is a render of another scene than {} (scene {} and {})",
                name(b),
                name(first),
                shown(&b.record.scene),
                shown(&first.record.scene)
            ));
        }
        if b.record.frame != first.record.frame {
            return Err(format!(
                "{} holds frame {}, but {} frame {}: merge one frame's batches",
                name(b),
                b.record.frame,
                name(first),
                first.record.frame
            ));
        }
        if b.record.time != first.record.time {
            return Err(format!(
                "{} holds the moment {} s of frame {}, but {} the moment {} s: a frame's \
                 batches trace one moment",
                name(b),
                b.record.time,
                b.record.frame,
                name(first),
                first.record.time
            ));
        }
    }
    let mut by_tile: BTreeMap<Tile, Vec<&Batch>> = BTreeMap::new();
    for b in batches {
        by_tile.entry(b.record.tile).or_default().push(b);
    }
    let groups: Vec<TileGroup> = by_tile
        .into_iter()
        .map(|(tile, mut batches)| {
            batches.sort_by_key(|b| b.record.sample_offset);
            TileGroup::new(tile, batches)
        })
        .collect::<Result<_, _>>()?;
    let named: Vec<(String, Tile)> = groups
        .iter()
        .map(|g| (name(g.batches[0]), g.tile))
        .collect();
    check_cover(image, &named)?;
    let range = |g: &TileGroup| {
        let start = g.batches[0].record.samples().start;
        start..start + g.samples
    };
    if let Some(g) = groups.iter().find(|g| range(g) != range(&groups[0])) {
        let (a, b) = (range(g), range(&groups[0]));
        return Err(format!(
            "{} (tile {}) holds samples {}..{}, but {} (tile {}) {}..{}: every tile of an \
             image needs the same samples",
            name(g.batches[0]),
            g.tile,
            a.start,
            a.end,
            name(groups[0].batches[0]),
            groups[0].tile,
            b.start,
            b.end
        ));
    }
    let samples = range(&groups[0]);
    let Ok(spp) = u32::try_from(samples.end - samples.start) else {
        return Err(format!(
            "{} and the others hold {} samples a pixel, more than a render record holds ({})",
            name(first),
            samples.end - samples.start,
            u32::MAX
        ));
    };
    let count = image.0 as usize * image.1 as usize;
    let mut out = Assembly {
        width: image.0,
        pixels: vec![[0.0f32; 4]; count],
        variance: vec![[0.0f32; 3]; count],
        guides: batches.iter().all(|b| b.guides.is_some()).then(|| Guides {
            albedo: vec![[0.0; 3]; count],
            normal: vec![[0.0; 3]; count],
        }),
        spread: SpreadSum::default(),
    };
    for group in &groups {
        group.assemble(&mut out);
    }
    let measured_tiles = groups.iter().filter(|g| g.has_variance()).count();
    let kernels = distinct(batches.iter().map(|b| b.record.kernel.as_str()));
    let adapters = distinct(batches.iter().map(|b| b.record.adapter.as_str()));
    Ok(Merged {
        width: image.0,
        height: image.1,
        pixels: out.pixels,
        record: RenderRecord {
            spp,
            sample_offset: groups[0].batches[0].record.sample_offset,
            tile: Tile::whole(image),
            kernel: kernels,
            adapter: adapters,
            ..first.record.clone()
        },
        variance: (measured_tiles == groups.len()).then_some(out.variance),
        measured_tiles,
        guides: out.guides,
        error: out.spread.error(),
        tiles: groups.len(),
        notes: batches.iter().flat_map(|b| b.notes.clone()).collect(),
    })
}

/// The values of `names` joined by ` + `, each once, in first-seen order.
fn distinct<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let mut seen: Vec<&str> = Vec::new();
    for n in names {
        if !seen.contains(&n) {
            seen.push(n);
        }
    }
    seen.join(" + ")
}

/// The batches of one tile, sorted by their first sample.
struct TileGroup<'a> {
    tile: Tile,
    batches: Vec<&'a Batch>,
    samples: u64,
}

impl<'a> TileGroup<'a> {
    /// Refused if two batches' sample ranges overlap or leave samples out
    /// between them: the merged record says one range, from the first
    /// sample to the last, which a later merge checks against (a gap
    /// would let a merge of the merge count the missing samples twice).
    fn new(tile: Tile, batches: Vec<&'a Batch>) -> Result<Self, String> {
        for pair in batches.windows(2) {
            let (a, b) = (pair[0].record.samples(), pair[1].record.samples());
            if b.start > a.end {
                return Err(format!(
                    "{} (samples {}..{}) and {} (samples {}..{}) leave samples {}..{} out: \
                     merge batches whose samples follow one another (render the missing batch)",
                    shown(&pair[0].path.display().to_string()),
                    a.start,
                    a.end,
                    shown(&pair[1].path.display().to_string()),
                    b.start,
                    b.end,
                    a.end,
                    b.start
                ));
            }
            if b.start < a.end {
                return Err(format!(
                    "{} (samples {}..{}) and {} (samples {}..{}) overlap: those samples would \
                     count twice; render batches at offsets spp apart (--sample-offset)",
                    shown(&pair[0].path.display().to_string()),
                    a.start,
                    a.end,
                    shown(&pair[1].path.display().to_string()),
                    b.start,
                    b.end
                ));
            }
        }
        let samples = batches.iter().map(|b| u64::from(b.record.spp)).sum();
        Ok(Self {
            tile,
            batches,
            samples,
        })
    }

    /// Whether the tile's variance is known: every batch has its moments,
    /// or there are two batches or more to measure their spread.
    fn has_variance(&self) -> bool {
        self.with_moments() || self.batches.len() >= 2
    }

    fn with_moments(&self) -> bool {
        self.batches.iter().all(|b| b.variance.is_some())
    }

    /// Writes the tile's mean, its variance where known and its guides
    /// into `out`, and adds the variance to the error's sums.
    fn assemble(&self, out: &mut Assembly) {
        let n = self.samples as f64;
        let (tile_width, _) = self.tile.size();
        let weight = |b: &Batch| f64::from(b.record.spp) / n;
        let weighted = |p: usize, value: &dyn Fn(&Batch, usize) -> f64| -> f64 {
            self.batches.iter().map(|b| weight(b) * value(b, p)).sum()
        };
        let moments = self.with_moments();
        for p in 0..self.tile.pixels() as usize {
            let (x, y) = (p as u32 % tile_width, p as u32 / tile_width);
            let at = (self.tile.y0 + y) as usize * out.width as usize + (self.tile.x0 + x) as usize;
            for c in 0..4 {
                let mean = weighted(p, &|b, p| f64::from(b.pixels[p][c]));
                out.pixels[at][c] = mean as f32;
                if c == 3 || !mean.is_finite() {
                    continue;
                }
                let variance = if moments {
                    // Independent batches: Var(Σ w_i x_i) = Σ w_i² Var(x_i).
                    self.batches
                        .iter()
                        .filter_map(|b| {
                            Some(weight(b).powi(2) * f64::from(b.variance.as_ref()?[p][c]))
                        })
                        .sum()
                } else if self.batches.len() >= 2 {
                    // Each batch's mean x_i of n_i samples has variance
                    // σ²/n_i: Σ n_i (x_i − m)² / (K − 1) estimates σ², and
                    // the merged mean's variance is σ² / N.
                    let squares: f64 = self
                        .batches
                        .iter()
                        .map(|b| {
                            f64::from(b.record.spp) * (f64::from(b.pixels[p][c]) - mean).powi(2)
                        })
                        .sum();
                    squares / ((self.batches.len() - 1) as f64 * n)
                } else {
                    continue;
                };
                out.variance[at][c] = variance as f32;
                out.spread.add(variance, mean);
            }
            if let Some(guides) = out.guides.as_mut() {
                for c in 0..3 {
                    let guide = |pick: fn(&Guides) -> &Vec<[f32; 3]>| {
                        weighted(p, &|b, p| {
                            b.guides.as_ref().map_or(0.0, |g| f64::from(pick(g)[p][c]))
                        }) as f32
                    };
                    guides.albedo[at][c] = guide(|g| &g.albedo);
                    guides.normal[at][c] = guide(|g| &g.normal);
                }
            }
        }
    }
}

/// The merged image under assembly, tile by tile.
struct Assembly {
    width: u32,
    pixels: Vec<[f32; 4]>,
    variance: Vec<[f32; 3]>,
    guides: Option<Guides>,
    spread: SpreadSum,
}

/// Sums of the per-channel variances of the merged means.
#[derive(Default)]
struct SpreadSum {
    variance: f64,
    relative: f64,
    channels: u64,
}

impl SpreadSum {
    fn add(&mut self, variance: f64, mean: f64) {
        self.variance += variance;
        self.relative += variance / (mean * mean + REL_EPSILON);
        self.channels += 1;
    }

    fn error(&self) -> Option<MergeError> {
        let per_channel = |sum: f64| (sum / self.channels as f64).sqrt();
        (self.channels > 0).then(|| MergeError {
            rmse: per_channel(self.variance),
            relative: per_channel(self.relative),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A batch of a 2×1 image, every pixel `value`.
    fn batch(name: &str, offset: u32, spp: u32, value: f32) -> Batch {
        tile_batch(name, Tile::whole((2, 1)), (2, 1), offset, spp, value)
    }

    fn tile_batch(
        name: &str,
        tile: Tile,
        image: (u32, u32),
        offset: u32,
        spp: u32,
        value: f32,
    ) -> Batch {
        let (width, height) = tile.size();
        Batch {
            path: PathBuf::from(name),
            width,
            height,
            pixels: vec![[value, value, value, 1.0]; tile.pixels() as usize],
            variance: None,
            guides: None,
            notes: Vec::new(),
            record: RenderRecord {
                spp,
                sample_offset: offset,
                image,
                tile,
                frame: 0,
                time: 0.0,
                scene: "0123456789abcdef".into(),
                kernel: "fragment".into(),
                adapter: "llvmpipe".into(),
                version: "0.1.0".into(),
            },
        }
    }

    /// Batches of 1, 1 and 2 samples of values 1, 3 and 2: the mean
    /// weighted by samples is 2; the spread Σ n_i (x_i − 2)² = 2 over
    /// K − 1 = 2 estimates σ² = 1, so the merged variance is 1/4: RMSE
    /// 0.5, relative 0.5 / √(4 + 0.01). The record counts 4 samples from
    /// the first.
    #[test]
    fn batches_average_by_their_samples_with_the_spread_as_error() {
        let merged = merge(&[
            batch("b.exr", 1, 1, 3.0),
            batch("a.exr", 0, 1, 1.0),
            batch("c.exr", 2, 2, 2.0),
        ])
        .unwrap();
        assert_eq!(merged.pixels, vec![[2.0, 2.0, 2.0, 1.0]; 2]);
        assert_eq!(
            merged.variance,
            Some(vec![[0.25; 3]; 2]),
            "per pixel, from the spread"
        );
        assert_eq!(merged.guides, None);
        assert_eq!((merged.record.spp, merged.record.sample_offset), (4, 0));
        let error = merged.error.unwrap();
        assert!((error.rmse - 0.5).abs() < 1e-12, "{}", error.rmse);
        let relative = 0.5 / (4.0f64 + REL_EPSILON).sqrt();
        assert!((error.relative - relative).abs() < 1e-12);
    }

    /// Two tiles of a 3×2 image, the left one in two batches: each pixel
    /// is its tile's mean, in its place; the error comes from the left
    /// tile only (the right has one batch).
    #[test]
    fn tiles_are_put_in_their_place() {
        let (left, right) = (
            Tile::parse("0,0,1,2").unwrap(),
            Tile::parse("1,0,3,2").unwrap(),
        );
        let merged = merge(&[
            tile_batch("r.exr", right, (3, 2), 0, 4, 5.0),
            tile_batch("l0.exr", left, (3, 2), 0, 2, 1.0),
            tile_batch("l1.exr", left, (3, 2), 2, 2, 3.0),
        ])
        .unwrap();
        let v = |x: f32| [x, x, x, 1.0];
        assert_eq!(
            merged.pixels,
            vec![v(2.0), v(5.0), v(5.0), v(2.0), v(5.0), v(5.0)]
        );
        assert_eq!((merged.width, merged.height, merged.tiles), (3, 2, 2));
        assert_eq!(merged.record.tile, Tile::whole((3, 2)));
        assert_eq!(merged.record.spp, 4);
        // Σ 2·(x − 2)² = 4 over K − 1 = 1, over N = 4: variance 1.
        assert!((merged.error.unwrap().rmse - 1.0).abs() < 1e-12);
        let alone = merge(&[
            tile_batch("r.exr", right, (3, 2), 0, 4, 5.0),
            tile_batch("l.exr", left, (3, 2), 0, 4, 1.0),
        ])
        .unwrap();
        assert_eq!(alone.error, None, "one batch a tile: no spread to measure");
        assert_eq!(alone.variance, None);
        assert_eq!((merged.measured_tiles, alone.measured_tiles), (1, 0));
    }

    /// Batches with their moments: the merged variance is Σ (n_i / N)²
    /// v_i, even for one batch a tile: 2 and 2 samples of variances 0.4
    /// and 0.8 give 0.25 · 0.4 + 0.25 · 0.8 = 0.3.
    #[test]
    fn moments_give_the_merged_variance() {
        let mut a = batch("a.exr", 0, 2, 1.0);
        let mut b = batch("b.exr", 2, 2, 3.0);
        a.variance = Some(vec![[0.4; 3]; 2]);
        b.variance = Some(vec![[0.8; 3]; 2]);
        let merged = merge(&[a, b]).unwrap();
        let variance = merged.variance.unwrap();
        assert!(
            variance.iter().flatten().all(|v| (v - 0.3).abs() < 1e-6),
            "{variance:?}"
        );
        let rmse = merged.error.unwrap().rmse;
        assert!((rmse - 0.3f64.sqrt()).abs() < 1e-6, "{rmse}");
    }

    /// Every refusal names its files and its cause.
    #[test]
    fn bad_merges_are_refused_naming_the_files() {
        let a = batch("a.exr", 0, 4, 1.0);
        let e = merge(std::slice::from_ref(&a)).unwrap_err();
        assert!(e.contains("two files") && e.contains("a.exr"), "{e}");
        let wide = tile_batch("wide.exr", Tile::whole((3, 1)), (3, 1), 4, 4, 1.0);
        let e = merge(&[a.clone(), wide]).unwrap_err();
        assert!(
            e.contains("wide.exr is part of a 3×1 image") && e.contains("a.exr of a 2×1"),
            "{e}"
        );
        let mut cut = batch("cut.exr", 4, 4, 1.0);
        cut.width = 1;
        let e = merge(&[a.clone(), cut]).unwrap_err();
        assert!(
            e.contains("cut.exr is 1×1") && e.contains("tile 0,0,2,1"),
            "{e}"
        );
        let mut other = batch("other.exr", 4, 4, 1.0);
        other.record.scene = "fedcba9876543210".into();
        let e = merge(&[a.clone(), other]).unwrap_err();
        assert!(e.contains("other.exr is a render of another scene"), "{e}");
        let mut later = batch("later.exr", 4, 4, 1.0);
        later.record.frame = 7;
        let e = merge(&[a.clone(), later]).unwrap_err();
        assert!(e.contains("later.exr holds frame 7"), "{e}");
        let overlapping = batch("again.exr", 2, 4, 1.0);
        let e = merge(&[a.clone(), overlapping]).unwrap_err();
        assert!(
            e.contains("a.exr (samples 0..4) and again.exr (samples 2..6) overlap"),
            "{e}"
        );
        let far = batch("far.exr", 8, 4, 1.0);
        let e = merge(&[a, far]).unwrap_err();
        assert!(
            e.contains("a.exr (samples 0..4) and far.exr (samples 8..12) leave samples 4..8 out"),
            "{e}"
        );
    }

    /// A batch of no samples is refused (it merged, weighing 0, and the
    /// spread of the other batch around itself called the merge exact:
    /// "0.000 %"); so are a batch of another moment of the frame, a time
    /// that is no moment, and more samples than a record holds (which the
    /// merged record cut to 2³² − 1).
    #[test]
    fn batches_their_records_disagree_on_are_refused() {
        let a = batch("a.exr", 0, 4, 1.0);
        let empty = batch("empty.exr", 4, 0, 3.0);
        let e = merge(&[a.clone(), empty]).unwrap_err();
        assert!(
            e.contains("empty.exr holds no samples (its record says spp=0)"),
            "{e}"
        );
        let e = merge(&[batch("z0.exr", 0, 0, 1.0), batch("z1.exr", 0, 0, 2.0)]).unwrap_err();
        assert!(e.contains("z0.exr holds no samples"), "{e}");
        let mut moved = batch("moved.exr", 4, 4, 1.0);
        moved.record.time = 0.5;
        let e = merge(&[a.clone(), moved]).unwrap_err();
        assert!(
            e.contains("moved.exr holds the moment 0.5 s of frame 0, but a.exr the moment 0 s"),
            "{e}"
        );
        let mut never = batch("never.exr", 4, 4, 1.0);
        never.record.time = f32::NAN;
        let e = merge(&[a, never]).unwrap_err();
        assert!(e.contains("never.exr: its record's time is NaN"), "{e}");
        let e = merge(&[
            batch("x.exr", 0, u32::MAX, 1.0),
            batch("y.exr", u32::MAX, 1, 1.0),
        ])
        .unwrap_err();
        assert!(e.contains("hold 4294967296 samples a pixel"), "{e}");
    }

    /// The batches' notes reach the merge's; a file name or a record's
    /// text with control characters is shown escaped in a refusal, so
    /// that a file cannot drive the terminal that prints it.
    #[test]
    fn notes_pass_on_and_record_text_is_shown_escaped() {
        let mut a = batch("a.exr", 0, 4, 1.0);
        a.notes = vec!["a.exr: 1 NaN value set to 0".into()];
        let merged = merge(&[a.clone(), batch("b.exr", 4, 4, 1.0)]).unwrap();
        assert_eq!(merged.notes, a.notes);
        let mut hostile = batch("c\u{1b}]0;owned\u{7}.exr", 4, 4, 1.0);
        hostile.record.scene = "\u{1b}[2J\r".into();
        let e = merge(&[a, hostile]).unwrap_err();
        assert!(
            !e.chars().any(char::is_control)
                && e.contains("c\\u{1b}]0;owned\\u{7}.exr is a render of another scene")
                && e.contains("scene \\u{1b}[2J\\r and"),
            "{e}"
        );
    }

    /// Tiles that leave a pixel out, overlap, or differ in samples.
    #[test]
    fn bad_tile_sets_are_refused_naming_the_files() {
        let image = (4, 1);
        let t = |s: &str| Tile::parse(s).unwrap();
        let e = merge(&[
            tile_batch("t0.exr", t("0,0,1,1"), image, 0, 4, 1.0),
            tile_batch("t1.exr", t("1,0,2,1"), image, 0, 4, 1.0),
        ])
        .unwrap_err();
        assert!(
            e.contains("leave 2 of the 4 × 1") && e.contains("(2, 0)"),
            "{e}"
        );
        let e = merge(&[
            tile_batch("t0.exr", t("0,0,3,1"), image, 0, 4, 1.0),
            tile_batch("t1.exr", t("2,0,4,1"), image, 0, 4, 1.0),
        ])
        .unwrap_err();
        assert!(
            e.contains("t0.exr (tile 0,0,3,1) and t1.exr (tile 2,0,4,1) overlap"),
            "{e}"
        );
        let e = merge(&[
            tile_batch("t0.exr", t("0,0,2,1"), image, 0, 4, 1.0),
            tile_batch("t1.exr", t("2,0,4,1"), image, 0, 8, 1.0),
        ])
        .unwrap_err();
        assert!(
            e.contains("t1.exr (tile 2,0,4,1) holds samples 0..8"),
            "{e}"
        );
        let e = merge(&[
            tile_batch("t0.exr", t("0,0,2,1"), image, 0, 4, 1.0),
            tile_batch("t1.exr", t("2,0,4,1"), image, 4, 4, 1.0),
        ])
        .unwrap_err();
        assert!(
            e.contains("t1.exr (tile 2,0,4,1) holds samples 4..8"),
            "{e}"
        );
    }
}
