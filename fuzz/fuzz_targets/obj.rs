//! Fuzzes the OBJ reader: `io::obj::parse_obj` on any bytes must return a mesh or an error,
//! never panic; a parsed mesh keeps its invariants, builds PN triangles or errs, and survives
//! `write_obj` → `parse_obj` (see `tessera::fuzzing::check_obj`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    tessera::fuzzing::check_obj(data);
});
