//! Which denoiser runs, and OIDN's side of it.
//!
//! A scene asks for OIDN or the à-trous filter (`DisplaySettings::
//! denoiser`). OIDN runs where its library is found (`marbre_oidn`);
//! elsewhere the à-trous filter runs instead and [`Running`] says why, for
//! the Stats panel and the CLI's notes. OIDN is a CPU library (or CUDA):
//! the accumulation and its guides are read back ([`GuidedImage`]), filtered
//! on the CPU — on a background thread in the viewer ([`OidnWorker`]) — and
//! the result uploaded for the display pass to tone-map like the raw mean.

mod oidn_worker;

pub use oidn_worker::{Done, Job, OidnWorker};

use crate::gpu::context::GpuContext;
use anyhow::{Result, anyhow};
use marbre_core::scene::{DenoiseQuality, Denoiser as Choice};
use marbre_oidn::{DeviceKind, Guides, Images, Library, Quality};
use std::sync::Arc;
use std::time::Duration;

/// What filters the displayed image, as the Stats panel and the CLI say.
#[derive(Debug, Clone, PartialEq)]
pub enum Running {
    Oidn {
        device: DeviceKind,
        /// OIDN's version, once its device reported it.
        version: Option<String>,
        quality: DenoiseQuality,
    },
    /// The à-trous filter; `instead_of_oidn` says why OIDN does not run
    /// when the scene asked for it.
    Atrous { instead_of_oidn: Option<String> },
}

impl Running {
    /// One line: "OIDN 2.5.1 on the CPU (balanced)", or "à-trous (OIDN's
    /// library … was not found: …)".
    pub fn describe(&self) -> String {
        match self {
            Running::Oidn {
                device,
                version,
                quality,
            } => format!(
                "OIDN{} on the {} ({})",
                version.as_ref().map_or(String::new(), |v| format!(" {v}")),
                device.name(),
                quality.label()
            ),
            Running::Atrous {
                instead_of_oidn: None,
            } => "à-trous".to_owned(),
            Running::Atrous {
                instead_of_oidn: Some(why),
            } => format!("à-trous, as {why}"),
        }
    }
}

/// What denoises, its last time, and how the viewer kept drawing.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DenoiseReport {
    pub running: Running,
    /// The last OIDN filter's wall time (the CPU's, or CUDA's with the
    /// copies through host memory), and the samples per pixel it filtered.
    pub last: Option<(Duration, u32)>,
    /// OIDN images shown since the renderer started.
    pub images: u32,
    /// The fewest frames the display drew while one of them was read back
    /// and filtered: the viewer never waits for OIDN, so it is several
    /// whenever the filter takes several frames' time.
    pub fewest_frames_meanwhile: Option<u32>,
}

impl Default for Running {
    fn default() -> Self {
        Running::Atrous {
            instead_of_oidn: None,
        }
    }
}

/// OIDN's library for a scene that asks for `choice`: `Ok(None)` when it
/// asks for the à-trous filter, `Err(why)` when OIDN is asked for and not
/// found.
pub fn oidn_for(choice: Choice) -> Result<Option<Arc<Library>>, String> {
    match choice {
        Choice::Atrous => Ok(None),
        Choice::Oidn => Library::shared().map(Some).map_err(|e| e.to_string()),
    }
}

/// OIDN's device for `ctx`'s adapter: CUDA on an NVIDIA GPU where OIDN's
/// CUDA device runs, the CPU otherwise.
pub fn device_for(ctx: &GpuContext, library: &Library) -> DeviceKind {
    const NVIDIA: u32 = 0x10de;
    if ctx.adapter.get_info().vendor == NVIDIA && marbre_oidn::Denoiser::cuda_supported(library) {
        DeviceKind::Cuda
    } else {
        DeviceKind::Cpu
    }
}

/// OIDN's network for a quality.
pub fn quality(q: DenoiseQuality) -> Quality {
    match q {
        DenoiseQuality::High => Quality::High,
        DenoiseQuality::Balanced => Quality::Balanced,
        DenoiseQuality::Fast => Quality::Fast,
    }
}

/// An accumulation and its guides as the trace writes them, read back:
/// the mean radiance, the first hit's albedo (plus emission) and its
/// shading normal encoded as 0.5 + 0.5·n, averaged over the samples (0
/// where a sample escaped).
#[derive(Debug, Clone, Default)]
pub struct GuidedImage {
    pub size: (u32, u32),
    pub mean: Vec<[f32; 4]>,
    pub albedo: Vec<[f32; 4]>,
    pub normal: Vec<[f32; 4]>,
}

impl GuidedImage {
    /// OIDN's output for it (alpha 1), with `oidn`'s device.
    pub fn denoise(
        &self,
        oidn: &mut marbre_oidn::Denoiser,
        q: DenoiseQuality,
    ) -> Result<Vec<[f32; 4]>> {
        let rgb = |v: &[[f32; 4]]| v.iter().map(|p| [p[0], p[1], p[2]]).collect::<Vec<_>>();
        let colour = rgb(&self.mean);
        let albedo = rgb(&self.albedo);
        let normal: Vec<[f32; 3]> = self.normal.iter().map(|p| decode_normal(*p)).collect();
        let out = oidn
            .denoise(
                &Images {
                    size: self.size,
                    colour: &colour,
                    guides: Some(Guides {
                        albedo: &albedo,
                        normal: &normal,
                    }),
                },
                quality(q),
            )
            .map_err(|e| anyhow!("{e}"))?;
        Ok(out.into_iter().map(|[r, g, b]| [r, g, b, 1.0]).collect())
    }
}

/// The normal guide decoded: 2g − 1, except where every sample escaped
/// (the guide is 0 there), which OIDN gets as no normal (0) rather than
/// (−1, −1, −1).
pub fn decode_normal(g: [f32; 4]) -> [f32; 3] {
    if g[0] == 0.0 && g[1] == 0.0 && g[2] == 0.0 {
        return [0.0; 3];
    }
    [2.0 * g[0] - 1.0, 2.0 * g[1] - 1.0, 2.0 * g[2] - 1.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_decode_and_an_escaped_pixel_has_none() {
        assert_eq!(decode_normal([0.5, 1.0, 0.0, 1.0]), [0.0, 1.0, -1.0]);
        assert_eq!(decode_normal([0.0, 0.0, 0.0, 1.0]), [0.0; 3]);
    }

    #[test]
    fn the_fallback_says_why() {
        let running = Running::Atrous {
            instead_of_oidn: Some("OIDN's library was not found".to_owned()),
        };
        assert_eq!(
            running.describe(),
            "à-trous, as OIDN's library was not found"
        );
    }
}
