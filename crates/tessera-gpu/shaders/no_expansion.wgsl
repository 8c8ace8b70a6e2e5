// The stand-in for `expansion.wgsl` in the transition pattern's own pipelines (counts,
// vertices), whose sinks never check: the names `transition.wgsl` reads, never taken, so
// that those pipelines compile without the expansion bound's code (every call is inlined,
// and lavapipe compiles the bound's code for minutes where it is inlined many times).

const EXPANSION_NONE: u32 = 0u;

struct Expansion {
    p: u32,
    kind: u32,
    third: vec4<f32>,
    fourth: vec3<f32>,
}

fn no_expansion(p: u32) -> Expansion {
    return Expansion(p, EXPANSION_NONE, vec4<f32>(0.0), vec3<f32>(0.0));
}

fn expansion_triangle_error(x: Expansion, t0: vec2<f32>, t1: vec2<f32>, t2: vec2<f32>) -> f32 {
    return 3.0e38;
}
