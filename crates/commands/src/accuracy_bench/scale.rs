//! How big a run is: image size, sample counts, references and the values
//! of the ordered knobs.

/// How big a run is. Sized for lavapipe on two shared CPU cores, where a
/// sample per pixel of the Cornell box costs about 13 µs a pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct Scale {
    pub size: (u32, u32),
    /// The spp knob renders 1, 2, 4 … up to this many samples per pixel.
    pub max_spp: u32,
    /// The spp knob's reference: many times `max_spp`, so that its own
    /// noise (its variance adds to each point's) leaves the slope alone.
    pub spp_reference: u32,
    /// Every other knob renders each variant at these counts, one curve of
    /// error against time per variant.
    pub variant_spp: Vec<u32>,
    pub reference_spp: u32,
    /// The maximum bounces swept (against 16).
    pub bounces: Vec<u32>,
    /// The octave counts swept (against 16).
    pub octaves: Vec<u32>,
    /// The denoise knob's counts, raw and filtered, its reference and its
    /// size: OIDN's network was trained on images of ordinary sizes, and a
    /// thumbnail's pixels each average much of the scene.
    pub denoise_spp: Vec<u32>,
    pub denoise_reference_spp: u32,
    pub denoise_size: (u32, u32),
}

impl Scale {
    /// Half a minute in a release build, references included.
    pub fn quick() -> Self {
        Self {
            size: (48, 48),
            max_spp: 64,
            spp_reference: 1024,
            variant_spp: vec![1, 4, 16],
            reference_spp: 256,
            bounces: vec![1, 2, 4, 8],
            octaves: vec![1, 2, 4, 8, 12],
            denoise_spp: vec![1, 4, 16],
            denoise_reference_spp: 256,
            denoise_size: (48, 48),
        }
    }

    /// Eight minutes in a release build, three with the references cached
    /// (the denoise knob: about 40 more, its references at 160 × 90).
    pub fn full() -> Self {
        Self {
            size: (64, 64),
            max_spp: 1024,
            spp_reference: 16384,
            variant_spp: vec![1, 4, 16, 64, 256],
            reference_spp: 2048,
            bounces: (1..=8).collect(),
            octaves: (1..=12).collect(),
            // 256 too: the target is OIDN at 16 spp against raw at
            // 256.
            denoise_spp: vec![1, 4, 16, 64, 256],
            denoise_reference_spp: 4096,
            denoise_size: (160, 90),
        }
    }
}
