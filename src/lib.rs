//! marbre's viewer: the winit window, the egui panel, and the soak driver
//! over the renderer library (`marbre-render`).

pub mod app;
pub mod exit_check;
pub mod headless;
pub mod heap;
pub mod panel;
