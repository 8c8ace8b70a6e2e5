// Counts of the uniform pattern for the count pass (`count.wgsl`): a visible patch's interior
// vertices and triangles (`pattern::uniform::Uniform::counts`) minus those that degenerate at
// a collapsed curve (only patches with a repeated corner have any; on quads only in the outer
// ring of cells).
fn uniform_patch_counts(p: u32) -> vec2<u32> {
    let n = interior[p].x;
    let tri = patch_is_tri(p);
    var counts = uniform_counts(tri, n);
    if (patch_repeated_corner(p)) {
        if (tri) {
            counts.y = kept_triangles(p, n);
        } else {
            counts.y = counts.y - ring_degenerates(p, n);
        }
    }
    return counts;
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
