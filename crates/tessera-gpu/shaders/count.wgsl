// Count pass, any pattern: the counts `tessera::engine::Layout::build` scans, written in
// place into the offset arrays (the scan turns them into offsets).
// Invocation x < E: edge x's inner vertices, `(segments − 1) · variants`, none for a collapsed
// edge or one no visible patch uses. E ≤ x < E + P: patch x − E's interior vertices
// and triangles, `{{PATCH_COUNTS}}(p)` of the pattern's own file (its `Pattern::counts` minus the
// triangles that degenerate at a collapsed curve), 0 for culled patches. x = E + P: the trailing entry, 0.
// The pattern's function is named by the pipeline's table (`src/tessellator/pipelines.rs`,
// `PatternShaders`), so a module built without that pattern's file fails to compile.

@compute @workgroup_size(WORKGROUP)
fn count(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let x = thread_index(wid, nwg, lid);
    let edges = params.edges;
    let patches = params.patches;
    if (x < edges) {
        vertex_offsets[x] = edge_count(x);
    } else if (x < edges + patches) {
        let p = x - edges;
        var counts = vec2<u32>(0u, 0u);
        if (visible[p] != 0u) {
            counts = {{PATCH_COUNTS}}(p);
        }
        vertex_offsets[x] = counts.x;
        triangle_offsets[p] = counts.y;
    } else if (x == edges + patches) {
        vertex_offsets[x] = 0u;
        triangle_offsets[patches] = 0u;
    }
}
