// What `expansion.wgsl` and its stand-in `no_expansion.wgsl` share: the type of one patch's
// expansion bound, and the patch without one.

const EXPANSION_NONE: u32 = 0u;

// One patch's expansion: its kind, the bounds on |S_uuu|, |S_uuv|, |S_uvv|, |S_vvv| and, for
// a bicubic, on the fourth derivatives |S_uuuv|, |S_uuvv|, |S_uvvv| (`taylor::
// ThirdDerivatives`; zero for a triangle, whose third derivatives are constant).
struct Expansion {
    p: u32,
    kind: u32,
    third: vec4<f32>,
    fourth: vec3<f32>,
}

// Patch p without an expansion bound (its plans keep the second-derivative bound).
fn no_expansion(p: u32) -> Expansion {
    return Expansion(p, EXPANSION_NONE, vec4<f32>(0.0), vec3<f32>(0.0));
}
