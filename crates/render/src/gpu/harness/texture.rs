//! Runs the texture library's WGSL patterns (`crates/core/src/texture/patterns.wgsl`)
//! in a compute pass, so the parity tests can hold them to the CPU reference
//! in [`marbre_core::texture`].

use super::points::PointsHarness;
use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::scene_gpu::NoiseParams;
use crate::gpu::shader_source::Program;
use anyhow::{Result, ensure};
use bytemuck::{Pod, Zeroable};
use glam::{Affine3A, Vec2, Vec3};
use marbre_core::noise::{FractalShape, NoiseSettings};
use marbre_core::texture::{ImageAtlas, ImageFilter, ImageWrap, MAX_RAMP_STOPS, RampStop};

/// One pattern with its parameters. 2D patterns read uv from the points'
/// x and y; `Bump` reads the unbumped normal from the point.
#[derive(Debug, Clone, PartialEq)]
pub enum PatternQuery {
    /// Result: (select, local u, local v).
    Checker2d {
        size: Vec2,
        phase: f32,
    },
    Checker3d {
        size: Vec3,
    },
    FilteredChecker2d {
        size: Vec2,
        phase: f32,
        half_width: Vec2,
    },
    FilteredChecker3d {
        size: Vec3,
        half_width: Vec3,
    },
    /// Result: (select, local u, local v).
    Brick {
        size: Vec2,
        mortar: f32,
        row_offset: f32,
    },
    /// Result: (select, ∂h/∂u, ∂h/∂v, the height profile for a bevel one
    /// unit high).
    Tile {
        mortar_half_width: f32,
        bevel_width: f32,
        bevel_height: f32,
    },
    Cutout {
        sides: u32,
        radius: f32,
    },
    Wood {
        axis: Vec3,
        ring_width: f32,
        turbulence_amount: f32,
        noise: NoiseSettings,
    },
    MarbleVeins {
        axis: Vec3,
        frequency: f32,
        turbulence_amount: f32,
        noise: NoiseSettings,
    },
    /// Massal's marble, his turbulence taken with `noise`.
    MassalMarble {
        stripe_frequency: f32,
        noise: NoiseSettings,
    },
    /// Result: (∂h/∂u, ∂h/∂v, the unit waves' height).
    WavesGradient {
        frequency: f32,
        amplitude: f32,
        direction: Vec2,
    },
    /// Result: the bumped normal.
    Bump {
        dp_du: Vec3,
        dp_dv: Vec3,
        dh_du: f32,
        dh_dv: f32,
    },
    /// Result: the colour at t = the point's x.
    Ramp {
        stops: Vec<RampStop>,
    },
    /// Result: (u, v) of the point as an offset from a sphere's centre.
    SphereUv,
    /// Result: (u, v) of the point as an offset from a cylinder's base.
    CylinderUv {
        height: f32,
    },
    /// Result: (u, v) in the frame origin + u·u_axis + v·v_axis.
    PlaneUv {
        origin: Vec3,
        u_axis: Vec3,
        v_axis: Vec3,
    },
    /// Result: the triangle's interpolated (u, v).
    TriangleUv {
        vertices: [Vec3; 3],
        uvs: [Vec2; 3],
    },
    /// Result: the 3D texture point.
    Transform {
        to_texture: Affine3A,
    },
    /// Result: image `entry` of the atlas sampled at the point's (x, y) as
    /// (u, v), with its z as the level of detail.
    Image {
        atlas: ImageAtlas,
        entry: usize,
        filter: ImageFilter,
        wrap: ImageWrap,
    },
}

/// Which function of the texture library the harness runs: its
/// `harness.mode`. Each has a named constant in texture.wgsl (`MODE_` and
/// the name in upper snake case), checked by a test, so that the shader's
/// `switch` reads names, not numbers.
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Checker2d = 0,
    Checker3d = 1,
    FilteredChecker2d = 2,
    Brick = 3,
    Tile = 4,
    Cutout = 5,
    Wood = 6,
    MarbleVeins = 7,
    WavesGradient = 8,
    Bump = 9,
    Ramp = 10,
    SphereUv = 11,
    CylinderUv = 12,
    PlaneUv = 13,
    TriangleUv = 14,
    Transform = 15,
    Image = 16,
    FilteredChecker3d = 17,
    MassalMarble = 18,
}

#[cfg(test)]
impl Mode {
    /// Every mode, for the test that finds their WGSL constants.
    const ALL: [Mode; 19] = [
        Mode::Checker2d,
        Mode::Checker3d,
        Mode::FilteredChecker2d,
        Mode::Brick,
        Mode::Tile,
        Mode::Cutout,
        Mode::Wood,
        Mode::MarbleVeins,
        Mode::WavesGradient,
        Mode::Bump,
        Mode::Ramp,
        Mode::SphereUv,
        Mode::CylinderUv,
        Mode::PlaneUv,
        Mode::TriangleUv,
        Mode::Transform,
        Mode::Image,
        Mode::FilteredChecker3d,
        Mode::MassalMarble,
    ];
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct TextureHarness {
    noise: NoiseParams,
    mode: u32,
    count: u32,
    sides: u32,
    _pad: u32,
    a: [f32; 4],
    b: [f32; 4],
    c: [f32; 4],
    stops: [[f32; 4]; MAX_RAMP_STOPS],
}

impl PatternQuery {
    fn uniform(&self, count: u32) -> Result<TextureHarness> {
        let mut u = TextureHarness::zeroed();
        u.count = count;
        let v2 = |v: Vec2, z: f32, w: f32| [v.x, v.y, z, w];
        let v3 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
        match self {
            PatternQuery::Checker2d { size, phase } => {
                u.mode = Mode::Checker2d as u32;
                u.a = v2(*size, *phase, 0.0);
            }
            PatternQuery::Checker3d { size } => {
                u.mode = Mode::Checker3d as u32;
                u.a = v3(*size, 0.0);
            }
            PatternQuery::FilteredChecker2d {
                size,
                phase,
                half_width,
            } => {
                u.mode = Mode::FilteredChecker2d as u32;
                u.a = v2(*size, *phase, 0.0);
                u.b = v2(*half_width, 0.0, 0.0);
            }
            PatternQuery::FilteredChecker3d { size, half_width } => {
                u.mode = Mode::FilteredChecker3d as u32;
                u.a = v3(*size, 0.0);
                u.b = v3(*half_width, 0.0);
            }
            PatternQuery::Brick {
                size,
                mortar,
                row_offset,
            } => {
                u.mode = Mode::Brick as u32;
                u.a = v2(*size, *mortar, *row_offset);
            }
            PatternQuery::Tile {
                mortar_half_width,
                bevel_width,
                bevel_height,
            } => {
                u.mode = Mode::Tile as u32;
                u.a = [*mortar_half_width, *bevel_width, *bevel_height, 0.0];
            }
            PatternQuery::Cutout { sides, radius } => {
                u.mode = Mode::Cutout as u32;
                u.sides = *sides;
                u.a[0] = *radius;
            }
            PatternQuery::Wood {
                axis,
                ring_width,
                turbulence_amount,
                noise,
            } => {
                u.mode = Mode::Wood as u32;
                u.noise = NoiseParams::new(noise, FractalShape::Absolute);
                u.a = v3(*axis, *ring_width);
                u.b[0] = *turbulence_amount;
            }
            PatternQuery::MarbleVeins {
                axis,
                frequency,
                turbulence_amount,
                noise,
            } => {
                u.mode = Mode::MarbleVeins as u32;
                u.noise = NoiseParams::new(noise, FractalShape::Absolute);
                u.a = v3(*axis, *frequency);
                u.b[0] = *turbulence_amount;
            }
            PatternQuery::MassalMarble {
                stripe_frequency,
                noise,
            } => {
                u.mode = Mode::MassalMarble as u32;
                u.noise = NoiseParams::new(noise, FractalShape::Absolute);
                u.a[0] = *stripe_frequency;
            }
            PatternQuery::WavesGradient {
                frequency,
                amplitude,
                direction,
            } => {
                u.mode = Mode::WavesGradient as u32;
                u.a = [*frequency, *amplitude, 0.0, 0.0];
                u.b = v2(*direction, 0.0, 0.0);
            }
            PatternQuery::Bump {
                dp_du,
                dp_dv,
                dh_du,
                dh_dv,
            } => {
                u.mode = Mode::Bump as u32;
                u.a = v3(*dp_du, 0.0);
                u.b = v3(*dp_dv, 0.0);
                u.c = [*dh_du, *dh_dv, 0.0, 0.0];
            }
            PatternQuery::Ramp { stops } => {
                ensure!(
                    stops.len() <= MAX_RAMP_STOPS,
                    "a ramp holds at most {MAX_RAMP_STOPS} stops on the GPU, not {}",
                    stops.len()
                );
                u.mode = Mode::Ramp as u32;
                u.sides = stops.len() as u32;
                for (slot, s) in u.stops.iter_mut().zip(stops) {
                    *slot = v3(s.color, s.position);
                }
            }
            PatternQuery::SphereUv => u.mode = Mode::SphereUv as u32,
            PatternQuery::CylinderUv { height } => {
                u.mode = Mode::CylinderUv as u32;
                u.a[0] = *height;
            }
            PatternQuery::PlaneUv {
                origin,
                u_axis,
                v_axis,
            } => {
                u.mode = Mode::PlaneUv as u32;
                u.a = v3(*origin, 0.0);
                u.b = v3(*u_axis, 0.0);
                u.c = v3(*v_axis, 0.0);
            }
            PatternQuery::TriangleUv { vertices, uvs } => {
                u.mode = Mode::TriangleUv as u32;
                for (slot, v) in u.stops.iter_mut().zip(vertices) {
                    *slot = v3(*v, 0.0);
                }
                for (slot, t) in u.stops[3..].iter_mut().zip(uvs) {
                    *slot = v2(*t, 0.0, 0.0);
                }
            }
            PatternQuery::Transform { to_texture } => {
                u.mode = Mode::Transform as u32;
                let (m, t) = (to_texture.matrix3, to_texture.translation);
                u.a = v3(m.x_axis.into(), t.x);
                u.b = v3(m.y_axis.into(), t.y);
                u.c = v3(m.z_axis.into(), t.z);
            }
            PatternQuery::Image {
                atlas,
                entry,
                filter,
                wrap,
            } => {
                u.mode = Mode::Image as u32;
                u.a = atlas.entries[*entry].params();
                u.b = [filter.id() as f32, wrap.id() as f32, 0.0, 0.0];
            }
        }
        Ok(u)
    }

    /// The noise a pattern's turbulence uses, if any: it picks the shader's
    /// noise features.
    fn noise(&self) -> NoiseSettings {
        match self {
            PatternQuery::Wood { noise, .. }
            | PatternQuery::MarbleVeins { noise, .. }
            | PatternQuery::MassalMarble { noise, .. } => *noise,
            _ => NoiseSettings::default(),
        }
    }
}

/// Evaluates `query` at every point on the GPU: one vec4 each (see
/// [`PatternQuery`] for what its components hold).
pub fn evaluate(ctx: &GpuContext, query: &PatternQuery, points: &[Vec3]) -> Result<Vec<[f32; 4]>> {
    let noise = query.noise();
    let atlas = match query {
        PatternQuery::Image { atlas, .. } => Some(atlas),
        _ => None,
    };
    PointsHarness::new(
        ctx,
        Program::TextureHarness,
        &FeatureSet::for_texture_library(&noise),
        atlas,
    )?
    .run(ctx, points, 1, |count| {
        Ok(bytemuck::bytes_of(&query.uniform(count as u32)?).to_vec())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The harness uniform has its WGSL twin's layout, as naga lays it out.
    #[test]
    fn the_uniform_has_its_wgsl_twins_layout() {
        use crate::gpu::twin_layout::{module_of, twin_layout};
        let module = &module_of(
            Program::TextureHarness,
            &FeatureSet::for_texture_library(&Default::default()),
            "",
        );
        twin_layout!(
            module,
            TextureHarness,
            [noise, mode, count, sides, a, b, c, stops]
        );
    }

    /// Every mode has its named constant in texture.wgsl, of its value:
    /// the shader's `switch` and [`Mode`] are one list.
    #[test]
    fn every_mode_has_its_wgsl_constant() {
        use crate::gpu::twin_layout::module_of;
        let module = module_of(
            Program::TextureHarness,
            &FeatureSet::for_texture_library(&Default::default()),
            "",
        );
        let value = |name: &str| {
            let (_, c) = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(name))?;
            match module.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => Some(v),
                _ => None,
            }
        };
        for mode in Mode::ALL {
            let name = format!("{mode:?}");
            let mut wgsl = String::from("MODE");
            for (i, ch) in name.char_indices() {
                let after_lower = i > 0 && name[..i].ends_with(|c: char| c.is_ascii_lowercase());
                if (ch.is_ascii_uppercase() || ch.is_ascii_digit()) && (i == 0 || after_lower) {
                    wgsl.push('_');
                }
                wgsl.push(ch.to_ascii_uppercase());
            }
            assert_eq!(value(&wgsl), Some(mode as u32), "{wgsl} in texture.wgsl");
        }
    }
}
