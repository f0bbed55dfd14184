//! Cube-map environments: six square faces, or one horizontal-cross image.
//!
//! # Convention
//!
//! Faces and their `(s, t)` follow the OpenGL / Vulkan table "Selection of
//! cube map images" (OpenGL 4.6 §8.13.1, Vulkan "Cube Map Face Selection"):
//! the largest component of the direction `r` (the major axis `ma`) picks
//! the face, and
//!
//! ```text
//! face   sc    tc    ma        s = (sc / |ma| + 1) / 2
//!  +x   -rz   -ry    rx        t = (tc / |ma| + 1) / 2
//!  -x   +rz   -ry    rx
//!  +y   +rx   +rz    ry        s grows with the image column,
//!  -y   +rx   -rz    ry        t with the row (row 0 = the top of the file)
//!  +z   +rx   -ry    rz
//!  -z   -rx   -ry    rz
//! ```
//!
//! so face files found on the web (`px`, `nx`, `py`, …, or `right`, `left`,
//! `top`, …) load as they are, without flips. World directions are used as
//! they are: the world's up (+y) is the cube's +y face, and the four side
//! faces are upright in their files.
//!
//! This agrees with the project's lat-long mapping ([`crate::envmap`]):
//! seen in the same frame, both pictures are the right way round, not
//! mirrored. On the +z face, `s` grows towards +x; in a lat-long map, `u`
//! grows from +z (0.5) towards +x (0.75). So a cube map and the lat-long
//! made from the same panorama look the same here, and [`CubeMap::from_latlong`]
//! followed by [`CubeMap::to_latlong`] gives back the original
//! (crates/render/tests/gpu/cubemap.rs checks both).
//!
//! A horizontal cross ([`CubeMap::from_cross`]) is 4 × 3 faces, each face
//! in its file orientation, so that it unfolds the cube without cuts along
//! the middle row:
//!
//! ```text
//!        +y
//!   -x   +z   +x   -z
//!        -y
//! ```
//!
//! # Sampling without seams
//!
//! [`CubeMap::sample`] filters bilinearly *across* faces. Each face is kept
//! with a one-texel border filled from its four neighbours (the texels of the
//! adjacent face that touch the shared edge), so a 2×2 footprint that
//! straddles an edge reads the same four texels from either side and the
//! filtered value is continuous over the edge. Clamping each face to its own
//! edge instead (what a plain 2D texture per face does) holds each face's
//! last texel up to the edge, and the two faces then disagree there: a
//! visible seam line, worst on small faces. Where three faces meet there is
//! no fourth texel; the corner of the border holds the average of the three
//! corner texels. That choice is symmetric in the three faces, so each of
//! them gives the same value (that average) at the corner and the filter
//! stays continuous there too.
//!
//! # Rendering: one resampling to lat-long
//!
//! The renderer only knows lat-long maps (its importance sampling, the GPU
//! lookup, the rotation all work on one). A cube map is therefore resampled
//! once, when it is loaded, into a lat-long [`EnvImage`] of 4N × 2N (N =
//! face size, at most [`MAX_LATLONG_WIDTH`] wide) with [`CubeMap::sample`],
//! 2 × 2 samples per lat-long texel: a lat-long texel is about 1.6/N
//! radians tall everywhere (and as wide on the horizon), while the cube's
//! texels shrink to about 1/N radians near its edges and corners (from 2/N
//! at a face centre), so one sample per texel would skip cube texels there
//! and alias. The cost is that resampling (32 N² cube samples, spread over
//! the cores, at every load) and one more filter on the way to the screen,
//! which softens the map slightly (see the round-trip tests); nothing
//! changes on the GPU.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use thiserror::Error;

use crate::env_sampling::EnvDistribution;
use crate::envmap::{self, EnvImage, EnvLoad, EnvMapError, LdrImages};
use crate::scene::EnvSource;

/// The widest lat-long image [`CubeMap::to_latlong`] makes (then 2048
/// rows): faces above 1024 texels are resampled at this size, which bounds
/// the resampling time and the texture memory (64 MiB as half floats).
pub const MAX_LATLONG_WIDTH: u32 = 4096;

/// The largest face size [`CubeMap::from_latlong`] accepts.
pub const MAX_FACE_SIZE: u32 = 8192;

/// A cube face, in the OpenGL order: +x, −x, +y, −y, +z, −z.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Face {
    PosX,
    NegX,
    PosY,
    NegY,
    PosZ,
    NegZ,
}

impl Face {
    /// The six faces in the OpenGL order, which is also the order of
    /// [`EnvSource::CubeFaces`].
    pub const ALL: [Face; 6] = [
        Face::PosX,
        Face::NegX,
        Face::PosY,
        Face::NegY,
        Face::PosZ,
        Face::NegZ,
    ];

    /// The face's position in [`Face::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// "+x", "-x", …, for messages and the panel.
    pub fn name(self) -> &'static str {
        ["+x", "-x", "+y", "-y", "+z", "-z"][self.index()]
    }

    /// The unit vector the face is centred on (its major axis).
    pub fn axis(self) -> Vec3 {
        match self {
            Face::PosX => Vec3::X,
            Face::NegX => Vec3::NEG_X,
            Face::PosY => Vec3::Y,
            Face::NegY => Vec3::NEG_Y,
            Face::PosZ => Vec3::Z,
            Face::NegZ => Vec3::NEG_Z,
        }
    }

    /// The directions along which `s` and `t` grow on the face: `sc = r·S`,
    /// `tc = r·T` in the OpenGL table.
    pub fn st_axes(self) -> (Vec3, Vec3) {
        match self {
            Face::PosX => (Vec3::NEG_Z, Vec3::NEG_Y),
            Face::NegX => (Vec3::Z, Vec3::NEG_Y),
            Face::PosY => (Vec3::X, Vec3::Z),
            Face::NegY => (Vec3::X, Vec3::NEG_Z),
            Face::PosZ => (Vec3::X, Vec3::NEG_Y),
            Face::NegZ => (Vec3::NEG_X, Vec3::NEG_Y),
        }
    }

    /// The face's cell (column, row) in a horizontal cross of 4 × 3 cells.
    pub fn cross_cell(self) -> (u32, u32) {
        match self {
            Face::PosX => (2, 1),
            Face::NegX => (0, 1),
            Face::PosY => (1, 0),
            Face::NegY => (1, 2),
            Face::PosZ => (1, 1),
            Face::NegZ => (3, 1),
        }
    }

    /// The (not normalised) direction through face point `(s, t)`; `s` and
    /// `t` may leave [0, 1], which reaches past the face's edges in its plane.
    pub fn direction(self, s: f32, t: f32) -> Vec3 {
        let (sa, ta) = self.st_axes();
        self.axis() + (2.0 * s - 1.0) * sa + (2.0 * t - 1.0) * ta
    }
}

/// The face a direction falls on and its `(s, t)` in [0, 1]², by the OpenGL
/// table. Ties (a direction exactly between faces) go to x before y before
/// z; with seamless sampling either face gives the same value. A zero or
/// non-finite direction gives the centre of +z.
pub fn face_st(d: Vec3) -> (Face, Vec2) {
    if !d.is_finite() || d == Vec3::ZERO {
        return (Face::PosZ, Vec2::splat(0.5));
    }
    let a = d.abs();
    let face = if a.x >= a.y && a.x >= a.z {
        if d.x >= 0.0 { Face::PosX } else { Face::NegX }
    } else if a.y >= a.z {
        if d.y >= 0.0 { Face::PosY } else { Face::NegY }
    } else if d.z >= 0.0 {
        Face::PosZ
    } else {
        Face::NegZ
    };
    let ma = d.dot(face.axis());
    let (sa, ta) = face.st_axes();
    let st = Vec2::new(d.dot(sa) / ma, d.dot(ta) / ma);
    let st = (st + 1.0) * 0.5;
    (face, st.clamp(Vec2::ZERO, Vec2::ONE))
}

/// Why a cube map could not be loaded. Every message names the file and,
/// for face files, the face.
#[derive(Debug, Error)]
pub enum CubeMapError {
    /// A face file is missing, unreadable or cannot be decoded.
    #[error("cube map face {face}: {error}")]
    Face {
        face: &'static str,
        /// Not a `#[source]`: the message already says it.
        error: EnvMapError,
    },
    /// A cross (or a lat-long) file is missing, unreadable or cannot be
    /// decoded.
    #[error(transparent)]
    Image(#[from] EnvMapError),
    /// A face file that is not square.
    #[error(
        "cube map face {face} {}: the image is {width}x{height}; a cube face must be square",
        .path.display()
    )]
    NotSquare {
        face: &'static str,
        path: PathBuf,
        width: u32,
        height: u32,
    },
    /// A face file whose size differs from the first face's.
    #[error(
        "cube map face {face} {}: the image is {size}x{size}, but face {first_face} {} is \
         {first_size}x{first_size}; all six faces must be the same size",
        .path.display(),
        .first_path.display()
    )]
    UnequalFaces {
        face: &'static str,
        path: PathBuf,
        size: u32,
        first_face: &'static str,
        first_path: PathBuf,
        first_size: u32,
    },
    /// A cross image that is not 4 × 3 square faces.
    #[error(
        "cube map {}: the image is {width}x{height}, not a horizontal cross of 4x3 square \
         faces (width:height must be 4:3, the width a multiple of 4)",
        .path.display()
    )]
    CrossAspect {
        path: PathBuf,
        width: u32,
        height: u32,
    },
}

impl CubeMapError {
    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            CubeMapError::Face { error, .. } | CubeMapError::Image(error) => error.path(),
            CubeMapError::NotSquare { path, .. }
            | CubeMapError::UnequalFaces { path, .. }
            | CubeMapError::CrossAspect { path, .. } => path,
        }
    }
}

/// Six square faces of linear RGB radiance, each `size` × `size`, row 0 =
/// `t` near 0 (the top of the face's file).
#[derive(Debug, Clone, PartialEq)]
pub struct CubeMap {
    size: u32,
    /// Each face with a one-texel border from its neighbours, row-major,
    /// `(size + 2)²` texels: what [`CubeMap::sample`] filters. The faces are
    /// kept only in this form, so a large cube is held once.
    padded: [Vec<[f32; 3]>; 6],
}

/// A loaded cube map and one note per kind of repair the loader made to
/// each file (see [`DecodedImage::sanitize`](crate::image_decode::DecodedImage::sanitize)).
#[derive(Debug, Clone)]
pub struct CubeLoad {
    pub cube: CubeMap,
    pub notes: Vec<String>,
}

impl CubeMap {
    /// A cube map from its faces in [`Face::ALL`] order, each row-major,
    /// row 0 first.
    ///
    /// # Panics
    /// If `size` is 0 or a face does not hold `size²` texels.
    pub fn new(size: u32, faces: [Vec<[f32; 3]>; 6]) -> CubeMap {
        assert!(size > 0, "a cube map needs faces of at least 1x1");
        let n = size as usize;
        for (face, texels) in Face::ALL.iter().zip(&faces) {
            assert_eq!(
                texels.len(),
                n * n,
                "face {} of a {size}x{size} cube map",
                face.name()
            );
        }
        let side = n + 2;
        let padded = faces.map(|texels| {
            let mut p = vec![[0.0; 3]; side * side];
            for (y, row) in texels.chunks_exact(n).enumerate() {
                p[(y + 1) * side + 1..(y + 1) * side + 1 + n].copy_from_slice(row);
            }
            p
        });
        let mut cube = CubeMap { size, padded };
        for face in Face::ALL {
            // The border reads only the other faces' own texels.
            let border = cube.border(face);
            let p = &mut cube.padded[face.index()];
            for (index, value) in border {
                p[index] = value;
            }
            fill_corners(p, side);
        }
        cube
    }

    /// A cube map whose texel `(x, y)` of `face` is `f(face, x, y)`.
    pub fn from_fn(size: u32, mut f: impl FnMut(Face, u32, u32) -> [f32; 3]) -> CubeMap {
        let faces = Face::ALL.map(|face| {
            (0..size * size)
                .map(|i| f(face, i % size, i / size))
                .collect()
        });
        CubeMap::new(size, faces)
    }

    /// Faces are `size` × `size` texels.
    pub fn size(&self) -> u32 {
        self.size
    }

    /// Texel `(x, y)` of `face` (row 0 = the top of the face's file).
    pub fn texel(&self, face: Face, x: u32, y: u32) -> [f32; 3] {
        let side = self.size as usize + 2;
        self.padded[face.index()][(y as usize + 1) * side + x as usize + 1]
    }

    /// The border texels of `face` but its corners, as (index in the
    /// padded face, value), taken from the neighbouring faces.
    fn border(&self, face: Face) -> Vec<(usize, [f32; 3])> {
        let n = self.size as i64;
        let side = (n + 2) as usize;
        let mut out = Vec::with_capacity(4 * n as usize);
        let inside = |c: i64| (0..n).contains(&c);
        for j in 0..n + 2 {
            for i in 0..n + 2 {
                let (x, y) = (i - 1, j - 1);
                if inside(x) == inside(y) {
                    continue; // the face's own texels, or a corner
                }
                // Unfold the plane of the face past its edge: the point half
                // a texel beyond it lies on the neighbour, in the
                // neighbour's texel that touches the edge there.
                let s = (x as f32 + 0.5) / n as f32;
                let t = (y as f32 + 0.5) / n as f32;
                let (g, st) = face_st(face.direction(s, t));
                let tx = ((st.x * n as f32) as u32).min(self.size - 1);
                let ty = ((st.y * n as f32) as u32).min(self.size - 1);
                out.push((j as usize * side + i as usize, self.texel(g, tx, ty)));
            }
        }
        out
    }

    /// The radiance towards `d` (any length), filtered bilinearly across
    /// faces without seams: see the module documentation.
    pub fn sample(&self, d: Vec3) -> [f32; 3] {
        let (face, st) = face_st(d);
        let n = self.size as f32;
        let side = self.size as usize + 2;
        // Padded texel j has its centre at s = (j - 0.5) / n.
        let p = st * n + 0.5;
        let x0 = (p.x.floor() as usize).min(self.size as usize);
        let y0 = (p.y.floor() as usize).min(self.size as usize);
        let fx = (p.x - x0 as f32).clamp(0.0, 1.0);
        let fy = (p.y - y0 as f32).clamp(0.0, 1.0);
        let texels = &self.padded[face.index()];
        let at = |i: usize, j: usize| texels[j * side + i];
        let (a, b) = (at(x0, y0), at(x0 + 1, y0));
        let (c, e) = (at(x0, y0 + 1), at(x0 + 1, y0 + 1));
        bilinear([a, b, c, e], fx, fy)
    }

    /// Resamples a lat-long map into a cube of `size` × `size` faces: each
    /// texel is the mean of 2 × 2 bilinear lookups of `image` (repeating in
    /// u, clamped in v, as the GPU reads it) spread over the texel. This is
    /// the converter the shipped cross was made with.
    ///
    /// # Panics
    /// If `size` is 0 or above [`MAX_FACE_SIZE`].
    pub fn from_latlong(image: &EnvImage, size: u32) -> CubeMap {
        assert!(
            (1..=MAX_FACE_SIZE).contains(&size),
            "cube face size {size} out of 1..={MAX_FACE_SIZE}"
        );
        let n = size as f32;
        let faces = Face::ALL.map(|face| {
            parallel_map(size * size, |i| {
                let (x, y) = ((i % size) as f32, (i / size) as f32);
                mean_of_four(|ox, oy| {
                    latlong_bilinear(image, face.direction((x + ox) / n, (y + oy) / n))
                })
            })
        });
        CubeMap::new(size, faces)
    }

    /// The lat-long image the renderer uses for this cube: see
    /// [`CubeMap::latlong_size`] for its size and the module documentation
    /// for why and at what cost.
    pub fn to_latlong(&self) -> EnvImage {
        let (w, _) = self.latlong_size();
        self.to_latlong_width(w)
    }

    /// 4N × 2N for faces of N, at most [`MAX_LATLONG_WIDTH`] × half that.
    pub fn latlong_size(&self) -> (u32, u32) {
        let w = (4 * self.size).min(MAX_LATLONG_WIDTH);
        (w, w / 2)
    }

    /// [`CubeMap::to_latlong`] at a given width (`width` × `width / 2`,
    /// `width` even and at least 2): each texel is the mean of 2 × 2
    /// [`CubeMap::sample`]s spread over it.
    pub fn to_latlong_width(&self, width: u32) -> EnvImage {
        let width = width.max(2) & !1;
        let height = width / 2;
        let size = Vec2::new(width as f32, height as f32);
        let pixels = parallel_map(width * height, |i| {
            let (x, y) = ((i % width) as f32, (i / width) as f32);
            let rgb = mean_of_four(|ox, oy| {
                let t = Vec2::new(x + ox, y + oy) / size;
                self.sample(EnvDistribution::direction(t, 0.0, 0.0).0)
            });
            [rgb[0], rgb[1], rgb[2], 1.0]
        });
        EnvImage {
            width,
            height,
            pixels,
        }
    }

    /// The faces laid out as a horizontal cross ([`Face::cross_cell`]),
    /// 4N × 3N, the six unused cells black.
    pub fn to_cross(&self) -> EnvImage {
        let n = self.size;
        let (width, height) = (4 * n, 3 * n);
        let mut pixels = vec![[0.0, 0.0, 0.0, 1.0]; (width * height) as usize];
        for face in Face::ALL {
            let (cx, cy) = face.cross_cell();
            for y in 0..n {
                for x in 0..n {
                    let [r, g, b] = self.texel(face, x, y);
                    pixels[((cy * n + y) * width + cx * n + x) as usize] = [r, g, b, 1.0];
                }
            }
        }
        EnvImage {
            width,
            height,
            pixels,
        }
    }

    /// Cuts the six faces out of a horizontal-cross image; `path` only names
    /// the file in the error for an image that is not 4:3 (with a width
    /// that divides by 4).
    pub fn from_cross(image: &EnvImage, path: &Path) -> Result<CubeMap, CubeMapError> {
        let (w, h) = (image.width, image.height);
        if w == 0 || w % 4 != 0 || h * 4 != w * 3 {
            return Err(CubeMapError::CrossAspect {
                path: path.to_path_buf(),
                width: w,
                height: h,
            });
        }
        let n = w / 4;
        Ok(CubeMap::from_fn(n, |face, x, y| {
            let (cx, cy) = face.cross_cell();
            let [r, g, b, _] = image.texel(cx * n + x, cy * n + y);
            [r, g, b]
        }))
    }

    /// Loads a horizontal-cross file in any format [`envmap::load`] reads,
    /// sanitised the same way.
    /// An 8- or 16-bit file is read as `ldr` says.
    pub fn load_cross(path: &Path, ldr: LdrImages) -> Result<CubeLoad, CubeMapError> {
        let l = envmap::load_ldr(path, ldr)?;
        Ok(CubeLoad {
            cube: CubeMap::from_cross(&l.image, path)?,
            notes: l.notes,
        })
    }

    /// Loads six face files, in [`Face::ALL`] order, each in any format
    /// [`envmap::load`] reads and sanitised the same way. Every face must be
    /// square and the same size as the first.
    /// 8- or 16-bit files are read as `ldr` says.
    pub fn load_faces(paths: &[PathBuf; 6], ldr: LdrImages) -> Result<CubeLoad, CubeMapError> {
        let mut notes = Vec::new();
        let mut faces: [Vec<[f32; 3]>; 6] = Default::default();
        let mut first: Option<(Face, &Path, u32)> = None;
        for (face, path) in Face::ALL.into_iter().zip(paths) {
            let l = envmap::load_ldr(path, ldr).map_err(|error| CubeMapError::Face {
                face: face.name(),
                error,
            })?;
            let (w, h) = (l.image.width, l.image.height);
            if w != h {
                return Err(CubeMapError::NotSquare {
                    face: face.name(),
                    path: path.clone(),
                    width: w,
                    height: h,
                });
            }
            match first {
                None => first = Some((face, path, w)),
                Some((first_face, first_path, first_size)) if first_size != w => {
                    return Err(CubeMapError::UnequalFaces {
                        face: face.name(),
                        path: path.clone(),
                        size: w,
                        first_face: first_face.name(),
                        first_path: first_path.to_path_buf(),
                        first_size,
                    });
                }
                Some(_) => {}
            }
            notes.extend(l.notes);
            faces[face.index()] = l.image.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
        }
        let size = first.map_or(0, |(_, _, s)| s);
        Ok(CubeLoad {
            cube: CubeMap::new(size, faces),
            notes,
        })
    }
}

/// Sets the four corners of a padded face (`side` × `side`) to the
/// average of the three texels that meet there: the face's corner texel
/// and the two neighbours' beside it in the border.
fn fill_corners(p: &mut [[f32; 3]], side: usize) {
    let last = side - 1;
    for (ci, cj, ni, nj) in [
        (0, 0, 1, 1),
        (last, 0, last - 1, 1),
        (0, last, 1, last - 1),
        (last, last, last - 1, last - 1),
    ] {
        let three = [p[nj * side + ni], p[cj * side + ni], p[nj * side + ci]];
        p[cj * side + ci] =
            std::array::from_fn(|c| (three[0][c] + three[1][c] + three[2][c]) / 3.0);
    }
}

/// The lat-long image an environment source stands for, loaded and
/// sanitised, with the loader's notes: a lat-long file as it is, a cube map
/// resampled by [`CubeMap::to_latlong`] (one more note says so). `None` for
/// a source without a map. 8- or 16-bit files are read as `ldr` says (the
/// scene's `environment.ldr_images`).
pub fn load_source(source: &EnvSource, ldr: LdrImages) -> Result<Option<EnvLoad>, CubeMapError> {
    let cube = match source {
        EnvSource::None | EnvSource::Constant { .. } => return Ok(None),
        EnvSource::LatLong { path } => return Ok(Some(envmap::load_ldr(path, ldr)?)),
        EnvSource::CubeFaces { faces } => CubeMap::load_faces(faces, ldr)?,
        EnvSource::CubeCross { path } => CubeMap::load_cross(path, ldr)?,
    };
    let image = cube.cube.to_latlong();
    let mut notes = cube.notes;
    notes.push(format!(
        "cube map of {n}x{n} faces resampled to a {}x{} lat-long map",
        image.width,
        image.height,
        n = cube.cube.size()
    ));
    Ok(Some(EnvLoad { image, notes }))
}

/// The bilinear blend of four texels (top left, top right, bottom left,
/// bottom right) at fractions `fx` across and `fy` down.
pub fn bilinear([a, b, c, e]: [[f32; 3]; 4], fx: f32, fy: f32) -> [f32; 3] {
    std::array::from_fn(|k| {
        let top = a[k] + (b[k] - a[k]) * fx;
        let bottom = c[k] + (e[k] - c[k]) * fx;
        top + (bottom - top) * fy
    })
}

/// The lat-long image's bilinear value towards `d` (any length), as the GPU
/// reads it: texel uv `(u, 1 - v)`, repeating in u, clamped in v.
fn latlong_bilinear(image: &EnvImage, d: Vec3) -> [f32; 3] {
    // `direction_to_uv` wants a unit vector (its v is an arccosine).
    let t = envmap::uv_to_texel_uv(envmap::direction_to_uv(d.normalize_or_zero()));
    let (w, h) = (image.width as i64, image.height as i64);
    let x = t.x * w as f32 - 0.5;
    let y = (t.y * h as f32 - 0.5).clamp(0.0, (h - 1) as f32);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let at = |i: i64, j: i64| image.texel(i.rem_euclid(w) as u32, j.clamp(0, h - 1) as u32);
    let (a, b, c, e) = (
        at(x0, y0),
        at(x0 + 1, y0),
        at(x0, y0 + 1),
        at(x0 + 1, y0 + 1),
    );
    bilinear([a, b, c, e].map(|t| [t[0], t[1], t[2]]), fx, fy)
}

/// The mean of `f` at the four points (0.25 | 0.75, 0.25 | 0.75) of a unit
/// texel.
fn mean_of_four(mut f: impl FnMut(f32, f32) -> [f32; 3]) -> [f32; 3] {
    let mut sum = [0.0f32; 3];
    for (ox, oy) in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
        let v = f(ox, oy);
        for k in 0..3 {
            sum[k] += v[k];
        }
    }
    sum.map(|s| s * 0.25)
}

/// `(0..count).map(f)`, computed in chunks on the available cores; in a
/// web page (wasm32, no threads) on the page's one.
fn parallel_map<T: Send + Default + Clone>(count: u32, f: impl Fn(u32) -> T + Sync) -> Vec<T> {
    if cfg!(target_arch = "wasm32") {
        return (0..count).map(f).collect();
    }
    let mut out = vec![T::default(); count as usize];
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let chunk = (count as usize).div_ceil(threads).max(4096);
    std::thread::scope(|scope| {
        for (c, slice) in out.chunks_mut(chunk).enumerate() {
            let f = &f;
            scope.spawn(move || {
                for (k, v) in slice.iter_mut().enumerate() {
                    *v = f((c * chunk + k) as u32);
                }
            });
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_axes_are_orthonormal_and_left_handed_like_gl() {
        for face in Face::ALL {
            let (s, t) = face.st_axes();
            let a = face.axis();
            assert_eq!(s.dot(t), 0.0);
            assert_eq!(s.dot(a), 0.0);
            assert_eq!(t.dot(a), 0.0);
            // The GL table is left-handed for every face alike.
            assert_eq!(s.cross(t), -a, "{}", face.name());
        }
    }

    #[test]
    fn face_st_inverts_direction() {
        for face in Face::ALL {
            for (s, t) in [(0.5, 0.5), (0.1, 0.8), (0.99, 0.01), (0.3, 0.3)] {
                let (f, st) = face_st(face.direction(s, t) * 3.0);
                assert_eq!(f, face);
                assert!((st - Vec2::new(s, t)).abs().max_element() < 1e-6, "{st}");
            }
        }
        assert_eq!(face_st(Vec3::ZERO), (Face::PosZ, Vec2::splat(0.5)));
        assert_eq!(face_st(Vec3::NAN).0, Face::PosZ);
    }

    #[test]
    fn border_holds_the_neighbours_edge_texels() {
        // Faces numbered by index and texel, so each texel is unique.
        let n = 4;
        let cube = CubeMap::from_fn(n, |f, x, y| [f.index() as f32, x as f32, y as f32]);
        let side = (n + 2) as usize;
        for face in Face::ALL {
            let p = &cube.padded[face.index()];
            for j in 1..side - 1 {
                for i in [0, side - 1] {
                    let v = p[j * side + i];
                    assert_ne!(v[0], face.index() as f32);
                    // The neighbour's texel touches the edge: its direction
                    // is about one texel from this face's edge texel.
                    let (x, y) = (if i == 0 { 0 } else { n - 1 }, j as u32 - 1);
                    let here = face
                        .direction((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32)
                        .normalize();
                    let g = Face::ALL[v[0] as usize];
                    let there = g
                        .direction((v[1] + 0.5) / n as f32, (v[2] + 0.5) / n as f32)
                        .normalize();
                    let angle = here.angle_between(there);
                    assert!(
                        angle < 1.2 * std::f32::consts::FRAC_PI_2 / n as f32,
                        "{angle}"
                    );
                }
            }
        }
    }

    #[test]
    fn latlong_size_is_capped() {
        let small = CubeMap::from_fn(3, |_, _, _| [1.0; 3]);
        assert_eq!(small.latlong_size(), (12, 6));
        let big = CubeMap {
            size: 2048,
            padded: Default::default(),
        };
        assert_eq!(
            big.latlong_size(),
            (MAX_LATLONG_WIDTH, MAX_LATLONG_WIDTH / 2)
        );
    }
}
