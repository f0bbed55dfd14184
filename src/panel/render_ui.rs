//! The Render section: the view, samples, bounces, exposure and tone map,
//! the anti-aliasing switches and the kernel.

use super::keying;
use super::widgets::slider;
use super::{PanelAction, Stats};
use egui::{ComboBox, Ui};
use marbre_core::animation::ParamPath;
use marbre_core::scene::{DenoiseQuality, Denoiser, Metering, RenderSettings, ToneMap, View};

pub(super) fn render_ui(ui: &mut Ui, render: &mut RenderSettings, actions: &mut Vec<PanelAction>) {
    ComboBox::new("view", "view")
        .selected_text(render.view.label())
        .show_ui(ui, |ui| {
            for v in View::ALL {
                ui.selectable_value(&mut render.view, v, v.label())
                    .on_hover_text(view_hint(v));
            }
        })
        .response
        .on_hover_text(
            "What each pixel records: the lit image, or the first surface the camera ray \
             meets (the Monte Carlo lab's first exercises); views are shown as they are, \
             without exposure or tone map",
        );
    ui.add(slider(
        &mut render.samples_per_frame,
        1..=RenderSettings::MAX_SAMPLES_PER_FRAME,
        "samples per frame",
    ))
    .on_hover_text("Jittered samples per pixel each frame: smoother, slower frames");
    ui.checkbox(&mut render.accumulate, "accumulate")
        .on_hover_text("Average frames while nothing changes; off shows each frame alone");
    ui.checkbox(&mut render.display.auto_exposure, "auto exposure")
        .on_hover_text(
            "Meter the image every frame and expose it by the metering below; off, the \
             exposure slider alone sets it",
        );
    ui.add_enabled_ui(render.display.auto_exposure, |ui| {
        ComboBox::new("metering", "metering")
            .selected_text(render.display.metering.label())
            .show_ui(ui, |ui| {
                for m in Metering::ALL {
                    ui.selectable_value(&mut render.display.metering, m, m.label())
                        .on_hover_text(match m {
                            Metering::Key => {
                                "The log-average luminance brought to middle grey \
                                 (Reinhard's key, 0.18)"
                            }
                            Metering::MassalRms => {
                                "Massal's: the RMS luminance over a 256 × 256 grid, scaled \
                                 by −ln(0.6)/L_rms, so that his 1 − exp tone map shows it \
                                 as 0.4"
                            }
                        });
                }
            })
            .response
            .on_hover_text("What auto exposure measures")
            .on_disabled_hover_text("Used with auto exposure on");
    });
    let (label, hint) = if render.display.auto_exposure {
        (
            "compensation",
            "Stops added to the automatic exposure: + brighter, − darker than middle grey",
        )
    } else {
        (
            "exposure",
            "Scales the radiance by 2^exposure before tone mapping",
        )
    };
    let stops = RenderSettings::MAX_EXPOSURE_STOPS;
    let exposure = ParamPath::parse("render.exposure").expect("a path");
    keying::number(ui, &exposure, &mut render.display.exposure, |ui, v| {
        ui.add(slider(v, -stops..=stops, label).suffix(" stops"))
    })
    .on_hover_text(hint);
    ComboBox::new("tone map", "tone map")
        .selected_text(render.display.tone_map.label())
        .show_ui(ui, |ui| {
            for t in ToneMap::ALL {
                ui.selectable_value(&mut render.display.tone_map, t, t.label())
                    .on_hover_text(tone_map_hint(t));
            }
        })
        .response
        .on_hover_text("How radiance is mapped to displayable [0, 1]");
    ui.add(slider(
        &mut render.interactive_scale,
        0.1..=1.0,
        "resolution while dragging",
    ))
    .on_hover_text("Resolution scale while the camera moves, to keep the view responsive");
    ui.checkbox(&mut render.filter_checkers, "filter checkers")
        .on_hover_text(
            "Average checkerboards over each ray's footprint (closed form): no aliasing far away",
        );
    ui.checkbox(&mut render.clamp_octaves, "clamp octaves to footprint")
        .on_hover_text("Stop fractal sums at the finest octave a pixel resolves (pbrt's rule)");
    ui.add_enabled_ui(render.view == View::Lit, |ui| denoise_ui(ui, render))
        .response
        .on_disabled_hover_text("Filters the lit image only");
    ui.checkbox(
        &mut render.display.show_non_finite,
        "show non-finite pixels",
    )
    .on_hover_text(
        "Debug view: paint magenta every pixel where a path gave a NaN or infinite sample \
             (the accumulation drops such samples; Stats counts them)",
    );
    if ui
        .button("Screenshot (F12)")
        .on_hover_text(
            "Save the image without the UI into screenshots/: a tone-mapped PNG and a linear \
             EXR",
        )
        .clicked()
    {
        actions.push(PanelAction::Screenshot);
    }
}

/// What a view shows, for its tooltip.
fn view_hint(view: View) -> &'static str {
    match view {
        View::Lit => "The radiance, lit as the Light transport section says",
        View::HitMask => "White where the camera ray meets a surface, black where it escapes",
        View::Primitive => {
            "One flat colour per sphere, cylinder, polygon, the ground and each mesh triangle"
        }
        View::Normal => "The shading normal, facing the camera, as 0.5 + 0.5·n",
        View::Albedo => "The diffuse reflectance of the first surface",
        View::Depth => {
            "t / (t + d): the distance t along the ray against the camera's distance d to its \
             target (0.5 there, white where the ray escapes)"
        }
    }
}

/// What a tone map entry does, for its tooltip.
pub(super) fn tone_map_hint(tone_map: ToneMap) -> &'static str {
    match tone_map {
        ToneMap::Aces => "Narkowicz's fit of the ACES filmic curve: soft highlights, more contrast",
        ToneMap::Reinhard => "x / (1 + x) per channel: never clips, but flattens highlights",
        ToneMap::Clamp => "Clamp to [0, 1]: the linear radiance untouched, highlights clip",
        ToneMap::Exponential => {
            "1 − exp(−x) per channel, Massal's photographic exposure: never clips, softer toe"
        }
    }
}

/// The Kernel switch: which kernel traces (all draw the same image), or
/// `auto`, the fastest here.
pub(super) fn kernel_ui(ui: &mut Ui, stats: &Stats, actions: &mut Vec<PanelAction>) {
    use marbre_render::gpu::KernelChoice;
    let name = |c: KernelChoice| match c {
        KernelChoice::Auto => "auto (the fastest)",
        KernelChoice::Fragment => "fragment",
        KernelChoice::Compute => "compute",
        KernelChoice::Cpu => "cpu",
    };
    let mut choice = stats.kernel_choice;
    egui::ComboBox::from_label("kernel")
        .selected_text(name(choice))
        .show_ui(ui, |ui| {
            for c in [
                KernelChoice::Auto,
                KernelChoice::Fragment,
                KernelChoice::Compute,
                KernelChoice::Cpu,
            ] {
                ui.selectable_value(&mut choice, c, name(c));
            }
        })
        .response
        .on_hover_text(
            "The trace as a fragment shader, a compute kernel, or native code on this machine's \
             cores (cpu: scenes without environment maps, bump, images, cylinders or polygons; \
             others are traced by the fragment kernel meanwhile): the same image, at a speed that \
             depends on the machine; auto times them on the scene and remembers the fastest",
        );
    if choice != stats.kernel_choice {
        actions.push(PanelAction::SetKernel(choice));
    }
}

/// The denoiser: off, OIDN or à-trous, and OIDN's network.
fn denoise_ui(ui: &mut Ui, render: &mut RenderSettings) {
    let display = &mut render.display;
    let mut choice = display.denoise.then_some(display.denoiser);
    ComboBox::from_label("denoiser")
        .selected_text(choice.map_or("off", Denoiser::label))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut choice, None, "off");
            for d in Denoiser::ALL {
                ui.selectable_value(&mut choice, Some(d), d.label());
            }
        })
        .response
        .on_hover_text(
            "Show the image denoised, guided by the first surface's albedo and normal. OIDN \
             (Intel Open Image Denoise, as Blender uses) runs on the CPU off the render \
             thread, where its library is found (Stats says which runs); à-trous is marbre's \
             edge-avoiding filter on the GPU. PNG screenshots are filtered; EXRs stay the raw \
             accumulation. Turning it on restarts the accumulation",
        );
    display.denoise = choice.is_some();
    if let Some(d) = choice {
        display.denoiser = d;
    }
    if choice == Some(Denoiser::Oidn) {
        ComboBox::from_label("OIDN quality")
            .selected_text(display.denoise_quality.label())
            .show_ui(ui, |ui| {
                for q in DenoiseQuality::ALL {
                    ui.selectable_value(&mut display.denoise_quality, q, q.label());
                }
            })
            .response
            .on_hover_text(
                "OIDN's network: high for final frames, balanced for interactive use, fast for \
                 real-time previews",
            );
    }
}
