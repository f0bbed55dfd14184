//! Baking a material property to an image (`marbre bake`): which object,
//! which property, and where each texel of the image lies on the object's
//! surface through its (u, v) parametrisation. The GPU evaluates the
//! renderer's generated texture code at these points (marbre-render's
//! `gpu::bake`); [`reference`] is its CPU oracle.
//!
//! The image is the (u, v) square [0, 1]²: texel (i, j), row j counted from
//! the top, is read at its centre u = (i + ½)/N, v = 1 − (j + ½)/N (v up,
//! as OpenGL and Blender lay out uv images). Each texel's surface point is
//! the one the renderer would shade at that (u, v), with the object and
//! world coordinates and the (u, v) it would compute there, so 2D and 3D
//! patterns alike come out as the render shows them on the object.

use crate::atomic_write::write_atomic_pair;
use crate::image_io::{self, ImageFormat, encode_exr, encode_png};
use crate::scene::color_encoding::srgb_encode;
use crate::scene::{Material, Property, Scene, SurfacePoint, UvFrame};
use crate::texture::{cylinder_uv, plane_uv, sphere_uv};
use anyhow::{Context, Result, bail};
use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};
use std::f32::consts::PI;
use std::path::{Path, PathBuf};

/// The largest image side `marbre bake` writes: 16M texels, whose points
/// and values the GPU takes in chunks.
pub const MAX_BAKE_SIZE: u32 = 4096;

/// What a bake writes: a material property (the bump's height field
/// being one).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum BakeProperty {
    Diffuse,
    Specular,
    Roughness,
    Bump,
    Opacity,
    Emission,
}

impl BakeProperty {
    pub const ALL: [BakeProperty; 6] = [
        BakeProperty::Diffuse,
        BakeProperty::Specular,
        BakeProperty::Roughness,
        BakeProperty::Bump,
        BakeProperty::Opacity,
        BakeProperty::Emission,
    ];

    pub fn name(self) -> &'static str {
        match self {
            BakeProperty::Diffuse => "diffuse",
            BakeProperty::Specular => "specular",
            BakeProperty::Roughness => "roughness",
            BakeProperty::Bump => "bump",
            BakeProperty::Opacity => "opacity",
            BakeProperty::Emission => "emission",
        }
    }

    /// The property called `name`, or an error listing the names.
    pub fn parse(name: &str) -> Result<Self> {
        match Self::ALL.into_iter().find(|p| p.name() == name) {
            Some(p) => Ok(p),
            None => bail!(
                "no property `{name}` to bake: it is one of {}",
                Self::ALL.map(Self::name).join(", ")
            ),
        }
    }

    /// The material property it is; `None` for the bump height.
    pub fn material_property(self) -> Option<Property> {
        match self {
            BakeProperty::Diffuse => Some(Property::Diffuse),
            BakeProperty::Specular => Some(Property::Specular),
            BakeProperty::Roughness => Some(Property::Roughness),
            BakeProperty::Bump => None,
            BakeProperty::Opacity => Some(Property::Opacity),
            BakeProperty::Emission => Some(Property::Emission),
        }
    }

    /// Whether its values are colours (written sRGB-encoded to a PNG by
    /// default) rather than data (written linear to an EXR by default).
    pub fn is_color(self) -> bool {
        matches!(
            self,
            BakeProperty::Diffuse | BakeProperty::Specular | BakeProperty::Emission
        )
    }

    /// The file extension a bake of it defaults to.
    pub fn default_extension(self) -> &'static str {
        if self.is_color() { "png" } else { "exr" }
    }
}

/// One object of a scene, by kind and index (names need not be unique).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ObjectRef {
    Sphere(usize),
    Cylinder(usize),
    Polygon(usize),
    Ground,
    Mesh(usize),
}

impl ObjectRef {
    /// Every object of `scene`, in the panel's order.
    pub fn all(scene: &Scene) -> Vec<ObjectRef> {
        let mut out: Vec<ObjectRef> = (0..scene.spheres.len()).map(ObjectRef::Sphere).collect();
        out.extend((0..scene.cylinders.len()).map(ObjectRef::Cylinder));
        out.extend((0..scene.polygons.len()).map(ObjectRef::Polygon));
        out.extend(scene.ground.iter().map(|_| ObjectRef::Ground));
        out.extend((0..scene.meshes.len()).map(ObjectRef::Mesh));
        out
    }

    /// The object called `name` (the ground is called `ground`). An unknown
    /// name, or one that several objects share, is an error naming the
    /// objects there are.
    pub fn find(scene: &Scene, name: &str) -> Result<ObjectRef> {
        let all = Self::all(scene);
        let matching: Vec<ObjectRef> = all
            .iter()
            .copied()
            .filter(|o| o.name(scene) == name)
            .collect();
        let listed = || {
            all.iter()
                .map(|o| format!("{} “{}”", o.kind(), o.name(scene)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        match matching.as_slice() {
            [one] => Ok(*one),
            [] => bail!("no object named `{name}` in the scene; it has {}", listed()),
            many => bail!(
                "{} objects are named `{name}`; give them distinct names ({})",
                many.len(),
                listed()
            ),
        }
    }

    pub fn kind(self) -> &'static str {
        match self {
            ObjectRef::Sphere(_) => "sphere",
            ObjectRef::Cylinder(_) => "cylinder",
            ObjectRef::Polygon(_) => "polygon",
            ObjectRef::Ground => "ground",
            ObjectRef::Mesh(_) => "mesh",
        }
    }

    /// The index in [`Scene::materials`] of its material (a mesh's
    /// first).
    pub fn first_material(self, scene: &Scene) -> u32 {
        let (s, c, p) = (
            scene.spheres.len(),
            scene.cylinders.len(),
            scene.polygons.len(),
        );
        (match self {
            ObjectRef::Sphere(i) => i,
            ObjectRef::Cylinder(i) => s + i,
            ObjectRef::Polygon(i) => s + c + i,
            ObjectRef::Ground => s + c + p,
            ObjectRef::Mesh(i) => scene
                .mesh_material_bases()
                .get(i)
                .map_or(0, |&b| b as usize),
        }) as u32
    }

    /// Its name in the preset (`ground` for the ground); empty if the index
    /// is past the scene's objects.
    pub fn name(self, scene: &Scene) -> String {
        let name = match self {
            ObjectRef::Sphere(i) => scene.spheres.get(i).map(|s| &s.name),
            ObjectRef::Cylinder(i) => scene.cylinders.get(i).map(|c| &c.name),
            ObjectRef::Polygon(i) => scene.polygons.get(i).map(|p| &p.name),
            ObjectRef::Ground => return "ground".into(),
            ObjectRef::Mesh(i) => scene.meshes.get(i).map(|m| &m.name),
        };
        name.cloned().unwrap_or_default()
    }
}

/// A texel's surface point and the material (its index in
/// [`Scene::materials`]) that colours it there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BakeTexel {
    pub material: u32,
    pub point: SurfacePoint,
}

/// How an object's (u, v) square lies on its surface.
#[derive(Debug, Clone)]
pub struct UvSurface {
    shape: Shape,
    /// For the sidecar: what (u, v) are on this object.
    pub description: String,
}

#[derive(Debug, Clone)]
enum Shape {
    Sphere {
        center: Vec3,
        radius: f32,
        material: u32,
    },
    Cylinder {
        base: Vec3,
        radius: f32,
        height: f32,
        material: u32,
    },
    /// A polygon's or the ground's plane: `normal` through `on_plane`;
    /// the ground's texture point drops its height (`flat`).
    Plane {
        frame: UvFrame,
        on_plane: Vec3,
        normal: Vec3,
        flat: bool,
        material: u32,
    },
    /// Triangles in the world with their uvs and materials, and for each
    /// texel the triangle covering its centre in uv ([`NO_TRIANGLE`] where
    /// none does).
    Mesh {
        triangles: Vec<([Vec3; 3], [Vec2; 3], u32)>,
        coverage: Vec<u32>,
    },
}

const NO_TRIANGLE: u32 = u32::MAX;

/// The (u, v) at the centre of texel `index` of a `size` × `size` image.
pub fn texel_uv(index: usize, size: u32) -> Vec2 {
    let (i, j) = (index as u32 % size, index as u32 / size);
    Vec2::new(
        (i as f32 + 0.5) / size as f32,
        1.0 - (j as f32 + 0.5) / size as f32,
    )
}

/// Checks a bake size, naming the bound.
pub fn check_size(size: u32) -> Result<()> {
    if !(1..=MAX_BAKE_SIZE).contains(&size) {
        bail!("bake size {size}: it must be 1 to {MAX_BAKE_SIZE} texels a side");
    }
    Ok(())
}

impl UvSurface {
    /// The parametrisation of `object` in `scene` for a `size` × `size`
    /// bake (a mesh's triangles are rasterised in uv at that size).
    pub fn new(scene: &Scene, object: ObjectRef, size: u32) -> Result<Self> {
        check_size(size)?;
        let material = object.first_material(scene);
        let missing = || anyhow::anyhow!("the scene has no {object:?}");
        Ok(match object {
            ObjectRef::Sphere(i) => {
                let sphere = scene.spheres.get(i).ok_or_else(missing)?;
                UvSurface {
                    shape: Shape::Sphere {
                        center: sphere.center,
                        radius: sphere.radius,
                        material,
                    },
                    description: "sphere: latitude-longitude about +y, u = (atan2(x, z) + π)/2π \
                                  around the axis, v from the south pole (0) to the north (1); \
                                  object point = surface point − centre"
                        .into(),
                }
            }
            ObjectRef::Cylinder(i) => {
                let cylinder = scene.cylinders.get(i).ok_or_else(missing)?;
                UvSurface {
                    shape: Shape::Cylinder {
                        base: cylinder.base,
                        radius: cylinder.radius,
                        height: cylinder.height,
                        material,
                    },
                    description: "cylinder side: u = (atan2(x, z) + π)/2π around +y, v = height \
                                  / cylinder height from the base (0) to the top (1); the caps \
                                  are not baked; object point = surface point − base"
                        .into(),
                }
            }
            ObjectRef::Polygon(i) => {
                let polygon = scene.polygons.get(i).ok_or_else(missing)?;
                let (Some(frame), Some(normal)) = (polygon.frame(), polygon.normal()) else {
                    bail!(
                        "polygon “{}” has no (u, v) frame: {}",
                        polygon.name,
                        polygon.problem().unwrap_or_else(|| "degenerate".into())
                    );
                };
                UvSurface {
                    shape: Shape::Plane {
                        frame,
                        on_plane: polygon.vertices[0],
                        normal,
                        flat: false,
                        material,
                    },
                    description: format!(
                        "polygon: the point origin + u·u_axis + v·v_axis of its frame (origin {}, \
                         u_axis {}, v_axis {}{}), on the polygon's plane; texels outside the \
                         outline show the texture as it runs on in the plane; object point = \
                         world point",
                        frame.origin,
                        frame.u_axis,
                        frame.v_axis,
                        if polygon.uv_frame.is_some() {
                            ", the preset's uv_frame"
                        } else {
                            ", the default: first vertex, first edge, last edge made orthogonal"
                        }
                    ),
                }
            }
            ObjectRef::Ground => {
                let ground = scene.ground.as_ref().ok_or_else(missing)?;
                let frame = ground.frame();
                UvSurface {
                    shape: Shape::Plane {
                        frame,
                        on_plane: Vec3::new(0.0, ground.height, 0.0),
                        normal: Vec3::Y,
                        flat: true,
                        material,
                    },
                    description: match ground.uv_frame {
                        Some(f) => format!(
                            "ground: the point origin + u·u_axis + v·v_axis of its uv_frame \
                             (origin {}, u_axis {}, v_axis {}) dropped onto y = {}; object \
                             point = (x, 0, z)",
                            f.origin, f.u_axis, f.v_axis, ground.height
                        ),
                        None => format!(
                            "ground without a uv_frame: (u, v) = world (x, z), so the image is \
                             the window 0 ≤ x ≤ 1, 0 ≤ z ≤ 1 of the plane y = {}; object point \
                             = (x, 0, z)",
                            ground.height
                        ),
                    },
                }
            }
            ObjectRef::Mesh(i) => {
                let mesh = scene.meshes.get(i).ok_or_else(missing)?;
                let first = material;
                let geometry = &mesh.geometry.0;
                let triangles: Vec<([Vec3; 3], [Vec2; 3], u32)> = mesh
                    .world_positions()
                    .zip(&geometry.uvs)
                    .zip(&geometry.materials)
                    .map(|((p, uv), m)| (p, *uv, first + m))
                    .collect();
                let coverage = rasterise(&triangles, size);
                UvSurface {
                    shape: Shape::Mesh {
                        triangles,
                        coverage,
                    },
                    description: "mesh: each triangle drawn in uv space from its vertices' \
                                  texture coordinates, the point inside it interpolated from its \
                                  placed vertices and the material its own; texels no triangle \
                                  covers (and uvs outside [0, 1]², which are not wrapped) are \
                                  transparent black; where triangles overlap in uv the first in \
                                  the file wins; object point = world point"
                        .into(),
                }
            }
        })
    }

    /// Where texel `index` of a `size` × `size` image lies (`size` must be
    /// the one the surface was made for); `None` off a mesh's triangles.
    pub fn texel(&self, index: usize, size: u32) -> Option<BakeTexel> {
        let uv = texel_uv(index, size);
        Some(match &self.shape {
            Shape::Sphere {
                center,
                radius,
                material,
            } => {
                let (phi, theta) = (2.0 * PI * uv.x - PI, PI * uv.y);
                let ring = theta.sin();
                let dir = Vec3::new(ring * phi.sin(), -theta.cos(), ring * phi.cos());
                let world = *center + dir * *radius;
                BakeTexel {
                    material: *material,
                    point: SurfacePoint {
                        object: world - *center,
                        world,
                        uv: sphere_uv(dir),
                    },
                }
            }
            Shape::Cylinder {
                base,
                radius,
                height,
                material,
            } => {
                let phi = 2.0 * PI * uv.x - PI;
                let local = Vec3::new(*radius * phi.sin(), uv.y * *height, *radius * phi.cos());
                BakeTexel {
                    material: *material,
                    point: SurfacePoint {
                        object: local,
                        world: *base + local,
                        uv: cylinder_uv(local, *height),
                    },
                }
            }
            Shape::Plane {
                frame,
                on_plane,
                normal,
                flat,
                material,
            } => {
                let q = frame.origin + uv.x * frame.u_axis + uv.y * frame.v_axis;
                let world = q - (q - *on_plane).dot(*normal) * *normal;
                let object = if *flat {
                    Vec3::new(world.x, 0.0, world.z)
                } else {
                    world
                };
                BakeTexel {
                    material: *material,
                    point: SurfacePoint {
                        object,
                        world,
                        uv: plane_uv(world, frame.origin, frame.u_axis, frame.v_axis),
                    },
                }
            }
            Shape::Mesh {
                triangles,
                coverage,
            } => {
                let t = *coverage.get(index)?;
                let (p, uvs, material) = triangles.get(t as usize)?;
                let b = barycentric(uv, uvs)?;
                let world = p[0] * b.x + p[1] * b.y + p[2] * b.z;
                BakeTexel {
                    material: *material,
                    point: SurfacePoint {
                        object: world,
                        world,
                        uv,
                    },
                }
            }
        })
    }
}

/// The barycentric weights of `uv` in the uv triangle `t`; `None` for a
/// triangle of no area.
fn barycentric(uv: Vec2, t: &[Vec2; 3]) -> Option<Vec3> {
    let (e1, e2, d) = (t[1] - t[0], t[2] - t[0], uv - t[0]);
    let det = e1.perp_dot(e2);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let b1 = d.perp_dot(e2) / det;
    let b2 = e1.perp_dot(d) / det;
    Some(Vec3::new(1.0 - b1 - b2, b1, b2))
}

/// For each texel of a `size` × `size` image, the first triangle whose uv
/// image holds the texel's centre (edges included).
fn rasterise(triangles: &[([Vec3; 3], [Vec2; 3], u32)], size: u32) -> Vec<u32> {
    let n = size as usize;
    let mut coverage = vec![NO_TRIANGLE; n * n];
    for (t, (_, uvs, _)) in triangles.iter().enumerate() {
        let lo = uvs[0].min(uvs[1]).min(uvs[2]);
        let hi = uvs[0].max(uvs[1]).max(uvs[2]);
        if !(lo.is_finite() && hi.is_finite()) {
            continue;
        }
        // Columns from u, rows from 1 − v; the box clipped to the image.
        let to_texels = |a: f32, b: f32| {
            let first = (a * size as f32 - 0.5).floor().max(0.0) as usize;
            let last = ((b * size as f32 - 0.5).ceil().max(0.0) as usize).min(n - 1);
            first..=last
        };
        for j in to_texels(1.0 - hi.y, 1.0 - lo.y) {
            for i in to_texels(lo.x, hi.x) {
                let index = j * n + i;
                if coverage[index] != NO_TRIANGLE {
                    continue;
                }
                let inside =
                    barycentric(texel_uv(index, size), uvs).is_some_and(|b| b.min_element() >= 0.0);
                if inside {
                    coverage[index] = t as u32;
                }
            }
        }
    }
    coverage
}

/// The value of `property` of `material` at a point: the CPU reference of
/// the GPU bake (`Material::value_at`, layers applied, unclamped; the bump
/// texture's height before `bump_height` scales it). RGB, alpha 1.
pub fn reference_value(material: &Material, property: BakeProperty, point: &SurfacePoint) -> Vec3 {
    match property.material_property() {
        Some(p) => material.value_at(p, point),
        None => Vec3::splat(material.bump.eval_at(point).x),
    }
}

/// The whole bake on the CPU: RGBA per texel, row 0 at the top; texels off
/// the surface are transparent black. Images read as unavailable (the CPU
/// reference without an `ImageSet`).
pub fn reference(
    scene: &Scene,
    surface: &UvSurface,
    property: BakeProperty,
    size: u32,
) -> Vec<[f32; 4]> {
    let materials: Vec<&Material> = scene.materials().collect();
    (0..(size as usize * size as usize))
        .map(|index| match surface.texel(index, size) {
            Some(t) => {
                let v = reference_value(materials[t.material as usize], property, &t.point);
                [v.x, v.y, v.z, 1.0]
            }
            None => [0.0; 4],
        })
        .collect()
}

/// What is written beside a baked image (`<image>.mapping.ron`): enough to
/// place it back on the object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BakeMapping {
    pub preset: String,
    pub object: String,
    /// sphere, cylinder, polygon, ground or mesh.
    pub primitive: String,
    /// How (u, v) map onto the surface.
    pub uv_mapping: String,
    /// How texel (i, j) reads (u, v).
    pub texels: String,
    pub property: String,
    pub size: u32,
    /// `srgb` (8-bit PNG of sRGB-encoded colours) or `linear`.
    pub color_space: String,
    /// For a bump: the material's `bump_height`, the scene units a value
    /// of 1 stands for (the image holds the unscaled height).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bump_height: Option<f32>,
}

impl BakeMapping {
    /// Where the sidecar of `image` goes: `<image>.mapping.ron`.
    pub fn path_for(image: &Path) -> PathBuf {
        let mut name = image.as_os_str().to_owned();
        name.push(".mapping.ron");
        PathBuf::from(name)
    }

    /// Writes `image_bytes` to `image` and this mapping beside it, as one
    /// atomic pair: if either cannot be written, neither changes (an image
    /// never goes beside a sidecar that describes another). Returns the
    /// sidecar's path.
    pub fn write_with_image(&self, image: &Path, image_bytes: &[u8]) -> Result<PathBuf> {
        let path = Self::path_for(image);
        let text = ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default())?;
        write_atomic_pair((image, image_bytes), (&path, text.as_bytes()))
            .with_context(|| format!("cannot write {} and {}", image.display(), path.display()))?;
        Ok(path)
    }
}

/// The format of a bake's output file, from its extension, once the image
/// and its sidecar are known to be writable (a bake creates no folders).
pub fn check_output(path: &Path) -> Result<ImageFormat> {
    let format = ImageFormat::from_path(path)?;
    image_io::check_output(path)?;
    image_io::check_output(&BakeMapping::path_for(path))?;
    Ok(format)
}

/// The colour space a bake of `property` is written in to `format`: a
/// colour in a PNG is sRGB-encoded; data in a PNG, and anything in an
/// EXR, is linear.
pub fn color_space(property: BakeProperty, format: ImageFormat) -> &'static str {
    match (format, property.is_color()) {
        (ImageFormat::Png, true) => "srgb",
        _ => "linear",
    }
}

/// The file of baked texels (linear RGBA, row 0 at the top) in `format`:
/// an EXR as they are (32-bit float), a PNG clamped to [0, 1] in 8 bits,
/// colours sRGB-encoded (see [`color_space`]), alpha linear.
pub fn encode_image(
    format: ImageFormat,
    property: BakeProperty,
    size: u32,
    texels: &[[f32; 4]],
) -> Result<Vec<u8>> {
    match format {
        ImageFormat::Exr => encode_exr(size, size, texels, None),
        ImageFormat::Png => {
            let srgb = color_space(property, format) == "srgb";
            let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
            let image = image::RgbaImage::from_fn(size, size, |x, y| {
                let t = texels[(y * size + x) as usize];
                let c = |v: f32| byte(if srgb { srgb_encode(v.max(0.0)) } else { v });
                image::Rgba([c(t[0]), c(t[1]), c(t[2]), byte(t[3])])
            });
            encode_png(&image)
        }
    }
}

/// How texels read (u, v), for the sidecar.
pub const TEXEL_CONVENTION: &str = "texel (i, j), row j from the top, holds the texture at its \
    centre u = (i + 0.5)/size, v = 1 - (j + 0.5)/size (v up); alpha 0 where no surface is";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::mesh::Geometry;
    use crate::scene::{Mesh, MeshMaterial, Sphere, TriangleMesh};
    use std::sync::Arc;

    /// Each texel's point on a sphere lies on it, and the renderer's (u, v)
    /// there is the texel's centre.
    #[test]
    fn sphere_texels_lie_on_the_sphere_at_their_uv() {
        let scene = Scene {
            spheres: vec![Sphere {
                center: Vec3::new(1.0, 2.0, -3.0),
                radius: 0.5,
                ..Sphere::default()
            }],
            ..Scene::default()
        };
        let surface = UvSurface::new(&scene, ObjectRef::Sphere(0), 16).unwrap();
        for index in 0..256 {
            let t = surface.texel(index, 16).unwrap();
            assert!((t.point.object.length() - 0.5).abs() < 1e-5);
            assert!((t.point.uv - texel_uv(index, 16)).abs().max_element() < 1e-5);
        }
    }

    /// A mesh of one triangle over the lower-left half of uv: texels below
    /// the diagonal are covered, with the point interpolated; the others
    /// are not.
    #[test]
    fn mesh_texels_are_the_triangles_in_uv() {
        let triangle = TriangleMesh {
            positions: vec![[
                Vec3::ZERO,
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 2.0),
            ]],
            uvs: vec![[Vec2::ZERO, Vec2::X, Vec2::Y]],
            materials: vec![0],
        };
        let scene = Scene {
            meshes: vec![Mesh {
                name: "tri".into(),
                materials: vec![MeshMaterial {
                    name: "m".into(),
                    material: Material::default(),
                    from_file: None,
                }],
                geometry: Geometry(Arc::new(triangle)),
                ..Mesh::default()
            }],
            ..Scene::default()
        };
        let size = 8;
        let surface = UvSurface::new(&scene, ObjectRef::Mesh(0), size).unwrap();
        for index in 0..64 {
            let uv = texel_uv(index, size);
            match surface.texel(index, size) {
                Some(t) => {
                    assert!(uv.x + uv.y <= 1.0, "{uv}");
                    assert!(
                        (t.point.world - Vec3::new(2.0 * uv.x, 0.0, 2.0 * uv.y)).length() < 1e-5
                    );
                }
                None => assert!(uv.x + uv.y > 1.0, "{uv} uncovered"),
            }
        }
    }

    #[test]
    fn bad_names_and_sizes_are_named() {
        let scene = Scene::default();
        let e = ObjectRef::find(&scene, "teapot").unwrap_err().to_string();
        assert!(e.contains("`teapot`"), "{e}");
        let e = BakeProperty::parse("shininess").unwrap_err().to_string();
        assert!(e.contains("`shininess`") && e.contains("roughness"), "{e}");
        for size in [0, MAX_BAKE_SIZE + 1] {
            let e = check_size(size).unwrap_err().to_string();
            assert!(e.contains(&size.to_string()), "{e}");
        }
    }
}
