// Cull pass: one invocation per patch writes the plan's visibility row from the camera, the
// GPU form of `tessera::criterion::screen::culled` — every control point beyond one frustum
// plane (the convex hull holds the patch), or back-facing by the conservative normal cone
// (`screen::back_facing`, with the cone and bounding sphere prepared once on the CPU).

fn to_camera(p: vec3<f32>) -> vec3<f32> {
    let d = p - view.eye.xyz;
    return vec3<f32>(dot(d, view.right.xyz), dot(d, view.up.xyz), dot(d, view.forward.xyz));
}

// `screen::back_facing`: γ > π/2 + α + β, with γ the angle between the cone's axis and the
// direction to the eye and sin β = radius / distance. Stated with cosines and sines, not
// acos and asin, whose f32 values lose half their digits near 0 and 1: with θ = α + β < π/2
// the condition is cos γ < cos(π/2 + θ) = −sin θ; for θ ≥ π/2 it never holds (γ ≤ π).
fn back_facing(p: u32) -> bool {
    let cone = patch_views[PATCH_VIEW_ROW * p];
    let sphere = patch_views[PATCH_VIEW_ROW * p + 1u];
    let trig = patch_views[PATCH_VIEW_ROW * p + 2u];
    if (trig.z == 0.0) { return false; }
    let to_eye = view.eye.xyz - sphere.xyz;
    let dist = length(to_eye);
    if (dist <= sphere.w) { return false; }
    let sin_b = sphere.w / dist;
    let cos_b = sqrt(max(0.0, 1.0 - sin_b * sin_b));
    let cos_t = trig.y * cos_b - trig.x * sin_b;
    if (cos_t <= 0.0) { return false; }
    let sin_t = trig.x * cos_b + trig.y * sin_b;
    return dot(cone.xyz, to_eye / dist) < -sin_t;
}

@compute @workgroup_size(WORKGROUP)
fn cull(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (p >= params.patches) { return; }
    // Each flag: all control points beyond that plane so far.
    var before_near = true;
    var beyond_far = true;
    var right_of = true;
    var left_of = true;
    var above = true;
    var below = true;
    for (var k = 0u; k < patch_point_count(p); k = k + 1u) {
        let c = to_camera(control_points[p * CONTROL_POINTS + k].xyz);
        before_near = before_near && c.z < view.near;
        beyond_far = beyond_far && c.z > view.far;
        right_of = right_of && c.x > view.tan_x * c.z;
        left_of = left_of && c.x < -view.tan_x * c.z;
        above = above && c.y > view.tan_y * c.z;
        below = below && c.y < -view.tan_y * c.z;
    }
    let outside = before_near || beyond_far || right_of || left_of || above || below;
    visible[p] = select(1u, 0u, outside || back_facing(p));
}
