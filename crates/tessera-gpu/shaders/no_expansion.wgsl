// The stand-in for `expansion.wgsl` in every pipeline of a frame planned with the
// second-derivative bound: the names the proposals (`factors.wgsl`), the check
// (`check.wgsl`) and the transition pattern (`transition.wgsl`) read, with no expansion
// (EXPANSION_NONE), so that the driver removes every branch of the expansion bound. lavapipe
// inlines every call, and the bound's code takes its LLVM about 10 s to compile: the frames
// that ask for it compile their own pipelines on first use (`Pipelines::expansion`), the
// others never do.

fn expansion_of(p: u32) -> Expansion {
    return no_expansion(p);
}

fn expansion_triangle_error(x: Expansion, t0: vec2<f32>, t1: vec2<f32>, t2: vec2<f32>) -> f32 {
    return 3.0e38;
}

fn expansion_grid_error(x: Expansion, tri: bool, nu: u32, nv: u32, stop: f32, cap: f32) -> f32 {
    return cap;
}

fn expansion_grid_fits(x: Expansion, tri: bool, nu: u32, nv: u32, eps: f32, cap: f32) -> bool {
    return cap <= eps;
}
