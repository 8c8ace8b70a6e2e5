//! Fuzzes the outside-glTF reader: `io::glb::parse_gltf_triangles` (through the `gltf` crate)
//! on any bytes must return a consistent mesh or an error, never panic, and a parsed mesh
//! builds PN triangles or refuses them (see `tessera::fuzzing::check_gltf`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    tessera::fuzzing::check_gltf(data);
});
