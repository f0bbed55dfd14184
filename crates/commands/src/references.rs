//! High-spp reference images, rendered offscreen and kept on disk between
//! runs: a reference costs minutes, a measurement against it seconds.
//! Shared by `bench-convergence` and `bench`.
//!
//! A reference is keyed by everything that decides its pixels: the scene
//! (its RON, and the contents of every file it reads: meshes, their
//! materials, the environment map, image textures), the size, the sample
//! count and the renderer (the shader sources' fingerprint and the crate
//! version). Change any of them and a new reference is rendered.

use anyhow::{Context, Result};
use marbre_core::scene::Scene;
use marbre_core::{envmap, image_io};
use marbre_render::gpu::GpuContext;
use marbre_render::gpu::shader_source::sources_fingerprint;
use marbre_render::session::{LoadedScene, accumulate, renderer_for};
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};

/// Samples per pixel a reference traces per frame: fewer frames, less
/// per-frame overhead, and (see [`render`]) never the seeds of a measured
/// render of one sample per frame.
pub const REFERENCE_SAMPLES_PER_FRAME: u32 = 16;

/// Where references are kept.
pub struct ReferenceCache {
    dir: PathBuf,
}

/// A reference image, and whether it came from the cache.
pub struct Reference {
    pub pixels: Vec<[f32; 4]>,
    pub path: PathBuf,
    pub cached: bool,
}

impl ReferenceCache {
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The reference of `loaded` at `size` and `spp`: from the cache, or
    /// rendered (calling `progress` with the samples done) and saved.
    pub fn get_or_render(
        &self,
        ctx: &GpuContext,
        loaded: &LoadedScene,
        size: (u32, u32),
        spp: u32,
        progress: impl FnMut(u32),
    ) -> Result<Reference> {
        let mut scene = loaded.scene.clone();
        scene.render.samples_per_frame = REFERENCE_SAMPLES_PER_FRAME;
        scene.render.accumulate = true;
        let path = self.path_of(&scene, size, spp)?;
        // A cached file of the wrong size (a hash collision) is re-rendered.
        let cached = envmap::load(&path)
            .ok()
            .filter(|l| (l.image.width, l.image.height) == size);
        if let Some(load) = cached {
            return Ok(Reference {
                pixels: load.image.pixels,
                path,
                cached: true,
            });
        }
        let pixels = render(ctx, loaded, scene, size, spp, progress)?;
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("creating {}", self.dir.display()))?;
        image_io::save_exr(size.0, size.1, &pixels, None, &path)?;
        Ok(Reference {
            pixels,
            path,
            cached: false,
        })
    }

    fn path_of(&self, scene: &Scene, size: (u32, u32), spp: u32) -> Result<PathBuf> {
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        hash_scene(scene, &mut hasher)?;
        (size, spp, env!("CARGO_PKG_VERSION")).hash(&mut hasher);
        sources_fingerprint().hash(&mut hasher);
        Ok(self
            .dir
            .join(format!("reference-{:016x}.exr", hasher.finish())))
    }
}

/// Hashes the scene's RON and the contents of the files it reads. A mesh's
/// materials come from its MTL file and are not all in the RON (only the
/// edited ones are): each is hashed as loaded.
fn hash_scene(scene: &Scene, hasher: &mut impl Hasher) -> Result<()> {
    ron::to_string(scene)
        .context("serialising the scene")?
        .hash(hasher);
    let read =
        |path: &Path| std::fs::read(path).with_context(|| format!("reading {}", path.display()));
    for mesh in &scene.meshes {
        read(&mesh.obj)?.hash(hasher);
        for material in &mesh.materials {
            ron::to_string(&material.material)
                .context("serialising a mesh material")?
                .hash(hasher);
        }
    }
    for path in scene.environment.source.paths() {
        read(path)?.hash(hasher);
    }
    for image in scene.image_sources() {
        read(&image.path)?.hash(hasher);
    }
    Ok(())
}

/// Renders the reference on a fresh renderer, from its frame 0.
///
/// The trace shader seeds sample `j` of a frame `f` from `j · φ + f`
/// (`shaders/trace.wgsl`). Here sample `j` lies in frame
/// `j / REFERENCE_SAMPLES_PER_FRAME`; a measured render, one sample per
/// frame after at least one warm-up frame, traces its sample `j` in a frame
/// past `j`. So no measured sample repeats a reference sample, and the
/// error measured is not shrunk by samples the two images share.
fn render(
    ctx: &GpuContext,
    loaded: &LoadedScene,
    scene: Scene,
    size: (u32, u32),
    spp: u32,
    progress: impl FnMut(u32),
) -> Result<Vec<[f32; 4]>> {
    let reference = LoadedScene {
        scene,
        env: loaded.env.clone(),
        images: loaded.images.clone(),
        notes: Vec::new(),
        substitutes: Vec::new(),
    };
    let mut renderer = renderer_for(ctx, &reference, size)?;
    accumulate(ctx, &mut renderer, spp, progress)?;
    Ok(renderer.read_radiance(ctx)?.2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use marbre_core::scene::Mesh;

    /// The file name follows everything that decides the pixels, and only
    /// that: the same inputs find the same file.
    #[test]
    fn the_key_changes_with_the_scene_its_files_the_size_and_the_samples() {
        let dir = tempfile::Builder::new()
            .prefix("reference-keys")
            .tempdir()
            .unwrap();
        let obj = dir.path().join("box.obj");
        std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let cache = ReferenceCache::new(dir.path().join("cache"));
        let mut scene = Scene::default();
        scene.meshes.push(Mesh {
            obj: obj.clone(),
            ..Mesh::default()
        });
        let key = |scene: &Scene, size, spp| cache.path_of(scene, size, spp).unwrap();
        let base = key(&scene, (8, 8), 64);
        assert_eq!(base, key(&scene.clone(), (8, 8), 64));
        assert_ne!(base, key(&scene, (8, 9), 64));
        assert_ne!(base, key(&scene, (8, 8), 128));
        let mut moved = scene.clone();
        moved.camera.distance += 1.0;
        assert_ne!(base, key(&moved, (8, 8), 64));
        std::fs::write(&obj, "v 0 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        assert_ne!(base, key(&scene, (8, 8), 64), "the OBJ file changed");
        assert!(base.starts_with(dir.path().join("cache")));
    }
}
