//! The scene's resources the trace shader binds (group 0): primitives,
//! meshes and lights, the noise table, the texture parameters, the
//! environment and its sampling CDFs, and the image atlas. They change
//! with the scene (`build.rs` rewrites them as an edit asks); the trace
//! stage lays group 0 out from [`SceneBindings::layout_entries`].

use crate::gpu::context::GpuContext;
use crate::gpu::geometry_buffers::GeometryBuffers;
use crate::gpu::mesh_buffers::MeshBuffers;
use crate::gpu::pipelines::{
    entry, float_texture, permutation_table, storage, uniform, upload_atlas, upload_rgba16f,
};
use marbre_core::env_sampling::EnvDistribution;
use marbre_core::envmap::{self, EnvImage};
use marbre_core::scene::Scene;
use marbre_core::texture::ImageSet;
use wgpu::util::DeviceExt;

pub(super) struct SceneBindings {
    pub(super) geometry: GeometryBuffers,
    /// Triangles, their BVH and the light table.
    pub(super) meshes: MeshBuffers,
    pub(super) perm_buffer: wgpu::Buffer,
    pub(super) texture_param_buffer: wgpu::Buffer,
    pub(super) env_view: wgpu::TextureView,
    pub(super) env_sampler: wgpu::Sampler,
    /// The environment's importance-sampling CDFs and their size in cells.
    pub(super) env_distribution: (wgpu::Buffer, [u32; 2]),
    /// The images the texture code reads, and their atlas on the GPU.
    pub(super) images: ImageSet,
    pub(super) image_atlas_view: wgpu::TextureView,
}

impl SceneBindings {
    /// `scene`'s resources, with `texture_params` the numbers of its
    /// generated texture code and `env` its environment (None: black).
    pub(super) fn new(
        ctx: &GpuContext,
        scene: &Scene,
        env: Option<&EnvImage>,
        images: ImageSet,
        texture_params: &[[f32; 4]],
    ) -> Self {
        let device = &ctx.device;
        let buffer = |label: &str, contents: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            })
        };
        let env_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("environment"),
            // Repeat in u: bilinear filtering wraps across the u = 0/1 seam.
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let env = env.map(|e| envmap::fit_within(e, device.limits().max_texture_dimension_2d));
        Self {
            geometry: GeometryBuffers::new(device, scene),
            meshes: MeshBuffers::new(device, scene),
            perm_buffer: buffer("permutation", bytemuck::cast_slice(&permutation_table())),
            texture_param_buffer: buffer(
                "texture parameters",
                bytemuck::cast_slice(texture_params),
            ),
            env_view: upload_env(ctx, env.as_deref()),
            env_sampler,
            env_distribution: upload_env_distribution(ctx, env.as_deref()),
            image_atlas_view: upload_atlas(ctx, images.atlas()),
            images,
        }
    }

    /// Their entries in the trace pass's bind group 0.
    pub(super) fn layout_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
        let mut entries: Vec<_> = GeometryBuffers::BINDINGS
            .iter()
            .map(|&b| entry(b, uniform()))
            .collect();
        entries.extend([
            entry(3, float_texture(true)),
            entry(
                4,
                wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            ),
            entry(6, uniform()),
            entry(7, uniform()),
            entry(8, float_texture(false)),
            entry(11, storage(true)),
        ]);
        entries.extend(
            MeshBuffers::BINDINGS
                .iter()
                .map(|&b| entry(b, storage(true))),
        );
        entries
    }

    /// Replaces the environment image (None: a black 1×1 placeholder). One
    /// larger than the GPU's textures is downscaled to fit (as
    /// `session::load_environment` does with a note), never refused.
    pub(super) fn set_environment(&mut self, ctx: &GpuContext, env: Option<&EnvImage>) {
        let env = env.map(|e| envmap::fit_within(e, ctx.device.limits().max_texture_dimension_2d));
        self.env_view = upload_env(ctx, env.as_deref());
        self.env_distribution = upload_env_distribution(ctx, env.as_deref());
    }

    /// Replaces the images the texture code reads and their atlas.
    pub(super) fn set_images(&mut self, ctx: &GpuContext, images: ImageSet) {
        self.image_atlas_view = upload_atlas(ctx, images.atlas());
        self.images = images;
    }

    /// Writes the texture code's numbers.
    pub(super) fn write_texture_params(&self, ctx: &GpuContext, params: &[[f32; 4]]) {
        ctx.queue
            .write_buffer(&self.texture_param_buffer, 0, bytemuck::cast_slice(params));
    }
}

/// What the renderer binds without an environment map: one black texel.
fn no_env() -> EnvImage {
    marbre_core::envmap::constant(1, 1, [0.0; 3])
}

/// The environment's importance-sampling CDFs (`env_sampling.wgsl`) and
/// their size in cells; a 1×1 uniform distribution without a map.
fn upload_env_distribution(ctx: &GpuContext, env: Option<&EnvImage>) -> (wgpu::Buffer, [u32; 2]) {
    let distribution = EnvDistribution::new(env.unwrap_or(&no_env()));
    let buffer = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("environment distribution"),
            contents: bytemuck::cast_slice(&distribution.gpu_data()),
            usage: wgpu::BufferUsages::STORAGE,
        });
    (buffer, [distribution.width, distribution.height])
}

/// Uploads an environment map as Rgba16Float (the sanitised values fit).
fn upload_env(ctx: &GpuContext, env: Option<&EnvImage>) -> wgpu::TextureView {
    let black = no_env();
    let image = env.unwrap_or(&black);
    upload_rgba16f(
        ctx,
        "environment",
        (image.width, image.height),
        bytemuck::cast_slice(&image.to_rgba16f()),
    )
}
