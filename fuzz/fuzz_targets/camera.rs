//! Fuzzes `--camera` parsing: `Camera::parse` on any text must return a valid camera or an
//! error, never panic, and a parsed camera reads back identically from a spec naming every
//! key (see `tessera::fuzzing::check_camera`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    tessera::fuzzing::check_camera(data);
});
