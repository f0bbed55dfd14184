//! The GPU passes, each owning its pipeline and buffers: the trace pass and
//! its bands (`trace_pass`, `trace_bands`), the accumulation targets it
//! writes, the meters that read them (`auto_exposure`, `error_meter`,
//! `metering_grid`, `non_finite`, `pass_timer`), the denoiser, and the
//! texture evaluations the panel and `marbre bake` run (`swatch`, `bake`).

pub mod accumulation;
pub mod auto_exposure;
pub mod bake;
pub mod denoise;
pub mod error_meter;
pub mod metering_grid;
pub mod non_finite;
pub mod pass_timer;
pub mod preview_ladder;
pub mod swatch;
pub mod trace_bands;
pub mod trace_pass;
