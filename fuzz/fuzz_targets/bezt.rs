//! Fuzzes the Bézier triangle reader: `io::bezt::parse_bezt` on any bytes must return a
//! consistent file or an error, never panic; a parsed file reads back from its own text, and
//! small files build and tessellate (see `tessera::fuzzing::check_bezt`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    tessera::fuzzing::check_bezt(data);
});
