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
use anyhow::Result;
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

impl DenoiseReport {
    /// This report after one more OIDN image: `took` to filter `samples`
    /// per pixel, with `meanwhile` frames drawn while it ran (the
    /// viewer's thread), or none counted (a denoise waited for).
    pub fn after_image(
        self,
        running: Running,
        took: Duration,
        samples: u32,
        meanwhile: Option<u32>,
    ) -> Self {
        let fewest = match (self.fewest_frames_meanwhile, meanwhile) {
            (Some(f), Some(m)) => Some(f.min(m)),
            (f, m) => f.or(m),
        };
        Self {
            running,
            last: Some((took, samples)),
            images: self.images + 1,
            fewest_frames_meanwhile: fewest,
        }
    }
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
    /// OIDN's output for it (alpha 1), with `oidn`'s device; the pixels
    /// that see an emitter keep their raw radiance ([`sees_an_emitter`]).
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
            .map_err(anyhow::Error::from)?;
        Ok(out
            .into_iter()
            .zip(&self.mean)
            .zip(&self.albedo)
            .map(|((d, m), a)| {
                if sees_an_emitter(*a) {
                    [m[0], m[1], m[2], 1.0]
                } else {
                    [d[0], d[1], d[2], 1.0]
                }
            })
            .collect())
    }
}

/// Whether a pixel's samples met an emitter first: its albedo guide
/// (albedo plus emission) exceeds 1, which no reflectance does. Such a
/// pixel keeps its raw radiance. OIDN takes albedo within [0, 1], so a
/// light reaches it as a white surface barely brighter than a white wall,
/// and its network spread the light into the ceiling around it: on the
/// Cornell box at 320 × 180 and 16 spp, OIDN's RMSE was 1.31× the raw
/// one's, 91 % of it in the light's pixels (which lost a third of their
/// radiance), though it halved the walls' error; with the light's pixels
/// kept, 0.85×.
fn sees_an_emitter(albedo_guide: [f32; 4]) -> bool {
    albedo_guide[..3].iter().any(|&v| v > 1.0)
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
    fn only_a_guide_above_any_reflectance_sees_an_emitter() {
        assert!(!sees_an_emitter([1.0, 1.0, 1.0, 1.0]));
        assert!(!sees_an_emitter([0.0, 0.0, 0.0, 1.0]));
        assert!(sees_an_emitter([0.2, 1.5, 0.2, 1.0]));
        assert!(sees_an_emitter([17.0, 12.0, 4.0, 1.0]));
    }

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
