//! `marbre noise`: evaluates noise at points read from stdin, on the GPU (the
//! real WGSL through the compute harness, in f32) or on the CPU reference
//! (in f64: Perlin's own Java is double precision, and far from the origin
//! f32 has lost the noise's digits).
//!
//! The points are read, evaluated and printed in batches of
//! [`BATCH_POINTS`], so that memory stays bounded and values come out while
//! a pipe still sends points (issue 47: 20 million points once held 5 GB
//! and then panicked, over the GPU's binding and dispatch limits, which
//! the harness now splits its work to).

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use glam::DVec3;
use marbre_core::noise::fractal::{FractalShape, fractal_sum_f64, noise_f64};
use marbre_core::noise::points::read_points;
use marbre_core::noise::{
    Evolution, FractalParams, HashKind, NoiseKind, NoiseSettings, Progression, noise4_f64,
};
use marbre_render::gpu::GpuContext;
use marbre_render::gpu::harness::noise::{Evaluate, NoiseEvaluator};
use std::io::{BufRead, BufWriter, Write};
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum KindArg {
    Gradient,
    Perlin,
    /// Perlin's noise with the gradients of Massal's tutorial.
    PerlinMassal,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ProgressionArg {
    Geometric,
    Linear,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum HashArg {
    Pcg,
    PcgTiled,
    Sin,
}

#[derive(Args, Debug)]
pub struct NoiseArgs {
    #[arg(long, value_enum, default_value = "gradient")]
    pub kind: KindArg,
    #[arg(long, value_enum, default_value = "pcg")]
    pub hash: HashArg,
    #[arg(long, default_value_t = 6.0)]
    pub octaves: f32,
    #[arg(long, default_value_t = 1.0)]
    pub frequency: f32,
    #[arg(long, default_value_t = 1.0)]
    pub amplitude: f32,
    #[arg(long, default_value_t = 0.5)]
    pub persistence: f32,
    #[arg(long, default_value_t = 2.0)]
    pub lacunarity: f32,
    /// How the octaves progress: geometric (frequency · lacunarityⁱ,
    /// amplitude · persistenceⁱ) or linear (Massal's harmonics: level k at
    /// frequency · k, weighted amplitude / k).
    #[arg(long, value_enum, default_value = "geometric")]
    pub progression: ProgressionArg,
    /// Print the fractal sum (fBm) instead of one octave of noise.
    #[arg(long, conflicts_with = "turbulence")]
    pub fbm: bool,
    /// Print turbulence (a sum of |noise|) instead of one octave of noise.
    #[arg(long)]
    pub turbulence: bool,
    /// Evaluate the evolving (4D) noise at this w (issue 29): one octave is
    /// the 4D noise at (x, y, z, w), the sums evolving ones.
    #[arg(long)]
    pub w: Option<f32>,
    /// With --w, the w lattice's period in cells, as a loop makes it.
    #[arg(long, requires = "w", value_parser = clap::value_parser!(u32).range(1..=i64::from(Evolution::MAX_PERIOD)))]
    pub w_period: Option<u32>,
    /// Evaluate with the CPU reference (double precision) instead of the
    /// shader (single precision); both print 9 significant digits.
    #[arg(long)]
    pub cpu: bool,
    /// Instead of reading points, draw the far-from-the-origin figure (the
    /// sin hash against pcg3d, GPU against CPU) to this PNG.
    #[arg(long, value_name = "PNG")]
    pub stability_figure: Option<PathBuf>,
}

impl NoiseArgs {
    fn settings(&self) -> NoiseSettings {
        NoiseSettings {
            kind: match self.kind {
                KindArg::Gradient => NoiseKind::Gradient,
                KindArg::Perlin => NoiseKind::Perlin,
                KindArg::PerlinMassal => NoiseKind::PerlinMassal,
            },
            hash: match self.hash {
                HashArg::Pcg => HashKind::Pcg,
                HashArg::PcgTiled => HashKind::PcgTiled,
                HashArg::Sin => HashKind::Sin,
            },
            fractal: FractalParams {
                octaves: self.octaves,
                frequency: self.frequency,
                amplitude: self.amplitude,
                persistence: self.persistence,
                lacunarity: self.lacunarity,
                progression: match self.progression {
                    ProgressionArg::Geometric => Progression::Geometric,
                    ProgressionArg::Linear => Progression::Linear,
                },
                ..Default::default()
            },
            evolution: self.w.map(|w| Evolution {
                w,
                speed: 0.0,
                w_period: self.w_period,
                ..Evolution::default()
            }),
        }
    }

    fn what(&self) -> Evaluate {
        if self.fbm {
            Evaluate::Fbm
        } else if self.turbulence {
            Evaluate::Turbulence
        } else if self.w.is_some() {
            Evaluate::Noise4
        } else {
            Evaluate::Noise
        }
    }
}

/// The CPU reference for the same request, in double precision.
pub fn evaluate_cpu(settings: &NoiseSettings, what: Evaluate, points: &[DVec3]) -> Vec<f64> {
    points
        .iter()
        .map(|&p| match what {
            Evaluate::Fbm => fractal_sum_f64(p, settings, FractalShape::Signed),
            Evaluate::Turbulence => fractal_sum_f64(p, settings, FractalShape::Absolute),
            _ => match settings.evolution {
                Some(e) => noise4_f64(
                    p,
                    f64::from(e.w_now()),
                    settings.kind,
                    settings.hash,
                    e.w_period,
                ),
                None => noise_f64(p, settings.kind, settings.hash),
            },
        })
        .collect()
}

/// How many points are read before they are evaluated and printed: a
/// few MiB of points, values and buffers at a time, and one GPU dispatch
/// large enough that its overhead does not count.
pub const BATCH_POINTS: usize = 1 << 16;

pub fn run(args: &NoiseArgs) -> Result<()> {
    if let Some(path) = &args.stability_figure {
        return super::noise_figure::write(path);
    }
    let settings = args.settings();
    let what = args.what();
    let mut gpu: Option<GpuNoise> = None;
    evaluate_input(
        std::io::stdin().lock(),
        &mut BufWriter::new(std::io::stdout().lock()),
        &mut std::io::stderr().lock(),
        BATCH_POINTS,
        |points| {
            if args.cpu {
                return Ok(evaluate_cpu(&settings, what, points));
            }
            let noise = match gpu.take() {
                Some(noise) => noise,
                None => GpuNoise::open(&settings, what)?,
            };
            let values = noise.evaluate(points);
            gpu = Some(noise);
            values
        },
    )
}

/// The shader's noise on a device, opened at the first batch and kept for
/// the others.
struct GpuNoise {
    ctx: GpuContext,
    harness: NoiseEvaluator,
}

impl GpuNoise {
    fn open(settings: &NoiseSettings, what: Evaluate) -> Result<Self> {
        Self::on(GpuContext::headless()?, settings, what)
    }

    fn on(ctx: GpuContext, settings: &NoiseSettings, what: Evaluate) -> Result<Self> {
        let harness = NoiseEvaluator::new(&ctx, settings, what)?;
        Ok(Self { ctx, harness })
    }

    /// The shader's values at `points` (rounded to f32 first, as the
    /// shader sees them), widened to f64 exactly.
    fn evaluate(&self, points: &[DVec3]) -> Result<Vec<f64>> {
        let points: Vec<_> = points.iter().map(|p| p.as_vec3()).collect();
        Ok(self
            .harness
            .evaluate_scalar(&self.ctx, &points)?
            .into_iter()
            .map(f64::from)
            .collect())
    }
}

/// Reads the points of `input`, reporting each bad line on `err` by its
/// number and what is wrong with it, and writes the value `evaluate`
/// gives at each good one to `out`, one a line in their order: `batch`
/// points at a time, each batch flushed once written, so that at most one
/// batch is held (`evaluate` is not called when there is none: no GPU is
/// opened for nothing). Any bad line fails the run at the end, once the
/// good ones are written, so that one typo neither hides the other values
/// nor passes unnoticed.
fn evaluate_input(
    input: impl BufRead,
    out: &mut impl Write,
    err: &mut impl Write,
    batch: usize,
    mut evaluate: impl FnMut(&[DVec3]) -> Result<Vec<f64>>,
) -> Result<()> {
    let mut points = Vec::with_capacity(batch);
    let (mut good, mut bad) = (0usize, 0usize);
    let mut write_batch = |points: &mut Vec<DVec3>| -> Result<()> {
        for v in evaluate(points)? {
            writeln!(out, "{}", format_value(v))?;
        }
        out.flush()?;
        good += points.len();
        points.clear();
        Ok(())
    };
    for line in read_points(input) {
        let line = line.context("reading stdin")?;
        match line.point {
            Ok(p) => {
                points.push(p);
                if points.len() == batch {
                    write_batch(&mut points)?;
                }
            }
            Err(why) => {
                bad += 1;
                writeln!(err, "marbre noise: line {}: {why}", line.number)?;
            }
        }
    }
    if !points.is_empty() {
        write_batch(&mut points)?;
    }
    if bad > 0 {
        bail!(
            "{bad} input line(s) were not points x,y,z (listed above); the {good} others were \
             evaluated"
        );
    }
    Ok(())
}

/// How many significant digits both paths print. The shader computes in
/// f32, and 9 significant digits tell every f32 apart (they read back to
/// the same f32): fewer would drop digits it computed, more would print
/// digits it never computed. The CPU's f64 values print the same way, so
/// the two outputs compare line by line.
const SIGNIFICANT_DIGITS: usize = 9;

/// `v` with [`SIGNIFICANT_DIGITS`] significant digits: positional between
/// 1e-4 and 1e9, as C's `%g` chooses, scientific outside (far-out
/// amplitudes, values that round to tiny numbers); non-finite values as
/// Rust writes them.
fn format_value(v: f64) -> String {
    let scientific = format!("{v:.*e}", SIGNIFICANT_DIGITS - 1);
    let Some(exponent) = scientific
        .split_once('e')
        .and_then(|(_, e)| e.parse::<i32>().ok())
    else {
        return scientific;
    };
    let digits = SIGNIFICANT_DIGITS as i32;
    if (-4..digits).contains(&exponent) {
        let decimals = (digits - 1 - exponent) as usize;
        format!("{v:.decimals$}")
    } else {
        scientific
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;
    use marbre_core::noise::improved_noise_f32;
    use marbre_render::gpu::harness::noise::evaluate_scalar;
    use marbre_render::gpu::testing::gpu_or_skip;
    use std::cell::RefCell;
    use std::io::Read;
    use std::rc::Rc;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: NoiseArgs,
    }

    /// `marbre noise` with these flags.
    fn args(flags: &[&str]) -> NoiseArgs {
        Cli::parse_from(std::iter::once("noise").chain(flags.iter().copied())).args
    }

    /// Perlin's Java reference points, `x y z value` (80 of them, the last
    /// 16 at |c| up to 1e4), as `marbre noise` reads them: `x,y,z` lines.
    fn reference() -> (Vec<DVec3>, Vec<f64>) {
        let text = include_str!("../../core/tests/data/perlin/reference_points.txt");
        let rows: Vec<Vec<f64>> = text
            .lines()
            .map(|l| l.split(' ').map(|v| v.parse().unwrap()).collect())
            .collect();
        let input: String = rows
            .iter()
            .map(|r| format!("{},{},{}\n", r[0], r[1], r[2]))
            .collect();
        let points = read_points(input.as_bytes())
            .map(|line| line.unwrap().point.unwrap())
            .collect();
        (points, rows.iter().map(|r| r[3]).collect())
    }

    #[test]
    fn the_cpu_reference_matches_perlins_java_far_from_the_origin() {
        let (points, expected) = reference();
        let args = args(&["--kind", "perlin", "--cpu"]);
        let values = evaluate_cpu(&args.settings(), args.what(), &points);
        for ((p, got), want) in points.iter().zip(&values).zip(&expected) {
            assert!(
                (got - want).abs() <= 1e-9,
                "noise({p}) = {got}, Java {want}"
            );
        }
        // Single precision is no reference out there: the same points in
        // f32 miss Perlin's values by far more.
        let worst_f32 = points
            .iter()
            .zip(&expected)
            .filter(|(p, _)| p.abs().max_element() > 1000.0)
            .map(|(p, want)| {
                let p = p.as_vec3();
                (f64::from(improved_noise_f32(p.x, p.y, p.z)) - want).abs()
            })
            .fold(0.0, f64::max);
        assert!(worst_f32 > 1e-4, "f32 is off by only {worst_f32:e}");
    }

    #[test]
    fn fractal_sums_of_one_octave_are_the_noise_itself() {
        let (points, _) = reference();
        let args = args(&["--kind", "perlin", "--cpu", "--octaves", "1"]);
        let noise = evaluate_cpu(&args.settings(), Evaluate::Noise, &points);
        let fbm = evaluate_cpu(&args.settings(), Evaluate::Fbm, &points);
        let turbulence = evaluate_cpu(&args.settings(), Evaluate::Turbulence, &points);
        for ((n, f), t) in noise.iter().zip(&fbm).zip(&turbulence) {
            assert_eq!(n, f);
            assert_eq!(n.abs(), *t);
        }
    }

    /// `--w` evaluates the 4D noise at that w (one octave, or an evolving
    /// sum), and `--w-period` makes it periodic in w.
    #[test]
    fn w_flags_give_the_4d_noise() {
        let (points, _) = reference();
        let evolving = args(&["--cpu", "--w", "1.25", "--w-period", "3"]);
        assert_eq!(evolving.what(), Evaluate::Noise4);
        let got = evaluate_cpu(&evolving.settings(), evolving.what(), &points);
        let plus_period = args(&["--cpu", "--w", "4.25", "--w-period", "3"]);
        assert_eq!(
            got,
            evaluate_cpu(&plus_period.settings(), plus_period.what(), &points)
        );
        for (p, v) in points.iter().zip(&got) {
            let want = noise4_f64(*p, 1.25, NoiseKind::Gradient, HashKind::Pcg, Some(3));
            assert_eq!(*v, want);
        }
        let still = args(&["--cpu"]);
        assert_ne!(got, evaluate_cpu(&still.settings(), still.what(), &points));
    }

    /// `--progression linear` with Massal's knobs is his turbulence, as the
    /// panel's recipe (`NoiseSettings::massal`) computes it.
    #[test]
    fn linear_progression_flags_give_massals_turbulence() {
        let args = args(&[
            "--kind",
            "perlin-massal",
            "--progression",
            "linear",
            "--octaves",
            "9",
            "--frequency",
            "0.05",
            "--turbulence",
            "--cpu",
        ]);
        assert_eq!(args.settings(), NoiseSettings::massal(0.05));
        let points = [
            DVec3::new(120.5, 33.25, 7.0),
            DVec3::new(-40.0, 250.0, 99.9),
        ];
        let values = evaluate_cpu(&args.settings(), args.what(), &points);
        for (p, got) in points.iter().zip(values) {
            let his: f64 = (1..10)
                .map(|level| {
                    let f = f64::from(level) * f64::from(0.05_f32);
                    marbre_core::noise::perlin::improved_noise_massal(f * p.x, f * p.y, f * p.z)
                        .abs()
                        / f64::from(level)
                })
                .sum();
            assert!((got - his).abs() < 1e-12, "{p}: {got} vs {his}");
        }
    }

    /// `evaluate_input` on `input` with `evaluate`, in batches of
    /// [`BATCH_POINTS`]: (its result, stdout, stderr).
    fn evaluate_text(
        input: &str,
        evaluate: impl FnMut(&[DVec3]) -> Result<Vec<f64>>,
    ) -> (Result<()>, String, String) {
        let (mut out, mut err) = (Vec::new(), Vec::new());
        let result = evaluate_input(input.as_bytes(), &mut out, &mut err, BATCH_POINTS, evaluate);
        let text = |bytes| String::from_utf8(bytes).unwrap();
        (result, text(out), text(err))
    }

    /// A bad line is reported by its number and what is wrong, the good
    /// lines around it are still evaluated and printed, and the run fails
    /// at the end.
    #[test]
    fn bad_lines_are_reported_and_the_good_ones_still_evaluated() {
        let args = args(&["--kind", "perlin", "--cpu"]);
        let input = "3.14,42,7\n1,2\n# a comment\n0.5 x 0.5\n0.25,0.5,0.75\n";
        let (result, out, err) = evaluate_text(input, |points| {
            Ok(evaluate_cpu(&args.settings(), args.what(), points))
        });
        // The same input without its bad lines.
        let good: Vec<DVec3> = read_points("3.14,42,7\n0.25,0.5,0.75\n".as_bytes())
            .map(|line| line.unwrap().point.unwrap())
            .collect();
        let expected: Vec<String> = evaluate_cpu(&args.settings(), args.what(), &good)
            .into_iter()
            .map(format_value)
            .collect();
        assert_eq!(out.lines().collect::<Vec<_>>(), expected);
        // Perlin's own value at (3.14, 42, 7) is 0.136919958784.
        assert_eq!(expected[0], "0.136919959");
        assert_eq!(
            err,
            "marbre noise: line 2: expected 3 numbers x,y,z, found 2\n\
             marbre noise: line 4: `x` is not a number (a line is x,y,z)\n"
        );
        let e = result.unwrap_err().to_string();
        assert!(e.starts_with("2 input line(s) were not points"), "{e}");
        assert!(e.ends_with("the 2 others were evaluated"), "{e}");
    }

    #[test]
    fn good_input_succeeds_and_no_points_evaluate_nothing() {
        let (result, out, err) = evaluate_text("1,2,3\n", |points| Ok(vec![0.5; points.len()]));
        assert!(result.is_ok());
        assert_eq!((out.as_str(), err.as_str()), ("0.500000000\n", ""));
        let (result, out, _) = evaluate_text("# nothing\nx\n", |_| panic!("evaluated"));
        assert!(result.is_err());
        assert_eq!(out, "");
    }

    /// Nine significant digits, positional where `%g` would be, and
    /// every f32 reads back from its text exactly: the precision the
    /// shader's values justify.
    #[test]
    fn values_print_with_nine_significant_digits_that_keep_every_f32() {
        assert_eq!(format_value(0.136919958784), "0.136919959");
        assert_eq!(format_value(-1.5), "-1.50000000");
        assert_eq!(format_value(0.0), "0.00000000");
        assert_eq!(format_value(123.456), "123.456000");
        assert_eq!(format_value(0.00012345678912), "0.000123456789");
        assert_eq!(format_value(1.0e-5), "1.00000000e-5");
        assert_eq!(format_value(2.5e9), "2.50000000e9");
        assert_eq!(format_value(f64::NAN), "NaN");
        let mut x = 1.0e-30_f32;
        while x < 1.0e30 {
            for v in [x, -x, x.next_up(), x * 1.234_567_9] {
                let text = format_value(f64::from(v));
                assert_eq!(text.parse::<f32>().unwrap(), v, "{v:e} printed {text}");
            }
            x *= 1.37;
        }
    }

    /// The GPU path prints the shader's f32 values in the same format,
    /// each reading back to exactly the value the shader returned.
    #[test]
    fn the_gpu_path_prints_the_shaders_values_exactly() {
        let Some(ctx) = gpu_or_skip("the_gpu_path_prints_the_shaders_values_exactly") else {
            return;
        };
        let args = args(&["--kind", "perlin"]);
        let (points, _) = reference();
        let input: String = points
            .iter()
            .map(|p| format!("{},{},{}\n", p.x, p.y, p.z))
            .collect();
        let gpu = GpuNoise::on(ctx.clone(), &args.settings(), args.what()).unwrap();
        let (result, out, err) = evaluate_text(&input, |points| gpu.evaluate(points));
        result.unwrap();
        assert_eq!(err, "");
        let f32_points: Vec<_> = points.iter().map(|p| p.as_vec3()).collect();
        let shader = evaluate_scalar(&ctx, &args.settings(), args.what(), &f32_points).unwrap();
        let printed: Vec<f32> = out.lines().map(|l| l.parse().unwrap()).collect();
        assert_eq!(printed, shader);
        assert!(
            out.lines().all(|l| l == format_value(l.parse().unwrap())),
            "{out}"
        );
    }

    /// The text of `count` points, generated as it is read (a pipe's
    /// worth of points never held whole): point `i` is a fixed
    /// pseudo-random spread in [-8, 8)³, written to 6 decimals.
    struct GeneratedPoints {
        next: usize,
        count: usize,
        line: Vec<u8>,
        at: usize,
    }

    impl GeneratedPoints {
        fn new(count: usize) -> Self {
            Self {
                next: 0,
                count,
                line: Vec::new(),
                at: 0,
            }
        }

        fn point(i: usize) -> DVec3 {
            let c = |k: u64| {
                let h = (i as u64 * 3 + k).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 40;
                (h % 16_000_000) as f64 * 1e-6 - 8.0
            };
            DVec3::new(c(0), c(1), c(2))
        }
    }

    impl Read for GeneratedPoints {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            if self.at == self.line.len() {
                if self.next == self.count {
                    return Ok(0);
                }
                let p = Self::point(self.next);
                self.line = format!("{:.6},{:.6},{:.6}\n", p.x, p.y, p.z).into_bytes();
                self.at = 0;
                self.next += 1;
            }
            let n = buf.len().min(self.line.len() - self.at);
            buf[..n].copy_from_slice(&self.line[self.at..self.at + n]);
            self.at += n;
            Ok(n)
        }
    }

    /// More points than one GPU dispatch covers (65535 workgroups of 64:
    /// 4,194,240; the old single dispatch panicked at 4,194,304) give the
    /// GPU's values in order, each within f32's error of the CPU
    /// reference's for the same point.
    #[test]
    fn the_gpu_path_over_one_dispatch_gives_the_cpu_references_values() {
        let Some(ctx) =
            gpu_or_skip("the_gpu_path_over_one_dispatch_gives_the_cpu_references_values")
        else {
            return;
        };
        let count = 65535 * 64 + 65;
        assert!(count > 4_194_304);
        let args = args(&["--kind", "perlin"]);
        let (settings, what) = (args.settings(), args.what());
        let gpu = GpuNoise::on(ctx, &settings, what).unwrap();
        let mut out = Vec::new();
        let input = std::io::BufReader::new(GeneratedPoints::new(count));
        evaluate_input(input, &mut out, &mut Vec::new(), BATCH_POINTS, |points| {
            gpu.evaluate(points)
        })
        .unwrap();
        let mut lines = 0;
        let mut worst = 0.0_f64;
        for (i, line) in out
            .split(|&b| b == b'\n')
            .filter(|l| !l.is_empty())
            .enumerate()
        {
            let printed: f64 = std::str::from_utf8(line).unwrap().parse().unwrap();
            // The point as printed, 6 decimals, is the point read.
            let p = GeneratedPoints::point(i);
            let p = DVec3::new(round6(p.x), round6(p.y), round6(p.z));
            let cpu = evaluate_cpu(&settings, what, &[p])[0];
            worst = worst.max((printed - cpu).abs());
            assert!(
                (printed - cpu).abs() < 1e-4,
                "point {i} {p}: GPU {printed}, CPU {cpu}"
            );
            lines += 1;
        }
        assert_eq!(lines, count);
        assert!(worst > 0.0, "f32 and f64 agree exactly everywhere");
    }

    /// `x` as its 6-decimal text reads back.
    fn round6(x: f64) -> f64 {
        format!("{x:.6}").parse().unwrap()
    }

    /// Output whose flushed bytes are kept apart from those still
    /// buffered: what a reader at the other end of a pipe has seen.
    #[derive(Clone, Default)]
    struct Flushed {
        seen: Rc<RefCell<Vec<u8>>>,
        pending: Vec<u8>,
    }

    impl Write for Flushed {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            self.pending.extend_from_slice(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            self.seen.borrow_mut().append(&mut self.pending);
            Ok(())
        }
    }

    /// Input that gives one batch of points, then, asked for more, notes
    /// how many values the output has shown by then, and gives one more
    /// point.
    struct ThenLook {
        first: std::io::Cursor<Vec<u8>>,
        output: Rc<RefCell<Vec<u8>>>,
        shown_before_more: Option<usize>,
        rest: std::io::Cursor<Vec<u8>>,
    }

    impl Read for ThenLook {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            let n = self.first.read(buf)?;
            if n > 0 {
                return Ok(n);
            }
            if self.shown_before_more.is_none() {
                let lines = self.output.borrow().iter().filter(|&&b| b == b'\n').count();
                self.shown_before_more = Some(lines);
            }
            self.rest.read(buf)
        }
    }

    /// `marbre noise` streams: the values of a first batch of points are
    /// written and flushed before any more input is read, so that a pipe
    /// that has not ended yet already gets them, and at most a batch is
    /// held; the last, partial batch follows at the end.
    #[test]
    fn each_batch_is_printed_before_more_input_is_read() {
        let args = args(&["--kind", "perlin", "--cpu"]);
        let first: String = (0..BATCH_POINTS)
            .map(|i| format!("{i},0.5,0.25\n"))
            .collect();
        let out = Flushed::default();
        let mut input = ThenLook {
            first: std::io::Cursor::new(first.into_bytes()),
            output: out.seen.clone(),
            shown_before_more: None,
            rest: std::io::Cursor::new(b"1,2\n0.5,0.5,0.5\n".to_vec()),
        };
        let mut calls = Vec::new();
        let result = evaluate_input(
            std::io::BufReader::new(&mut input),
            &mut out.clone(),
            &mut Vec::new(),
            BATCH_POINTS,
            |points| {
                calls.push(points.len());
                Ok(evaluate_cpu(&args.settings(), args.what(), points))
            },
        );
        assert_eq!(input.shown_before_more, Some(BATCH_POINTS));
        assert_eq!(calls, [BATCH_POINTS, 1]);
        let e = result.unwrap_err().to_string();
        assert!(
            e.ends_with(&format!("the {} others were evaluated", BATCH_POINTS + 1)),
            "{e}"
        );
        let seen = out.seen.borrow();
        let text = std::str::from_utf8(&seen).unwrap();
        let last = evaluate_cpu(&args.settings(), args.what(), &[DVec3::splat(0.5)])[0];
        assert_eq!(text.lines().count(), BATCH_POINTS + 1);
        assert_eq!(text.lines().last(), Some(format_value(last).as_str()));
    }
}
