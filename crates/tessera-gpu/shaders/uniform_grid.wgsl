// The uniform pattern's grid (`tessera::pattern::uniform`) on quads and triangles, mapped to
// output vertices by the layout's numbering rule (`tessera::engine` `LocalMap::vertex`), and
// the rule that drops triangles degenerate at a collapsed curve
// (`engine::layout::degenerate_after_collapse`).

// The uniform pattern's interior grid: n × n cells (read by the interior vertex pass).
fn uniform_interior_grid(p: u32) -> vec2<u32> {
    let n = interior[p].x;
    return vec2<u32>(n, n);
}

// What grid point (i, j) of an n-grid is: a corner, a sample of a local edge (counted in the
// patch's own direction, corner e → e + 1) or an interior point. Mirrors `uniform::quad_local`
// and `uniform::tri_local`.
struct GridSlot {
    // 0 corner, 1 edge sample, 2 interior.
    kind: u32,
    // The corner or the local edge.
    index: u32,
    // The sample along the edge (edges), the interior vertex j (interior).
    k: u32,
}

fn grid_slot(tri: bool, n: u32, i: u32, j: u32) -> GridSlot {
    if (tri) {
        if (j == 0u && i == 0u) { return GridSlot(0u, 0u, 0u); }
        if (j == 0u && i == n) { return GridSlot(0u, 1u, 0u); }
        if (i == 0u && j == n) { return GridSlot(0u, 2u, 0u); }
        if (j == 0u) { return GridSlot(1u, 0u, i); }
        if (i + j == n) { return GridSlot(1u, 1u, j); }
        if (i == 0u) { return GridSlot(1u, 2u, n - j); }
        // Rows 1 … j − 1 before this one hold n − 1 − r points each.
        let before = (j - 1u) * (n - 1u) - (j - 1u) * j / 2u;
        return GridSlot(2u, 0u, before + (i - 1u));
    }
    if (j == 0u && i == 0u) { return GridSlot(0u, 0u, 0u); }
    if (j == 0u && i == n) { return GridSlot(0u, 1u, 0u); }
    if (j == n && i == n) { return GridSlot(0u, 2u, 0u); }
    if (j == n && i == 0u) { return GridSlot(0u, 3u, 0u); }
    if (j == 0u) { return GridSlot(1u, 0u, i); }
    if (i == n) { return GridSlot(1u, 1u, j); }
    if (j == n) { return GridSlot(1u, 2u, n - i); }
    if (i == 0u) { return GridSlot(1u, 3u, n - j); }
    return GridSlot(2u, 0u, (j - 1u) * (n - 1u) + (i - 1u));
}

// The output vertex of grid point (i, j) of visible patch p: `LocalMap::vertex`.
fn grid_vertex(p: u32, n: u32, i: u32, j: u32) -> u32 {
    let s = grid_slot(patch_is_tri(p), n, i, j);
    if (s.kind == 0u) { return patch_corner_entry(p, s.index); }
    if (s.kind == 1u) { return edge_sample_vertex(p, s.index, s.k); }
    return vertex_offsets[params.edges + p] + s.k;
}

// The identity `degenerate_after_collapse` compares: corners and samples of collapsed
// curves are their corner entry (x = 1); any other grid point is itself (x = 0).
fn collapse_id(p: u32, n: u32, i: u32, j: u32) -> vec2<u32> {
    let s = grid_slot(patch_is_tri(p), n, i, j);
    if (s.kind == 0u) { return vec2<u32>(1u, patch_corner_entry(p, s.index)); }
    if (s.kind == 1u && patch_edge_collapsed(p, s.index)) { return vec2<u32>(1u, patch_corner_entry(p, s.index)); }
    return vec2<u32>(0u, j * (n + 1u) + i);
}

// Triangle `half` (0 or 1) of quad cell (i, j), as `uniform::grid` emits it: [a, b, c],
// [a, c, d] with a = (i, j), b = (i + 1, j), c = (i + 1, j + 1), d = (i, j + 1).
fn cell_triangle(i: u32, j: u32, half: u32) -> array<vec2<u32>, 3> {
    let a = vec2<u32>(i, j);
    let c = vec2<u32>(i + 1u, j + 1u);
    if (half == 0u) {
        return array<vec2<u32>, 3>(a, vec2<u32>(i + 1u, j), c);
    }
    return array<vec2<u32>, 3>(a, c, vec2<u32>(i, j + 1u));
}

// Pattern triangle t (grid points) of the uniform pattern, in `uniform::grid`'s order. Quads:
// two per cell, cells row after row. Triangles: row j holds 2(n − j) − 1, the rows before it
// j(2n − j).
fn pattern_triangle(tri: bool, n: u32, t: u32) -> array<vec2<u32>, 3> {
    if (!tri) {
        return row_triangle(false, t / (2u * n), t % (2u * n));
    }
    // The row from the inverse of j(2n − j), then corrected for rounding.
    var j = u32(max(0.0, f32(n) - sqrt(max(0.0, f32(n * n - min(t, n * n))))));
    j = min(j, n - 1u);
    while (j > 0u && j * (2u * n - j) > t) { j = j - 1u; }
    while (j + 1u < n && (j + 1u) * (2u * n - j - 1u) <= t) { j = j + 1u; }
    return row_triangle(true, j, t - j * (2u * n - j));
}

// Triangles in row j of the uniform pattern's n-grid: 2n on quads, 2(n − j) − 1 on triangles.
fn row_length(tri: bool, n: u32, j: u32) -> u32 {
    return select(2u * n, 2u * (n - j) - 1u, tri);
}

// Triangle q of row j (grid points), in `uniform::grid`'s order. Quads: cell (q / 2, j), half
// q mod 2. Triangles: [a, b, d] then [b, (i + 1, j + 1), d] for each i = q / 2.
fn row_triangle(tri: bool, j: u32, q: u32) -> array<vec2<u32>, 3> {
    let i = q / 2u;
    if (!tri) {
        return cell_triangle(i, j, q % 2u);
    }
    if (q % 2u == 0u) {
        return array<vec2<u32>, 3>(vec2<u32>(i, j), vec2<u32>(i + 1u, j), vec2<u32>(i, j + 1u));
    }
    return array<vec2<u32>, 3>(vec2<u32>(i + 1u, j), vec2<u32>(i + 1u, j + 1u), vec2<u32>(i, j + 1u));
}

// `Uniform::counts`: interior vertices and pattern triangles.
fn uniform_counts(tri: bool, n: u32) -> vec2<u32> {
    if (tri) {
        return vec2<u32>(select(0u, (n - 1u) * (n - 2u) / 2u, n >= 2u), n * n);
    }
    return vec2<u32>((n - 1u) * (n - 1u), 2u * n * n);
}

fn triangle_degenerates(p: u32, n: u32, t: array<vec2<u32>, 3>) -> bool {
    let a = collapse_id(p, n, t[0].x, t[0].y);
    let b = collapse_id(p, n, t[1].x, t[1].y);
    let c = collapse_id(p, n, t[2].x, t[2].y);
    return all(a == b) || all(b == c) || all(a == c);
}
