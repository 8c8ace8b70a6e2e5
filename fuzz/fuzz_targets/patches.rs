//! Fuzzes the Newell patch reader: `io::patches::parse_patches` on any bytes must return a
//! file or an error, never panic; a parsed file keeps its invariants, reads back from its own
//! Newell text, and small files build and tessellate (see `tessera::fuzzing::check_patches`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    tessera::fuzzing::check_patches(data);
});
