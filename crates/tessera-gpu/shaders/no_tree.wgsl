// The stand-in for `tree.wgsl` in the pipelines of sets without subdivision patches: the same
// functions, never taken. Evaluating pipelines compile several times faster without the
// tree walk (lavapipe), so a set's pipelines include it only when the set has trees.

fn patch_is_tree(p: u32) -> bool { return false; }

fn tree_eval(p: u32, uv: vec2<f32>) -> SurfacePoint {
    return SurfacePoint(vec3<f32>(0.0), vec3<f32>(0.0, 0.0, 1.0));
}

fn patch_is_loop(p: u32) -> bool { return false; }

fn loop_derivatives(p: u32, uv: vec2<f32>) -> Derivatives {
    return Derivatives(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
}
