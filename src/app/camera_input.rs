//! Mouse control of the orbit camera over the image area.

use marbre_core::scene::OrbitCamera;

/// Degrees of rotation per point of drag.
const ORBIT_DEGREES_PER_POINT: f32 = 0.3;

/// Applies this frame's drags and wheel on the image to the camera.
/// Returns whether the camera is being dragged (for the reduced resolution).
pub fn apply(ui: &egui::Ui, response: &egui::Response, camera: &mut OrbitCamera) -> bool {
    let delta = response.drag_delta();
    let height = response.rect.height().max(1.0);
    if response.dragged_by(egui::PointerButton::Primary) {
        camera.orbit(
            -delta.x * ORBIT_DEGREES_PER_POINT,
            delta.y * ORBIT_DEGREES_PER_POINT,
        );
    } else if response.dragged_by(egui::PointerButton::Secondary)
        || response.dragged_by(egui::PointerButton::Middle)
    {
        camera.pan(delta.x / height, delta.y / height);
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            camera.zoom(scroll / 50.0);
        }
    }
    response.dragged()
}
