//! The scene sections: materials, meshes, the point light, the camera and
//! its saved views.

use super::PanelAction;
use super::keying;
use super::material_editor::material_ui;
use super::node_graph;
use super::widgets::{labelled_color, slider, uv_frame_ui, vec3_field, vec3_ui};
use egui::{CollapsingHeader, Ui};
use marbre_core::animation::ParamPath;
use marbre_core::bake::{BakeProperty, ObjectRef};
use marbre_core::scene::{Ground, MaterialKey, OrbitCamera, PointLight, Projection, Scene};

/// One collapsible block per object (spheres, cylinders, polygons), then
/// the ground. Only the first is open at start, so a scene with many
/// objects still fits on screen. Each material has its node-graph toggle
/// (`graph`: the material whose graph window is open).
/// Returns the object and property of a Bake… button pressed.
pub(super) fn materials_ui(
    ui: &mut Ui,
    scene: &mut Scene,
    graph: &mut Option<MaterialKey>,
) -> Option<(ObjectRef, BakeProperty)> {
    let mut first = true;
    let mut bake = None;
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
            &mut |ui| {
                node_graph::toggle(ui, graph, MaterialKey::Sphere(i));
                let pressed = material_ui(ui, MaterialKey::Sphere(i), &mut sphere.material);
                bake = bake.or(pressed.map(|p| (ObjectRef::Sphere(i), p)));
            },
        );
    }
    for (i, cylinder) in scene.cylinders.iter_mut().enumerate() {
        object(
            ui,
            ("cylinder", i),
            format!("cylinder “{}”", cylinder.name),
            &mut |ui| {
                let at = |field: &str| {
                    ParamPath::parse(&format!("cylinders[{i}].{field}"))
                        .expect("a cylinder's field is a parameter path")
                };
                vec3_ui(
                    ui,
                    &at("base"),
                    "base",
                    &mut cylinder.base,
                    0.01,
                    "Centre of the bottom cap",
                );
                keying::number(ui, &at("radius"), &mut cylinder.radius, |ui, v| {
                    ui.add(slider(v, 0.01..=10.0, "radius").logarithmic(true))
                })
                .on_hover_text("Radius of the side and caps, in scene units");
                keying::number(ui, &at("height"), &mut cylinder.height, |ui, v| {
                    ui.add(slider(v, 0.01..=10.0, "height").logarithmic(true))
                })
                .on_hover_text("Along +y; the side's v runs from 0 at the base to 1 at the top");
                node_graph::toggle(ui, graph, MaterialKey::Cylinder(i));
                let pressed = material_ui(ui, MaterialKey::Cylinder(i), &mut cylinder.material);
                bake = bake.or(pressed.map(|p| (ObjectRef::Cylinder(i), p)));
            },
        );
    }
    for (i, polygon) in scene.polygons.iter_mut().enumerate() {
        object(
            ui,
            ("polygon", i),
            format!("polygon “{}”", polygon.name),
            &mut |ui| {
                node_graph::toggle(ui, graph, MaterialKey::Polygon(i));
                let pressed = material_ui(ui, MaterialKey::Polygon(i), &mut polygon.material);
                bake = bake.or(pressed.map(|p| (ObjectRef::Polygon(i), p)));
            },
        );
    }
    if let Some(ground) = &mut scene.ground {
        object(ui, ("ground", 0), "ground".into(), &mut |ui| {
            let default = Ground::default().frame();
            let frame = ParamPath::parse("ground.uv_frame").expect("a parameter path");
            uv_frame_ui(
                ui,
                &frame,
                &mut ground.uv_frame,
                "uv frame",
                "The report's APTX: 2D textures read (u, v) along an origin and two axes \
                 (oblique ones too) instead of world (x, z)",
                default,
            );
            node_graph::toggle(ui, graph, MaterialKey::Ground);
            let pressed = material_ui(ui, MaterialKey::Ground, &mut ground.material);
            bake = bake.or(pressed.map(|p| (ObjectRef::Ground, p)));
        });
    }
    for (i, mesh) in scene.meshes.iter_mut().enumerate() {
        object(
            ui,
            ("mesh", i),
            format!("mesh “{}”", mesh.name),
            &mut |ui| {
                let pressed = mesh_ui(ui, mesh, i, graph);
                bake = bake.or(pressed.map(|p| (ObjectRef::Mesh(i), p)));
            },
        );
    }
    bake
}

/// A mesh's placement and each of its MTL materials, editable like any
/// other (a Cornell box wall can be marble); "reset" goes back to the file.
/// Returns the property of a Bake… button pressed (a bake covers the whole
/// mesh, each triangle in its own material). `index` is the mesh's in the
/// scene, for the node-graph toggle.
pub(super) fn mesh_ui(
    ui: &mut Ui,
    mesh: &mut marbre_core::scene::Mesh,
    index: usize,
    graph: &mut Option<MaterialKey>,
) -> Option<BakeProperty> {
    let mut bake = None;
    ui.label(format!(
        "{} triangles from {}",
        mesh.geometry.0.len(),
        mesh.obj.display()
    ));
    let p = &mut mesh.placement;
    let at = |field: &str| {
        ParamPath::parse(&format!("meshes[{index}].placement.{field}"))
            .expect("a placement's field is a parameter path")
    };
    vec3_ui(
        ui,
        &at("translate"),
        "translate",
        &mut p.translate,
        0.01,
        "Moves the mesh",
    );
    keying::number(
        ui,
        &at("rotate_y_degrees"),
        &mut p.rotate_y_degrees,
        |ui, v| ui.add(slider(v, -180.0..=180.0, "turn").suffix("°")),
    )
    .on_hover_text("Turns the mesh about the vertical axis (rebuilds the BVH)");
    keying::number(ui, &at("scale"), &mut p.scale, |ui, v| {
        ui.add(slider(v, 0.01..=100.0, "scale").logarithmic(true))
    })
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
                    let key = MaterialKey::Mesh {
                        mesh: index,
                        material: k,
                    };
                    node_graph::toggle(ui, graph, key);
                    bake = bake.or(material_ui(ui, key, &mut m.material));
                });
        });
    }
    bake
}

pub(super) fn point_light_ui(ui: &mut Ui, light: &mut Option<PointLight>) {
    let mut enabled = light.is_some();
    if ui
        .checkbox(&mut enabled, "enabled")
        .on_hover_text("An isotropic point light, besides the environment")
        .changed()
    {
        *light = enabled.then(PointLight::default);
    }
    if let Some(l) = light {
        let at = |field: &str| {
            ParamPath::parse("point_light")
                .expect("a path")
                .field(field)
        };
        keying::vector(ui, &at("position"), &mut l.position, |ui, v| {
            vec3_field(
                ui,
                "position",
                v,
                0.05,
                "Where the light is, in scene units",
            )
        });
        keying::vector(ui, &at("color"), &mut l.color, |ui, c| {
            labelled_color(ui, c, "colour").on_hover_text("The light's colour")
        });
        keying::number(ui, &at("intensity"), &mut l.intensity, |ui, v| {
            ui.add(
                slider(v, 0.0..=10_000.0, "intensity")
                    .logarithmic(true)
                    .smallest_positive(0.1),
            )
        })
        .on_hover_text("Radiant intensity in watts per steradian (times the colour)");
    }
}

pub(super) fn camera_ui(ui: &mut Ui, scene: &mut Scene, actions: &mut Vec<PanelAction>) {
    let camera = &mut scene.camera;
    let at = |field: &str| ParamPath::parse("camera").expect("a path").field(field);
    keying::vector(ui, &at("target"), &mut camera.target, |ui, v| {
        vec3_field(
            ui,
            "target",
            v,
            0.05,
            "The point the camera orbits and looks at",
        )
    });
    keying::number(ui, &at("distance"), &mut camera.distance, |ui, v| {
        ui.add(slider(v, OrbitCamera::MIN_DISTANCE..=1000.0, "distance").logarithmic(true))
    })
    .on_hover_text("Distance from the target");
    keying::number(ui, &at("yaw_degrees"), &mut camera.yaw_degrees, |ui, v| {
        ui.add(slider(v, 0.0..=360.0, "yaw").suffix("°"))
    })
    .on_hover_text("Rotation about the vertical axis");
    keying::number(
        ui,
        &at("pitch_degrees"),
        &mut camera.pitch_degrees,
        |ui, v| ui.add(slider(v, -89.0..=89.0, "pitch").suffix("°")),
    )
    .on_hover_text("Elevation above the horizontal");
    keying::number(ui, &at("fov_degrees"), &mut camera.fov_degrees, |ui, v| {
        ui.add(slider(v, 10.0..=120.0, "field of view").suffix("°"))
    })
    .on_hover_text("Vertical field of view");
    egui::ComboBox::new("projection", "projection")
        .selected_text(camera.projection.label())
        .show_ui(ui, |ui| {
            for p in Projection::ALL {
                ui.selectable_value(&mut camera.projection, p, p.label())
                    .on_hover_text(match p {
                        Projection::Perspective => "Rays from the camera: far things look smaller",
                        Projection::Orthographic => {
                            "Parallel rays (Massal's figures): size does not change with \
                             depth; the view is as high as the perspective one at the \
                             target, and the distance zooms"
                        }
                    });
            }
        });
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

/// The preset's saved views: recall (or Ctrl+1–9), rename, delete, and
/// save the current camera as a new one.
pub(super) fn views_ui(ui: &mut Ui, scene: &mut Scene) {
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
        .on_hover_text("Keep the current camera in the preset; Ctrl+1–9 recall the first nine")
        .clicked()
    {
        scene.save_view();
    }
}
