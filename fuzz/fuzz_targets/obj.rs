//! OBJ files and their material library: the input is the OBJ's bytes, then
//! a NUL byte and the bytes of `input.mtl` (absent without the NUL: the
//! library cannot be read). Both go through `obj_loader::parse_bytes`, the
//! reader `obj_loader::load` uses.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let (obj, mtl) = match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], Some(&data[i + 1..])),
        None => (data, None),
    };
    let _ =
        marbre_core::obj_loader::parse_bytes(obj, Path::new("/fuzz/obj/input.obj"), |library| {
            match (library == Path::new("/fuzz/obj/input.mtl"), mtl) {
                (true, Some(bytes)) => Ok(bytes.to_vec()),
                _ => Err(std::io::ErrorKind::NotFound.into()),
            }
        });
});
