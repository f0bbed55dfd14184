//! The side panel: egui controls that edit a [`Scene`] in place.
//!
//! The panel knows nothing about the GPU. It mutates the scene and reports the
//! buttons pressed; the app compares the scene before and after the frame to
//! decide what to rebuild (shader features, buffers, accumulation). For that
//! comparison to be meaningful, no widget here may write to the scene unless
//! the user touched it, which is why sliders do not clamp existing values and
//! colours are written back only on a change.

mod environment_ui;
mod file_ui;
pub mod help;
pub mod keying;
mod material_editor;
pub mod node_graph;
mod quality;
pub mod render_dialog;
mod render_ui;
pub mod save_as;
mod scene_ui;
mod stats;
pub mod swatches;
pub mod timeline;
mod transport;
mod tx_ui;
mod widgets;

use egui::{ScrollArea, Ui};
use environment_ui::environment_ui;
use glam::Vec3;
use marbre_core::scene::texture_graph::NodePath;
use marbre_core::scene::{EnvSource, MaterialKey, Scene, Texture};
use marbre_render::gpu::NonFiniteCounts;
pub use material_editor::BAKE_SIZE;
pub use quality::{QualityControls, QualityStats};
use render_ui::{kernel_ui, render_ui};
use scene_ui::{camera_ui, materials_ui, point_light_ui};
use stats::{headline, stats_ui};
use std::path::PathBuf;
use widgets::{color_button, labelled_color, section, section_headed, slider, vec3_ui};

/// How many of the latest messages the Preset section shows.
const SHOWN_MESSAGES: usize = 5;
/// How many messages are kept (the older ones fold under the latest), so
/// that a long session does not grow the list without bound.
const KEPT_MESSAGES: usize = 50;

/// A line of feedback for the user (a preset loaded, a file that failed).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Message {
    pub text: String,
    pub is_error: bool,
    /// When it came, local time as `HH:MM:SS`: which of two similar
    /// messages is the latest.
    pub time: String,
}

/// What the panel keeps between frames that is not part of the scene.
#[derive(Debug, Clone)]
pub struct PanelState {
    /// The preset path being typed; Load and Save as use it.
    pub preset_path: String,
    /// The environment map path being typed; its Load button uses it.
    pub env_path: String,
    /// Feedback for the user, newest last.
    pub messages: Vec<Message>,
    /// The constant environment radiance last seen, so that switching the
    /// source away from constant and back does not lose the colour.
    last_radiance: Vec3,
    /// The cube face paths being typed (+x, -x, +y, -y, +z, -z) and the
    /// cross path; their Load buttons use them.
    cube_faces: [String; 6],
    cube_cross: String,
    /// The cube source last seen in the scene: when the scene's source
    /// changes (a preset loaded), the path fields above take its paths.
    cube_seen: Option<EnvSource>,
    /// A cube entry picked in the source dropdown before its paths were
    /// typed (true: six faces, false: cross): the panel shows its fields
    /// while the scene keeps its source until Load.
    cube_pending: Option<bool>,
    /// The target error and what to do on reaching it.
    pub quality: QualityControls,
    /// Whether the app has edits to undo and to redo (enables the buttons).
    pub can_undo: bool,
    pub can_redo: bool,
    /// Whether the scene has edits its preset file does not have.
    pub unsaved: bool,
    /// Whether Share is offered: in a web page, whose address can carry
    /// the scene (`app::share_link`).
    pub shares_links: bool,
    /// Recently opened presets and environment maps, newest first.
    pub recent_files: Vec<PathBuf>,
    /// Set to put the keyboard in the preset or environment path field
    /// (the first cube path field for a cube source) where no file dialog
    /// can open; cleared once done. Enter in any path field loads it.
    pub focus_preset_path: bool,
    pub focus_env_path: bool,
    /// A preset loading in the background: what it is doing, and the
    /// fraction done.
    pub progress: Option<(String, f32)>,
    /// The Render dialog's fields and the render under way.
    pub render_dialog: render_dialog::RenderDialog,
    /// Save as asking for a path, where no file dialog can open.
    pub save_as: Option<save_as::SaveAs>,
    /// The material whose node-graph window is open.
    pub node_graph: Option<MaterialKey>,
}

impl PanelState {
    pub fn new(preset_path: String, env_path: String) -> Self {
        Self {
            preset_path,
            env_path,
            messages: Vec::new(),
            last_radiance: Vec3::ONE,
            cube_faces: Default::default(),
            cube_cross: String::new(),
            cube_seen: None,
            cube_pending: None,
            quality: QualityControls::default(),
            can_undo: false,
            can_redo: false,
            unsaved: false,
            shares_links: cfg!(target_arch = "wasm32"),
            recent_files: Vec::new(),
            focus_preset_path: false,
            focus_env_path: false,
            progress: None,
            render_dialog: Default::default(),
            save_as: None,
            node_graph: None,
        }
    }

    /// Adds an informational message.
    pub fn info(&mut self, text: impl Into<String>) {
        self.push(text.into(), false);
    }

    /// Adds an error message, shown in red.
    pub fn error(&mut self, text: impl Into<String>) {
        self.push(text.into(), true);
    }

    /// A preset that failed to load: the error, and the path field back on
    /// `document` (the preset still open, or where its Save as writes), so
    /// that a later Save as does not write to the path that failed.
    pub fn load_failed(&mut self, text: impl Into<String>, document: &std::path::Path) {
        self.error(text);
        self.preset_path = document.display().to_string();
    }

    /// Also writes the message to the log: a run without anyone at the
    /// window (a test, a script) still says what it reported.
    fn push(&mut self, text: String, is_error: bool) {
        if is_error {
            log::warn!("{text}");
        } else {
            log::info!("{text}");
        }
        let time = chrono::Local::now().format("%H:%M:%S").to_string();
        self.messages.push(Message {
            text,
            is_error,
            time,
        });
        let excess = self.messages.len().saturating_sub(KEPT_MESSAGES);
        self.messages.drain(..excess);
    }
}

/// Figures the app measures and the panel only displays.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    pub fps: f32,
    pub ms_per_frame: f32,
    /// Whether `ms_per_frame` comes from GPU timestamps rather than the CPU
    /// clock around the frame.
    pub ms_is_gpu: bool,
    /// Samples per pixel accumulated in the current image.
    pub samples: u32,
    pub adapter: String,
    pub backend: String,
    /// The shader features the current scene compiled in.
    pub features: Vec<String>,
    /// Size of the trace shader's WGSL: what specialisation keeps it to.
    pub shader_bytes: usize,
    pub resolution: (u32, u32),
    /// A new shader is being built (the old one renders meanwhile).
    pub building: bool,
    /// How long the last shader build took, from the edit to the pipeline.
    pub last_build_ms: Option<f32>,
    /// Entries of the light table (point, sphere and triangle lights).
    pub lights: usize,
    pub triangles: usize,
    pub bvh_nodes: usize,
    pub bvh_build_ms: f32,
    /// Samples the accumulation dropped for being NaN or infinite.
    pub non_finite: NonFiniteCounts,
    pub quality: QualityStats,
    /// The trace kernel drawing now, what the user chose, and why it runs.
    pub kernel: marbre_render::gpu::Kernel,
    pub kernel_choice: marbre_render::gpu::KernelChoice,
    pub kernel_reason: String,
    /// The fraction of the sample round under way already traced (a slow
    /// adapter traces a round over several frames).
    pub round_progress: f32,
    /// What denoises the display and its last time, when denoising.
    pub denoise: Option<marbre_render::denoiser::DenoiseReport>,
}

/// A button press the app must act on: these need files, the GPU or the
/// window, which the panel has no access to.
#[derive(Debug, Clone, PartialEq)]
pub enum PanelAction {
    LoadPreset(PathBuf),
    /// Save to the preset file the scene came from.
    SavePreset,
    /// Put the scene in the page's address, to pass on as a link (a web
    /// page's Share; `app::share_link`).
    ShareLink,
    /// Save to a typed path (the Preset field's Save as, or the Save as
    /// dialog); a file already there is replaced only once confirmed.
    SavePresetAs(PathBuf),
    LoadEnvironment(PathBuf),
    Screenshot,
    ResetCamera,
    /// Compile a shader feature out (or back in), to time the scene
    /// without it.
    ToggleFeature(marbre_render::gpu::Feature),
    /// Trace with another kernel (or the faster, `auto`).
    SetKernel(marbre_render::gpu::KernelChoice),
    Undo,
    Redo,
    /// Pick a preset to open, a file to save as, or an environment map,
    /// in a native file dialog.
    BrowsePreset,
    BrowseSavePresetAs,
    BrowseEnvironment,
    /// Open a file from the recent list (a preset or an environment map).
    OpenRecent(PathBuf),
    /// Bake an object's property to an image beside the preset.
    Bake {
        object: marbre_core::bake::ObjectRef,
        property: marbre_core::bake::BakeProperty,
    },
    /// Render the scene as it is now to a file, in the background (the
    /// Render dialog's button; the app picks the kernel).
    StartRender(marbre_render::final_render::FinalRender),
    CancelRender,
}

/// Draws the whole panel contents into `ui` and returns the buttons pressed.
pub fn draw(
    ui: &mut Ui,
    scene: &mut Scene,
    state: &mut PanelState,
    stats: &Stats,
    timeline: &mut timeline::Timeline,
) -> Vec<PanelAction> {
    let mut actions = Vec::new();
    ScrollArea::vertical()
        .id_salt("panel scroll")
        .show(ui, |ui| {
            // The frame rate heads the panel, not the bottom of Stats.
            let header = format!("Preset      {}", headline(stats));
            section_headed(ui, "Preset", header, true, |ui| {
                file_ui::preset_ui(ui, state, &mut actions);
            });
            section(ui, "Materials", true, |ui| {
                if let Some((object, property)) = materials_ui(ui, scene, &mut state.node_graph) {
                    actions.push(PanelAction::Bake { object, property });
                }
            });
            section(ui, "Environment", true, |ui| {
                environment_ui(ui, &mut scene.environment, state, &mut actions);
            });
            section(ui, "Point light", false, |ui| {
                point_light_ui(ui, &mut scene.point_light);
            });
            section(ui, "Camera", false, |ui| {
                camera_ui(ui, scene, &mut actions);
            });
            section(ui, "Light transport", true, |ui| {
                transport::transport_ui(ui, &mut scene.render);
            });
            section(ui, "Render", true, |ui| {
                render_ui(ui, &mut scene.render, &mut actions);
                kernel_ui(ui, stats, &mut actions);
                render_dialog::button(ui, &mut state.render_dialog);
            });
            // Under the sections above, whose places the window tests
            // know; open, so that a scene's time is found at once.
            section(ui, "Time", true, |ui| {
                timeline::timeline_ui(ui, scene, timeline);
            });

            section(ui, "Stats", true, |ui| stats_ui(ui, stats));
        });
    // The graph's nodes show the same preview swatches as the tree's.
    let ctx = ui.ctx().clone();
    let swatch = |key: MaterialKey, path: &NodePath, _: &Texture| {
        swatches::swatch(
            &ctx,
            swatches::SwatchPlace {
                key,
                path: path.clone(),
            },
        )
    };
    node_graph::window(ui.ctx(), scene, &mut state.node_graph, &swatch);
    actions
}

/// Draws the Quality strip (under the image, so that convergence and cost
/// stay in view while the side panel scrolls) and returns the buttons
/// pressed.
pub fn draw_quality(ui: &mut Ui, state: &mut PanelState, stats: &Stats) -> Vec<PanelAction> {
    let mut actions = Vec::new();
    quality::quality_ui(ui, &mut state.quality, &stats.quality, &mut actions);
    actions
}

#[cfg(test)]
mod tests {
    use super::*;
    use environment_ui::cube_source_from;
    use marbre_core::noise::NoiseSettings;
    use marbre_core::scene::{Environment, PointLight};
    use marbre_core::scene::{Ground, Sphere};
    use marbre_core::scene::{Pattern, Texture};
    use material_editor::material_ui;
    use std::path::Path;

    fn marble_scene() -> Scene {
        let mut sphere = Sphere::default();
        sphere.material.diffuse = Texture::blend(
            Pattern::Marble {
                noise: NoiseSettings::default(),
                stripe_frequency: 4.0,
            },
            Vec3::new(0.9, 0.88, 0.85),
            Vec3::new(0.2, 0.25, 0.3),
        );
        Scene {
            spheres: vec![sphere],
            ground: Some(Ground::default()),
            ..Scene::default()
        }
    }

    /// Runs one headless egui frame around `f`.
    fn frame(mut f: impl FnMut(&mut Ui)) {
        let ctx = egui::Context::default();
        ctx.run_ui(egui::RawInput::default(), |ui| {
            egui::CentralPanel::default().show(ui, &mut f);
        })
        .drop_without_applying_deltas();
    }

    /// Two headless frames on one context: in the first, `f` puts the
    /// keyboard in a field (through the panel's focus request); in the
    /// second, Enter is pressed there.
    fn focus_then_press_enter(mut f: impl FnMut(&mut Ui)) {
        let ctx = egui::Context::default();
        let enter = egui::Event::Key {
            key: egui::Key::Enter,
            physical_key: None,
            pressed: true,
            repeat: false,
            modifiers: egui::Modifiers::NONE,
        };
        for events in [vec![], vec![enter]] {
            let input = egui::RawInput {
                events,
                ..Default::default()
            };
            ctx.run_ui(input, |ui| {
                egui::CentralPanel::default().show(ui, &mut f);
            })
            .drop_without_applying_deltas();
        }
    }

    #[test]
    fn enter_in_the_environment_path_loads_the_map() {
        let mut env = Environment {
            source: EnvSource::LatLong {
                path: "old.exr".into(),
            },
            ..Environment::default()
        };
        let mut state = PanelState::new(String::new(), "old/../maps/./sky.exr ".into());
        state.focus_env_path = true;
        let mut actions = Vec::new();
        focus_then_press_enter(|ui| environment_ui(ui, &mut env, &mut state, &mut actions));
        assert_eq!(
            actions,
            [PanelAction::LoadEnvironment("maps/sky.exr".into())]
        );
    }

    #[test]
    fn enter_in_a_cube_path_field_loads_the_cube() {
        let faces = ["px.exr", "nx.exr", "py.exr", "ny.exr", "pz.exr", "nz.exr"];
        for is_faces in [true, false] {
            let mut env = Environment::default();
            let mut state = PanelState::new(String::new(), String::new());
            state.cube_faces = faces.map(String::from);
            state.cube_cross = "cross.exr".into();
            // As after picking the cube entry in the source dropdown.
            state.cube_pending = Some(is_faces);
            state.focus_env_path = true;
            let mut actions = Vec::new();
            focus_then_press_enter(|ui| environment_ui(ui, &mut env, &mut state, &mut actions));
            let expected = if is_faces {
                EnvSource::CubeFaces {
                    faces: faces.map(PathBuf::from),
                }
            } else {
                EnvSource::CubeCross {
                    path: "cross.exr".into(),
                }
            };
            assert_eq!(env.source, expected);
        }
    }

    /// Enter with a face path missing loads nothing: half a cube is not a
    /// source.
    #[test]
    fn enter_in_an_incomplete_cube_loads_nothing() {
        let mut env = Environment::default();
        let before = env.clone();
        let mut state = PanelState::new(String::new(), String::new());
        state.cube_faces = ["px.exr", "nx.exr", "py.exr", "", "pz.exr", "nz.exr"].map(String::from);
        state.cube_pending = Some(true);
        state.focus_env_path = true;
        let mut actions = Vec::new();
        focus_then_press_enter(|ui| environment_ui(ui, &mut env, &mut state, &mut actions));
        assert_eq!(env, before);
    }

    #[test]
    fn enter_in_the_preset_path_loads_the_preset() {
        let mut state = PanelState::new("presets/a.ron".into(), String::new());
        state.focus_preset_path = true;
        let mut actions = Vec::new();
        focus_then_press_enter(|ui| file_ui::preset_ui(ui, &mut state, &mut actions));
        assert_eq!(actions, [PanelAction::LoadPreset("presets/a.ron".into())]);
    }

    #[test]
    fn drawing_without_input_changes_nothing() {
        let mut scene = marble_scene();
        let before = scene.clone();
        let mut state = PanelState::new("presets/a.ron".into(), String::new());
        state.error("something failed");
        let mut actions = Vec::new();
        frame(|ui| {
            actions = draw(
                ui,
                &mut scene,
                &mut state,
                &Stats::default(),
                &mut timeline::Timeline::default(),
            )
        });
        assert_eq!(scene, before);
        assert!(actions.is_empty(), "{actions:?}");
    }

    /// With the viewer's swatch book in place and a swatch delivered for
    /// every node that asked, drawing the material editor shows them and
    /// still changes nothing.
    #[test]
    fn drawing_with_swatches_changes_nothing() {
        let mut scene = marble_scene();
        let before = scene.clone();
        let ctx = egui::Context::default();
        let book = swatches::SharedSwatchBook::default();
        swatches::install(&ctx, book.clone());
        let draw_once = |scene: &mut Scene| {
            ctx.run_ui(egui::RawInput::default(), |ui| {
                egui::CentralPanel::default().show(ui, |ui| {
                    material_ui(ui, MaterialKey::Sphere(0), &mut scene.spheres[0].material)
                });
            })
            .drop_without_applying_deltas();
        };
        draw_once(&mut scene);
        book.lock()
            .unwrap()
            .observe(&scene, marbre_core::scene::Change::empty());
        let asked = book.lock().unwrap().take_requests(64);
        assert!(
            !asked.is_empty(),
            "the open marble node asks for its swatch"
        );
        for request in &asked {
            let image = ctx.load_texture("s", egui::ColorImage::example(), Default::default());
            book.lock().unwrap().deliver(&request.place, image);
        }
        draw_once(&mut scene);
        book.lock()
            .unwrap()
            .observe(&scene, marbre_core::scene::Change::empty());
        assert_eq!(book.lock().unwrap().shown(), asked.len());
        assert!(book.lock().unwrap().take_requests(64).is_empty());
        assert_eq!(scene, before);
    }

    /// `draw` leaves some sections closed; their bodies must not edit the
    /// scene either, whatever the source, pattern or light.
    #[test]
    fn closed_sections_change_nothing_either() {
        let mut scene = marble_scene();
        scene.point_light = Some(PointLight::default());
        scene.ground.as_mut().unwrap().material.roughness.pattern = Pattern::Checker { size: 0.5 };
        let mut state = PanelState::new(String::new(), "sky.exr".into());
        for source in [
            EnvSource::Constant {
                radiance: Vec3::new(0.3, 0.7, 2.0),
            },
            EnvSource::LatLong {
                path: "sky.exr".into(),
            },
            EnvSource::CubeFaces {
                faces: ["px.exr", "nx.exr", "py.exr", "ny.exr", "pz.exr", "nz.exr"]
                    .map(PathBuf::from),
            },
            EnvSource::CubeCross {
                path: "cross.exr".into(),
            },
        ] {
            scene.environment.source = source;
            let before = scene.clone();
            let mut actions = Vec::new();
            frame(|ui| {
                for (i, s) in scene.spheres.iter_mut().enumerate() {
                    material_ui(ui, MaterialKey::Sphere(i), &mut s.material);
                }
                material_ui(
                    ui,
                    MaterialKey::Ground,
                    &mut scene.ground.as_mut().unwrap().material,
                );
                environment_ui(ui, &mut scene.environment, &mut state, &mut actions);
                point_light_ui(ui, &mut scene.point_light);
                camera_ui(ui, &mut scene, &mut actions);
            });
            assert_eq!(scene, before);
            assert!(actions.is_empty(), "{actions:?}");
        }
    }

    /// The cube path fields take the scene's cube paths (a preset loaded),
    /// and a cube entry picked before its paths are typed shows its fields
    /// without touching the scene.
    #[test]
    fn cube_fields_follow_the_scene_and_a_pending_cube_leaves_it_alone() {
        let mut env = Environment {
            source: EnvSource::CubeCross {
                path: "maps/cross.exr".into(),
            },
            ..Environment::default()
        };
        let mut state = PanelState::new(String::new(), String::new());
        let mut actions = Vec::new();
        frame(|ui| environment_ui(ui, &mut env, &mut state, &mut actions));
        assert_eq!(state.cube_cross, "maps/cross.exr");

        env.source = EnvSource::LatLong {
            path: "sky.exr".into(),
        };
        let before = env.clone();
        state.cube_pending = Some(true);
        frame(|ui| environment_ui(ui, &mut env, &mut state, &mut actions));
        assert_eq!(env, before);
        assert_eq!(state.cube_pending, Some(true));
        assert!(actions.is_empty(), "{actions:?}");
        // Once the scene holds a six-face cube, nothing is pending.
        env.source = cube_source_from(&state, true);
        frame(|ui| environment_ui(ui, &mut env, &mut state, &mut actions));
        assert_eq!(state.cube_pending, None);
    }

    /// The Quality strip, with an estimate, pass times and feature costs
    /// to show, is drawn without changing the controls or pressing a button.
    #[test]
    fn drawing_the_quality_strip_without_input_changes_nothing() {
        let mut state = PanelState::new(String::new(), String::new());
        state.quality.stop_at_target = true;
        let before = state.quality.clone();
        let stats = Stats {
            quality: QualityStats {
                points: vec![[0.5, 0.1], [2.0, 0.05]],
                latest: Some(marbre_render::gpu::error_meter::ErrorEstimate {
                    rmse: 0.01,
                    relative: 0.05,
                    frames: 40,
                    samples: 40,
                    seconds: 2.0,
                    generation: 0,
                }),
                passes: vec![("trace", Some(3.5)), ("display", None)],
                scene_features: vec![marbre_render::gpu::Feature::Pattern(
                    marbre_core::scene::PatternKind::Cutout,
                )],
                with_all_ms: Some(3.5),
                without_ms: vec![Some(3.1)],
                ..QualityStats::default()
            },
            ..Stats::default()
        };
        let mut actions = Vec::new();
        frame(|ui| actions = draw_quality(ui, &mut state, &stats));
        assert_eq!(state.quality, before);
        assert!(actions.is_empty(), "{actions:?}");
    }

    #[test]
    fn a_failed_load_puts_the_path_field_back_on_the_document() {
        let mut state = PanelState::new("presets/a.ron".into(), String::new());
        state.preset_path = "presets/typo.ron".into();
        state.load_failed("presets/typo.ron: no such file", Path::new("presets/a.ron"));
        assert_eq!(state.preset_path, "presets/a.ron");
        let last = state.messages.last().unwrap();
        assert!(last.is_error && last.text.contains("typo.ron"), "{last:?}");
    }

    /// Each message has its local time, `HH:MM:SS`.
    #[test]
    fn messages_are_time_stamped() {
        let mut state = PanelState::new(String::new(), String::new());
        let before = chrono::Local::now().time();
        state.info("loaded");
        let after = chrono::Local::now().time();
        let time = &state.messages[0].time;
        let parsed = chrono::NaiveTime::parse_from_str(time, "%H:%M:%S")
            .unwrap_or_else(|e| panic!("{time}: {e}"));
        let second = |t: chrono::NaiveTime| t.format("%H:%M:%S").to_string();
        assert!(
            second(before) <= second(parsed) && second(parsed) <= second(after),
            "{time} between {before} and {after}"
        );
    }

    /// The frame rate is on the panel's first line, the Preset section's
    /// header, not at the bottom of a long scroll.
    #[test]
    fn the_frame_rate_heads_the_panel() {
        let mut scene = marble_scene();
        let mut state = PanelState::new(String::new(), String::new());
        let stats = Stats {
            fps: 42.5,
            samples: 7,
            ..Stats::default()
        };
        let ctx = egui::Context::default();
        let output = ctx.run_ui(egui::RawInput::default(), |ui| {
            egui::CentralPanel::default().show(ui, |ui| {
                draw(
                    ui,
                    &mut scene,
                    &mut state,
                    &stats,
                    &mut timeline::Timeline::default(),
                );
            });
        });
        let texts: Vec<(f32, String)> = output
            .shapes
            .iter()
            .filter_map(|clipped| match &clipped.shape {
                egui::Shape::Text(text) => Some((text.pos.y, text.galley.text().to_owned())),
                _ => None,
            })
            .collect();
        output.drop_without_applying_deltas();
        let top = texts
            .iter()
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .expect("some text");
        assert!(
            top.1.starts_with("Preset") && top.1.contains("42.5 fps · 7 spp"),
            "the first line is {top:?}"
        );
    }

    /// On the octave slider, in a panel as wide as the viewer's, a press
    /// sets the value under the pointer and a 20-px drag from there moves
    /// it by less than two octaves, landing on quarters.
    #[test]
    fn the_octave_slider_moves_in_quarters_at_a_usable_rate() {
        let ctx = egui::Context::default();
        let screen = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(380.0, 300.0));
        let run = |events: Vec<egui::Event>, octaves: &mut f32| {
            let mut rail = egui::Rect::NOTHING;
            let input = egui::RawInput {
                screen_rect: Some(screen),
                events,
                ..Default::default()
            };
            ctx.run_ui(input, |ui| {
                egui::CentralPanel::default().show(ui, |ui| {
                    rail = material_editor::octaves_slider(ui, octaves).rect;
                });
            })
            .drop_without_applying_deltas();
            rail
        };
        let button = |pos, pressed| egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        };
        let mut octaves = 4.0_f32;
        let rail = run(vec![], &mut octaves);
        let start = egui::pos2(rail.left() + 0.25 * rail.width(), rail.center().y);
        let end = start + egui::vec2(20.0, 0.0);
        run(
            vec![egui::Event::PointerMoved(start), button(start, true)],
            &mut octaves,
        );
        let pressed = octaves;
        for events in [
            vec![egui::Event::PointerMoved(start + egui::vec2(10.0, 0.0))],
            vec![egui::Event::PointerMoved(end)],
            vec![button(end, false)],
        ] {
            run(events, &mut octaves);
        }
        let quarter = |v: f32| v * 4.0 == (v * 4.0).round();
        assert!(quarter(pressed) && quarter(octaves), "{pressed}, {octaves}");
        assert!(
            octaves > pressed && octaves - pressed < 2.0,
            "20 px moved the octaves from {pressed} to {octaves}"
        );
    }

    /// Stats with an estimate and a converging history to plot.
    fn converging_stats() -> Stats {
        Stats {
            quality: QualityStats {
                points: (1..40)
                    .map(|i| [0.1 * f64::from(i), 0.2 / f64::from(i).sqrt()])
                    .collect(),
                latest: Some(marbre_render::gpu::error_meter::ErrorEstimate {
                    rmse: 0.01,
                    relative: 0.032,
                    frames: 39,
                    samples: 39,
                    seconds: 3.9,
                    generation: 0,
                }),
                ..QualityStats::default()
            },
            ..Stats::default()
        }
    }

    /// The Quality strip's texts (top-left corner, text) and the points of
    /// the plot's curves, over `frames` frames of `events` each.
    fn quality_frame(
        ctx: &egui::Context,
        state: &mut PanelState,
        stats: &Stats,
        events: Vec<egui::Event>,
    ) -> (Vec<(egui::Rect, String)>, Vec<egui::Pos2>) {
        let input = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(
                egui::Pos2::ZERO,
                egui::vec2(900.0, 200.0),
            )),
            events,
            ..Default::default()
        };
        let output = ctx.run_ui(input, |ui| {
            egui::CentralPanel::default().show(ui, |ui| {
                draw_quality(ui, state, stats);
            });
        });
        let mut texts = Vec::new();
        let mut curve = Vec::new();
        for clipped in &output.shapes {
            match &clipped.shape {
                egui::Shape::Text(text) => {
                    texts.push((text.visual_bounding_rect(), text.galley.text().to_owned()));
                }
                // More than a fold arrow's three points: a plotted line.
                egui::Shape::Path(path) if path.points.len() > 3 => {
                    curve.extend(&path.points);
                }
                _ => {}
            }
        }
        output.drop_without_applying_deltas();
        (texts, curve)
    }

    /// The plot's key is drawn above the plot, off every curve.
    #[test]
    fn the_plot_key_sits_outside_the_plot() {
        let ctx = egui::Context::default();
        let mut state = PanelState::new(String::new(), String::new());
        let stats = converging_stats();
        quality_frame(&ctx, &mut state, &stats, vec![]);
        let (texts, curve) = quality_frame(&ctx, &mut state, &stats, vec![]);
        assert!(curve.len() > 10, "no curve drawn");
        let highest = curve.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
        for name in ["estimate", "1/√t", "target"] {
            let (rect, _) = texts
                .iter()
                .find(|(_, t)| t.ends_with(name))
                .unwrap_or_else(|| panic!("no key for {name}: {texts:?}"));
            assert!(
                rect.bottom() <= highest,
                "the key {name} at {rect:?} is over the curve (top {highest})"
            );
        }
    }

    /// A click on the strip's header folds it to that line (no plot, the
    /// estimate still said); another unfolds it.
    #[test]
    fn the_quality_strip_folds_from_its_header() {
        let ctx = egui::Context::default();
        let mut state = PanelState::new(String::new(), String::new());
        let stats = converging_stats();
        let click = |ctx: &egui::Context, state: &mut PanelState| {
            let (texts, _) = quality_frame(ctx, state, &stats, vec![]);
            let (rect, _) = texts
                .iter()
                .find(|(_, t)| t.ends_with("Quality"))
                .expect("a Quality header")
                .clone();
            let at = rect.center();
            let button = |pressed| egui::Event::PointerButton {
                pos: at,
                button: egui::PointerButton::Primary,
                pressed,
                modifiers: egui::Modifiers::NONE,
            };
            quality_frame(
                ctx,
                state,
                &stats,
                vec![egui::Event::PointerMoved(at), button(true)],
            );
            quality_frame(ctx, state, &stats, vec![button(false)]);
        };
        let has = |texts: &[(egui::Rect, String)], what: &str| {
            texts.iter().any(|(_, t)| t.contains(what))
        };
        assert!(!state.quality.folded);
        click(&ctx, &mut state);
        assert!(state.quality.folded, "the click did not fold the strip");
        let (texts, curve) = quality_frame(&ctx, &mut state, &stats, vec![]);
        assert!(curve.is_empty() && !has(&texts, "GPU time"), "{texts:?}");
        assert!(has(&texts, "estimated error 3.20 %"), "{texts:?}");
        click(&ctx, &mut state);
        assert!(!state.quality.folded);
        let (texts, _) = quality_frame(&ctx, &mut state, &stats, vec![]);
        assert!(has(&texts, "seconds (log)"), "{texts:?}");
    }

    #[test]
    fn messages_are_capped() {
        let mut state = PanelState::new(String::new(), String::new());
        for i in 0..KEPT_MESSAGES + 7 {
            state.info(format!("{i}"));
        }
        assert_eq!(state.messages.len(), KEPT_MESSAGES);
        assert_eq!(
            state.messages.last().unwrap().text,
            format!("{}", KEPT_MESSAGES + 6)
        );
    }
}
