// Triangle write passes, uniform pattern: triangle t of patch p goes to
// `triangle_offsets[p] + t` with its corners mapped by `grid_vertex` (the layout's rule).

// One invocation per output triangle, for patches without a repeated corner (every pattern
// triangle kept, so output triangle t is pattern triangle t).
@compute @workgroup_size(WORKGROUP)
fn write_uniform_triangles(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let t = thread_index(wid, nwg, lid);
    let p = plain_triangle_patch(t);
    if (p == params.patches) { return; }
    let local = t - triangle_offsets[p];
    let n = interior[p].x;
    let tri = pattern_triangle(patch_is_tri(p), n, local);
    for (var c = 0u; c < 3u; c = c + 1u) {
        indices[3u * t + c] = grid_vertex(p, n, tri[c].x, tri[c].y);
    }
}

// One invocation per patch with a repeated corner: its triangles in pattern order, leaving
// out those that degenerate (`engine::layout::degenerate_after_collapse`), so the kept ones
// are numbered as on the CPU. Serial within the patch: O(n²) for one invocation, for the few
// patches that touch a collapsed curve.
@compute @workgroup_size(WORKGROUP)
fn write_uniform_collapsed_triangles(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (!collapsed_patch(p)) { return; }
    let n = interior[p].x;
    let is_tri = patch_is_tri(p);
    var t = triangle_offsets[p];
    for (var local = 0u; local < uniform_counts(is_tri, n).y; local = local + 1u) {
        let tri = pattern_triangle(is_tri, n, local);
        if (triangle_degenerates(p, n, tri)) { continue; }
        for (var c = 0u; c < 3u; c = c + 1u) {
            indices[3u * t + c] = grid_vertex(p, n, tri[c].x, tri[c].y);
        }
        t = t + 1u;
    }
}
