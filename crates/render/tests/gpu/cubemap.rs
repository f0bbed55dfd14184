//! Cube-map environments: the face convention, the cross layout, sampling
//! without seams, the lat-long round trip, errors for bad input, the shipped
//! cross, and (on a GPU adapter) the cross as a rendered background.
//!
//! Regenerate the shipped cross with
//! `cargo test --release --test cubemap -- --ignored regenerate_shipped_cross`.

use crate::common;

use glam::{Vec2, Vec3};
use marbre_core::cubemap::{self, CubeMap, CubeMapError, Face};
use marbre_core::envmap::{self, EnvImage};
use marbre_core::image_decode;
use marbre_core::scene::{EnvSource, LdrImages, OrbitCamera, Scene};
use std::f32::consts::PI;
use std::path::{Path, PathBuf};

use crate::common::root;

/// The shipped cross and the lat-long map it was made from.
const SHIPPED_CROSS: &str = "envmaps/cube/studio-cross.exr";
const SHIPPED_SOURCE: &str = "envmaps/studio.exr";
const SHIPPED_FACE_SIZE: u32 = 128;

/// A fresh folder for one test, removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> TempDir {
        let dir =
            std::env::temp_dir().join(format!("marbre-cubemap-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    fn path(&self, file: &str) -> PathBuf {
        self.0.join(file)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Writes a 32-bit float RGB OpenEXR.
fn write_exr(path: &Path, width: u32, height: u32, texel: impl Fn(u32, u32) -> [f32; 3] + Sync) {
    exr::prelude::write_rgb_file(path, width as usize, height as usize, |x, y| {
        let [r, g, b] = texel(x as u32, y as u32);
        (r, g, b)
    })
    .unwrap();
}

/// Writes `image` as the shipped maps are stored: RGB half floats, ZIP.
fn write_half_exr(path: &Path, image: &EnvImage) {
    use exr::prelude::*;
    let w = image.width as usize;
    let layer = Layer::new(
        (w, image.height as usize),
        LayerAttributes::named("cube cross"),
        Encoding {
            compression: Compression::ZIP16,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        },
        SpecificChannels::rgb(|p: Vec2<usize>| {
            let t = image.pixels[p.y() * w + p.x()];
            (
                half::f16::from_f32(t[0]),
                half::f16::from_f32(t[1]),
                half::f16::from_f32(t[2]),
            )
        }),
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

fn max_abs_diff(a: [f32; 3], b: [f32; 3]) -> f32 {
    (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f32::max)
}

/// A lat-long image whose texel is `f` of the direction through its centre.
fn latlong_of(width: u32, f: impl Fn(Vec3) -> [f32; 3]) -> EnvImage {
    let height = width / 2;
    let mut pixels = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let t = Vec2::new(
                (x as f32 + 0.5) / width as f32,
                (y as f32 + 0.5) / height as f32,
            );
            let [r, g, b] = f(texel_direction(t));
            pixels.push([r, g, b, 1.0]);
        }
    }
    EnvImage {
        width,
        height,
        pixels,
    }
}

/// The direction of lat-long texel uv `t` (row 0 = up), the inverse of
/// `envmap::direction_to_uv` written out from its formula.
fn texel_direction(t: Vec2) -> Vec3 {
    let (u, v) = (t.x, 1.0 - t.y);
    let phi = 2.0 * PI * u - PI;
    let theta = PI * v; // from straight down
    Vec3::new(
        theta.sin() * phi.sin(),
        -theta.cos(),
        theta.sin() * phi.cos(),
    )
}

// ---------------------------------------------------------------------------
// The face convention

/// Six constant faces sampled along the six axes (and off-centre on each
/// face) give their own colours.
#[test]
fn axis_directions_give_their_faces_colours() {
    let colours: [[f32; 3]; 6] = [
        [1.0, 0.0, 0.0], // +x red
        [0.0, 1.0, 0.0], // -x green
        [0.0, 0.0, 1.0], // +y blue
        [1.0, 1.0, 0.0], // -y yellow
        [1.0, 0.0, 1.0], // +z magenta
        [0.0, 1.0, 1.0], // -z cyan
    ];
    let cube = CubeMap::from_fn(4, |f, _, _| colours[f.index()]);
    let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    for (axis, colour) in axes.iter().zip(colours) {
        assert_eq!(cube.sample(*axis), colour, "{axis}");
        assert_eq!(cube.sample(*axis * 7.0), colour, "{axis} (any length)");
        // 20° off the axis is still well inside the face, a texel away from
        // any edge.
        let other = if axis.y == 0.0 { Vec3::Y } else { Vec3::X };
        let tilted = *axis + 0.36 * other;
        assert_eq!(cube.sample(tilted), colour, "{tilted}");
    }
}

/// Each face's (s, t) follow the OpenGL table "Selection of cube map
/// images", written out here by hand: the direction built from (s, t) by
/// the table reads the texel at (s, t).
#[test]
fn face_coordinates_follow_the_opengl_table() {
    let n = 8u32;
    // Texel (x, y) of face f holds (f, x, y).
    let cube = CubeMap::from_fn(n, |f, x, y| [f.index() as f32, x as f32, y as f32]);
    // sc, tc of the table solved for r, with |ma| = 1.
    let table = |face: usize, sc: f32, tc: f32| match face {
        0 => Vec3::new(1.0, -tc, -sc),  // +x: sc = -rz, tc = -ry
        1 => Vec3::new(-1.0, -tc, sc),  // -x: sc = +rz, tc = -ry
        2 => Vec3::new(sc, 1.0, tc),    // +y: sc = +rx, tc = +rz
        3 => Vec3::new(sc, -1.0, -tc),  // -y: sc = +rx, tc = -rz
        4 => Vec3::new(sc, -tc, 1.0),   // +z: sc = +rx, tc = -ry
        _ => Vec3::new(-sc, -tc, -1.0), // -z: sc = -rx, tc = -ry
    };
    for face in 0..6 {
        for (x, y) in [(0u32, 0u32), (1, 6), (7, 2), (4, 4), (7, 7)] {
            let s = (x as f32 + 0.5) / n as f32;
            let t = (y as f32 + 0.5) / n as f32;
            let d = table(face, 2.0 * s - 1.0, 2.0 * t - 1.0);
            let got = cube.sample(d);
            let want = [face as f32, x as f32, y as f32];
            assert!(
                max_abs_diff(got, want) < 1e-4,
                "face {face} texel ({x}, {y}): {got:?}"
            );
            assert_eq!(cubemap::face_st(d).0, Face::ALL[face]);
        }
    }
}

/// A horizontal cross laid out by hand (cells of the standard layout,
/// typed here, not taken from the library) loads to the right faces, each
/// the right way round.
#[test]
fn a_horizontal_cross_laid_out_by_hand_loads_to_the_right_faces() {
    let n = 3u32;
    // (face index, column, row) of the 4x3 cells:
    //        +y
    //   -x   +z   +x   -z
    //        -y
    let cells = [
        (0, 2, 1),
        (1, 0, 1),
        (2, 1, 0),
        (3, 1, 2),
        (4, 1, 1),
        (5, 3, 1),
    ];
    let texel = |x: u32, y: u32| -> [f32; 3] {
        let (cx, cy) = (x / n, y / n);
        match cells.iter().find(|c| (c.1, c.2) == (cx, cy)) {
            // Face index + 1 (so that no value is 0), column, row in the face.
            Some(c) => [c.0 as f32 + 1.0, (x % n) as f32, (y % n) as f32],
            None => [100.0; 3],
        }
    };
    let dir = TempDir::new("cross");
    let path = dir.path("hand-cross.exr");
    write_exr(&path, 4 * n, 3 * n, texel);
    let loaded = CubeMap::load_cross(&path, LdrImages::Srgb).unwrap();
    assert!(loaded.notes.is_empty(), "{:?}", loaded.notes);
    let cube = loaded.cube;
    assert_eq!(cube.size(), n);
    for (face, _, _) in cells {
        for y in 0..n {
            for x in 0..n {
                assert_eq!(
                    cube.texel(Face::ALL[face], x, y),
                    [face as f32 + 1.0, x as f32, y as f32],
                    "face {face} ({x}, {y})"
                );
            }
        }
    }
    // And the layout is a seamless unfolding: +z's right column and +x's
    // left column look along the same edge.
    assert_eq!(cubemap::face_st(Vec3::new(1.0, 0.0, 0.999)).0, Face::PosX);
    let to_cross = cube.to_cross();
    assert_eq!((to_cross.width, to_cross.height), (4 * n, 3 * n));
    for y in 0..3 * n {
        for x in 0..4 * n {
            let want = texel(x, y);
            let got = to_cross.texel(x, y);
            if want[0] != 100.0 {
                assert_eq!([got[0], got[1], got[2]], want, "({x}, {y})");
            }
        }
    }
}

/// The cube's +y is the world's up and its pictures are the same way round
/// as the lat-long's: on the +z face, s (the column) grows towards +x just
/// as u grows from +z (0.5) towards +x (0.75), and rows go down.
#[test]
fn a_cube_from_a_lat_long_keeps_its_up_and_its_handedness() {
    // Texel = (u, lab v, 0): where it sits in the lat-long.
    let image = {
        let (w, h) = (256u32, 128u32);
        let pixels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                [
                    (x as f32 + 0.5) / w as f32,
                    1.0 - (y as f32 + 0.5) / h as f32,
                    0.0,
                    1.0,
                ]
            })
            .collect();
        EnvImage {
            width: w,
            height: h,
            pixels,
        }
    };
    let n = 16;
    let cube = CubeMap::from_latlong(&image, n);
    let centre = |f: Face| {
        let a = cube.texel(f, n / 2 - 1, n / 2 - 1);
        let b = cube.texel(f, n / 2, n / 2);
        [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0]
    };
    let near = |a: f32, b: f32| (a - b).abs() < 0.02;
    // +z centre is the middle of the picture, +x a quarter turn right.
    let [u, v] = centre(Face::PosZ);
    assert!(near(u, 0.5) && near(v, 0.5), "{u} {v}");
    let [u, v] = centre(Face::PosX);
    assert!(near(u, 0.75) && near(v, 0.5), "{u} {v}");
    let [u, _] = centre(Face::NegX);
    assert!(near(u, 0.25), "{u}");
    // +y is the sky (top rows), -y the ground.
    assert!(centre(Face::PosY)[1] > 0.95);
    assert!(centre(Face::NegY)[1] < 0.05);
    // Along the middle row of +z, u grows with the column; down the middle
    // column, lab v falls with the row: upright and not mirrored.
    let row: Vec<f32> = (0..n)
        .map(|x| cube.texel(Face::PosZ, x, n / 2)[0])
        .collect();
    assert!(row.windows(2).all(|w| w[1] > w[0]), "{row:?}");
    let column: Vec<f32> = (0..n)
        .map(|y| cube.texel(Face::PosZ, n / 2, y)[1])
        .collect();
    assert!(column.windows(2).all(|w| w[1] < w[0]), "{column:?}");
}

// ---------------------------------------------------------------------------
// Sampling without seams

/// The per-face filter the cube map must not be: bilinear on each face on
/// its own, clamped to the face's edge. It has a seam on every edge.
fn naive_clamped_sample(cube: &CubeMap, d: Vec3) -> [f32; 3] {
    let (face, st) = cubemap::face_st(d);
    let n = cube.size() as i64;
    let p = st * n as f32 - 0.5;
    let (x0, y0) = (p.x.floor(), p.y.floor());
    let (fx, fy) = (p.x - x0, p.y - y0);
    let at = |x: i64, y: i64| cube.texel(face, x.clamp(0, n - 1) as u32, y.clamp(0, n - 1) as u32);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let (a, b, c, e) = (
        at(x0, y0),
        at(x0 + 1, y0),
        at(x0, y0 + 1),
        at(x0 + 1, y0 + 1),
    );
    cubemap::bilinear([a, b, c, e], fx, fy)
}

/// Faces of distinct constant colours, each with a smooth gradient.
fn gradient_cube(n: u32) -> CubeMap {
    let base: [[f32; 3]; 6] = [
        [0.9, 0.1, 0.2],
        [0.1, 0.8, 0.3],
        [0.2, 0.3, 0.9],
        [0.7, 0.7, 0.1],
        [0.6, 0.1, 0.7],
        [0.1, 0.6, 0.8],
    ];
    CubeMap::from_fn(n, |f, x, y| {
        let (s, t) = (x as f32 / n as f32, y as f32 / n as f32);
        let b = base[f.index()];
        [b[0] + 0.1 * s, b[1] + 0.1 * t, b[2] + 0.05 * (s + t)]
    })
}

/// The 12 edges as (face a, face b, the edge's own direction).
fn edges() -> Vec<(Vec3, Vec3, Vec3)> {
    let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    let mut out = Vec::new();
    for (i, a) in axes.iter().enumerate() {
        for b in &axes[i + 1..] {
            if a.dot(*b) == 0.0 {
                out.push((*a, *b, a.cross(*b)));
            }
        }
    }
    out
}

/// Per channel, the spread (max - min) of the texels whose centres lie
/// within `radius` radians of `d`: what a bilinear footprint at `d` can
/// read, the neighbour's texels across an edge included.
fn local_spread(cube: &CubeMap, d: Vec3, radius: f32) -> [f32; 3] {
    let n = cube.size();
    let d = d.normalize();
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for face in Face::ALL {
        for y in 0..n {
            for x in 0..n {
                let c = face
                    .direction((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32)
                    .normalize();
                if c.angle_between(d) <= radius {
                    let v = cube.texel(face, x, y);
                    for k in 0..3 {
                        lo[k] = lo[k].min(v[k]);
                        hi[k] = hi[k].max(v[k]);
                    }
                }
            }
        }
    }
    std::array::from_fn(|k| hi[k] - lo[k])
}

/// Walks across each of the 12 edges, at several places along it (the
/// corners included), in steps of under 0.01 texel. A bilinear filter moves
/// by at most (spread of its footprint) x (texels moved) per step, so a
/// seam, a jump at the edge, breaks the bound. The seamless sampler keeps
/// it everywhere; the per-face clamped filter breaks it on every edge.
#[test]
fn sampling_crosses_all_twelve_edges_without_a_jump() {
    let n = 8u32;
    let cube = gradient_cube(n);
    let edges = edges();
    assert_eq!(edges.len(), 12);
    // Texel centres a bilinear footprint can touch lie within about 1.5
    // texel diagonals; a texel spans at most 2/n radians (at a face centre).
    let radius = 3.5 / n as f32;
    let steps = 200;
    let half_span = 0.05f32;
    let mut naive_broken_edges = 0;
    for (a, b, e) in &edges {
        let mut naive_broke_here = false;
        for w in [-1.0, -0.97, -0.6, -0.2, 0.0, 0.35, 0.8, 0.99, 1.0] {
            // Crosses the edge at τ = 0: on face a for τ < 0, b for τ > 0.
            let path = |tau: f32| (1.0 - tau) * *a + (1.0 + tau) * *b + w * *e;
            // Texels moved per unit τ, bounded in the frame of either face
            // (coordinates along the other face's axis and along the edge,
            // times n/2 texels per unit), both added for a step that
            // crosses the edge.
            let texels_per_tau = |tau: f32| {
                let in_a = (2.0 + w.abs()) / (1.0 - tau).powi(2);
                let in_b = (2.0 + w.abs()) / (1.0 + tau).powi(2);
                (in_a + in_b) * n as f32 / 2.0
            };
            let dtau = 2.0 * half_span / steps as f32;
            let mut previous = (path(-half_span), cube.sample(path(-half_span)));
            let mut naive_previous = naive_clamped_sample(&cube, path(-half_span));
            for i in 1..=steps {
                let tau = -half_span + i as f32 * dtau;
                let d = path(tau);
                let now = cube.sample(d);
                let moved = texels_per_tau(tau.abs() + dtau) * dtau;
                let spread_a = local_spread(&cube, previous.0, radius);
                let spread_b = local_spread(&cube, d, radius);
                for k in 0..3 {
                    let allowed = spread_a[k].max(spread_b[k]) * moved + 1e-5;
                    let change = (now[k] - previous.1[k]).abs();
                    assert!(
                        change <= allowed,
                        "edge {a}|{b} at w={w}, τ={tau}: channel {k} moved {change} > {allowed}"
                    );
                    let naive_now = naive_clamped_sample(&cube, d);
                    if (naive_now[k] - naive_previous[k]).abs() > allowed {
                        naive_broke_here = true;
                    }
                }
                previous = (d, now);
                naive_previous = naive_clamped_sample(&cube, d);
            }
        }
        if naive_broke_here {
            naive_broken_edges += 1;
        }
    }
    assert_eq!(
        naive_broken_edges, 12,
        "the counter-case must show a seam on every edge, or the test cannot tell"
    );
}

/// Where three faces meet, every face gives the average of the three
/// corner texels.
#[test]
fn corners_give_the_average_of_their_three_texels() {
    let n = 4u32;
    let cube = gradient_cube(n);
    for sx in [-1.0f32, 1.0] {
        for sy in [-1.0f32, 1.0] {
            for sz in [-1.0f32, 1.0] {
                let corner = Vec3::new(sx, sy, sz);
                // The corner texel of each face the corner belongs to.
                let mut sum = [0.0f32; 3];
                let mut faces = 0;
                for face in Face::ALL {
                    if face.axis().dot(corner) <= 0.0 {
                        continue;
                    }
                    let (s, t) = face.st_axes();
                    let x = if s.dot(corner) > 0.0 { n - 1 } else { 0 };
                    let y = if t.dot(corner) > 0.0 { n - 1 } else { 0 };
                    let v = cube.texel(face, x, y);
                    for k in 0..3 {
                        sum[k] += v[k] / 3.0;
                    }
                    faces += 1;
                }
                assert_eq!(faces, 3);
                let got = cube.sample(corner);
                assert!(
                    max_abs_diff(got, sum) < 1e-5,
                    "{corner}: {got:?} vs {sum:?}"
                );
                // Approached from inside each face, too.
                for face in Face::ALL {
                    if face.axis().dot(corner) > 0.0 {
                        let inside = corner + 1e-4 * face.axis();
                        let got = cube.sample(inside);
                        assert!(max_abs_diff(got, sum) < 1e-3, "{corner} via {face:?}");
                    }
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Lat-long round trip

/// A smooth map (values 0.3 to 1.8) survives lat-long (256 x 128) → cube
/// (64) → lat-long (256 x 128) within 0.002 everywhere, the poles, the u
/// seam and the cube's edges and corners included (measured: 0.0005).
#[test]
fn lat_long_to_cube_and_back_is_the_identity_on_a_smooth_map() {
    let f = |d: Vec3| {
        [
            1.0 + 0.5 * d.x,
            1.0 + 0.5 * d.y + 0.25 * d.z * d.z,
            1.0 + 0.4 * d.x * d.z + 0.2 * d.y,
        ]
    };
    let original = latlong_of(256, f);
    let cube = CubeMap::from_latlong(&original, 64);
    assert_eq!(cube.latlong_size(), (256, 128));
    let back = cube.to_latlong();
    assert_eq!((back.width, back.height), (256, 128));
    let mut worst = (0.0f32, 0u32, 0u32);
    for y in 0..128 {
        for x in 0..256 {
            let a = original.texel(x, y);
            let b = back.texel(x, y);
            let err = max_abs_diff([a[0], a[1], a[2]], [b[0], b[1], b[2]]);
            if err > worst.0 {
                worst = (err, x, y);
            }
        }
    }
    eprintln!("smooth round trip: worst error {worst:?}");
    assert!(worst.0 < 0.002, "worst error {worst:?}");
    // The cube itself holds f at its texel centres.
    for face in Face::ALL {
        let d = face.direction(0.3, 0.8);
        let got = cube.sample(d);
        assert!(max_abs_diff(got, f(d.normalize())) < 0.002, "{face:?}");
    }
}

/// The shipped studio map (512 x 256, soft boxes up to 3730 against a
/// dark room) through a cube of 64 and back at 512 x 256: the light it
/// sends (luminance x sin θ summed over the sphere) within 1 %, and half
/// its texels within 3 % (the sharp edges of the boxes soften more; the
/// filters are box and bilinear).
#[test]
fn lat_long_to_cube_and_back_keeps_the_studio_map() {
    let original = envmap::load(&root().join(SHIPPED_SOURCE)).unwrap().image;
    let (w, h) = (original.width, original.height);
    let back = CubeMap::from_latlong(&original, 64).to_latlong_width(w);
    assert_eq!((back.width, back.height), (w, h));
    let luminance = |p: [f32; 4]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    let (mut flux, mut flux_back) = (0.0f64, 0.0f64);
    let mut relative = Vec::new();
    for y in 0..h {
        let sin_theta = f64::from(((y as f32 + 0.5) / h as f32 * PI).sin());
        for x in 0..w {
            let a = luminance(original.texel(x, y));
            let b = luminance(back.texel(x, y));
            flux += f64::from(a) * sin_theta;
            flux_back += f64::from(b) * sin_theta;
            relative.push((a - b).abs() / (a + 1e-3));
        }
    }
    relative.sort_by(f32::total_cmp);
    let median = relative[relative.len() / 2];
    let ratio = flux_back / flux;
    eprintln!("studio round trip: flux ratio {ratio}, median relative error {median}");
    assert!((ratio - 1.0).abs() < 0.01, "flux ratio {ratio}");
    assert!(median < 0.03, "median relative error {median}");
}

// ---------------------------------------------------------------------------
// Bad input

fn face_paths(dir: &TempDir) -> [PathBuf; 6] {
    ["px", "nx", "py", "ny", "pz", "nz"].map(|f| dir.path(&format!("{f}.exr")))
}

fn write_faces(paths: &[PathBuf; 6], size: u32) {
    for (i, p) in paths.iter().enumerate() {
        write_exr(p, size, size, |_, _| [i as f32 + 1.0, 0.5, 0.25]);
    }
}

#[test]
fn six_face_files_load_in_order() {
    let dir = TempDir::new("faces");
    let paths = face_paths(&dir);
    write_faces(&paths, 4);
    let cube = CubeMap::load_faces(&paths, LdrImages::Srgb).unwrap().cube;
    assert_eq!(cube.size(), 4);
    for face in Face::ALL {
        assert_eq!(
            cube.texel(face, 3, 1),
            [face.index() as f32 + 1.0, 0.5, 0.25]
        );
    }
}

#[test]
fn faces_of_unequal_sizes_are_refused_naming_both_files() {
    let dir = TempDir::new("unequal");
    let paths = face_paths(&dir);
    write_faces(&paths, 4);
    write_exr(&paths[3], 8, 8, |_, _| [1.0; 3]);
    let err = CubeMap::load_faces(&paths, LdrImages::Srgb).unwrap_err();
    assert!(matches!(err, CubeMapError::UnequalFaces { .. }), "{err:?}");
    let msg = err.to_string();
    eprintln!("{msg}");
    for needle in ["ny.exr", "-y", "8x8", "px.exr", "4x4", "same size"] {
        assert!(msg.contains(needle), "{needle} not in {msg}");
    }
    assert_eq!(err.path(), paths[3]);
}

#[test]
fn a_non_square_face_is_refused_naming_the_file() {
    let dir = TempDir::new("non-square");
    let paths = face_paths(&dir);
    write_faces(&paths, 4);
    write_exr(&paths[4], 4, 3, |_, _| [1.0; 3]);
    let err = CubeMap::load_faces(&paths, LdrImages::Srgb).unwrap_err();
    assert!(matches!(err, CubeMapError::NotSquare { .. }), "{err:?}");
    let msg = err.to_string();
    eprintln!("{msg}");
    for needle in ["pz.exr", "+z", "4x3", "must be square"] {
        assert!(msg.contains(needle), "{needle} not in {msg}");
    }
}

#[test]
fn a_cross_of_the_wrong_aspect_is_refused_naming_the_file() {
    let dir = TempDir::new("aspect");
    for (w, h) in [(16, 16), (12, 8), (10, 7), (6, 3)] {
        let path = dir.path(&format!("cross-{w}x{h}.exr"));
        write_exr(&path, w, h, |_, _| [1.0; 3]);
        let err = CubeMap::load_cross(&path, LdrImages::Srgb).unwrap_err();
        assert!(matches!(err, CubeMapError::CrossAspect { .. }), "{err:?}");
        let msg = err.to_string();
        for needle in [
            format!("cross-{w}x{h}.exr"),
            format!("{w}x{h}"),
            "4:3".into(),
        ] {
            assert!(msg.contains(&needle), "{needle} not in {msg}");
        }
    }
    // 4:3 with square cells loads.
    let ok = dir.path("cross-ok.exr");
    write_exr(&ok, 8, 6, |_, _| [1.0; 3]);
    assert_eq!(
        CubeMap::load_cross(&ok, LdrImages::Srgb)
            .unwrap()
            .cube
            .size(),
        2
    );
}

#[test]
fn a_missing_face_file_is_refused_naming_the_face_and_the_file() {
    let dir = TempDir::new("missing");
    let paths = face_paths(&dir);
    write_faces(&paths, 4);
    std::fs::remove_file(&paths[1]).unwrap();
    let err = CubeMap::load_faces(&paths, LdrImages::Srgb).unwrap_err();
    assert!(
        matches!(err, CubeMapError::Face { face: "-x", .. }),
        "{err:?}"
    );
    let msg = err.to_string();
    eprintln!("{msg}");
    for needle in ["-x", "nx.exr", "cannot read"] {
        assert!(msg.contains(needle), "{needle} not in {msg}");
    }
    assert_eq!(err.path(), paths[1]);

    let err = CubeMap::load_cross(&dir.path("no-cross.exr"), LdrImages::Srgb).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("no-cross.exr") && msg.contains("cannot read"),
        "{msg}"
    );
}

/// Bad values in a face are repaired as in a lat-long map, and reported
/// with the file's name.
#[test]
fn faces_are_sanitised_like_lat_long_maps() {
    let dir = TempDir::new("sanitise");
    let paths = face_paths(&dir);
    write_faces(&paths, 2);
    write_exr(&paths[2], 2, 2, |x, _| {
        if x == 0 {
            [f32::NAN, -1.0, 1e6]
        } else {
            [1.0; 3]
        }
    });
    let loaded = CubeMap::load_faces(&paths, LdrImages::Srgb).unwrap();
    assert_eq!(
        loaded.cube.texel(Face::PosY, 0, 0),
        [0.0, 0.0, image_decode::F16_MAX]
    );
    assert!(
        loaded
            .notes
            .iter()
            .any(|n| n.starts_with("py.exr: ") && n.contains("NaN")),
        "{:?}",
        loaded.notes
    );
}

// ---------------------------------------------------------------------------
// Sources, presets and the shipped cross

#[test]
fn every_source_loads_to_a_lat_long_image() {
    let dir = TempDir::new("sources");
    let paths = face_paths(&dir);
    write_faces(&paths, 4);
    assert!(
        cubemap::load_source(&EnvSource::None, LdrImages::Srgb)
            .unwrap()
            .is_none()
    );
    let faces = cubemap::load_source(
        &EnvSource::CubeFaces {
            faces: paths.clone(),
        },
        LdrImages::Srgb,
    )
    .unwrap()
    .unwrap();
    assert_eq!((faces.image.width, faces.image.height), (16, 8));
    // Straight up is the +y face (value 3), straight down -y (value 4).
    assert!((faces.image.texel(5, 0)[0] - 3.0).abs() < 1e-5);
    assert!((faces.image.texel(5, 7)[0] - 4.0).abs() < 1e-5);
    assert!(faces.notes.iter().any(|n| n.contains("resampled")));
    let cross = cubemap::load_source(
        &EnvSource::CubeCross {
            path: root().join(SHIPPED_CROSS),
        },
        LdrImages::Srgb,
    )
    .unwrap()
    .unwrap();
    assert_eq!(
        (cross.image.width, cross.image.height),
        (4 * SHIPPED_FACE_SIZE, 2 * SHIPPED_FACE_SIZE)
    );
    let latlong = cubemap::load_source(
        &EnvSource::LatLong {
            path: root().join(SHIPPED_SOURCE),
        },
        LdrImages::Srgb,
    )
    .unwrap()
    .unwrap();
    assert_eq!((latlong.image.width, latlong.image.height), (512, 256));
}

/// A preset's cube paths are relative to the preset, like a lat-long's,
/// on the way in and on the way out.
#[test]
fn preset_cube_paths_are_relative_to_the_preset() {
    use marbre_core::preset;
    let text = r#"(
        scene: (
            environment: (
                source: CubeFaces(faces: ["f/px.png", "f/nx.png", "f/py.png", "f/ny.png", "f/pz.png", "/abs/nz.png"]),
            ),
        ),
    )"#;
    let loaded = preset::parse(text, Path::new("/data/presets/cube.ron")).unwrap();
    let EnvSource::CubeFaces { faces } = &loaded.preset.scene.environment.source else {
        panic!("{:?}", loaded.preset.scene.environment.source);
    };
    assert_eq!(faces[0], Path::new("/data/presets/f/px.png"));
    assert_eq!(faces[5], Path::new("/abs/nz.png"));
    let saved = preset::to_text(&loaded.preset, Path::new("/data/presets/cube.ron")).unwrap();
    assert!(saved.contains("\"f/pz.png\""), "{saved}");

    let text = r#"(scene: (environment: (source: CubeCross(path: "../envmaps/c.exr"))))"#;
    let loaded = preset::parse(text, Path::new("/data/presets/x.ron")).unwrap();
    assert_eq!(
        loaded.preset.scene.environment.source,
        EnvSource::CubeCross {
            path: "/data/envmaps/c.exr".into()
        }
    );
}

/// The shipped cross is what the converter makes of the shipped studio map
/// (to half-float precision), and stays small.
#[test]
fn the_shipped_cross_is_the_converted_studio_map() {
    let path = root().join(SHIPPED_CROSS);
    let bytes = std::fs::metadata(&path).unwrap().len();
    assert!(bytes < 1 << 20, "{bytes} bytes");
    let loaded = CubeMap::load_cross(&path, LdrImages::Srgb).unwrap();
    assert!(loaded.notes.is_empty(), "{:?}", loaded.notes);
    assert_eq!(loaded.cube.size(), SHIPPED_FACE_SIZE);
    let source = envmap::load(&root().join(SHIPPED_SOURCE)).unwrap().image;
    let made = CubeMap::from_latlong(&source, SHIPPED_FACE_SIZE);
    let n = SHIPPED_FACE_SIZE;
    for face in Face::ALL {
        for (x, y) in (0..n * n).map(|i| (i % n, i / n)) {
            let (got, want) = (loaded.cube.texel(face, x, y), made.texel(face, x, y));
            for k in 0..3 {
                // Half floats hold 11 significant bits.
                assert!(
                    (got[k] - want[k]).abs() <= want[k] * 1e-3 + 1e-6,
                    "{face:?} ({x}, {y}): {got:?} vs {want:?}"
                );
            }
        }
    }
}

/// Writes `envmaps/cube/studio-cross.exr` from `envmaps/studio.exr`.
#[test]
#[ignore = "regenerates a shipped asset"]
fn regenerate_shipped_cross() {
    let source = envmap::load(&root().join(SHIPPED_SOURCE)).unwrap().image;
    let cube = CubeMap::from_latlong(&source, SHIPPED_FACE_SIZE);
    let path = root().join(SHIPPED_CROSS);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    write_half_exr(&path, &cube.to_cross());
    eprintln!(
        "wrote {} ({} bytes)",
        path.display(),
        std::fs::metadata(&path).unwrap().len()
    );
}

// ---------------------------------------------------------------------------
// On the GPU

/// A scene with no geometry and the shipped cross as its visible
/// background: pixels looking along the axes, across edges and into corners
/// read what `CubeMap::sample` gives there (averaged over the pixel, as the
/// jittered camera rays are), through the lat-long resampling, the half-float
/// texture and the GPU's filter. A mirrored cube, compared the same way,
/// does not match: the test can tell.
#[test]
fn the_cross_as_background_renders_what_the_cube_samples() {
    let Some(ctx) = marbre_render::gpu::testing::gpu_or_skip(
        "the_cross_as_background_renders_what_the_cube_samples",
    ) else {
        return;
    };
    let cube = CubeMap::load_cross(&root().join(SHIPPED_CROSS), LdrImages::Srgb)
        .unwrap()
        .cube;
    let env = cubemap::load_source(
        &EnvSource::CubeCross {
            path: root().join(SHIPPED_CROSS),
        },
        LdrImages::Srgb,
    )
    .unwrap()
    .unwrap()
    .image;
    let size = (24u32, 16u32);
    let mut errors = Vec::new();
    let mut mirrored_errors = Vec::new();
    // (yaw, pitch): along -z (yaw 0), +x, +z, -x, up and down, and views
    // centred on an edge and near a corner.
    for (yaw, pitch) in [
        (0.0, 0.0),
        (90.0, 0.0),
        (180.0, 0.0),
        (270.0, 0.0),
        (0.0, 80.0),
        (0.0, -80.0),
        (45.0, 0.0),
        (135.0, 30.0),
    ] {
        let mut scene = Scene {
            camera: OrbitCamera {
                target: Vec3::ZERO,
                distance: 1.0,
                yaw_degrees: yaw,
                pitch_degrees: pitch,
                fov_degrees: 20.0,
                ..Default::default()
            },
            ..Scene::default()
        };
        scene.environment.source = EnvSource::CubeCross {
            path: root().join(SHIPPED_CROSS),
        };
        scene.environment.background_visible = true;
        let mut r = marbre_render::gpu::Renderer::new(&ctx, &scene, Some(&env), size).unwrap();
        marbre_render::session::accumulate(&ctx, &mut r, 64, |_| {}).unwrap();
        let (_, _, pixels) = r.read_radiance(&ctx).unwrap();
        for (px, py) in [(12u32, 8u32), (3, 3), (20, 12), (6, 13), (18, 2)] {
            let gpu = pixels[(py * size.0 + px) as usize];
            // The pixel's mean over a 4x4 grid, as its jittered rays see it.
            let mean = |sample: &dyn Fn(Vec3) -> [f32; 3]| {
                let mut sum = [0.0f32; 3];
                for j in 0..4 {
                    for i in 0..4 {
                        let at = Vec2::new(
                            px as f32 + (i as f32 + 0.5) / 4.0,
                            py as f32 + (j as f32 + 0.5) / 4.0,
                        );
                        let (_, d) = common::camera_ray(&scene, size, at);
                        let v = sample(d);
                        for k in 0..3 {
                            sum[k] += v[k] / 16.0;
                        }
                    }
                }
                sum
            };
            let want = mean(&|d| cube.sample(d));
            let mirrored = mean(&|d| cube.sample(Vec3::new(-d.x, d.y, d.z)));
            let rel = |w: [f32; 3]| {
                let scale = w.iter().sum::<f32>() / 3.0 + 0.02;
                (0..3).map(|k| (gpu[k] - w[k]).abs()).sum::<f32>() / 3.0 / scale
            };
            let err = rel(want);
            eprintln!(
                "yaw {yaw} pitch {pitch} pixel ({px}, {py}): gpu {:?} cube {want:?} rel {err:.4}",
                &gpu[..3]
            );
            assert!(
                err < 0.08,
                "yaw {yaw} pitch {pitch} pixel ({px},{py}): {gpu:?} vs {want:?}"
            );
            errors.push(err);
            mirrored_errors.push(rel(mirrored));
        }
    }
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
    eprintln!(
        "mean relative error {}, against the mirrored cube {}",
        mean(&errors),
        mean(&mirrored_errors)
    );
    assert!(mean(&errors) < 0.02, "{errors:?}");
    assert!(mean(&mirrored_errors) > 5.0 * mean(&errors));
}
