//! Data between the CPU and the GPU: the scene flattened into the
//! shader's structs (`scene_gpu`), its buffers (`geometry_buffers`,
//! `mesh_buffers`), and textures read back (`readback`,
//! `async_readback`).

pub mod async_readback;
pub mod geometry_buffers;
pub mod mesh_buffers;
pub mod readback;
pub mod scene_gpu;
