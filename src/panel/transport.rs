//! The Light transport section: integrator, bounces, how lights are chosen
//! and how strategies combine. Every control is a uniform of the shader, so
//! a change restarts accumulation without a shader build.

use super::slider;
use egui::{ComboBox, Ui};
use marbre_core::lights::LightSelection;
use marbre_core::scene::{Integrator, LightPoints, RenderSettings, Strategy, TransportSettings};

pub fn transport_ui(ui: &mut Ui, render: &mut RenderSettings) {
    let t = &mut render.transport;
    ui.horizontal(|ui| {
        ui.label("integrator");
        ui.selectable_value(&mut t.integrator, Integrator::Direct, "direct")
            .on_hover_text(
                "Camera rays and shadow rays only (the lab's first exercises): no indirect light",
            );
        ui.selectable_value(&mut t.integrator, Integrator::Path, "path tracing")
            .on_hover_text("Paths of up to `max bounces` reflections: indirect light too");
    });
    if t.integrator == Integrator::Path {
        ui.add(slider(
            &mut render.max_bounces,
            1..=RenderSettings::MAX_BOUNCES,
            "max bounces",
        ))
        .on_hover_text("1 is direct light only; each more adds one reflection");
        ui.add(slider(
            &mut t.russian_roulette_from,
            0..=16,
            "Russian roulette from",
        ))
        .on_hover_text(
            "From this bounce on, a path goes on with the chance of its throughput and the \
                 survivors are weighted up (unbiased, cheaper); 0 never ends paths early",
        );
    }
    ui.add(slider(
        &mut t.light_samples,
        1..=TransportSettings::MAX_LIGHT_SAMPLES,
        "light samples",
    ))
    .on_hover_text("Points sampled on the lights at each shading point (the lab's N)");
    ComboBox::new("light selection", "light selection")
        .selected_text(t.light_selection.label())
        .show_ui(ui, |ui| {
            for s in LightSelection::ALL {
                ui.selectable_value(&mut t.light_selection, s, s.label());
            }
        })
        .response
        .on_hover_text(
            "How each light sample picks its light: every light (triangle, sphere, point) \
             equally, or in proportion to its power",
        );
    ComboBox::new("light points", "light points")
        .selected_text(t.light_points.label())
        .show_ui(ui, |ui| {
            for p in LightPoints::ALL {
                ui.selectable_value(&mut t.light_points, p, p.label());
            }
        })
        .response
        .on_hover_text(
            "Where each light sample lies on its light: a random point (correct), the \
             centroid of each light (the lab's exercise 3: hard shadows), or the same \
             points for every pixel (exercise 4: bands that never average away); the fixed \
             points turn MIS into light sampling",
        );
    ComboBox::new("strategy", "direct light")
        .selected_text(t.strategy.label())
        .show_ui(ui, |ui| {
            for s in Strategy::ALL {
                ui.selectable_value(&mut t.strategy, s, s.label());
            }
        })
        .response
        .on_hover_text(
            "Sample the lights, follow the BSDF, or both weighted by multiple importance \
             sampling (balance or power heuristic); or follow directions uniform over the \
             hemisphere (the BSDF's diffuse lobe, pdf 1/2π: noisier); the environment map \
             follows the same rule",
        );
    ui.checkbox(&mut render.env_importance, "sample the environment map")
        .on_hover_text(
            "Also draw light directions from a lat-long map by its luminance, combined with \
             BSDF sampling by MIS: a sun stops making fireflies",
        );
    let mut clamp_on = t.sample_clamp.is_some();
    ui.horizontal(|ui| {
        ui.checkbox(&mut clamp_on, "clamp fireflies")
            .on_hover_text(
                "Scale down any sample brighter than this in its largest channel: fewer \
                 fireflies, but a darker, biased image (the bench measures how much); off by default",
            );
        if clamp_on {
            let value = t.sample_clamp.get_or_insert(DEFAULT_SAMPLE_CLAMP);
            ui.add(
                egui::Slider::new(value, 0.1..=1.0e4)
                    .logarithmic(true)
                    .text("max"),
            )
            .on_hover_text(
                "The brightest a sample may be in its largest channel; lower removes more \
                 fireflies and darkens more",
            );
        } else {
            t.sample_clamp = None;
        }
    });
}

/// Where the firefly clamp starts when switched on: ten times a white
/// surface under a sky of radiance 1.
const DEFAULT_SAMPLE_CLAMP: f32 = 10.0;
