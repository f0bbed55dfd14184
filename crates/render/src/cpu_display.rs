//! The display pass (`shaders/tonemap.wgsl`) on the CPU, for images that
//! never sit whole on the GPU: a merge of a farm's batches and tiles
//! (`marbre merge -o x.png`), and a render too large for one set of
//! targets, traced a tile at a time. Exposure (manual, or metered over
//! the whole image by `auto_exposure::meter`), the tone curve and the sRGB
//! encoding, as the GPU applies them; the GPU test
//! `cpu_display_matches_the_display_pass` holds the two together.

use crate::gpu::auto_exposure;
use marbre_core::scene::{DisplaySettings, ToneMap};

/// The image `pixels` (linear radiance, rows of `size.0`) shows with
/// `display`, 8-bit sRGB, and the metered exposure in stops when
/// `display` meters it. The non-finite debug view is not drawn: a merged
/// or assembled image has no spread target to read it from.
pub fn show(
    pixels: &[[f32; 4]],
    size: (u32, u32),
    display: &DisplaySettings,
) -> (image::RgbaImage, Option<f32>) {
    let metered = display
        .auto_exposure
        .then(|| auto_exposure::meter(pixels).stops_for(display.metering));
    let scale = display.exposure.exp2() * metered.unwrap_or(0.0).exp2();
    let bytes = pixels
        .iter()
        .flat_map(|p| {
            let [r, g, b] =
                [0, 1, 2].map(|c| encode(tone_map(display.tone_map, (p[c] * scale).max(0.0))));
            [r, g, b, 255]
        })
        .collect();
    let image = image::RgbaImage::from_raw(size.0, size.1, bytes)
        .expect("one pixel of 4 bytes for each of size.0 × size.1");
    (image, metered)
}

/// The tone curves of `shaders/tonemap.wgsl`'s `tone_map`.
fn tone_map(tone_map: ToneMap, x: f32) -> f32 {
    match tone_map {
        // Narkowicz's fit of the ACES filmic curve.
        ToneMap::Aces => ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0),
        ToneMap::Reinhard => x / (1.0 + x),
        ToneMap::Clamp => x.clamp(0.0, 1.0),
        ToneMap::Exponential => 1.0 - (-x).exp(),
    }
}

/// sRGB's encoding to 8 bits, rounded to nearest as a `Rgba8UnormSrgb`
/// target stores it.
fn encode(c: f32) -> u8 {
    let s = if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s.clamp(0.0, 1.0) * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values whose results are known: black and white under clamp, 1 under
    /// Reinhard (½, sRGB 188), a stop of exposure doubling the radiance,
    /// and the auto exposure of a uniform grey of luminance 0.18 (Reinhard's
    /// key: 0 stops).
    #[test]
    fn known_values_show_as_their_curves_say() {
        let clamp = DisplaySettings {
            tone_map: ToneMap::Clamp,
            ..Default::default()
        };
        let (image, metered) = show(&[[0.0; 4], [2.0, 1.0, 0.5, 1.0]], (2, 1), &clamp);
        assert_eq!(metered, None);
        assert_eq!(image.as_raw(), &[0, 0, 0, 255, 255, 255, 188, 255]);
        let reinhard = DisplaySettings {
            tone_map: ToneMap::Reinhard,
            exposure: 1.0,
            ..Default::default()
        };
        let (image, _) = show(&[[0.5, 0.5, 0.5, 1.0]], (1, 1), &reinhard);
        assert_eq!(image.as_raw()[..3], [188, 188, 188]);
        let auto = DisplaySettings {
            auto_exposure: true,
            tone_map: ToneMap::Clamp,
            ..Default::default()
        };
        let (_, metered) = show(&[[0.18, 0.18, 0.18, 1.0]; 4], (2, 2), &auto);
        assert!(metered.unwrap().abs() < 1e-3, "{metered:?}");
    }
}
