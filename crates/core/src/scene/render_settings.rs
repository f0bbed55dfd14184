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
    /// The course display: the report's presets and `marbre tx` show
    /// their typed colours as typed through it (no curve, sRGB out).
    Clamp,
    /// `1 − exp(−x)`: Massal's photographic exposure curve. His tutorial
    /// computes `1 − exp(e · c)` with a negative exposure `e` (−1 by
    /// default); marbre scales the radiance by 2^stops first, so his `e`
    /// is `log2(−e)` stops (0 for his default).
    Exponential,
}

impl ToneMap {
    pub const ALL: [ToneMap; 4] = [
        ToneMap::Aces,
        ToneMap::Reinhard,
        ToneMap::Clamp,
        ToneMap::Exponential,
    ];

    pub fn label(self) -> &'static str {
        match self {
            ToneMap::Aces => "ACES (filmic)",
            ToneMap::Reinhard => "Reinhard",
            ToneMap::Clamp => "clamp (course: colours as typed)",
            ToneMap::Exponential => "1 − exp (Massal)",
        }
    }
}

/// Which filter the display's `denoise` runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
pub enum Denoiser {
    /// Intel Open Image Denoise, where its library is found (the render
    /// crate's `denoiser`); the à-trous filter otherwise, with a note.
    #[default]
    Oidn,
    /// marbre's edge-avoiding à-trous filter, on the GPU.
    Atrous,
}

impl Denoiser {
    pub const ALL: [Denoiser; 2] = [Denoiser::Oidn, Denoiser::Atrous];

    /// The name `render --denoise` and `merge --denoise` take.
    pub fn name(self) -> &'static str {
        match self {
            Denoiser::Oidn => "oidn",
            Denoiser::Atrous => "atrous",
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Denoiser::Oidn => "OIDN",
            Denoiser::Atrous => "à-trous",
        }
    }
}

/// OIDN's three networks (its `quality`), slowest and best first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
pub enum DenoiseQuality {
    /// For final frames: `marbre render` and `merge` use it.
    High,
    /// For interactive rendering: the viewer's default.
    #[default]
    Balanced,
    /// For real-time previews.
    Fast,
}

impl DenoiseQuality {
    pub const ALL: [DenoiseQuality; 3] = [
        DenoiseQuality::High,
        DenoiseQuality::Balanced,
        DenoiseQuality::Fast,
    ];

    pub fn label(self) -> &'static str {
        match self {
            DenoiseQuality::High => "high",
            DenoiseQuality::Balanced => "balanced",
            DenoiseQuality::Fast => "fast",
        }
    }
}

/// How auto exposure meters the image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Metering {
    /// Reinhard et al.'s key: the log-average luminance brought to middle
    /// grey (0.18).
    #[default]
    Key,
    /// Massal's tutorial (annex I): the RMS luminance L = √(0.2126·⟨r²⟩ +
    /// 0.715160·⟨g²⟩ + 0.072169·⟨b²⟩) over a grid of at most 256 × 256
    /// samples, scaled by −ln(0.6)/L, so that through his `1 − exp(−x)`
    /// ([`ToneMap::Exponential`]) the RMS luminance shows as 0.4; below
    /// L = 0.001 his default exposure (scale 1).
    MassalRms,
}

impl Metering {
    pub const ALL: [Metering; 2] = [Metering::Key, Metering::MassalRms];

    pub fn label(self) -> &'static str {
        match self {
            Metering::Key => "key (Reinhard)",
            Metering::MassalRms => "RMS (Massal)",
        }
    }
}

/// What is traced and how the result is shown. The display part is its
/// own type: an edit there keeps the accumulated samples, and
/// [`RenderSettings::traces_like`] compares the rest.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(from = "RenderSettingsFile", into = "RenderSettingsFile")]
pub struct RenderSettings {
    /// Jittered samples traced per pixel each frame.
    pub samples_per_frame: u32,
    /// Average frames while nothing changes; off shows each frame alone.
    pub accumulate: bool,
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
    /// What each sample records: the lit image or a view of the first
    /// hit (hit mask, primitive, normal, albedo, depth).
    pub view: super::render_view::View,
    /// How the accumulated radiance is shown.
    pub display: DisplaySettings,
}

/// How the accumulated radiance becomes pixels: exposure, tone map and the
/// non-finite debug view. Nothing here changes what is traced.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplaySettings {
    /// Exposure in stops: the radiance is scaled by 2^exposure. With
    /// `auto_exposure` it is a compensation added to the automatic value.
    pub exposure: f32,
    /// Expose by Reinhard's key: the image's log-average luminance is
    /// brought to middle grey (0.18), `exposure` stops on top; metered on
    /// the GPU every frame (`gpu::auto_exposure`). Off, `exposure` alone
    /// sets it: the manual override.
    pub auto_exposure: bool,
    /// What auto exposure meters: Reinhard's key, or Massal's RMS.
    pub metering: Metering,
    pub tone_map: ToneMap,
    /// Debug view: pixels where a path gave a NaN or infinite sample (which
    /// the accumulation drops and counts) are painted magenta.
    pub show_non_finite: bool,
    /// Show the accumulation through the denoiser, guided by the first
    /// hit's albedo and normal, which the trace pass then accumulates
    /// beside the radiance (a specialised shader). Biased; off by default,
    /// and saved EXRs stay the raw accumulation.
    pub denoise: bool,
    /// Which denoiser, when `denoise` is on.
    pub denoiser: Denoiser,
    /// OIDN's network.
    pub denoise_quality: DenoiseQuality,
}

impl Default for DisplaySettings {
    fn default() -> Self {
        Self {
            exposure: 0.0,
            auto_exposure: false,
            metering: Metering::Key,
            tone_map: ToneMap::Aces,
            show_non_finite: false,
            denoise: false,
            denoiser: Denoiser::Oidn,
            denoise_quality: DenoiseQuality::Balanced,
        }
    }
}

/// The render settings as presets write them: one flat record, as they
/// always were, whatever the types in memory. Each field means what the
/// field of the same name in [`RenderSettings`] or [`DisplaySettings`]
/// says.
#[derive(Serialize, Deserialize)]
#[serde(default)]
struct RenderSettingsFile {
    samples_per_frame: u32,
    accumulate: bool,
    exposure: f32,
    auto_exposure: bool,
    tone_map: ToneMap,
    interactive_scale: f32,
    max_bounces: u32,
    filter_checkers: bool,
    clamp_octaves: bool,
    env_importance: bool,
    transport: super::transport::TransportSettings,
    show_non_finite: bool,
    /// `DisplaySettings::metering`; presets written before it read Key.
    auto_exposure_metering: Metering,
    view: super::render_view::View,
    denoise: bool,
    /// Presets written before it denoise with OIDN, as ones written after
    /// it do by default.
    denoiser: Denoiser,
    denoise_quality: DenoiseQuality,
}

impl From<RenderSettingsFile> for RenderSettings {
    fn from(f: RenderSettingsFile) -> Self {
        Self {
            samples_per_frame: f.samples_per_frame,
            accumulate: f.accumulate,
            interactive_scale: f.interactive_scale,
            max_bounces: f.max_bounces,
            filter_checkers: f.filter_checkers,
            clamp_octaves: f.clamp_octaves,
            env_importance: f.env_importance,
            transport: f.transport,
            view: f.view,
            display: DisplaySettings {
                exposure: f.exposure,
                auto_exposure: f.auto_exposure,
                metering: f.auto_exposure_metering,
                tone_map: f.tone_map,
                show_non_finite: f.show_non_finite,
                denoise: f.denoise,
                denoiser: f.denoiser,
                denoise_quality: f.denoise_quality,
            },
        }
    }
}

impl From<RenderSettings> for RenderSettingsFile {
    fn from(r: RenderSettings) -> Self {
        Self {
            samples_per_frame: r.samples_per_frame,
            accumulate: r.accumulate,
            exposure: r.display.exposure,
            auto_exposure: r.display.auto_exposure,
            tone_map: r.display.tone_map,
            interactive_scale: r.interactive_scale,
            max_bounces: r.max_bounces,
            filter_checkers: r.filter_checkers,
            clamp_octaves: r.clamp_octaves,
            env_importance: r.env_importance,
            transport: r.transport,
            show_non_finite: r.display.show_non_finite,
            auto_exposure_metering: r.display.metering,
            view: r.view,
            denoise: r.display.denoise,
            denoiser: r.display.denoiser,
            denoise_quality: r.display.denoise_quality,
        }
    }
}

impl Default for RenderSettingsFile {
    fn default() -> Self {
        RenderSettings::default().into()
    }
}

impl RenderSettings {
    pub const MAX_SAMPLES_PER_FRAME: u32 = 64;
    pub const MAX_BOUNCES: u32 = 16;
    /// The exposure (or compensation) range of the panel and of presets.
    pub const MAX_EXPOSURE_STOPS: f32 = 20.0;

    /// Whether `self` and `other` trace the same samples: every setting
    /// but the display's equal. Destructured in full, so that a new field
    /// has to be sorted into traced or displayed.
    pub fn traces_like(&self, other: &Self) -> bool {
        let Self {
            samples_per_frame,
            accumulate,
            interactive_scale,
            max_bounces,
            filter_checkers,
            clamp_octaves,
            env_importance,
            transport,
            view,
            display: _,
        } = *self;
        (
            samples_per_frame,
            accumulate,
            interactive_scale,
            max_bounces,
            filter_checkers,
            clamp_octaves,
            env_importance,
            transport,
            view,
        ) == (
            other.samples_per_frame,
            other.accumulate,
            other.interactive_scale,
            other.max_bounces,
            other.filter_checkers,
            other.clamp_octaves,
            other.env_importance,
            other.transport,
            other.view,
        )
    }

    /// The display settings the display pass applies: the preset's for the
    /// lit image; a view's values shown as they are (no exposure, clamped
    /// to [0, 1], the sRGB encoding of a PNG aside), so a hit mask is
    /// white and black on screen as in its EXR.
    pub fn shown_display(&self) -> DisplaySettings {
        if self.view.is_data() {
            DisplaySettings {
                exposure: 0.0,
                auto_exposure: false,
                tone_map: ToneMap::Clamp,
                show_non_finite: self.display.show_non_finite,
                metering: self.display.metering,
                denoise: false,
                ..self.display
            }
        } else {
            self.display
        }
    }

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
        let display = &mut self.display;
        if !display.exposure.is_finite() || display.exposure.abs() > Self::MAX_EXPOSURE_STOPS {
            let what = if display.auto_exposure {
                "exposure compensation"
            } else {
                "exposure"
            };
            notes.push(format!("render: {what} {} clamped", display.exposure));
            display.exposure = if display.exposure.is_finite() {
                display
                    .exposure
                    .clamp(-Self::MAX_EXPOSURE_STOPS, Self::MAX_EXPOSURE_STOPS)
            } else {
                d.display.exposure
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
            interactive_scale: 0.5,
            max_bounces: 3,
            filter_checkers: true,
            clamp_octaves: true,
            env_importance: true,
            transport: Default::default(),
            view: Default::default(),
            display: DisplaySettings::default(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::View;
    use super::*;

    /// A preset written before the denoiser could be chosen denoises with
    /// OIDN's balanced network, as a new one does by default; a choice
    /// round-trips.
    #[test]
    fn the_denoiser_reads_oidn_from_old_presets_and_round_trips() {
        let old: RenderSettings = ron::from_str("(denoise: true)").unwrap();
        assert!(old.display.denoise);
        assert_eq!(old.display.denoiser, Denoiser::Oidn);
        assert_eq!(old.display.denoise_quality, DenoiseQuality::Balanced);
        let mut chosen = old;
        chosen.display.denoiser = Denoiser::Atrous;
        chosen.display.denoise_quality = DenoiseQuality::Fast;
        let text = ron::to_string(&chosen).unwrap();
        assert!(text.contains("denoiser:Atrous"), "{text}");
        assert_eq!(ron::from_str::<RenderSettings>(&text).unwrap(), chosen);
    }

    #[test]
    fn auto_exposure_reads_off_from_old_presets_and_on_when_set() {
        let old: RenderSettings = ron::from_str("(exposure: 1.5, tone_map: Reinhard)").unwrap();
        assert!(!old.display.auto_exposure);
        assert_eq!(old.display.exposure, 1.5);
        assert_eq!(old.display.tone_map, ToneMap::Reinhard);
        let auto: RenderSettings = ron::from_str("(auto_exposure: true, exposure: -1.0)").unwrap();
        assert!(auto.display.auto_exposure);
        assert_eq!(auto.display.exposure, -1.0);
        // Both meter by Reinhard's key, as they did before Massal's RMS.
        assert_eq!(old.display.metering, Metering::Key);
        assert_eq!(auto.display.metering, Metering::Key);
        let massal: RenderSettings =
            ron::from_str("(auto_exposure: true, auto_exposure_metering: MassalRms)").unwrap();
        assert!(massal.display.auto_exposure);
        assert_eq!(massal.display.metering, Metering::MassalRms);
        let text = ron::to_string(&massal).unwrap();
        assert!(text.contains("auto_exposure_metering:MassalRms"), "{text}");
        assert_eq!(ron::from_str::<RenderSettings>(&text).unwrap(), massal);
    }

    /// The display settings live in their own type in memory, but a preset
    /// still writes one flat record, which reads back the same.
    #[test]
    fn presets_keep_the_flat_record() {
        let render = RenderSettings {
            max_bounces: 5,
            display: DisplaySettings {
                exposure: 2.5,
                show_non_finite: true,
                ..DisplaySettings::default()
            },
            ..RenderSettings::default()
        };
        let text = ron::to_string(&render).unwrap();
        assert!(
            text.starts_with("(samples_per_frame:1,accumulate:true,exposure:2.5,"),
            "{text}"
        );
        assert!(!text.contains("display"), "{text}");
        assert_eq!(ron::from_str::<RenderSettings>(&text).unwrap(), render);
    }

    #[test]
    fn only_traced_settings_change_what_is_traced() {
        let base = RenderSettings::default();
        let mut shown = base;
        shown.display = DisplaySettings {
            exposure: 3.0,
            auto_exposure: true,
            metering: Metering::MassalRms,
            tone_map: ToneMap::Clamp,
            show_non_finite: true,
            // Its guides come with a new pipeline, which restarts the
            // accumulation by itself.
            denoise: true,
            denoiser: Denoiser::Atrous,
            denoise_quality: DenoiseQuality::Fast,
        };
        assert!(base.traces_like(&shown));
        let mut traced = base;
        traced.max_bounces += 1;
        assert!(!base.traces_like(&traced));
        let mut traced = base;
        traced.transport.light_samples += 1;
        assert!(!base.traces_like(&traced));
        let mut traced = base;
        traced.view = View::Depth;
        assert!(!base.traces_like(&traced));
        let mut traced = base;
        traced.transport.light_points = super::super::LightPoints::FixedSet;
        assert!(!base.traces_like(&traced));
    }

    #[test]
    fn views_read_lit_from_old_presets_and_show_unexposed() {
        let old: RenderSettings = ron::from_str("(exposure: 1.5)").unwrap();
        assert_eq!(old.view, View::Lit);
        assert_eq!(old.shown_display(), old.display);
        let mask: RenderSettings =
            ron::from_str("(exposure: 1.5, auto_exposure: true, view: HitMask)").unwrap();
        assert_eq!(mask.view, View::HitMask);
        let shown = mask.shown_display();
        assert_eq!((shown.exposure, shown.auto_exposure), (0.0, false));
        assert_eq!(shown.tone_map, ToneMap::Clamp);
        assert_eq!(
            ron::from_str::<RenderSettings>(&ron::to_string(&mask).unwrap()).unwrap(),
            mask
        );
    }

    #[test]
    fn exposure_compensation_is_clamped_with_a_note() {
        let mut render = RenderSettings {
            display: DisplaySettings {
                auto_exposure: true,
                exposure: 35.0,
                ..DisplaySettings::default()
            },
            ..RenderSettings::default()
        };
        let mut notes = Vec::new();
        render.sanitize(&mut notes);
        assert_eq!(render.display.exposure, 20.0);
        assert!(render.display.auto_exposure);
        assert_eq!(notes, ["render: exposure compensation 35 clamped"]);
    }
}
