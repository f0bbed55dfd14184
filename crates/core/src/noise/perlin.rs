//! Ken Perlin's improved noise (SIGGRAPH 2002), transcribed from his Java
//! reference implementation.
//!
//! The gradient function is the reference's; Massal's tutorial (in the
//! course material) has a variant that differs at h = 13 and 14, offered as
//! [`Gradients::Massal`] (the noise kind `PerlinMassal`).

/// The shader code this module is the CPU twin of (or, for a harness, runs).
pub const WGSL: crate::wgsl::WgslFile = crate::wgsl_file!("crates/core/src/noise/perlin.wgsl");

/// Perlin's permutation of 0..=255.
pub const PERMUTATION: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69,
    142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219,
    203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175,
    74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122, 60, 211, 133, 230,
    220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216, 80, 73, 209, 76,
    132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173,
    186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206,
    59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163,
    70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232,
    178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162,
    241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184, 84, 204,
    176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141,
    128, 195, 78, 66, 215, 61, 156, 180,
];

/// A provable bound: each corner value is |g|·|d| ≤ √2·√3.
pub const IMPROVED_NOISE_BOUND: f64 = 2.449_489_742_783_178;

/// The arithmetic the algorithm needs, so one transcription serves both the
/// f64 reference and the f32 twin of the shader.
pub trait Real:
    Copy
    + PartialOrd
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Neg<Output = Self>
{
    const ZERO: Self;
    const ONE: Self;
    fn floor(self) -> Self;
    fn from_i32(v: i32) -> Self;
    fn to_i32(self) -> i32;
    fn from_f64(v: f64) -> Self;
}

macro_rules! impl_real {
    ($t:ty) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            fn floor(self) -> Self {
                <$t>::floor(self)
            }
            fn from_i32(v: i32) -> Self {
                v as $t
            }
            fn to_i32(self) -> i32 {
                self as i32
            }
            fn from_f64(v: f64) -> Self {
                v as $t
            }
        }
    };
}
impl_real!(f32);
impl_real!(f64);

fn perm(i: i32) -> i32 {
    i32::from(PERMUTATION[(i & 255) as usize])
}

fn fade<T: Real>(t: T) -> T {
    let c6 = T::from_f64(6.0);
    let c15 = T::from_f64(15.0);
    let c10 = T::from_f64(10.0);
    t * t * t * (t * (t * c6 - c15) + c10)
}

fn lerp<T: Real>(t: T, a: T, b: T) -> T {
    a + t * (b - a)
}

/// Which of the two 12-direction gradient tables the corners use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Gradients {
    /// Perlin's Java: `u = h<8 ? x : y`, `v = h<4 ? y : h==12||h==14 ? x : z`.
    Perlin,
    /// Massal's tutorial: `u = h<8||h==12||h==13 ? x : y`,
    /// `v = h<4||h==12||h==13 ? y : z`: h = 13 gives y − x (Perlin's
    /// z − y) and h = 14 gives y − z (Perlin's y − x).
    Massal,
}

fn grad<T: Real>(hash: i32, x: T, y: T, z: T, table: Gradients) -> T {
    let h = hash & 15;
    let massal = table == Gradients::Massal && (h == 12 || h == 13);
    let u = if h < 8 || massal { x } else { y };
    let v = if h < 4 || massal {
        y
    } else if table == Gradients::Perlin && (h == 12 || h == 14) {
        x
    } else {
        z
    };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

/// Improved noise at (x, y, z), generic over the precision.
pub fn improved_noise_generic<T: Real>(x: T, y: T, z: T) -> T {
    improved_noise_with(x, y, z, Gradients::Perlin)
}

/// Improved noise with the gradient table `table`.
pub fn improved_noise_with<T: Real>(x: T, y: T, z: T, table: Gradients) -> T {
    let (fx, fy, fz) = (x.floor(), y.floor(), z.floor());
    let xi = fx.to_i32() & 255;
    let yi = fy.to_i32() & 255;
    let zi = fz.to_i32() & 255;
    let (x, y, z) = (x - fx, y - fy, z - fz);
    let (u, v, w) = (fade(x), fade(y), fade(z));
    let one = T::ONE;
    let a = perm(xi) + yi;
    let aa = perm(a) + zi;
    let ab = perm(a + 1) + zi;
    let b = perm(xi + 1) + yi;
    let ba = perm(b) + zi;
    let bb = perm(b + 1) + zi;
    lerp(
        w,
        lerp(
            v,
            lerp(
                u,
                grad(perm(aa), x, y, z, table),
                grad(perm(ba), x - one, y, z, table),
            ),
            lerp(
                u,
                grad(perm(ab), x, y - one, z, table),
                grad(perm(bb), x - one, y - one, z, table),
            ),
        ),
        lerp(
            v,
            lerp(
                u,
                grad(perm(aa + 1), x, y, z - one, table),
                grad(perm(ba + 1), x - one, y, z - one, table),
            ),
            lerp(
                u,
                grad(perm(ab + 1), x, y - one, z - one, table),
                grad(perm(bb + 1), x - one, y - one, z - one, table),
            ),
        ),
    )
}

/// The f64 reference.
pub fn improved_noise(x: f64, y: f64, z: f64) -> f64 {
    improved_noise_generic(x, y, z)
}

/// The f32 evaluation a shader performs.
pub fn improved_noise_f32(x: f32, y: f32, z: f32) -> f32 {
    improved_noise_generic(x, y, z)
}

/// Massal's variant (his `grad()`), the f64 reference.
pub fn improved_noise_massal(x: f64, y: f64, z: f64) -> f64 {
    improved_noise_with(x, y, z, Gradients::Massal)
}

/// Massal's variant in f32, as the shader.
pub fn improved_noise_massal_f32(x: f32, y: f32, z: f32) -> f32 {
    improved_noise_with(x, y, z, Gradients::Massal)
}

/// Blender's 4D gradient (`noise_grad` of Cycles' and its GPU noise, as in
/// Gustavson's `Noise1234`): the low 5 bits of the hash pick one of the 32
/// edges of the hypercube, (±1, ±1, ±1) on three axes and 0 on the fourth.
/// Massal's tutorial has no 4D table, so both Perlin kinds evolve with this
/// one.
fn grad4<T: Real>(hash: i32, x: T, y: T, z: T, w: T) -> T {
    let h = hash & 31;
    let u = if h < 24 { x } else { y };
    let v = if h < 16 { y } else { z };
    let s = if h < 8 { z } else { w };
    (if h & 1 == 0 { u } else { -u })
        + (if h & 2 == 0 { v } else { -v })
        + (if h & 4 == 0 { s } else { -s })
}

/// A provable bound on the 4D improved noise: |g|·|d| ≤ √3·2.
pub const IMPROVED_NOISE4_BOUND: f64 = 3.464_101_615_137_755;

/// Improved noise in 4D (evolving noise, issue 29): the permutation applied
/// a fourth time (`perm(perm(perm(perm(x) + y) + z) + w)`, Perlin's 3D
/// hash extended as Blender's 4D), the 32 gradients of [`grad4`] and the
/// quintic fade, interpolated along x, y, z, then w. With `w_period` P the
/// lattice's w wraps modulo P cells before the permutation (which then
/// wraps it modulo 256), so the noise at w + P is the noise at w.
pub fn improved_noise4_generic<T: Real>(p: [T; 4], w_period: Option<u32>) -> T {
    let fl = p.map(Real::floor);
    let xi = fl[0].to_i32() & 255;
    let yi = fl[1].to_i32() & 255;
    let zi = fl[2].to_i32() & 255;
    let cell_w = fl[3].to_i32();
    let wi = [
        super::hash::wrap_w(cell_w, w_period) & 255,
        super::hash::wrap_w(cell_w.wrapping_add(1), w_period) & 255,
    ];
    let [x, y, z, w] = [p[0] - fl[0], p[1] - fl[1], p[2] - fl[2], p[3] - fl[3]];
    let (fx, fy, fz, fw) = (fade(x), fade(y), fade(z), fade(w));
    let one = T::ONE;
    let corner = |dx: i32, dy: i32, dz: i32, dw: usize| {
        let h = perm(perm(perm(perm(xi + dx) + yi + dy) + zi + dz) + wi[dw]);
        let d = |c: T, o: i32| if o == 0 { c } else { c - one };
        grad4(h, d(x, dx), d(y, dy), d(z, dz), d(w, dw as i32))
    };
    let cube = |dw: usize| {
        lerp(
            fz,
            lerp(
                fy,
                lerp(fx, corner(0, 0, 0, dw), corner(1, 0, 0, dw)),
                lerp(fx, corner(0, 1, 0, dw), corner(1, 1, 0, dw)),
            ),
            lerp(
                fy,
                lerp(fx, corner(0, 0, 1, dw), corner(1, 0, 1, dw)),
                lerp(fx, corner(0, 1, 1, dw), corner(1, 1, 1, dw)),
            ),
        )
    };
    lerp(fw, cube(0), cube(1))
}

/// The 4D improved noise, the f64 reference.
pub fn improved_noise4(p: [f64; 4], w_period: Option<u32>) -> f64 {
    improved_noise4_generic(p, w_period)
}

/// The 4D improved noise in f32, as the shader.
pub fn improved_noise4_f32(p: [f32; 4], w_period: Option<u32>) -> f32 {
    improved_noise4_generic(p, w_period)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    // Perlin's published point is x = 3.14, not π.
    #[allow(clippy::approx_constant)]
    fn matches_perlins_published_value() {
        // From Perlin's reference page: noise(3.14, 42, 7) = 0.13691995878400012.
        let v = improved_noise(3.14, 42.0, 7.0);
        assert!((v - 0.136_919_958_784).abs() < 1e-9, "{v}");
    }

    #[test]
    fn gradient_table_is_perlins_twelve_edges() {
        // The reference's grad() for h in 0..16 evaluated at (x, y, z) = (1, 10, 100)
        // gives x±y, x±z, y±z and the four repeats (h = 12..15: y+x, -y+z, y-x, -y-z).
        let expected = [
            11.0, 9.0, -9.0, -11.0, 101.0, 99.0, -99.0, -101.0, 110.0, 90.0, -90.0, -110.0, 11.0,
            90.0, 9.0, -110.0,
        ];
        for (h, e) in expected.iter().enumerate() {
            assert_eq!(
                grad(h as i32, 1.0, 10.0, 100.0, Gradients::Perlin),
                *e,
                "h = {h}"
            );
        }
    }

    /// Massal's `grad()` transcribed from the tutorial, against the table.
    #[test]
    fn massals_gradients_are_his_tutorials() {
        fn massal(hash: i32, x: f64, y: f64, z: f64) -> f64 {
            let h = hash & 15;
            let u = if h < 8 || h == 12 || h == 13 { x } else { y };
            let v = if h < 4 || h == 12 || h == 13 { y } else { z };
            (if (h & 1) == 0 { u } else { -u }) + (if (h & 2) == 0 { v } else { -v })
        }
        for h in 0..16 {
            let (x, y, z) = (1.0, 10.0, 100.0);
            assert_eq!(
                grad(h, x, y, z, Gradients::Massal),
                massal(h, x, y, z),
                "h = {h}"
            );
            let same = grad(h, x, y, z, Gradients::Perlin) == massal(h, x, y, z);
            assert_eq!(same, h != 13 && h != 14, "h = {h}: only 13 and 14 differ");
        }
        // So the noises differ where a corner hashes to 13 or 14.
        let differ = (0..200)
            .map(|i| f64::from(i) * 0.37)
            .filter(|&t| {
                improved_noise_massal(t, 1.3 * t, 0.7 * t) != improved_noise(t, 1.3 * t, 0.7 * t)
            })
            .count();
        assert!(differ > 100, "{differ} of 200 points differ");
    }

    #[test]
    fn zero_on_the_lattice_and_bounded() {
        for k in 0..1000 {
            let p = (
                k as f64 * 0.7548776662,
                k as f64 * 0.5698402910,
                k as f64 * 0.41,
            );
            let l = (p.0.floor(), p.1.floor(), p.2.floor());
            assert_eq!(improved_noise(l.0, l.1, l.2), 0.0);
            assert!(improved_noise(p.0, p.1, p.2).abs() <= IMPROVED_NOISE_BOUND);
        }
    }

    #[test]
    fn range_over_a_million_samples() {
        // The provable bound is √6 ≈ 2.45; the improved noise's known extreme
        // is about 1.04 (Perlin's gradients are edge midpoints, so the
        // corner contributions rarely align).
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        for k in 0..1_000_000u32 {
            let t = f64::from(k);
            let v = improved_noise(
                (t * 0.754_877_666_2).fract() * 512.0 - 256.0,
                (t * 0.569_840_291).fract() * 512.0 - 256.0,
                (t * 0.438_579_849_3).fract() * 512.0 - 256.0,
            );
            lo = lo.min(v);
            hi = hi.max(v);
        }
        assert!(lo >= -1.1 && hi <= 1.1, "[{lo}, {hi}]");
        assert!(lo < -0.7 && hi > 0.7, "[{lo}, {hi}]: too narrow");
    }

    #[test]
    fn f32_twin_stays_close_to_the_reference() {
        for k in 0..10_000 {
            let t = k as f64;
            let p = [
                (t * 0.754_877_666_2).fract() * 200.0 - 100.0,
                (t * 0.569_840_291).fract() * 200.0 - 100.0,
                (t * 0.41).fract() * 200.0 - 100.0,
            ];
            let pf = p.map(|c| c as f32);
            // Compare at the f32 point, so only the arithmetic differs.
            let r = improved_noise(pf[0] as f64, pf[1] as f64, pf[2] as f64);
            let s = improved_noise_f32(pf[0], pf[1], pf[2]) as f64;
            assert!((r - s).abs() < 1e-5, "{p:?}: {r} vs {s}");
        }
    }

    /// The 4D table is the hypercube's 32 edges: each gradient has one zero
    /// and three ±1 components, and all 32 differ.
    #[test]
    fn grad4_is_the_32_hypercube_edges() {
        let mut seen = std::collections::HashSet::new();
        for h in 0..32 {
            let g = [0, 1, 2, 3].map(|a| {
                let e = [0.0f64; 4].map(|_| 0.0);
                let mut e = e;
                e[a] = 1.0;
                grad4(h, e[0], e[1], e[2], e[3]) as i32
            });
            assert_eq!(g.iter().filter(|&&c| c == 0).count(), 1, "h {h}: {g:?}");
            assert!(g.iter().all(|c| c.abs() <= 1));
            assert!(seen.insert(g), "h {h} repeats {g:?}");
        }
    }

    /// Gustavson's classic 4D noise (`Noise1234::noise(x, y, z, w)`),
    /// re-derived: his explicit 16 corners, interpolated in his order (w
    /// first, then z, y, x), his doubled 512-entry table read without masks,
    /// his gradient as the table of the 32 edge vectors (three ±1 with one
    /// axis zeroed, by the hash's bits), and the permutation composed in
    /// Perlin's order (x outermost) as ours. Equal to rounding.
    #[test]
    fn noise4_matches_gustavsons_formulation() {
        let table: Vec<usize> = (0..512)
            .map(|i| usize::from(PERMUTATION[i % 256]))
            .collect();
        let edge = |h: usize| -> [f64; 4] {
            let h = h & 31;
            let zero = 3 - h / 8;
            let mut g = [0.0; 4];
            let mut bit = 0;
            for (axis, c) in g.iter_mut().enumerate() {
                if axis != zero {
                    *c = if h >> bit & 1 == 1 { -1.0 } else { 1.0 };
                    bit += 1;
                }
            }
            g
        };
        let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
        let lerp = |t: f64, a: f64, b: f64| a + t * (b - a);
        let gustavson = |p: [f64; 4]| {
            let i: Vec<usize> = p
                .iter()
                .map(|c| (c.floor() as i64).rem_euclid(256) as usize)
                .collect();
            let f0: Vec<f64> = p.iter().map(|c| c - c.floor()).collect();
            let f1: Vec<f64> = f0.iter().map(|f| f - 1.0).collect();
            let (r, s, t, q) = (fade(f0[0]), fade(f0[1]), fade(f0[2]), fade(f0[3]));
            let n = |dx: usize, dy: usize, dz: usize, dw: usize| {
                let h = table[table[table[table[i[0] + dx] + i[1] + dy] + i[2] + dz] + i[3] + dw];
                let g = edge(h);
                let v = [
                    if dx == 0 { f0[0] } else { f1[0] },
                    if dy == 0 { f0[1] } else { f1[1] },
                    if dz == 0 { f0[2] } else { f1[2] },
                    if dw == 0 { f0[3] } else { f1[3] },
                ];
                g[0] * v[0] + g[1] * v[1] + g[2] * v[2] + g[3] * v[3]
            };
            let nxy = |dx, dy| {
                lerp(
                    t,
                    lerp(q, n(dx, dy, 0, 0), n(dx, dy, 0, 1)),
                    lerp(q, n(dx, dy, 1, 0), n(dx, dy, 1, 1)),
                )
            };
            let nx = |dx| lerp(s, nxy(dx, 0), nxy(dx, 1));
            lerp(r, nx(0), nx(1))
        };
        let mut spread = (f64::MAX, f64::MIN);
        for k in 0..5000 {
            let t = f64::from(k);
            let p = [
                (t * 0.754_877_666_2).fract() * 600.0 - 300.0,
                (t * 0.569_840_291).fract() * 600.0 - 300.0,
                (t * 0.438_579_849_3).fract() * 600.0 - 300.0,
                (t * 0.319_472_01).fract() * 600.0 - 300.0,
            ];
            let got = improved_noise4(p, None);
            let want = gustavson(p);
            assert!((got - want).abs() < 1e-12, "{p:?}: {got} vs {want}");
            assert!(got.abs() <= IMPROVED_NOISE4_BOUND);
            spread = (spread.0.min(got), spread.1.max(got));
        }
        assert!(spread.0 < -0.6 && spread.1 > 0.6, "{spread:?}");
    }

    /// With a period P in w the 4D noise repeats every P in w, to the bit;
    /// continuous across w's lattice planes (where the period wraps too).
    #[test]
    fn noise4_is_periodic_and_continuous_in_w() {
        for k in 0..3000 {
            let t = k as f32;
            let xyz = [
                (t * 0.754_877_7).fract() * 50.0,
                (t * 0.569_840_3).fract() * 50.0,
                (t * 0.41).fract() * 50.0,
            ];
            let w = (k % 512) as f32 / 32.0 - 8.0;
            for period in [1u32, 3, 300] {
                let at = improved_noise4_f32([xyz[0], xyz[1], xyz[2], w], Some(period));
                let next =
                    improved_noise4_f32([xyz[0], xyz[1], xyz[2], w + period as f32], Some(period));
                assert_eq!(at, next, "{xyz:?} w {w} P {period}");
                for plane in [-1.0f32, 0.0, 1.0, 3.0] {
                    let lo =
                        improved_noise4_f32([xyz[0], xyz[1], xyz[2], plane - 1e-5], Some(period));
                    let hi =
                        improved_noise4_f32([xyz[0], xyz[1], xyz[2], plane + 1e-5], Some(period));
                    assert!((lo - hi).abs() < 1e-3, "{xyz:?} w {plane}: {lo} {hi}");
                }
            }
        }
    }

    #[test]
    fn noise4_f32_twin_stays_close_to_the_reference() {
        for k in 0..10_000 {
            let t = k as f64;
            let p = [0.754_877_666_2, 0.569_840_291, 0.41, 0.3271]
                .map(|a| ((t * a).fract() * 200.0 - 100.0) as f32);
            let r = improved_noise4(p.map(f64::from), Some(9));
            let s = improved_noise4_f32(p, Some(9));
            assert!((r - f64::from(s)).abs() < 1e-5, "{p:?}: {r} vs {s}");
        }
    }
}
