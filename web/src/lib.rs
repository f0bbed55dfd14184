//! The web page's wasm module: its entry starts the viewer on the page's
//! canvas (`marbre::app::web`). Built by `web/build.sh`; a desktop build
//! of this crate is empty.

#[cfg(target_arch = "wasm32")]
#[wasm_bindgen::prelude::wasm_bindgen(start)]
pub fn start() {
    marbre::app::web::start();
}
