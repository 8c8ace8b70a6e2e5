//! Fuzzes the STL reader: `io::stl::parse_stl` on any bytes must return a consistent mesh
//! or an error, never panic, and a parsed mesh survives `write_stl` → `parse_stl` unchanged
//! (see `tessera::fuzzing::check_stl`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    tessera::fuzzing::check_stl(data);
});
