//! Runs the shader's scene-free ray geometry (`marbre_core::geometry`'s
//! `sphere.wgsl`, `ray_offset.wgsl`) and shading-normal fallback
//! (`texture/bump.wgsl`) on given inputs in a compute pass (`geometry.wgsl`
//! beside this file), so the
//! stability tests can hold the real WGSL to its CPU twins
//! ([`marbre_core::geometry`], [`marbre_core::texture::bump`]) and to double precision.

use super::points::PointsHarness;
use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::shader_source::Program;
use anyhow::Result;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// `QUERY_POINTS` in harness/geometry.wgsl: the inputs of one query.
const QUERY_POINTS: usize = 5;

/// `struct GeometryHarness` in harness/geometry.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GeometryHarness {
    mode: u32,
    count: u32,
    _pad: [u32; 2],
}

/// A ray and a sphere, for `sphere_distance`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereQuery {
    pub origin: Vec3,
    /// Unit length, as the renderer's rays are.
    pub direction: Vec3,
    pub center: Vec3,
    pub radius: f32,
}

/// A bump's inputs at a hit, for `bumped_normal` then
/// `facing_shading_normal`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingQuery {
    /// The geometric normal, facing the viewer.
    pub normal: Vec3,
    pub dp_du: Vec3,
    pub dp_dv: Vec3,
    pub dh_du: f32,
    pub dh_dv: f32,
    /// Towards the viewer.
    pub wo: Vec3,
}

/// The shading normal the shader uses, and the bumped normal it came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingNormal {
    pub shading: Vec3,
    pub bumped: Vec3,
}

fn run(ctx: &GpuContext, mode: u32, queries: Vec<[Vec3; QUERY_POINTS]>) -> Result<Vec<[Vec3; 2]>> {
    let points: Vec<Vec3> = queries.into_iter().flatten().collect();
    let harness = PointsHarness::new(ctx, Program::GeometryHarness, &FeatureSet::default(), None)?;
    let results = harness.run(ctx, &points, QUERY_POINTS, |count| {
        let uniform = GeometryHarness {
            mode,
            count: (count / QUERY_POINTS) as u32,
            _pad: [0; 2],
        };
        Ok(bytemuck::bytes_of(&uniform).to_vec())
    })?;
    Ok(results
        .chunks_exact(QUERY_POINTS)
        .map(|r| [0, 1].map(|k| Vec3::from_slice(&r[k][..3])))
        .collect())
}

/// `sphere_distance` of each query: t, or `geometry::NO_HIT` for a miss.
pub fn sphere_distances(ctx: &GpuContext, queries: &[SphereQuery]) -> Result<Vec<f32>> {
    let inputs = queries
        .iter()
        .map(|q| {
            [
                q.origin,
                q.direction,
                q.center,
                Vec3::new(q.radius, 0.0, 0.0),
                Vec3::ZERO,
            ]
        })
        .collect();
    Ok(run(ctx, 0, inputs)?.iter().map(|r| r[0].x).collect())
}

/// `offset_ray(p, n)` of each (point, normal) pair.
pub fn offset_rays(ctx: &GpuContext, points_and_normals: &[(Vec3, Vec3)]) -> Result<Vec<Vec3>> {
    let inputs = points_and_normals
        .iter()
        .map(|&(p, n)| [p, n, Vec3::ZERO, Vec3::ZERO, Vec3::ZERO])
        .collect();
    Ok(run(ctx, 1, inputs)?.iter().map(|r| r[0]).collect())
}

/// The shading normal of each query, as the trace pass computes it under a
/// bump.
pub fn shading_normals(ctx: &GpuContext, queries: &[ShadingQuery]) -> Result<Vec<ShadingNormal>> {
    let inputs = queries
        .iter()
        .map(|q| {
            [
                q.normal,
                q.dp_du,
                q.dp_dv,
                Vec3::new(q.dh_du, q.dh_dv, 0.0),
                q.wo,
            ]
        })
        .collect();
    Ok(run(ctx, 2, inputs)?
        .iter()
        .map(|r| ShadingNormal {
            shading: r[0],
            bumped: r[1],
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::pipelines::validate;
    use crate::gpu::shader_source::assemble;

    /// naga accepts the harness, and its constants are the CPU twins'.
    #[test]
    fn the_harness_wgsl_validates_with_the_cpu_constants() {
        use naga::{Expression, Literal};
        let source = assemble(Program::GeometryHarness, &FeatureSet::default(), "").unwrap();
        validate(&source).unwrap();
        let module = naga::front::wgsl::parse_str(&source).unwrap();
        crate::gpu::twin_layout::twin_layout!(&module, GeometryHarness, [mode, count,]);
        let constant = |name: &str| {
            let (_, c) = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(name))
                .unwrap();
            match module.global_expressions[c.init] {
                Expression::Literal(l) => l,
                ref e => panic!("{name}: {e:?}"),
            }
        };
        assert_eq!(constant("QUERY_POINTS"), Literal::U32(QUERY_POINTS as u32));
        assert_eq!(
            constant("NO_HIT"),
            Literal::F32(marbre_core::geometry::NO_HIT)
        );
        use marbre_core::geometry::ray_offset::{FLOAT_SCALE, INT_SCALE, ORIGIN};
        assert_eq!(constant("OFFSET_ORIGIN"), Literal::F32(ORIGIN));
        assert_eq!(constant("OFFSET_FLOAT_SCALE"), Literal::F32(FLOAT_SCALE));
        assert_eq!(constant("OFFSET_INT_SCALE"), Literal::F32(INT_SCALE));
        assert_eq!(
            constant("MIN_TILTED_LENGTH"),
            Literal::F32(marbre_core::texture::bump::MIN_TILTED_LENGTH)
        );
        assert_eq!(
            constant("FACING_MIN_COS"),
            Literal::F32(marbre_core::texture::bump::FACING_MIN_COS)
        );
    }
}
