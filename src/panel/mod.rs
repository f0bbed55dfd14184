//! The side panel: egui controls that edit a [`Scene`] in place.
//!
//! The panel knows nothing about the GPU. It mutates the scene and reports the
//! buttons pressed; the app compares the scene before and after the frame to
//! decide what to rebuild (shader features, buffers, accumulation). For that
//! comparison to be meaningful, no widget here may write to the scene unless
//! the user touched it, which is why sliders do not clamp existing values and
//! colours are written back only on a change.

mod file_ui;
pub mod help;
mod material_editor;
mod quality;
mod transport;

use egui::emath::Numeric;
use egui::{
    CollapsingHeader, Color32, ComboBox, DragValue, Response, ScrollArea, Slider, SliderClamping,
    TextEdit, Ui,
};
use glam::Vec3;
use marbre_core::scene::{
    EnvSource, Environment, OrbitCamera, PointLight, RenderSettings, Scene, ToneMap,
};
use marbre_render::gpu::NonFiniteCounts;
use material_editor::material_ui;
pub use quality::{QualityControls, QualityStats};
use std::ops::RangeInclusive;
use std::path::PathBuf;

/// How many of the latest messages the Preset section shows.
const SHOWN_MESSAGES: usize = 5;
/// How many messages are kept, so that a long session does not grow the list
/// without bound.
const KEPT_MESSAGES: usize = 100;

/// The environment sources in the order of the source dropdown.
const ENV_SOURCE_NAMES: [&str; 5] = [
    "none",
    "constant",
    "lat-long map",
    "cube (6 faces)",
    "cube (cross)",
];

/// A line of feedback for the user (a preset loaded, a file that failed).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Message {
    pub text: String,
    pub is_error: bool,
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
    /// Recently opened presets and environment maps, newest first.
    pub recent_files: Vec<PathBuf>,
    /// Set to put the keyboard in the preset or environment path field
    /// (where no file dialog can open); cleared once done.
    pub focus_preset_path: bool,
    pub focus_env_path: bool,
    /// A preset loading in the background: what it is doing, and the
    /// fraction done.
    pub progress: Option<(String, f32)>,
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
            recent_files: Vec::new(),
            focus_preset_path: false,
            focus_env_path: false,
            progress: None,
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

    fn push(&mut self, text: String, is_error: bool) {
        self.messages.push(Message { text, is_error });
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
}

/// A button press the app must act on: these need files, the GPU or the
/// window, which the panel has no access to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PanelAction {
    LoadPreset(PathBuf),
    /// Save to the preset file the scene came from.
    SavePreset,
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
}

/// Draws the whole panel contents into `ui` and returns the buttons pressed.
pub fn draw(
    ui: &mut Ui,
    scene: &mut Scene,
    state: &mut PanelState,
    stats: &Stats,
) -> Vec<PanelAction> {
    let mut actions = Vec::new();
    ScrollArea::vertical()
        .id_salt("panel scroll")
        .show(ui, |ui| {
            section(ui, "Preset", true, |ui| {
                file_ui::preset_ui(ui, state, &mut actions);
            });
            section(ui, "Materials", true, |ui| materials_ui(ui, scene));
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
            });

            section(ui, "Stats", true, |ui| stats_ui(ui, stats));
        });
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

/// A top-level collapsible section, its open state keyed by its title.
fn section(ui: &mut Ui, title: &str, default_open: bool, body: impl FnOnce(&mut Ui)) {
    CollapsingHeader::new(title)
        .id_salt(("section", title))
        .default_open(default_open)
        .show(ui, body);
}

/// A slider that clamps what the user enters but leaves a value already out
/// of range (from a hand-written preset) alone: egui's default clamps and
/// rounds the value every frame, which would edit the scene by itself.
fn slider<'a, Num: Numeric>(
    value: &'a mut Num,
    range: RangeInclusive<Num>,
    text: &str,
) -> Slider<'a> {
    Slider::new(value, range)
        .clamping(SliderClamping::Edits)
        .text(text)
}

/// Edits a linear RGB colour, writing it back only when the user changed it:
/// egui goes through HSVA, whose round trip is not bit-exact, and a spurious
/// change would restart the accumulation every frame.
fn color_button(ui: &mut Ui, color: &mut Vec3) -> Response {
    let mut rgb = color.to_array();
    let response = ui.color_edit_button_rgb(&mut rgb);
    if response.changed() {
        *color = Vec3::from_array(rgb);
    }
    response
}

/// A colour button followed by its label, on one line.
fn labelled_color(ui: &mut Ui, color: &mut Vec3, label: &str) -> Response {
    ui.horizontal(|ui| {
        let response = color_button(ui, color);
        ui.label(label);
        response
    })
    .inner
}

/// Three drag values for a point or direction, each with the same tooltip.
fn vec3_ui(ui: &mut Ui, label: &str, v: &mut Vec3, speed: f32, hint: &str) {
    ui.horizontal(|ui| {
        for (prefix, c) in [("x ", &mut v.x), ("y ", &mut v.y), ("z ", &mut v.z)] {
            ui.add(DragValue::new(c).speed(speed).prefix(prefix))
                .on_hover_text(hint);
        }
        ui.label(label);
    });
}

/// One collapsible block per object (spheres, cylinders, polygons), then
/// the ground. Only the first is open at start, so a scene with many
/// objects still fits on screen.
fn materials_ui(ui: &mut Ui, scene: &mut Scene) {
    let mut first = true;
    let mut object =
        |ui: &mut Ui, key: (&str, usize), title: String, body: &mut dyn FnMut(&mut Ui)| {
            // Keyed by index: names come from the preset and need not be unique.
            ui.push_id(key, |ui| {
                CollapsingHeader::new(title)
                    .id_salt("object")
                    .default_open(std::mem::take(&mut first))
                    .show(ui, |ui| body(ui));
            });
        };
    for (i, sphere) in scene.spheres.iter_mut().enumerate() {
        object(
            ui,
            ("sphere", i),
            format!("sphere “{}”", sphere.name),
            &mut |ui| material_ui(ui, &mut sphere.material),
        );
    }
    for (i, cylinder) in scene.cylinders.iter_mut().enumerate() {
        object(
            ui,
            ("cylinder", i),
            format!("cylinder “{}”", cylinder.name),
            &mut |ui| {
                vec3_ui(
                    ui,
                    "base",
                    &mut cylinder.base,
                    0.01,
                    "Centre of the bottom cap",
                );
                ui.add(slider(&mut cylinder.radius, 0.01..=10.0, "radius").logarithmic(true))
                    .on_hover_text("Radius of the side and caps, in scene units");
                ui.add(slider(&mut cylinder.height, 0.01..=10.0, "height").logarithmic(true))
                    .on_hover_text(
                        "Along +y; the side's v runs from 0 at the base to 1 at the top",
                    );
                material_ui(ui, &mut cylinder.material);
            },
        );
    }
    for (i, polygon) in scene.polygons.iter_mut().enumerate() {
        object(
            ui,
            ("polygon", i),
            format!("polygon “{}”", polygon.name),
            &mut |ui| material_ui(ui, &mut polygon.material),
        );
    }
    if let Some(ground) = &mut scene.ground {
        object(ui, ("ground", 0), "ground".into(), &mut |ui| {
            material_ui(ui, &mut ground.material)
        });
    }
    for (i, mesh) in scene.meshes.iter_mut().enumerate() {
        object(
            ui,
            ("mesh", i),
            format!("mesh “{}”", mesh.name),
            &mut |ui| mesh_ui(ui, mesh),
        );
    }
}

/// A mesh's placement and each of its MTL materials, editable like any
/// other (a Cornell box wall can be marble); "reset" goes back to the file.
fn mesh_ui(ui: &mut Ui, mesh: &mut marbre_core::scene::Mesh) {
    ui.label(format!(
        "{} triangles from {}",
        mesh.geometry.0.len(),
        mesh.obj.display()
    ));
    let p = &mut mesh.placement;
    vec3_ui(ui, "translate", &mut p.translate, 0.01, "Moves the mesh");
    ui.add(slider(&mut p.rotate_y_degrees, -180.0..=180.0, "turn").suffix("°"))
        .on_hover_text("Turns the mesh about the vertical axis (rebuilds the BVH)");
    ui.add(slider(&mut p.scale, 0.01..=100.0, "scale").logarithmic(true))
        .on_hover_text("Scales the mesh about its file's origin (rebuilds the BVH)");
    for (k, m) in mesh.materials.iter_mut().enumerate() {
        ui.push_id(("mesh material", k), |ui| {
            CollapsingHeader::new(format!("material “{}”", m.name))
                .id_salt("mesh material")
                .show(ui, |ui| {
                    if let Some(original) = &m.from_file
                        && m.material != *original
                        && ui
                            .small_button("reset to the MTL file")
                            .on_hover_text("Forget the edits: the file's values come back")
                            .clicked()
                    {
                        m.material = original.clone();
                    }
                    material_ui(ui, &mut m.material);
                });
        });
    }
}

fn environment_ui(
    ui: &mut Ui,
    env: &mut Environment,
    state: &mut PanelState,
    actions: &mut Vec<PanelAction>,
) {
    env_source_ui(ui, &mut env.source, state);
    if let Some(faces) = state.cube_pending {
        cube_source_ui(ui, &mut env.source, state, faces);
    } else {
        source_fields_ui(ui, &mut env.source, state, actions);
    }
    ui.add(slider(&mut env.rotation_degrees, -180.0..=180.0, "rotation").suffix("°"))
        .on_hover_text("Turns the environment about the vertical axis");
    ui.add(slider(&mut env.intensity, 0.01..=100.0, "intensity").logarithmic(true))
        .on_hover_text("Multiplies the environment's radiance");
    ui.checkbox(&mut env.background_visible, "background visible")
        .on_hover_text("Show the environment behind the scene; it lights the scene either way");
}

/// The controls of the scene's current source.
fn source_fields_ui(
    ui: &mut Ui,
    source: &mut EnvSource,
    state: &mut PanelState,
    actions: &mut Vec<PanelAction>,
) {
    match source {
        EnvSource::None => {}
        EnvSource::Constant { radiance } => {
            labelled_color(ui, radiance, "colour").on_hover_text(
                "Radiance arriving from every direction, times the intensity below \
                 (white at intensity 1 is the white-furnace test)",
            );
        }
        EnvSource::LatLong { path } => {
            ui.label(format!("current: {}", path.display()))
                .on_hover_text("The map the scene uses; relative to the preset file");
            ui.horizontal(|ui| {
                let field = ui
                    .add(TextEdit::singleline(&mut state.env_path).hint_text("map.exr"))
                    .on_hover_text("Latitude-longitude image: .exr, .hdr, .png or .jpg");
                if std::mem::take(&mut state.focus_env_path) {
                    field.request_focus();
                }
                if ui
                    .add_enabled(!state.env_path.trim().is_empty(), egui::Button::new("Load"))
                    .on_hover_text("Load the map at this path")
                    .on_disabled_hover_text("Type a path first")
                    .clicked()
                {
                    actions.push(PanelAction::LoadEnvironment(PathBuf::from(
                        state.env_path.trim(),
                    )));
                }
            });
            ui.horizontal(|ui| {
                if ui
                    .button("Open…")
                    .on_hover_text("Pick a lat-long map in a file dialog")
                    .clicked()
                {
                    actions.push(PanelAction::BrowseEnvironment);
                }
                ui.weak("or drop a file on the window");
            });
        }
        EnvSource::CubeFaces { .. } => cube_source_ui(ui, source, state, true),
        EnvSource::CubeCross { .. } => cube_source_ui(ui, source, state, false),
    }
}

/// The path fields of a cube map (six faces, or a cross) and a Load button
/// that puts them in the scene: typing alone does not load half a path.
fn cube_source_ui(ui: &mut Ui, source: &mut EnvSource, state: &mut PanelState, is_faces: bool) {
    let is_cube = matches!(
        source,
        EnvSource::CubeFaces { .. } | EnvSource::CubeCross { .. }
    );
    if is_cube && state.cube_seen.as_ref() != Some(source) {
        match source {
            EnvSource::CubeFaces { faces } => {
                state.cube_faces = faces.each_ref().map(|p| p.display().to_string());
            }
            EnvSource::CubeCross { path } => state.cube_cross = path.display().to_string(),
            _ => {}
        }
        state.cube_seen = Some(source.clone());
    }
    if is_cube {
        for path in source.paths() {
            ui.label(format!("current: {}", path.display()))
                .on_hover_text("A file the scene uses; relative to the preset file");
        }
    }
    let ready = if is_faces {
        let names = ["+x", "-x", "+y", "-y", "+z", "-z"];
        let hints = ["px.exr", "nx.exr", "py.exr", "ny.exr", "pz.exr", "nz.exr"];
        for ((name, hint), path) in names.iter().zip(hints).zip(&mut state.cube_faces) {
            ui.horizontal(|ui| {
                ui.label(*name);
                ui.add(TextEdit::singleline(path).hint_text(hint))
                    .on_hover_text(
                        "A square face (.exr, .hdr, .png or .jpg), OpenGL orientation; \
                         all six the same size",
                    );
            });
        }
        state.cube_faces.iter().all(|p| !p.trim().is_empty())
    } else {
        ui.add(TextEdit::singleline(&mut state.cube_cross).hint_text("cross.exr"))
            .on_hover_text(
                "One image of 4x3 square faces: +y above +z; -x, +z, +x, -z across; -y below",
            );
        !state.cube_cross.trim().is_empty()
    };
    if ui
        .add_enabled(ready, egui::Button::new("Load"))
        .on_hover_text("Load the cube map at these paths (resampled to lat-long)")
        .on_disabled_hover_text(if is_faces {
            "Type all six face paths first"
        } else {
            "Type the cross image's path first"
        })
        .clicked()
    {
        *source = cube_source_from(state, is_faces);
    }
}

/// A cube source with the paths typed in the panel.
fn cube_source_from(state: &PanelState, faces: bool) -> EnvSource {
    if faces {
        EnvSource::CubeFaces {
            faces: state.cube_faces.each_ref().map(|p| PathBuf::from(p.trim())),
        }
    } else {
        EnvSource::CubeCross {
            path: PathBuf::from(state.cube_cross.trim()),
        }
    }
}

/// The source dropdown. Switching to constant restores the last colour;
/// switching to a map takes the path typed below, which the app then loads.
fn env_source_ui(ui: &mut Ui, source: &mut EnvSource, state: &mut PanelState) {
    let current = match source {
        EnvSource::None => 0,
        EnvSource::Constant { radiance } => {
            state.last_radiance = *radiance;
            1
        }
        EnvSource::LatLong { .. } => 2,
        EnvSource::CubeFaces { .. } => 3,
        EnvSource::CubeCross { .. } => 4,
    };
    // A cube entry waiting for its paths shows as picked.
    let shown = match state.cube_pending {
        Some(faces) if current == if faces { 3 } else { 4 } => {
            state.cube_pending = None;
            current
        }
        Some(true) => 3,
        Some(false) => 4,
        None => current,
    };
    let mut index = shown;
    ComboBox::new("env source", "source")
        .show_index(ui, &mut index, ENV_SOURCE_NAMES.len(), |i| {
            ENV_SOURCE_NAMES[i]
        })
        .on_hover_text("What rays that leave the scene see");
    if index == shown {
        return;
    }
    state.cube_pending = None;
    if index == current {
        return;
    }
    let cube_typed = |faces: bool| {
        if faces {
            state.cube_faces.iter().all(|p| !p.trim().is_empty())
        } else {
            !state.cube_cross.trim().is_empty()
        }
    };
    if (index == 3 || index == 4) && !cube_typed(index == 3) {
        // Nothing to load yet: show the fields, keep the scene's source.
        state.cube_pending = Some(index == 3);
        return;
    }
    *source = match index {
        1 => EnvSource::Constant {
            radiance: state.last_radiance,
        },
        2 => EnvSource::LatLong {
            path: PathBuf::from(state.env_path.trim()),
        },
        3 => cube_source_from(state, true),
        4 => cube_source_from(state, false),
        _ => EnvSource::None,
    };
}

fn point_light_ui(ui: &mut Ui, light: &mut Option<PointLight>) {
    let mut enabled = light.is_some();
    if ui
        .checkbox(&mut enabled, "enabled")
        .on_hover_text("An isotropic point light, besides the environment")
        .changed()
    {
        *light = enabled.then(PointLight::default);
    }
    if let Some(l) = light {
        vec3_ui(
            ui,
            "position",
            &mut l.position,
            0.05,
            "Where the light is, in scene units",
        );
        labelled_color(ui, &mut l.color, "colour").on_hover_text("The light's colour");
        ui.add(
            slider(&mut l.intensity, 0.0..=10_000.0, "intensity")
                .logarithmic(true)
                .smallest_positive(0.1),
        )
        .on_hover_text("Radiant intensity in watts per steradian (times the colour)");
    }
}

fn camera_ui(ui: &mut Ui, scene: &mut Scene, actions: &mut Vec<PanelAction>) {
    let camera = &mut scene.camera;
    vec3_ui(
        ui,
        "target",
        &mut camera.target,
        0.05,
        "The point the camera orbits and looks at",
    );
    ui.add(
        slider(
            &mut camera.distance,
            OrbitCamera::MIN_DISTANCE..=1000.0,
            "distance",
        )
        .logarithmic(true),
    )
    .on_hover_text("Distance from the target");
    ui.add(slider(&mut camera.yaw_degrees, 0.0..=360.0, "yaw").suffix("°"))
        .on_hover_text("Rotation about the vertical axis");
    ui.add(slider(&mut camera.pitch_degrees, -89.0..=89.0, "pitch").suffix("°"))
        .on_hover_text("Elevation above the horizontal");
    ui.add(slider(&mut camera.fov_degrees, 10.0..=120.0, "field of view").suffix("°"))
        .on_hover_text("Vertical field of view");
    if ui
        .button("Reset")
        .on_hover_text("Back to the preset's camera")
        .clicked()
    {
        actions.push(PanelAction::ResetCamera);
    }
    ui.weak("left drag: orbit · right/middle drag: pan · wheel: zoom");
    views_ui(ui, scene);
}

/// The preset's saved views: recall (or keys 1–9), rename, delete, and
/// save the current camera as a new one.
fn views_ui(ui: &mut Ui, scene: &mut Scene) {
    let mut recall = None;
    let mut remove = None;
    for (i, view) in scene.views.iter_mut().enumerate() {
        ui.push_id(("view", i), |ui| {
            ui.horizontal(|ui| {
                let key = if i < 9 {
                    format!("{}", i + 1)
                } else {
                    "·".to_owned()
                };
                if ui
                    .button(key)
                    .on_hover_text("Go to this view (the number key does it too)")
                    .clicked()
                {
                    recall = Some(i);
                }
                ui.text_edit_singleline(&mut view.name)
                    .on_hover_text("The view's name, saved with the preset");
                if ui
                    .small_button("✕")
                    .on_hover_text("Delete this view")
                    .clicked()
                {
                    remove = Some(i);
                }
            });
        });
    }
    if let Some(i) = recall {
        scene.recall_view(i);
    }
    if let Some(i) = remove {
        scene.views.remove(i);
    }
    if ui
        .button("Save view")
        .on_hover_text("Keep the current camera in the preset; keys 1–9 recall the first nine")
        .clicked()
    {
        scene.save_view();
    }
}

fn render_ui(ui: &mut Ui, render: &mut RenderSettings, actions: &mut Vec<PanelAction>) {
    ui.add(slider(
        &mut render.samples_per_frame,
        1..=RenderSettings::MAX_SAMPLES_PER_FRAME,
        "samples per frame",
    ))
    .on_hover_text("Jittered samples per pixel each frame: smoother, slower frames");
    ui.checkbox(&mut render.accumulate, "accumulate")
        .on_hover_text("Average frames while nothing changes; off shows each frame alone");
    ui.checkbox(&mut render.auto_exposure, "auto exposure")
        .on_hover_text(
            "Meter the image every frame and expose its log-average luminance to middle grey \
             (Reinhard's key, 0.18); off, the exposure slider alone sets it",
        );
    let (label, hint) = if render.auto_exposure {
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
    ui.add(slider(&mut render.exposure, -stops..=stops, label).suffix(" stops"))
        .on_hover_text(hint);
    ComboBox::new("tone map", "tone map")
        .selected_text(render.tone_map.label())
        .show_ui(ui, |ui| {
            for t in ToneMap::ALL {
                ui.selectable_value(&mut render.tone_map, t, t.label())
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
    ui.checkbox(&mut render.show_non_finite, "show non-finite pixels")
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

/// What a tone map entry does, for its tooltip.
fn tone_map_hint(tone_map: ToneMap) -> &'static str {
    match tone_map {
        ToneMap::Aces => "Narkowicz's fit of the ACES filmic curve: soft highlights, more contrast",
        ToneMap::Reinhard => "x / (1 + x) per channel: never clips, but flattens highlights",
        ToneMap::Clamp => "Clamp to [0, 1]: the linear radiance untouched, highlights clip",
    }
}

/// The NaN and Inf counters: red as soon as one sample was dropped, since a
/// correct renderer never produces one.
fn non_finite_ui(ui: &mut Ui, counts: &NonFiniteCounts) {
    let text = format!(
        "non-finite samples: {} NaN, {} Inf ({} pixels)",
        counts.nan, counts.infinite, counts.pixels
    );
    let label = if counts.is_zero() {
        ui.label(text)
    } else {
        ui.colored_label(Color32::from_rgb(230, 60, 60), text)
    };
    label.on_hover_text(
        "Samples the accumulation dropped since the image restarted because they were NaN or \
         infinite; \"show non-finite pixels\" (Render) paints where they fell",
    );
}

/// The Kernel switch: which kernel traces (both draw the same image), or
/// `auto`, the faster on this adapter.
fn kernel_ui(ui: &mut Ui, stats: &Stats, actions: &mut Vec<PanelAction>) {
    use marbre_render::gpu::KernelChoice;
    let name = |c: KernelChoice| match c {
        KernelChoice::Auto => "auto (the faster)",
        KernelChoice::Fragment => "fragment",
        KernelChoice::Compute => "compute",
    };
    let mut choice = stats.kernel_choice;
    egui::ComboBox::from_label("kernel")
        .selected_text(name(choice))
        .show_ui(ui, |ui| {
            for c in [
                KernelChoice::Auto,
                KernelChoice::Fragment,
                KernelChoice::Compute,
            ] {
                ui.selectable_value(&mut choice, c, name(c));
            }
        })
        .response
        .on_hover_text(
            "The trace as a fragment shader or a compute kernel: the same image, at a speed that \
             depends on the GPU; auto times both on the scene and remembers the faster",
        );
    if choice != stats.kernel_choice {
        actions.push(PanelAction::SetKernel(choice));
    }
}

fn stats_ui(ui: &mut Ui, stats: &Stats) {
    ui.label(format!("{:.1} fps", stats.fps));
    ui.label(format!("{} lights", stats.lights)).on_hover_text(
        "Entries of the light table: the point light, emissive spheres and triangles",
    );
    if stats.triangles > 0 {
        ui.label(format!(
            "{} triangles, {} BVH nodes (built in {:.1} ms)",
            stats.triangles, stats.bvh_nodes, stats.bvh_build_ms
        ))
        .on_hover_text("The meshes' triangles and their bounding volume hierarchy (binned SAH)");
    }
    let clock = if stats.ms_is_gpu { "GPU" } else { "CPU" };
    ui.label(format!(
        "{:.2} ms per sample round ({clock})",
        stats.ms_per_frame
    ))
    .on_hover_text(
        "The trace's cost of one round (samples per frame for every pixel), from its measured \
         time per pixel. GPU: timestamp queries around the passes; CPU: wall time per frame",
    );
    ui.label(format!("{} samples accumulated", stats.samples));
    if stats.round_progress > 0.0 {
        ui.add(
            egui::ProgressBar::new(stats.round_progress)
                .text("next round")
                .desired_height(12.0),
        )
        .on_hover_text(
            "A round costs more than a frame's trace budget: it is traced a band of rows per \
             frame, and shown once complete",
        );
    }
    ui.label(format!(
        "trace kernel: {} ({})",
        stats.kernel, stats.kernel_reason
    ));
    non_finite_ui(ui, &stats.non_finite);
    let (w, h) = stats.resolution;
    ui.label(format!("{w} × {h}"));
    ui.label(format!("{} ({})", stats.adapter, stats.backend));
    let features = if stats.features.is_empty() {
        "none".to_owned()
    } else {
        stats.features.join(", ")
    };
    ui.label(format!("shader features: {features}"))
        .on_hover_text("What the current scene compiled into the shader");
    ui.label(format!(
        "trace shader: {:.1} KiB of WGSL",
        stats.shader_bytes as f32 / 1024.0
    ))
    .on_hover_text("The assembled trace module: the files its features need, plus the code generated from the texture trees");
    if stats.building {
        ui.label("building a new shader… (the old one renders meanwhile)");
    } else if let Some(ms) = stats.last_build_ms {
        ui.label(format!("last shader build: {ms:.0} ms"))
            .on_hover_text(
                "From the structural edit to the new pipeline, built off the render thread",
            );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use marbre_core::noise::NoiseSettings;
    use marbre_core::scene::{Ground, Sphere};
    use marbre_core::scene::{Pattern, Texture};

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

    #[test]
    fn drawing_without_input_changes_nothing() {
        let mut scene = marble_scene();
        let before = scene.clone();
        let mut state = PanelState::new("presets/a.ron".into(), String::new());
        state.error("something failed");
        let mut actions = Vec::new();
        frame(|ui| actions = draw(ui, &mut scene, &mut state, &Stats::default()));
        assert_eq!(scene, before);
        assert!(actions.is_empty(), "{actions:?}");
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
                for s in &mut scene.spheres {
                    material_ui(ui, &mut s.material);
                }
                material_ui(ui, &mut scene.ground.as_mut().unwrap().material);
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
                scene_features: vec![marbre_render::gpu::Feature::PatternCutout],
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
