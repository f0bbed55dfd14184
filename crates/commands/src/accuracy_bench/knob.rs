//! The knobs the bench sweeps, by the names the command line and the CSV
//! use.

/// What a sweep varies. The names are the `--knobs` values and the CSV's
/// `knob` column.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Knob {
    Spp,
    Bounces,
    LightSelection,
    Strategy,
    EnvSampling,
    Octaves,
    OctaveClamping,
    Filtering,
    Hash,
    Shader,
    FireflyClamp,
    Denoise,
}

impl Knob {
    pub const ALL: [Knob; 12] = [
        Knob::Spp,
        Knob::Bounces,
        Knob::LightSelection,
        Knob::Strategy,
        Knob::EnvSampling,
        Knob::Octaves,
        Knob::OctaveClamping,
        Knob::Filtering,
        Knob::Hash,
        Knob::Shader,
        Knob::FireflyClamp,
        Knob::Denoise,
    ];

    pub fn id(self) -> &'static str {
        match self {
            Knob::Spp => "spp",
            Knob::Bounces => "bounces",
            Knob::LightSelection => "light-selection",
            Knob::Strategy => "strategy",
            Knob::EnvSampling => "env-sampling",
            Knob::Octaves => "octaves",
            Knob::OctaveClamping => "octave-clamping",
            Knob::Filtering => "filtering",
            Knob::Hash => "hash",
            Knob::Shader => "shader",
            Knob::FireflyClamp => "firefly-clamp",
            Knob::Denoise => "denoise",
        }
    }

    pub fn title(self) -> &'static str {
        match self {
            Knob::Spp => "Samples per pixel",
            Knob::Bounces => "Maximum bounces",
            Knob::LightSelection => "Light selection",
            Knob::Strategy => "Direct-light strategy",
            Knob::EnvSampling => "Environment sampling",
            Knob::Octaves => "Fractal octaves",
            Knob::OctaveClamping => "Footprint clamping of octaves",
            Knob::Filtering => "Texture filtering",
            Knob::Hash => "Noise hash",
            Knob::Shader => "Specialised or uber shader",
            Knob::FireflyClamp => "Firefly clamp (biased)",
            Knob::Denoise => "Denoised preview (biased)",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn knob_ids_are_their_command_line_names() {
        use clap::ValueEnum;
        for knob in Knob::ALL {
            let value = knob.to_possible_value().unwrap();
            assert_eq!(value.get_name(), knob.id());
        }
    }
}
