//! One path, as `trace_path` in shaders/trace.wgsl traces it: the same
//! intersections (the CPU twins of the sphere, ground and BVH tests), the
//! same light sampling (`lights.wgsl`), BSDF (`bsdf.rs`) and MIS weights
//! (`mis.rs`), the same random numbers drawn in the same order. Written
//! line for line after the shader, so that a change to one is a change to
//! both (the parity tests hold them to each other, pixel by pixel).

use super::rng::Rng;
use super::scene::{CpuScene, SurfaceValues};
use crate::gpu::scene_gpu::Frame;
use glam::{UVec3, Vec2, Vec3};
use marbre_core::bsdf::{basis, eval_bsdf, sample_bsdf};
use marbre_core::geometry::ray_offset::offset_ray;
use marbre_core::geometry::sphere::{NO_HIT, sphere_distance};
use marbre_core::lights::LightKind;
use marbre_core::mis::{bsdf_sample_weight, light_sample_weight};
use marbre_core::noise::hash::pcg3d;
use marbre_core::scene::SurfacePoint;
use marbre_core::texture::mapping::sphere_uv;
use std::f32::consts::PI;

/// `MAX_CROSSINGS` of trace.wgsl: the most surfaces a ray passes through.
const MAX_CROSSINGS: u32 = 16;
/// `LIGHT_POINTS_CENTROID`, `LIGHT_POINTS_FIXED_SET` and `FIXED_SET_SEED`
/// of lights.wgsl.
const LIGHT_POINTS_CENTROID: u32 = 1;
const LIGHT_POINTS_FIXED_SET: u32 = 2;
const FIXED_SET_SEED: u32 = 0x51ED_270B;

#[derive(Clone, Copy, PartialEq, Eq)]
enum Shape {
    Sphere,
    Ground,
    Triangle,
}

/// `Hit` of intersect.wgsl; a triangle keeps its barycentrics for (u, v).
#[derive(Clone, Copy)]
struct Hit {
    t: f32,
    p: Vec3,
    n: Vec3,
    texture_point: Vec3,
    material: u32,
    shape: Shape,
    index: u32,
    front: bool,
    barycentrics: Vec2,
}

/// What a path reads besides the scene: the frame's settings.
pub struct Tracer<'a> {
    pub scene: &'a CpuScene,
    pub frame: &'a Frame,
}

/// A sample's radiance and, for the denoiser's guides, what its camera
/// ray met first (zero where it escaped).
pub struct PathSample {
    pub radiance: Vec3,
    pub albedo: Vec3,
    pub normal: Vec3,
}

impl Tracer<'_> {
    fn intersect(&self, o: Vec3, d: Vec3) -> Hit {
        let s = self.scene;
        let mut hit = Hit {
            t: NO_HIT,
            p: Vec3::ZERO,
            n: Vec3::ZERO,
            texture_point: Vec3::ZERO,
            material: 0,
            shape: Shape::Sphere,
            index: 0,
            front: true,
            barycentrics: Vec2::ZERO,
        };
        let mut index = 0;
        for (i, sphere) in s.spheres.iter().enumerate() {
            let t = sphere_distance(o, d, sphere.center, sphere.radius);
            if t < hit.t {
                hit.t = t;
                index = i;
            }
        }
        if hit.t < NO_HIT {
            let sphere = s.spheres[index];
            let dir = (o + hit.t * d - sphere.center).normalize();
            hit.p = sphere.center + dir * sphere.radius;
            hit.n = dir;
            hit.texture_point = hit.p - sphere.center;
            hit.material = index as u32;
            hit.index = index as u32;
        }
        if let Some(ground) = &s.ground
            && d.y != 0.0
        {
            let t = (ground.height - o.y) / d.y;
            if t > 0.0 && t < hit.t {
                hit.t = t;
                hit.p = Vec3::new(o.x + t * d.x, ground.height, o.z + t * d.z);
                hit.n = Vec3::Y;
                hit.texture_point = Vec3::new(hit.p.x, 0.0, hit.p.z);
                hit.material = s.spheres.len() as u32;
                hit.shape = Shape::Ground;
                hit.index = 0;
            }
        }
        let mesh = &*s.mesh;
        if !mesh.positions.is_empty()
            && let Some(m) = mesh.wide.intersect(&mesh.positions, o, d, hit.t)
            && m.t < hit.t
        {
            let [v0, v1, v2] = mesh.positions[m.triangle as usize];
            let (e1, e2) = (v1 - v0, v2 - v0);
            hit.t = m.t;
            hit.p = v0 + m.b1 * e1 + m.b2 * e2;
            hit.n = e1.cross(e2).normalize();
            hit.texture_point = hit.p;
            hit.material = mesh.attributes[m.triangle as usize].material;
            hit.shape = Shape::Triangle;
            hit.index = m.triangle;
            hit.barycentrics = Vec2::new(m.b1, m.b2);
        }
        hit.front = hit.n.dot(d) <= 0.0;
        if hit.t < NO_HIT && !hit.front {
            hit.n = -hit.n;
        }
        hit
    }

    /// Whether anything lies along o + t d for 0 < t < t_max.
    fn occluded(&self, o: Vec3, d: Vec3, t_max: f32) -> bool {
        let s = self.scene;
        if s.spheres
            .iter()
            .any(|sphere| sphere_distance(o, d, sphere.center, sphere.radius) < t_max)
        {
            return true;
        }
        if let Some(ground) = &s.ground
            && d.y != 0.0
        {
            let t = (ground.height - o.y) / d.y;
            if t > 0.0 && t < t_max {
                return true;
            }
        }
        let mesh = &*s.mesh;
        !mesh.positions.is_empty() && mesh.wide.occluded(&mesh.positions, o, d, t_max)
    }

    /// The hit's texture coordinates, as intersect.wgsl computes them.
    fn uv(&self, hit: &Hit) -> Vec2 {
        match hit.shape {
            Shape::Sphere => sphere_uv(hit.texture_point),
            Shape::Ground => self
                .scene
                .ground
                .as_ref()
                .map_or(Vec2::ZERO, |g| g.uv(hit.p)),
            Shape::Triangle => self.triangle_uv(hit.index, hit.barycentrics),
        }
    }

    fn triangle_uv(&self, triangle: u32, b: Vec2) -> Vec2 {
        let a = &self.scene.mesh.attributes[triangle as usize];
        let (uv0, uv1, uv2) = (
            Vec2::new(a.uv01[0], a.uv01[1]),
            Vec2::new(a.uv01[2], a.uv01[3]),
            Vec2::from_array(a.uv2),
        );
        (1.0 - b.x - b.y) * uv0 + b.x * uv1 + b.y * uv2
    }

    /// `surface_at`: the material's values at the hit.
    fn surface(&self, hit: &Hit) -> SurfaceValues {
        let material = &self.scene.materials[hit.material as usize];
        let uniform_diffuse = self.scene.strategy == marbre_core::scene::Strategy::Hemisphere;
        if material.is_constant() {
            return material.at(&SurfacePoint::new(Vec3::ZERO, Vec2::ZERO), uniform_diffuse);
        }
        let point = SurfacePoint {
            object: hit.texture_point,
            world: hit.p,
            uv: self.uv(hit),
        };
        material.at(&point, uniform_diffuse)
    }

    /// `transmittance` (OPACITY) or `occluded`: the light going from `o`
    /// along `d` that reaches `t_max`, per channel.
    fn visibility(&self, o: Vec3, d: Vec3, t_max: f32) -> Vec3 {
        if !self.scene.opacity {
            return if self.occluded(o, d, t_max) {
                Vec3::ZERO
            } else {
                Vec3::ONE
            };
        }
        let mut origin = o;
        let mut remaining = t_max;
        let mut through = Vec3::ONE;
        let mut crossings = 0;
        loop {
            let h = self.intersect(origin, d);
            if h.t >= remaining {
                break;
            }
            remaining -= h.t;
            let s = self.surface(&h);
            through *= (1.0 - s.opacity) * s.transmission;
            origin = offset_ray(h.p, -h.n);
            crossings += 1;
            if through.cmple(Vec3::ZERO).all() || crossings >= MAX_CROSSINGS {
                break;
            }
        }
        if crossings >= MAX_CROSSINGS {
            Vec3::ZERO
        } else {
            through
        }
    }

    /// `light_numbers(k)`.
    fn light_numbers(&self, k: u32, rng: &mut Rng) -> Vec3 {
        let u = Vec3::new(rng.next(), rng.next(), rng.next());
        if self.frame.light_points == LIGHT_POINTS_FIXED_SET {
            let h: UVec3 = pcg3d(UVec3::new(k, FIXED_SET_SEED, 0)) >> 8;
            return h.as_vec3() * (1.0 / 16_777_216.0);
        }
        u
    }

    /// `sample_light(x, k)`.
    fn sample_light(&self, x: Vec3, k: u32, rng: &mut Rng) -> LightSample {
        let mut out = LightSample::NONE;
        let u = self.light_numbers(k, rng);
        let table = &self.scene.lights;
        let index = table.choose(u.x, self.scene.selection);
        let pmf = table.pmf(index, self.scene.selection);
        let light = table.lights[index];
        let centroid = self.frame.light_points == LIGHT_POINTS_CENTROID;
        let triangle = light.kind == LightKind::Triangle as u32;
        let u1 = if centroid {
            if triangle { 4.0 / 9.0 } else { 0.0 }
        } else {
            u.y
        };
        let u2 = if centroid { 0.5 } else { u.z };
        if light.kind == LightKind::Point as u32 {
            let to_light = Vec3::from_array(self.frame.light_pos) - x;
            let d2 = to_light.dot(to_light);
            out.distance = d2.sqrt();
            out.wi = to_light / out.distance;
            out.radiance = Vec3::from_array(self.frame.light_power) / d2;
            out.pdf = pmf;
            out.delta = true;
        } else if light.kind == LightKind::Sphere as u32 {
            let s = self.scene.spheres[light.primitive as usize];
            let to_c = s.center - x;
            let d2 = to_c.dot(to_c);
            let r2 = s.radius * s.radius;
            let cone = sphere_cone(r2, d2);
            let k = u1 * cone;
            let cos_t = 1.0 - k;
            let sin_t = (k * (2.0 - k)).max(0.0).sqrt();
            let phi = 2.0 * PI * u2;
            let wi =
                basis(to_c / d2.sqrt()) * Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
            let t = sphere_distance(x, wi, s.center, s.radius);
            let emission = |dir: Vec3| {
                let y = s.center + dir * s.radius;
                self.scene.materials[light.primitive as usize].emission_at(&SurfacePoint {
                    object: y - s.center,
                    world: y,
                    uv: sphere_uv(dir),
                })
            };
            if d2 > r2 && t < NO_HIT {
                let dir = (x + t * wi - s.center).normalize();
                out.wi = wi;
                out.distance = t;
                out.radiance = emission(dir);
                out.pdf = pmf / (2.0 * PI * cone);
            }
            if d2 <= r2 {
                let z = 1.0 - 2.0 * u1;
                let ring = (1.0 - z * z).max(0.0).sqrt();
                let dir = Vec3::new(ring * phi.cos(), ring * phi.sin(), z);
                let y = s.center + dir * s.radius;
                let to_y = y - x;
                let distance = to_y.length();
                let wi_inside = to_y / distance;
                let cos_l = dir.dot(wi_inside).abs();
                if distance > 0.0 && cos_l > 0.0 {
                    out.wi = wi_inside;
                    out.distance = distance;
                    out.radiance = emission(dir);
                    out.pdf = pmf * distance * distance / (4.0 * PI * r2 * cos_l);
                }
            }
        } else {
            let [v0, v1, v2] = self.scene.mesh.positions[light.primitive as usize];
            let (e1, e2) = (v1 - v0, v2 - v0);
            let c = e1.cross(e2);
            let twice_area = c.length();
            let su = u1.sqrt();
            let (w1, w2) = (su * (1.0 - u2), su * u2);
            let y = v0 + w1 * e1 + w2 * e2;
            let to_y = y - x;
            let d2 = to_y.dot(to_y);
            let distance = d2.sqrt();
            let wi = to_y / distance;
            let cos_l = -c.dot(wi) / twice_area;
            if cos_l > 0.0 && twice_area > 0.0 {
                let material = self.scene.mesh.attributes[light.primitive as usize].material;
                let uv = self.triangle_uv(light.primitive, Vec2::new(w1, w2));
                out.wi = wi;
                out.distance = distance;
                out.radiance = self.scene.materials[material as usize].emission_at(&SurfacePoint {
                    object: y,
                    world: y,
                    uv,
                });
                out.pdf = pmf * d2 / (0.5 * twice_area * cos_l);
            }
        }
        out
    }

    /// `emitter_pdf(hit, x)`.
    fn emitter_pdf(&self, hit: &Hit, x: Vec3) -> f32 {
        let emitted = self.scene.emitted[hit.material as usize];
        let light_count = self.scene.lights.lights.len();
        if emitted <= 0.0 || light_count == 0 {
            return 0.0;
        }
        let (power_area, solid_angle_pdf) = match hit.shape {
            Shape::Sphere => {
                let s = self.scene.spheres[hit.index as usize];
                let r = s.radius;
                (4.0 * PI * r * r, sphere_light_pdf(s.center, r, x, hit.p))
            }
            Shape::Triangle => {
                let [v0, v1, v2] = self.scene.mesh.positions[hit.index as usize];
                let c = (v1 - v0).cross(v2 - v0);
                let area = 0.5 * c.length();
                let to_hit = hit.p - x;
                let cos_l = c.dot(to_hit).abs() / (2.0 * area * to_hit.length());
                let pdf = if area > 0.0 && cos_l > 0.0 {
                    to_hit.dot(to_hit) / (area * cos_l)
                } else {
                    0.0
                };
                (area, pdf)
            }
            Shape::Ground => (0.0, 0.0),
        };
        let pmf = match self.scene.selection {
            marbre_core::lights::LightSelection::Uniform => 1.0 / light_count as f32,
            marbre_core::lights::LightSelection::Power => {
                PI * emitted * power_area / self.scene.lights.total_power
            }
        };
        pmf * solid_angle_pdf
    }

    /// `direct_light`: the light table's samples at a hit.
    fn direct_light(&self, hit: &Hit, s: &SurfaceValues, wo: Vec3, rng: &mut Rng) -> Vec3 {
        let count = self.frame.light_samples;
        let mut sum = Vec3::ZERO;
        for k in 0..count {
            let light = self.sample_light(hit.p, k, rng);
            let side = leaving_side(light.wi, hit.n, hit.n);
            if light.pdf > 0.0 && side != 0.0 {
                let e = eval_bsdf(&s.bsdf, hit.n, wo, light.wi);
                let weight = if light.delta {
                    1.0
                } else {
                    light_sample_weight(
                        count as f32 * light.pdf,
                        (1.0 - s.bsdf.mirror) * e.pdf,
                        self.scene.strategy,
                    )
                };
                if weight > 0.0 && e.f_cos != Vec3::ZERO {
                    let t_max = if light.delta {
                        light.distance
                    } else {
                        light.distance * (1.0 - 1e-4)
                    };
                    let through = self.visibility(offset_ray(hit.p, side * hit.n), light.wi, t_max);
                    sum += through * e.f_cos * light.radiance * (weight / light.pdf);
                }
            }
        }
        (1.0 - s.bsdf.mirror) * sum / count as f32
    }

    /// `trace_path`: one sample through the pixel position `pixel` (in the
    /// whole image).
    pub fn trace_path(&self, pixel: Vec2, rng: &mut Rng) -> PathSample {
        let frame = self.frame;
        let scene = self.scene;
        let final_vertex_pass = u32::from(scene.emission || scene.opacity);
        let (origin, mut d) = self.camera_ray(pixel);
        let mut hit = self.intersect(origin, d);
        let mut throughput = Vec3::ONE;
        let mut out = PathSample {
            radiance: Vec3::ZERO,
            albedo: Vec3::ZERO,
            normal: Vec3::ZERO,
        };
        let mut alive = true;
        let mut bounces = 0;
        let mut crossings = 0;
        let mut last_bsdf_pdf = 0.0;
        let mut scatter_point = origin;
        if hit.t < NO_HIT && frame.max_bounces > 0 {
            loop {
                let s = self.surface(&hit);
                if bounces == 0 && crossings == 0 {
                    out.albedo = s.bsdf.diffuse + s.emission;
                    out.normal = 0.5 + 0.5 * hit.n;
                }
                let wo = -d;
                let crossing = scene.opacity && s.opacity < 1.0 && rng.next() >= s.opacity;
                let origin;
                if crossing {
                    throughput *= s.transmission;
                    origin = offset_ray(hit.p, -hit.n);
                    crossings += 1;
                } else {
                    if scene.emission {
                        let emits = hit.front || hit.shape != Shape::Triangle;
                        let mut emission_weight = if emits { 1.0 } else { 0.0 };
                        if scene.area_lights && emits && last_bsdf_pdf > 0.0 {
                            let light_pdf =
                                frame.light_samples as f32 * self.emitter_pdf(&hit, scatter_point);
                            emission_weight =
                                bsdf_sample_weight(last_bsdf_pdf, light_pdf, scene.strategy);
                        }
                        out.radiance += throughput * s.emission * emission_weight;
                    }
                    if final_vertex_pass == 1 && bounces >= frame.max_bounces {
                        alive = false;
                        break;
                    }
                    if frame.light_count > 0 {
                        out.radiance += throughput * self.direct_light(&hit, &s, wo, rng);
                    }
                    let u = [rng.next(), rng.next(), rng.next(), rng.next()];
                    let bs = sample_bsdf(&s.bsdf, hit.n, wo, u);
                    let side = leaving_side(bs.wi, hit.n, hit.n);
                    if !bs.valid || side == 0.0 {
                        alive = false;
                        break;
                    }
                    throughput *= bs.weight;
                    last_bsdf_pdf = bs.pdf;
                    scatter_point = hit.p;
                    d = bs.wi;
                    origin = offset_ray(hit.p, side * hit.n);
                    bounces += 1;
                    if frame.russian_roulette_from > 0 && bounces >= frame.russian_roulette_from {
                        let survive = throughput.max_element().min(1.0);
                        if rng.next() >= survive {
                            alive = false;
                            break;
                        }
                        throughput /= survive;
                    }
                }
                hit = self.intersect(origin, d);
                if bounces >= frame.max_bounces + final_vertex_pass
                    || hit.t >= NO_HIT
                    || crossings >= MAX_CROSSINGS
                {
                    break;
                }
            }
        }
        let escaped = alive && hit.t >= NO_HIT && crossings < MAX_CROSSINGS;
        if escaped && (bounces > 0 || frame.background_visible != 0) {
            out.radiance += throughput * self.sky();
        }
        out
    }

    /// `environment(d)` of a constant sky (the CPU kernel traces no map).
    fn sky(&self) -> Vec3 {
        let f = self.frame;
        if f.env_kind == 1 {
            Vec3::from_array(f.env_constant) * f.env_intensity
        } else {
            Vec3::ZERO
        }
    }

    /// `camera_ray(pixel)`: origin and direction.
    fn camera_ray(&self, pixel: Vec2) -> (Vec3, Vec3) {
        let f = self.frame;
        let size = Vec2::from_array(f.image_size);
        let ndc = Vec2::new(pixel.x / size.x * 2.0 - 1.0, 1.0 - pixel.y / size.y * 2.0);
        let (pos, right, up, forward) = (
            Vec3::from_array(f.cam_pos),
            Vec3::from_array(f.cam_right),
            Vec3::from_array(f.cam_up),
            Vec3::from_array(f.cam_forward),
        );
        if f.ortho_half_height > 0.0 {
            let h = f.ortho_half_height;
            return (pos + ndc.x * h * f.aspect * right + ndc.y * h * up, forward);
        }
        let x = ndc.x * f.tan_half_fov * f.aspect;
        let y = ndc.y * f.tan_half_fov;
        (pos, (forward + x * right + y * up).normalize())
    }
}

/// `LightSample` of lights.wgsl.
struct LightSample {
    wi: Vec3,
    distance: f32,
    radiance: Vec3,
    pdf: f32,
    delta: bool,
}

impl LightSample {
    const NONE: LightSample = LightSample {
        wi: Vec3::ZERO,
        distance: 0.0,
        radiance: Vec3::ZERO,
        pdf: 0.0,
        delta: false,
    };
}

/// `leaving_side(wi, n, s_n)` of trace.wgsl.
fn leaving_side(wi: Vec3, n: Vec3, s_n: Vec3) -> f32 {
    let side = wi.dot(n);
    let reflected = if side > 0.0 { 1.0 } else { 0.0 };
    let transmitted = if side < 0.0 { -1.0 } else { 0.0 };
    if wi.dot(s_n) < 0.0 {
        transmitted
    } else {
        reflected
    }
}

/// `sphere_cone(r2, d2)` of lights.wgsl: 1 − cos θmax.
fn sphere_cone(r2: f32, d2: f32) -> f32 {
    let sin2 = r2 / d2;
    sin2 / (1.0 + (1.0 - sin2).max(0.0).sqrt())
}

/// `sphere_light_pdf` of lights.wgsl.
fn sphere_light_pdf(center: Vec3, radius: f32, x: Vec3, y: Vec3) -> f32 {
    let to_c = center - x;
    let d2 = to_c.dot(to_c);
    let r2 = radius * radius;
    if d2 > r2 {
        return 1.0 / (2.0 * PI * sphere_cone(r2, d2));
    }
    let to_y = y - x;
    let cos_l = (y - center).normalize().dot(to_y.normalize()).abs();
    if cos_l > 0.0 {
        to_y.dot(to_y) / (4.0 * PI * r2 * cos_l)
    } else {
        0.0
    }
}
