// Count pass, uniform pattern: the counts `tessera::engine::Layout::build` scans, written in
// place into the offset arrays (the scan turns them into offsets).
// Invocation x < E: edge x's inner vertices, `(segments − 1) · variants`, none for a collapsed
// edge or one no visible patch uses. E ≤ x < E + P: patch x − E's interior vertices
// and triangles (`pattern::uniform::Uniform::counts`) minus those that degenerate at a
// collapsed curve (only patches with a repeated corner have any; on quads only in the outer
// ring of cells). x = E + P: the trailing entry, 0.

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
        var inner = 0u;
        var triangles = 0u;
        if (visible[p] != 0u) {
            let n = interior[p].x;
            let tri = patch_is_tri(p);
            let counts = uniform_counts(tri, n);
            inner = counts.x;
            triangles = counts.y;
            if (patch_repeated_corner(p)) {
                if (tri) {
                    triangles = kept_triangles(p, n);
                } else {
                    triangles = triangles - ring_degenerates(p, n);
                }
            }
        }
        vertex_offsets[x] = inner;
        triangle_offsets[p] = triangles;
    } else if (x == edges + patches) {
        vertex_offsets[x] = 0u;
        triangle_offsets[patches] = 0u;
    }
}

// Triangles of the outer ring of cells of patch p that degenerate (no other cell has two
// boundary points, so no other triangle can). Each ring cell is visited once. Cost: O(n).
fn ring_degenerates(p: u32, n: u32) -> u32 {
    var dropped = 0u;
    for (var j = 0u; j < n; j = j + 1u) {
        if (j == 0u || j == n - 1u) {
            for (var i = 0u; i < n; i = i + 1u) {
                dropped = dropped + cell_degenerates(p, n, i, j);
            }
        } else {
            // A middle row (n > 2): its first and last cell only.
            dropped = dropped + cell_degenerates(p, n, 0u, j) + cell_degenerates(p, n, n - 1u, j);
        }
    }
    return dropped;
}

fn cell_degenerates(p: u32, n: u32, i: u32, j: u32) -> u32 {
    var dropped = 0u;
    for (var h = 0u; h < 2u; h = h + 1u) {
        if (triangle_degenerates(p, n, cell_triangle(i, j, h))) { dropped = dropped + 1u; }
    }
    return dropped;
}

// Pattern triangles of triangle patch p that do not degenerate. Cost: O(n²), serial; only
// for patches with a repeated corner.
fn kept_triangles(p: u32, n: u32) -> u32 {
    var kept = 0u;
    for (var t = 0u; t < n * n; t = t + 1u) {
        if (!triangle_degenerates(p, n, pattern_triangle(true, n, t))) { kept = kept + 1u; }
    }
    return kept;
}
