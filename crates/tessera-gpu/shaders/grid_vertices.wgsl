// Where the integer patterns (uniform, transition) put their vertices, read by the vertex
// passes (`write_vertices.wgsl`): edge samples at equal steps and interior vertices on the
// pattern's grid (`{{INTERIOR_GRID}}`, the pattern's own file's, named by the pipeline's
// table).

// Parameter k of edge e in canonical orientation: `Plan::param` of a `SamplingKind::Uniform`
// plan, `tessera::sampling::uniform_param`.
fn grid_edge_param(e: u32, k: u32) -> f32 {
    return uniform_param(segments[e], k);
}

// Interior vertex j of patch p: on a quad, grid point (j mod (nu − 1) + 1, j div (nu − 1) + 1)
// at `(i · (1 / nu), j · (1 / nv))`, as the uniform and transition patterns place their grids
// (`uniform::grid`, `transition::QuadLayout::build`); on a triangle the n-grid's interior
// points row after row (`TriLayout::build`).
fn grid_interior_point(p: u32, j: u32) -> vec2<f32> {
    let grid = {{INTERIOR_GRID}}(p);
    if (patch_is_tri(p)) {
        // The triangle grid's interior rows r = 1 … n − 2 hold n − 1 − r points each
        // (`uniform::grid`). Cost: O(n) to find the row.
        let n = grid.x;
        var row = 1u;
        var first = 0u;
        while (j >= first + (n - 1u - row)) {
            first = first + (n - 1u - row);
            row = row + 1u;
        }
        let step = 1.0 / f32(n);
        return vec2<f32>(f32(j - first + 1u) * step, f32(row) * step);
    }
    return vec2<f32>(
        f32(j % (grid.x - 1u) + 1u) * (1.0 / f32(grid.x)),
        f32(j / (grid.x - 1u) + 1u) * (1.0 / f32(grid.y)),
    );
}
