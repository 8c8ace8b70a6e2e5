//! Fuzzes the GLB reader: `io::glb::parse_glb` on any bytes must return a consistent mesh
//! or an error, never panic, and a parsed mesh survives `write_glb` → `parse_glb` unchanged
//! (see `tessera::fuzzing::check_glb`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    tessera::fuzzing::check_glb(data);
});
