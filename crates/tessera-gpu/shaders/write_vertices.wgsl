// Vertex write passes: every output vertex evaluated once, at the place the layout gives it
// (`tessera::engine::write`'s corners, edges and patches). Shared edge vertices are written
// once, by the edge's owner use, and every patch indexes them: watertight bit for bit.
// Where the pattern puts its vertices, `{{EDGE_PARAM}}` and `{{INTERIOR_POINT}}`, are the
// functions of the pattern's files that the pipeline's table names
// (`src/tessellator/pipelines.rs`, `PatternShaders`).

// Corner entry x: position from its vertex's first entry's owner (`position_entry`), normal
// and uv from its own owner, as `engine::write_corners` and the split-normal copy do.
@compute @workgroup_size(WORKGROUP)
fn write_corners(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let x = thread_index(wid, nwg, lid);
    if (x >= params.corners) { return; }
    let row = x * CORNER_ROW;
    let owner = corner_rows[row];
    let uv = domain_corner(owner, corner_rows[row + 1u]);
    let normal = eval_patch(owner, uv).normal;
    let first = corner_rows[row + 2u];
    let position = eval_patch(first, domain_corner(first, corner_rows[row + 3u])).position;
    store_vertex(x, position, normal, uv);
}

// The first use of edge e with normal variant `variant` (the owner for variant 0).
fn use_of_variant(e: u32, variant: u32) -> u32 {
    var u = edge_first_use(e);
    for (; u < edge_end_use(e); u = u + 1u) {
        if (use_variant(u) == variant) { break; }
    }
    return u;
}

// Edge vertex corners + x: `engine::write_edge`. Sample k of variant v of edge e, evaluated by
// the first use of variant v (its normal and uv) at the canonical parameter the pattern's file
// gives (`{{EDGE_PARAM}}(e, k)`, `Plan::param`) mirrored for a reversed use; its position is
// variant 0's.
@compute @workgroup_size(WORKGROUP)
fn write_edge_vertices(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let v = params.corners + thread_index(wid, nwg, lid);
    if (v >= vertex_offsets[params.edges]) { return; }
    let e = find_vertex_range(0u, params.edges, v);
    let s = segments[e];
    let local = v - vertex_offsets[e];
    let variant = local / (s - 1u);
    let k = local % (s - 1u) + 1u;
    let t = {{EDGE_PARAM}}(e, k);
    let owner = edge_first_use(e);
    let u = use_of_variant(e, variant);
    let uv = edge_use_point(u, t);
    let normal = eval_patch(use_patch(u), uv).normal;
    let position = eval_patch(use_patch(owner), edge_use_point(owner, t)).position;
    store_vertex(v, position, normal, uv);
}

// Domain point of canonical parameter t of an edge, in the patch of use u.
fn edge_use_point(u: u32, t: f32) -> vec2<f32> {
    var local_t = t;
    if (use_reversed(u)) { local_t = 1.0 - t; }
    return domain_edge_point(use_patch(u), use_local(u), local_t);
}

// Interior vertex j of patch p (`vertex_offsets[E + p] + j`), at the pattern's
// `{{INTERIOR_POINT}}(p, j)`: the engine's `Writer::patch`.
@compute @workgroup_size(WORKGROUP)
fn write_interior_vertices(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let edges = params.edges;
    let v = vertex_offsets[edges] + thread_index(wid, nwg, lid);
    if (v >= vertex_offsets[edges + params.patches]) { return; }
    let p = find_vertex_range(edges, edges + params.patches, v) - edges;
    let uv = {{INTERIOR_POINT}}(p, v - vertex_offsets[edges + p]);
    let point = eval_patch(p, uv);
    store_vertex(v, point.position, point.normal, uv);
}
