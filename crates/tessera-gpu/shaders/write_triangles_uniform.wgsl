// Triangle write passes, uniform pattern: triangle t of patch p goes to
// `triangle_offsets[p] + t` with its corners mapped by `grid_vertex` (the layout's rule).

// One invocation per output triangle, for patches without a repeated corner (every pattern
// triangle kept, so triangle t is half t mod 2 of cell t div 2, cells row after row).
@compute @workgroup_size(WORKGROUP)
fn write_triangles(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let t = thread_index(wid, nwg, lid);
    if (t >= triangle_offsets[params.patches]) { return; }
    let p = find_triangle_range(0u, params.patches, t);
    if (patch_repeated_corner(p)) { return; }
    let local = t - triangle_offsets[p];
    let n = interior[p].x;
    let cell = local / 2u;
    let tri = cell_triangle(cell % n, cell / n, local % 2u);
    for (var c = 0u; c < 3u; c = c + 1u) {
        indices[3u * t + c] = grid_vertex(p, n, tri[c].x, tri[c].y);
    }
}

// One invocation per patch with a repeated corner: its triangles in pattern order, leaving
// out those that degenerate (`engine::layout::degenerate_after_collapse`), so the kept ones
// are numbered as on the CPU. Serial within the patch: O(n²) for one invocation, for the few
// patches that touch a collapsed curve.
@compute @workgroup_size(WORKGROUP)
fn write_collapsed_patch_triangles(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (p >= params.patches) { return; }
    if (visible[p] == 0u || !patch_repeated_corner(p)) { return; }
    let n = interior[p].x;
    var t = triangle_offsets[p];
    for (var j = 0u; j < n; j = j + 1u) {
        for (var i = 0u; i < n; i = i + 1u) {
            for (var h = 0u; h < 2u; h = h + 1u) {
                let tri = cell_triangle(i, j, h);
                if (triangle_degenerates(p, n, tri)) { continue; }
                for (var c = 0u; c < 3u; c = c + 1u) {
                    indices[3u * t + c] = grid_vertex(p, n, tri[c].x, tri[c].y);
                }
                t = t + 1u;
            }
        }
    }
}
