//! The Render… dialog (Ctrl+R, or the Render section's button): a final
//! render of the scene as it is now, at any size, to a PNG or EXR file, as
//! `marbre render` makes it. The dialog only gathers the settings and shows
//! the progress; the app runs the render (`app/render_job.rs`).

use super::PanelAction;
use egui::{ComboBox, Ui};
use marbre_core::image_io::ImageFormat;
use marbre_core::scene::{DenoiseQuality, Denoiser, Metering};
use marbre_render::final_render::{FinalRender, Stop, parse_size};
use marbre_render::gpu::KernelChoice;
use std::path::PathBuf;

/// The dialog's fields, kept while it is closed.
#[derive(Debug, Clone)]
pub struct RenderDialog {
    pub open: bool,
    /// The output file being typed; its extension is the format.
    pub output: String,
    /// WIDTHxHEIGHT, as `render --size` takes it.
    pub size: String,
    /// Stop at a target error rather than at a number of samples.
    pub by_error: bool,
    /// Render every frame of the scene's animation (the output's name
    /// numbered with #), not the moment under the play head.
    pub all_frames: bool,
    /// With every frame, also assemble them into one animated file.
    pub assemble: bool,
    /// That file (.gif, .apng, .webp or .mp4), as `render --animation`.
    pub animation: String,
    pub spp: u32,
    /// The target relative error, in percent.
    pub target_percent: f64,
    /// The most samples per pixel a render to a target may take.
    pub max_spp: u32,
    /// Auto exposure for the PNG (`None`: as the scene has it).
    pub auto_exposure: Option<Metering>,
    /// Filter with this denoiser (`render --denoise oidn|atrous`): the
    /// PNG, or the EXR (`--denoise --denoise-exr`); `None`: raw.
    pub denoise: Option<Denoiser>,
    /// The render under way, if any.
    pub running: Option<RunningView>,
    /// How the last render ended, or why the settings were refused.
    pub last_result: Option<(String, bool)>,
    /// Put the keyboard in the output field (the dialog just opened).
    focus_output: bool,
}

/// What the dialog shows of a render under way.
#[derive(Debug, Clone)]
pub struct RunningView {
    pub output: String,
    pub fraction: f32,
    pub line: String,
}

/// `render`'s defaults: its size, its samples, its cap.
const DEFAULT_SIZE: &str = "1280x720";
const DEFAULT_SPP: u32 = 64;
const DEFAULT_MAX_SPP: u32 = 16384;
const DEFAULT_TARGET_PERCENT: f64 = 1.0;

impl Default for RenderDialog {
    fn default() -> Self {
        Self {
            open: false,
            output: "render.png".to_owned(),
            size: DEFAULT_SIZE.to_owned(),
            by_error: false,
            all_frames: false,
            assemble: false,
            animation: "render.gif".to_owned(),
            spp: DEFAULT_SPP,
            target_percent: DEFAULT_TARGET_PERCENT,
            max_spp: DEFAULT_MAX_SPP,
            auto_exposure: None,
            denoise: None,
            running: None,
            last_result: None,
            focus_output: false,
        }
    }
}

impl RenderDialog {
    /// Opens the dialog (the keyboard in its output field), or closes it.
    pub fn toggle(&mut self) {
        self.open = !self.open;
        self.focus_output = self.open;
    }

    /// The render these fields ask for, or what is wrong with them. The
    /// kernel is the app's to choose.
    pub fn job(&self) -> Result<FinalRender, String> {
        let output = PathBuf::from(self.output.trim());
        let format = ImageFormat::from_path(&output).map_err(|e| format!("{e:#}"))?;
        let size = parse_size(&self.size)?;
        let stop = if self.by_error {
            Stop::TargetError {
                target: self.target_percent / 100.0,
                max_spp: self.max_spp,
            }
        } else {
            Stop::Samples(self.spp)
        };
        Ok(FinalRender {
            size,
            stop,
            auto_exposure: self.auto_exposure,
            kernel: KernelChoice::Auto,
            output,
            denoise: self.denoise,
            // A final frame: OIDN's best network.
            denoise_quality: DenoiseQuality::High,
            // An EXR is filtered only when asked (`--denoise-exr`): here the
            // box asks it of either format.
            denoise_exr: self.denoise.is_some() && format == ImageFormat::Exr,
            // The viewer shows the placeholder and its note: it renders
            // what it shows.
            allow_placeholders: true,
            timing: Default::default(),
            sample_offset: 0,
            tile: None,
            max_tile_pixels: marbre_render::final_render::DEFAULT_MAX_TILE_PIXELS,
            moments: false,
            guides: false,
        })
    }

    /// The animated file to assemble the frames into, when every frame
    /// is rendered and one is asked for.
    pub fn animation_file(&self) -> Option<PathBuf> {
        (self.all_frames && self.assemble).then(|| PathBuf::from(self.animation.trim()))
    }

    /// The output's format as its extension says, if it says one.
    fn format(&self) -> Option<ImageFormat> {
        ImageFormat::from_path(std::path::Path::new(self.output.trim())).ok()
    }

    /// Gives the output path `format`'s extension.
    fn set_format(&mut self, format: ImageFormat) {
        let extension = match format {
            ImageFormat::Png => "png",
            ImageFormat::Exr => "exr",
        };
        let path = PathBuf::from(self.output.trim()).with_extension(extension);
        self.output = path.display().to_string();
    }
}

/// The Render section's button: opens the dialog, or shows the render
/// under way.
pub fn button(ui: &mut Ui, dialog: &mut RenderDialog) {
    let text = match &dialog.running {
        Some(running) => format!("Rendering… {:.0} %", 100.0 * running.fraction),
        None => "Render to a file…".to_owned(),
    };
    if ui
        .button(text)
        .on_hover_text("A final render at any size, PNG or EXR, in the background (Ctrl+R)")
        .clicked()
    {
        dialog.toggle();
    }
}

/// Draws the dialog when open; Render and Cancel become actions.
pub fn show(ctx: &egui::Context, dialog: &mut RenderDialog, actions: &mut Vec<PanelAction>) {
    if !dialog.open {
        return;
    }
    let mut open = true;
    egui::Window::new("Render")
        .open(&mut open)
        .anchor(egui::Align2::LEFT_TOP, [12.0, 12.0])
        .collapsible(false)
        .resizable(false)
        .show(ctx, |ui| dialog_ui(ui, dialog, actions));
    if !open {
        dialog.open = false;
    }
}

fn dialog_ui(ui: &mut Ui, dialog: &mut RenderDialog, actions: &mut Vec<PanelAction>) {
    let idle = dialog.running.is_none();
    let mut enter = false;
    ui.add_enabled_ui(idle, |ui| {
        egui::Grid::new("render dialog")
            .num_columns(2)
            .show(ui, |ui| {
                ui.label("output");
                let field = ui
                    .add(egui::TextEdit::singleline(&mut dialog.output).desired_width(220.0))
                    .on_hover_text(
                        "The file to write: .png (tone-mapped, sRGB) or .exr (linear radiance, \
                     float); written whole or not at all",
                    );
                if std::mem::take(&mut dialog.focus_output) {
                    field.request_focus();
                }
                enter |= field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                ui.end_row();
                ui.label("size");
                let field = ui
                    .add(egui::TextEdit::singleline(&mut dialog.size).desired_width(100.0))
                    .on_hover_text("WIDTHxHEIGHT in pixels, any size up to 16384 a side");
                enter |= field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                ui.end_row();
                ui.label("format");
                let format = dialog.format();
                let mut chosen = format;
                ComboBox::new("render format", "")
                    .selected_text(match format {
                        Some(ImageFormat::Png) => "PNG",
                        Some(ImageFormat::Exr) => "EXR",
                        None => "?",
                    })
                    .show_ui(ui, |ui| {
                        ui.selectable_value(&mut chosen, Some(ImageFormat::Png), "PNG");
                        ui.selectable_value(&mut chosen, Some(ImageFormat::Exr), "EXR");
                    });
                if let Some(f) = chosen.filter(|&f| Some(f) != format) {
                    dialog.set_format(f);
                }
                ui.end_row();
                ui.label("stop at");
                ui.horizontal(|ui| {
                    ui.radio_value(&mut dialog.by_error, false, "samples");
                    ui.radio_value(&mut dialog.by_error, true, "target error");
                });
                ui.end_row();
                if dialog.by_error {
                    ui.label("target");
                    ui.add(
                        egui::DragValue::new(&mut dialog.target_percent)
                            .range(0.01..=100.0)
                            .speed(0.01)
                            .suffix(" %"),
                    )
                    .on_hover_text(
                        "Stop when the estimated relative error (√relMSE, as the Quality strip \
                     shows it) is at most this",
                    );
                    ui.end_row();
                    ui.label("at most");
                    ui.add(
                        egui::DragValue::new(&mut dialog.max_spp)
                            .range(2..=1_000_000)
                            .suffix(" spp"),
                    );
                } else {
                    ui.label("samples");
                    ui.add(
                        egui::DragValue::new(&mut dialog.spp)
                            .range(1..=1_000_000)
                            .suffix(" spp"),
                    );
                }
                ui.end_row();
                ui.label("time");
                ui.checkbox(&mut dialog.all_frames, "every frame of the animation")
                    .on_hover_text(
                        "As `render --frames`: each frame to the output with its # replaced by \
                         the frame number (out/frame_####.png); off, the moment under the play head",
                    );
                ui.end_row();
                if dialog.all_frames {
                    ui.label("animation");
                    ui.horizontal(|ui| {
                        ui.checkbox(&mut dialog.assemble, "also as")
                            .on_hover_text(
                                "As `render --animation`: the PNG frames assembled into one \
                                 looping file",
                            );
                        ui.add_enabled(
                            dialog.assemble,
                            egui::TextEdit::singleline(&mut dialog.animation).desired_width(140.0),
                        )
                        .on_hover_text(
                            ".gif or .apng (written by marbre), .webp or .mp4 (through ffmpeg, \
                             when it is installed)",
                        );
                    });
                    ui.end_row();
                }
                ui.label("auto exposure");
                ComboBox::new("render auto exposure", "")
                    .selected_text(auto_exposure_label(dialog.auto_exposure))
                    .show_ui(ui, |ui| {
                        for choice in [None, Some(Metering::Key), Some(Metering::MassalRms)] {
                            ui.selectable_value(
                                &mut dialog.auto_exposure,
                                choice,
                                auto_exposure_label(choice),
                            );
                        }
                    })
                    .response
                    .on_hover_text(
                        "As `render --auto-exposure`: expose the PNG by its metering, the \
                     scene's exposure becoming a compensation; an EXR stays unscaled radiance",
                    );
                ui.end_row();
                ui.label("denoise");
                let label = dialog.denoise.map_or("off", Denoiser::label);
                ComboBox::from_id_salt("render denoiser")
                    .selected_text(label)
                    .show_ui(ui, |ui| {
                        ui.selectable_value(&mut dialog.denoise, None, "off");
                        for d in Denoiser::ALL {
                            ui.selectable_value(&mut dialog.denoise, Some(d), d.label());
                        }
                    })
                    .response
                    .on_hover_text(
                        "As `render --denoise oidn|atrous`: filter the image, guided by the \
                         first hit's albedo and normal, with Intel Open Image Denoise (its \
                         high-quality network; the à-trous filter where its library is not \
                         found) or the viewer's à-trous filter; an EXR is filtered too \
                         (`--denoise-exr`)",
                    );
                ui.end_row();
            });
    });
    match &dialog.running {
        Some(running) => {
            // Cancel first on its row: its place does not depend on the
            // length of the path below.
            ui.horizontal(|ui| {
                if ui.button("Cancel").clicked() {
                    actions.push(PanelAction::CancelRender);
                }
                ui.add(egui::ProgressBar::new(running.fraction).text(running.line.as_str()));
            });
            ui.label(format!("rendering {}", running.output));
        }
        None => {
            if ui.button("Render").clicked() || enter {
                match dialog.job() {
                    Ok(job) => actions.push(PanelAction::StartRender(job)),
                    Err(e) => dialog.last_result = Some((e, true)),
                }
            }
        }
    }
    if let Some((text, is_error)) = &dialog.last_result {
        let color = if *is_error {
            ui.visuals().error_fg_color
        } else {
            ui.visuals().text_color()
        };
        ui.colored_label(color, text.as_str());
    }
}

fn auto_exposure_label(choice: Option<Metering>) -> &'static str {
    match choice {
        None => "as the scene",
        Some(metering) => metering.label(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fields become `render`'s job: the size parsed as `--size`, the
    /// target in percent as a fraction, the format from the extension.
    #[test]
    fn the_fields_make_the_job() {
        let mut dialog = RenderDialog {
            output: " out/final.exr ".to_owned(),
            size: "640x360".to_owned(),
            by_error: true,
            target_percent: 2.0,
            max_spp: 500,
            ..RenderDialog::default()
        };
        let job = dialog.job().unwrap();
        assert_eq!(job.size, (640, 360));
        assert_eq!(job.output, PathBuf::from("out/final.exr"));
        assert_eq!(
            job.stop,
            Stop::TargetError {
                target: 0.02,
                max_spp: 500
            }
        );
        dialog.by_error = false;
        dialog.spp = 7;
        assert_eq!(dialog.job().unwrap().stop, Stop::Samples(7));
        dialog.set_format(ImageFormat::Png);
        assert_eq!(dialog.output, "out/final.png");
    }

    /// The frames are assembled into the animated file only when every
    /// frame is rendered and "also as" is ticked.
    #[test]
    fn the_animated_file_is_asked_for_with_every_frame_only() {
        let mut dialog = RenderDialog {
            animation: " out/loop.webp ".to_owned(),
            assemble: true,
            ..RenderDialog::default()
        };
        assert_eq!(dialog.animation_file(), None);
        dialog.all_frames = true;
        assert_eq!(
            dialog.animation_file(),
            Some(PathBuf::from("out/loop.webp"))
        );
        dialog.assemble = false;
        assert_eq!(dialog.animation_file(), None);
    }

    /// "denoise" asks the job to filter the image, a PNG's and, as
    /// `--denoise-exr`, an EXR's.
    #[test]
    fn denoise_filters_either_format() {
        let mut dialog = RenderDialog {
            denoise: Some(Denoiser::Oidn),
            ..RenderDialog::default()
        };
        let job = dialog.job().unwrap();
        assert!(job.denoise == Some(Denoiser::Oidn) && !job.denoise_exr);
        assert_eq!(job.denoise_quality, DenoiseQuality::High);
        dialog.output = "render.exr".to_owned();
        dialog.denoise = Some(Denoiser::Atrous);
        let job = dialog.job().unwrap();
        assert!(job.denoise == Some(Denoiser::Atrous) && job.denoise_exr);
        dialog.denoise = None;
        let job = dialog.job().unwrap();
        assert!(job.denoise.is_none() && !job.denoise_exr);
    }

    #[test]
    fn bad_fields_are_refused_with_the_reason() {
        let dialog = RenderDialog {
            size: "640 by 360".to_owned(),
            ..RenderDialog::default()
        };
        assert!(dialog.job().unwrap_err().contains("640 by 360"));
        let dialog = RenderDialog {
            output: "image.tiff".to_owned(),
            ..RenderDialog::default()
        };
        let e = dialog.job().unwrap_err();
        assert!(
            e.contains("image.tiff") && e.contains(".png or .exr"),
            "{e}"
        );
    }
}
