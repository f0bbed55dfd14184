//! How the image is sampled and displayed.

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum ToneMap {
    /// The Narkowicz fit of the ACES filmic curve.
    #[default]
    Aces,
    /// `x / (1 + x)`.
    Reinhard,
    /// Clamp to [0, 1]: what the linear radiance looks like untouched.
    Clamp,
}

impl ToneMap {
    pub const ALL: [ToneMap; 3] = [ToneMap::Aces, ToneMap::Reinhard, ToneMap::Clamp];

    pub fn label(self) -> &'static str {
        match self {
            ToneMap::Aces => "ACES (filmic)",
            ToneMap::Reinhard => "Reinhard",
            ToneMap::Clamp => "clamp",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RenderSettings {
    /// Jittered samples traced per pixel each frame.
    pub samples_per_frame: u32,
    /// Average frames while nothing changes; off shows each frame alone.
    pub accumulate: bool,
    /// Exposure in stops: the radiance is scaled by 2^exposure. With
    /// `auto_exposure` it is a compensation added to the automatic value.
    pub exposure: f32,
    /// Expose by Reinhard's key: the image's log-average luminance is
    /// brought to middle grey (0.18), `exposure` stops on top; metered on
    /// the GPU every frame (`gpu::auto_exposure`). Off, `exposure` alone
    /// sets it: the manual override.
    pub auto_exposure: bool,
    pub tone_map: ToneMap,
    /// Resolution scale used while the camera is being dragged, so the view
    /// stays responsive; full resolution comes back when the mouse is still.
    pub interactive_scale: f32,
    /// Path length: 1 is direct light only (point light and environment),
    /// each more bounce adds one more reflection.
    pub max_bounces: u32,
    /// Checkerboards averaged over each ray's footprint in closed form,
    /// rather than point sampled (which aliases far away).
    pub filter_checkers: bool,
    /// Fractal sums stop at the octaves the footprint resolves (pbrt's
    /// rule), rather than summing detail finer than a pixel.
    pub clamp_octaves: bool,
    /// A lat-long environment is also sampled in proportion to its
    /// luminance at every bounce, combined with BSDF sampling by multiple
    /// importance sampling (power heuristic); off, only BSDF sampling
    /// finds it.
    pub env_importance: bool,
    pub transport: super::transport::TransportSettings,
    /// Debug view: pixels where a path gave a NaN or infinite sample (which
    /// the accumulation drops and counts) are painted magenta.
    pub show_non_finite: bool,
}

impl RenderSettings {
    pub const MAX_SAMPLES_PER_FRAME: u32 = 64;
    pub const MAX_BOUNCES: u32 = 16;
    /// The exposure (or compensation) range of the panel and of presets.
    pub const MAX_EXPOSURE_STOPS: f32 = 20.0;

    pub(crate) fn sanitize(&mut self, notes: &mut Vec<String>) {
        let d = Self::default();
        let spp = self.samples_per_frame.clamp(1, Self::MAX_SAMPLES_PER_FRAME);
        if spp != self.samples_per_frame {
            notes.push(format!(
                "render: samples per frame {} clamped to {spp}",
                self.samples_per_frame
            ));
            self.samples_per_frame = spp;
        }
        let b = self.max_bounces.clamp(1, Self::MAX_BOUNCES);
        if b != self.max_bounces {
            notes.push(format!(
                "render: max bounces {} clamped to {b}",
                self.max_bounces
            ));
            self.max_bounces = b;
        }
        if !self.exposure.is_finite() || self.exposure.abs() > Self::MAX_EXPOSURE_STOPS {
            let what = if self.auto_exposure {
                "exposure compensation"
            } else {
                "exposure"
            };
            notes.push(format!("render: {what} {} clamped", self.exposure));
            self.exposure = if self.exposure.is_finite() {
                self.exposure
                    .clamp(-Self::MAX_EXPOSURE_STOPS, Self::MAX_EXPOSURE_STOPS)
            } else {
                d.exposure
            };
        }
        if !(self.interactive_scale.is_finite() && (0.1..=1.0).contains(&self.interactive_scale)) {
            notes.push(format!(
                "render: interactive scale {} reset",
                self.interactive_scale
            ));
            self.interactive_scale = d.interactive_scale;
        }
        self.transport.sanitize(notes);
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            samples_per_frame: 1,
            accumulate: true,
            exposure: 0.0,
            auto_exposure: false,
            tone_map: ToneMap::Aces,
            interactive_scale: 0.5,
            max_bounces: 3,
            filter_checkers: true,
            clamp_octaves: true,
            env_importance: true,
            transport: Default::default(),
            show_non_finite: false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_exposure_reads_off_from_old_presets_and_on_when_set() {
        let old: RenderSettings = ron::from_str("(exposure: 1.5, tone_map: Reinhard)").unwrap();
        assert!(!old.auto_exposure);
        assert_eq!(old.exposure, 1.5);
        let auto: RenderSettings = ron::from_str("(auto_exposure: true, exposure: -1.0)").unwrap();
        assert!(auto.auto_exposure);
        assert_eq!(auto.exposure, -1.0);
    }

    #[test]
    fn exposure_compensation_is_clamped_with_a_note() {
        let mut render = RenderSettings {
            auto_exposure: true,
            exposure: 35.0,
            ..RenderSettings::default()
        };
        let mut notes = Vec::new();
        render.sanitize(&mut notes);
        assert_eq!(render.exposure, 20.0);
        assert!(render.auto_exposure);
        assert_eq!(notes, ["render: exposure compensation 35 clamped"]);
    }
}
