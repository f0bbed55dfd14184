// Scene data shared by the trace pass: the frame uniform, spheres, materials.

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
}

struct Texture {
    kind: u32,        // 0 constant, 1 checker, 2 fBm, 3 turbulence, 4 marble
    noise_kind: u32,
    hash: u32,
    octaves: f32,
    frequency: f32,
    amplitude: f32,
    persistence: f32,
    lacunarity: f32,
    // Checker: cell size. Marble: stripe frequency.
    param: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
    a: vec4f,
    b: vec4f,
}

struct Material {
    diffuse: Texture,
    specular: Texture,
    roughness: Texture,
    mirror: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

struct Sphere {
    center: vec3f,
    radius: f32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> spheres: array<Sphere>;
@group(0) @binding(2) var<storage, read> materials: array<Material>;
