//! Fuzzes the engine: the bytes choose a small surface set (closed bicubic or PN shapes with
//! jittered integer control points, or random patches and triangles), a scheme, factors up to
//! 16 and a camera; the plan is built as the CLI builds it, without culling, and tessellated.
//! No panic, a consistent mesh, strips that decode to the triangles, and for closed inputs a
//! watertight output (see `tessera::fuzzing::check_engine`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    tessera::fuzzing::check_engine(data);
});
