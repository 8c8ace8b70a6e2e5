//! Fuzzes the PLY reader: `io::ply::parse_ply` on any bytes must return a consistent mesh
//! or an error, never panic, and a parsed mesh survives `write_ply` → `parse_ply` unchanged
//! (see `tessera::fuzzing::check_ply`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    tessera::fuzzing::check_ply(data);
});
