// Scene data shared by the trace pass: the frame uniform, spheres, materials.

#import crates/core/src/noise/fractal.wgsl
#if MESH
#import crates/core/src/accel/traverse.wgsl
#endif

struct Frame {
    cam_pos: vec3f,
    tan_half_fov: f32,
    cam_right: vec3f,
    aspect: f32,
    cam_up: vec3f,
    frame_index: u32,
    cam_forward: vec3f,
    // Samples already averaged in the accumulation target before this frame.
    accumulated: u32,
    light_pos: vec3f,
    env_intensity: f32,
    light_power: vec3f,
    env_rotation: f32,
    env_constant: vec3f,
    background_visible: u32,
    ground_height: f32,
    sphere_count: u32,
    samples_per_frame: u32,
    max_bounces: u32,
    render_size: vec2f,
    // Runtime switches, so an uber shader (every feature compiled in) still
    // renders exactly the scene: 0 none, 1 constant, 2 map.
    env_kind: u32,
    has_ground: u32,
    cylinder_count: u32,
    polygon_count: u32,
    // The angle a pixel subtends at the camera: the spread of ray cones (0
    // for an orthographic camera, whose rays are parallel).
    pixel_spread: f32,
    // Non-zero: sample the environment map by its luminance (MIS).
    env_sampling: u32,
    // Cells of the environment's sampling distribution (env_sampling.wgsl).
    env_distribution_size: vec2u,
    // The light table (lights.wgsl): its length, how a light is chosen
    // (0 uniformly, 1 by power) and the sum of its powers.
    light_count: u32,
    light_selection: u32,
    light_total_power: f32,
    // Light samples per shading point (the lab's N).
    light_samples: u32,
    // How light and BSDF samples combine (mis.wgsl).
    strategy: u32,
    // Russian roulette from this bounce on (0: never).
    russian_roulette_from: u32,
    triangle_count: u32,
    // Always 1.0, but the compiler cannot know it (accumulation.wgsl).
    opaque_one: f32,
    // The firefly clamp on a sample's largest channel; 0: off.
    sample_clamp: f32,
    // The rows [band_start, band_end) this pass traces: the compute
    // kernel's dispatch covers only them (the fragment kernel's scissor
    // does the same), so a frame can trace part of a sample round
    // (gpu/trace_rounds.rs).
    band_start: u32,
    band_end: u32,
    // What each sample records (view.wgsl; Rust: scene::View).
    view: u32,
    // Where light samples lie on their light (lights.wgsl; Rust:
    // scene::LightPoints).
    light_points: u32,
    // The depth view's d in t / (t + d): the camera's distance to its target.
    depth_scale: f32,
    // The ground's (u, v) frame (Rust: Ground::frame): world (x, z) is the
    // frame at the origin on +x and +z.
    ground_uv_origin: vec3f,
    // An orthographic camera's half-height in scene units; 0: perspective.
    ortho_half_height: f32,
    ground_uv_u: vec3f,
    ground_uv_v: vec3f,
    // A crop of a larger image (render --tile): the targets hold the
    // pixels from `crop_origin` of an image of `image_size`, whose camera
    // and per-pixel samples they trace, so that tiles assemble to the
    // whole render. (0, 0) and the render size without a crop.
    crop_origin: vec2u,
    image_size: vec2f,
}

const MAX_SIGNALS: u32 = 4u;

struct Material {
    // The distinct fractal sums the material's textures read, each evaluated
    // once per hit (see textures.wgsl).
    signals: array<NoiseParams, 4>,
    // Signal k is taken at its mapping of the hit: rows 3k to 3k + 2 of an
    // affine map, applied to the object point or (`world`) the world one.
    signal_rows: array<vec4f, 12>,
    signal_count: u32,
    // Signals before this index are gradient noise, from it on Perlin noise.
    first_perlin: u32,
    // Scene units of height for a bump value of 1.
    bump_height: f32,
    // Mean emitted luminance: above 0, the material's spheres and triangles
    // are in the light table (Rust: lights::emitted_luminance).
    emitted_luminance: f32,
}

struct Sphere {
    center: vec3f,
    radius: f32,
}

// A closed cylinder standing on `base` along +y.
struct Cylinder {
    base: vec3f,
    radius: f32,
    height: f32,
}

// A flat convex polygon, its vertices counter-clockwise about `normal`,
// and its (u, v) frame (Rust: scene::Polygon::frame).
const MAX_POLYGON_VERTICES: u32 = 8u;

struct Polygon {
    vertices: array<vec4f, 8>,
    normal: vec3f,
    vertex_count: u32,
    uv_origin: vec3f,
    uv_u: vec3f,
    uv_v: vec3f,
}

// The frame's settings, in a uniform buffer of two slots (the second a
// copy of the first), read through an index that is 0 at run time but not
// a constant to the compiler (`frame_slot`). Mesa 22's lavapipe inlines
// uniform values read at constant offsets in loop and branch conditions
// into the shader and compiles a new variant for every command buffer,
// never freeing the old ones: 5 MB of JIT code a frame (RSS past 1 GiB in
// 300 frames of the soak test) on any scene whose shader it picks. Read at
// a uniform but non-constant offset they are not inlined, and still
// uniform to llvmpipe (a storage buffer stopped the leak too, but made
// loops on them divergent: frames 1.4x slower).
@group(0) @binding(0) var<uniform> frame_slots: array<Frame, 2>;
// The settings, copied from `frame_slots` once per invocation (`fs_trace`).
var<private> frame: Frame;

// The slot holding the frame's settings: 0, computed from a uniform.
fn frame_slot() -> u32 {
    return u32(frame_slots[0].opaque_one) - 1u;
}
// Uniform arrays of fixed size (Rust: scene::MAX_SPHERES). Lanes of one SIMD
// group read different elements; lavapipe does that far faster from a
// uniform buffer than from a storage buffer (measured: 14 % of the frame).
const MAX_SPHERES: u32 = 63u;
@group(0) @binding(1) var<uniform> spheres: array<Sphere, 63>;
// The materials of the spheres, cylinders and polygons, the ground's, then
// the meshes' (Rust: scene::MAX_MATERIALS).
@group(0) @binding(2) var<uniform> materials: array<Material, 160>;
@group(0) @binding(9) var<uniform> cylinders: array<Cylinder, 8>;
@group(0) @binding(10) var<uniform> polygons: array<Polygon, 16>;
// The numbers of the scene's texture trees, read at constant indices by the
// generated texture functions (Rust: gpu::texture_codegen).
@group(0) @binding(7) var<uniform> texture_params: array<vec4f, 1024>;

#if IMAGE
// Every image of the scene with its mip levels (Rust: texture::ImageAtlas),
// read with textureLoad and filtered by hand (texture/image.wgsl).
@group(0) @binding(8) var image_atlas: texture_2d<f32>;
#endif

// One entry of the light table (Rust: lights::LightGpu).
struct Light {
    // 0 the point light, 1 a sphere, 2 a triangle.
    kind: u32,
    primitive: u32,
    // Cumulative chance by power, up to and including this light.
    cdf: f32,
    power: f32,
}

#if POINT_LIGHT || AREA_LIGHT
@group(0) @binding(15) var<storage, read> lights: array<Light>;
#endif

#if MESH
// A triangle's texture coordinates (uv0 and uv1 packed, then uv2) and
// material (Rust: gpu::mesh_buffers).
struct TriangleAttributes {
    uv01: vec4f,
    uv2: vec2f,
    material: u32,
    _pad: u32,
}

// The meshes' triangles in BVH order (accel/traverse.wgsl reads the nodes and the
// vertices; the attributes are read once per hit).
@group(0) @binding(12) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(13) var<storage, read> mesh_triangles: array<TriangleVerts>;
@group(0) @binding(14) var<storage, read> mesh_attributes: array<TriangleAttributes>;
#endif
