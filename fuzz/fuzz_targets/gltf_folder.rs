//! Fuzzes the outside-glTF reader on `.gltf` files inside a folder of hostile buffer files
//! (short, empty, sparse-huge, a folder, links to `/dev/zero`, out of the folder and to
//! themselves): `io::glb::read_gltf_triangles` must refuse or parse, never panic, hang or
//! read past a buffer's `byteLength` (see `tessera::fuzzing::check_gltf_folder`). Seed it
//! with `tessera::fuzzing::one_triangle_gltf` of those file names.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    tessera::fuzzing::check_gltf_folder(data);
});
