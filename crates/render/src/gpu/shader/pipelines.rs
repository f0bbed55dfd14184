//! Shader modules and pipelines, with validation errors caught instead of
//! panicking, so a bad shader never takes the app down.

use crate::gpu::context::GpuContext;
use crate::gpu::features::FeatureSet;
use crate::gpu::shader_source::{Program, assemble};
use anyhow::{Result, anyhow};
use marbre_core::texture::ImageAtlas;
use wgpu::util::DeviceExt;

/// Assembles and validates a program with naga, then creates the module. A
/// naga error names the file and line, which the wgpu panic would not.
pub fn shader_module(
    device: &wgpu::Device,
    program: Program,
    features: &FeatureSet,
    generated_textures: &str,
) -> Result<wgpu::ShaderModule> {
    let source = assemble(program, features, generated_textures)?;
    compile_wgsl(device, program, source)
}

/// A compute pipeline running `entry_point` of `program` (built with
/// `features`), with one bind group of `entries`; and that group's layout.
pub fn compute_pipeline(
    device: &wgpu::Device,
    program: Program,
    features: &FeatureSet,
    entries: &[wgpu::BindGroupLayoutEntry],
    entry_point: &str,
) -> Result<(wgpu::ComputePipeline, wgpu::BindGroupLayout)> {
    compute_pipeline_with(device, program, features, "", entries, entry_point)
}

/// [`compute_pipeline`] of a program that reads a scene's generated
/// texture code (`generated_textures`).
pub fn compute_pipeline_with(
    device: &wgpu::Device,
    program: Program,
    features: &FeatureSet,
    generated_textures: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
    entry_point: &str,
) -> Result<(wgpu::ComputePipeline, wgpu::BindGroupLayout)> {
    let module = shader_module(device, program, features, generated_textures)?;
    let label = format!("{program:?}");
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(&label),
        entries,
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(&label),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = checked(device, &format!("{label} pipeline"), || {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(&label),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some(entry_point),
            compilation_options: Default::default(),
            cache: None,
        })
    })?;
    Ok((pipeline, layout))
}

/// Validates assembled WGSL with naga, then creates the module.
pub fn compile_wgsl(
    device: &wgpu::Device,
    program: Program,
    source: String,
) -> Result<wgpu::ShaderModule> {
    validate(&source).map_err(|e| anyhow!("{program:?} shader: {e}"))?;
    let (module, error) = in_validation_scope(device, || {
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(&format!("{program:?}")),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        })
    });
    if let Some(e) = error {
        return Err(anyhow!("{program:?} shader rejected by the device: {e}"));
    }
    Ok(module)
}

/// Runs `create` and returns what it made with the validation error it
/// caused, if any. A web page cannot wait for the scope's answer (the
/// browser gives it on its own event loop, which a blocked page never
/// returns to): there no scope is opened, and an error arrives as an
/// uncaptured one, which the viewer's device watch shows (issue 34).
fn in_validation_scope<T>(
    device: &wgpu::Device,
    create: impl FnOnce() -> T,
) -> (T, Option<wgpu::Error>) {
    if cfg!(target_arch = "wasm32") {
        return (create(), None);
    }
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let value = create();
    (value, pollster::block_on(scope.pop()))
}

/// In a web page the browser's compiler validates the module, and reports
/// through the device's uncaptured errors (the viewer's device watch).
#[cfg(target_arch = "wasm32")]
pub fn validate(_source: &str) -> Result<(), String> {
    Ok(())
}

/// Parses and validates WGSL with naga, as the device will.
#[cfg(not(target_arch = "wasm32"))]
pub fn validate(source: &str) -> Result<(), String> {
    let module = naga::front::wgsl::parse_str(source)
        .map_err(|e| located(source, e.location(source), e.emit_to_string(source)))?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| located(source, e.location(source), e.emit_to_string(source)))?;
    Ok(())
}

/// naga's report headed by the WGSL file and line the error is at:
/// naga counts lines in the assembled module, which no one edits.
#[cfg(not(target_arch = "wasm32"))]
fn located(source: &str, location: Option<naga::SourceLocation>, report: String) -> String {
    let position = location.and_then(|at| {
        crate::gpu::shader_source::source_position(source, at.line_number)
            .map(|(file, line)| format!("{file}:{line}:{}", at.line_position))
    });
    match position {
        Some(position) => format!("at {position}\n{report}"),
        None => report,
    }
}

/// Runs `create` inside a validation error scope.
pub fn checked<T>(device: &wgpu::Device, what: &str, create: impl FnOnce() -> T) -> Result<T> {
    match in_validation_scope(device, create) {
        (_, Some(e)) => Err(anyhow!("{what}: {e}")),
        (value, None) => Ok(value),
    }
}

/// A pipeline drawing the full-screen triangle of `vs_fullscreen` with
/// `fragment_entry`, its override constants set to `constants`.
pub fn fullscreen_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    layout: &wgpu::BindGroupLayout,
    fragment_entry: &str,
    formats: &[wgpu::TextureFormat],
    constants: &[(&str, f64)],
) -> Result<wgpu::RenderPipeline> {
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    fullscreen_pipeline_with_layout(
        device,
        label,
        module,
        &pipeline_layout,
        fragment_entry,
        formats,
        constants,
    )
}

/// [`fullscreen_pipeline`] with a pipeline layout of several groups.
pub fn fullscreen_pipeline_with_layout(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    pipeline_layout: &wgpu::PipelineLayout,
    fragment_entry: &str,
    formats: &[wgpu::TextureFormat],
    constants: &[(&str, f64)],
) -> Result<wgpu::RenderPipeline> {
    checked(device, label, || {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(pipeline_layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_fullscreen"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(fragment_entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants,
                    ..Default::default()
                },
                targets: &formats.iter().map(|&f| Some(f.into())).collect::<Vec<_>>(),
            }),
            multiview_mask: None,
            cache: None,
        })
    })
}

/// A bind group layout entry visible to the fragment and compute stages.
pub fn entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE,
        ty,
        count: None,
    }
}

/// A bind group entry holding the whole of `buffer`.
pub fn buffer_entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}

pub fn uniform() -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Uniform,
        has_dynamic_offset: false,
        min_binding_size: None,
    }
}

pub fn storage(read_only: bool) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only },
        has_dynamic_offset: false,
        min_binding_size: None,
    }
}

pub fn float_texture(filterable: bool) -> wgpu::BindingType {
    wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable },
        view_dimension: wgpu::TextureViewDimension::D2,
        multisampled: false,
    }
}

/// Perlin's permutation doubled to 512 entries, as the shader indexes it.
pub fn permutation_table() -> Vec<u32> {
    let p = marbre_core::noise::perlin::PERMUTATION;
    (0..512).map(|i| u32::from(p[i & 255])).collect()
}

/// The image atlas as an `Rgba16Float` texture (read with `textureLoad`).
pub fn upload_atlas(ctx: &GpuContext, atlas: &ImageAtlas) -> wgpu::TextureView {
    upload_rgba16f(
        ctx,
        "image atlas",
        (atlas.width, atlas.height),
        atlas.rgba16f_bytes(),
    )
}

/// A sampled `Rgba16Float` texture holding `bytes` (row 0 first).
pub fn upload_rgba16f(
    ctx: &GpuContext,
    label: &str,
    (width, height): (u32, u32),
    bytes: &[u8],
) -> wgpu::TextureView {
    let texture = ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytes,
    );
    texture.create_view(&Default::default())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wgsl_error_names_the_shader_file_and_its_own_line() {
        let module = "// ---- a.wgsl\nfn ok() {}\n// ---- b.wgsl\n\nfn broken( {\n";
        let error = validate(module).unwrap_err();
        assert!(error.starts_with("at b.wgsl:2:12\n"), "{error}");
        assert!(error.contains("expected identifier"), "{error}");
        let invalid = "// ---- c.wgsl\nfn f() -> f32 {\n    return 1u;\n}\n";
        let error = validate(invalid).unwrap_err();
        assert!(error.starts_with("at c.wgsl:"), "{error}");
    }
}
