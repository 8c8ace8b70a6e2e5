// A cubic Bézier triangle's control points in the patch's control-point slots (`src/upload.rs`):
// b(i, j, 3 − i − j), `i` the exponent of λ0 = 1 − u − v, `j` of u, at
// `BezierTriangle::index`. Read by the evaluation (`bezier_triangle.wgsl`); the expansion
// bound (`expansion.wgsl`) reads its nets in the same order (`tri_index`). Needs the
// includer's `control_points` and `CONTROL_POINTS`.

fn tri_index(i: u32, j: u32) -> u32 {
    return (3u - i) * (4u - i) / 2u + (3u - i - j);
}

fn tri_point(p: u32, i: u32, j: u32) -> vec3<f32> {
    return control_points[p * CONTROL_POINTS + tri_index(i, j)].xyz;
}
