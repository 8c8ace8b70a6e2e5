// The semi-uniform pattern (`tessera::pattern::semi_uniform::SemiUniform`, paper 000): the
// uniform pattern's n-grid (n = 2^m, the patch level `interior[p].x`) with every boundary
// point moved by the snap function to its edge's own, coarser dyadic sampling; triangles
// whose corners then coincide are dropped, the others keep `uniform::grid`'s order. Numbered
// as every pattern is (`local.wgsl`), so the layout maps it as on the CPU.
//
// Only a triangle with two corners on the boundary can drop (interior points never move,
// and a collapsed curve's points are boundary points too): on a quad the cells of the outer
// ring, on a triangle the first two and last two triangles of a row, and the whole first
// and last rows. A row's kept triangles are therefore counted in O(1) but for those two rows
// (O(n)), and the triangle pass splits a patch's rows into `Params::blocks` blocks (at most
// ROW_BLOCKS), one invocation each: a block's first output triangle follows from the rows
// before it in O(n), so no invocation walks a whole pattern (2n² triangles, past lavapipe's
// loop limit at level 8) and the blocks are written in parallel. Blocks rather than one
// invocation a row: most patches of a frame have few rows, and a dispatch sized for the
// cap's rows left most invocations idle (6× the transition pattern's pass on lavapipe).

// `semi_uniform::snap_index`: `σ_p(k / 2^m) = K / 2^p`, ties towards the nearer corner.
fn snap_index(p: u32, m: u32, k: u32) -> u32 {
    let n = 1u << m;
    let s = 1u << (m - p);
    let r = k % s;
    let up = 2u * r > s || (2u * r == s && 2u * k >= n);
    return k / s + select(0u, 1u, up);
}

// The local index of φ(i, j) for a patch of level m (`semi_uniform::Layout::local`): corners
// and interior points stay, an edge point goes to its snapped sample (or a corner).
fn semi_uniform_local(input: LocalNumbering, n: u32, m: u32, i: u32, j: u32) -> u32 {
    let slot = grid_slot(input.nc == 3u, n, i, j);
    if (slot.kind == 0u) { return slot.index; }
    if (slot.kind == 2u) { return input.interior_base + slot.k; }
    let e = slot.index;
    let s = pick4(input.s, e);
    let snapped = snap_index(countTrailingZeros(s), m, slot.k);
    if (snapped == 0u) { return e; }
    if (snapped == s) { return (e + 1u) % input.nc; }
    return pick4(input.base, e) + snapped - 1u;
}

// The domain position of grid point (i, j) after the snap (`PatternInput::local_positions`
// of the local index `semi_uniform_local` gives): a corner, the snapped sample of its edge
// (`uniform_param` along `Domain::edge_point`), or the grid point itself.
fn semi_uniform_param(input: LocalNumbering, n: u32, m: u32, i: u32, j: u32) -> vec2<f32> {
    let slot = grid_slot(input.nc == 3u, n, i, j);
    if (slot.kind == 0u) { return domain_corner(input.p, slot.index); }
    if (slot.kind == 2u) { return vec2<f32>(f32(i) * (1.0 / f32(n)), f32(j) * (1.0 / f32(n))); }
    let s = pick4(input.s, slot.index);
    let snapped = snap_index(countTrailingZeros(s), m, slot.k);
    return domain_edge_point(input.p, slot.index, uniform_param(s, snapped));
}

// Triangle q of row j as local indices, x = y when it snaps away (two corners coincide).
fn semi_uniform_triangle(input: LocalNumbering, n: u32, m: u32, j: u32, q: u32) -> vec3<u32> {
    let g = row_triangle(input.nc == 3u, j, q);
    let t = vec3<u32>(
        semi_uniform_local(input, n, m, g[0].x, g[0].y),
        semi_uniform_local(input, n, m, g[1].x, g[1].y),
        semi_uniform_local(input, n, m, g[2].x, g[2].y),
    );
    if (t.y == t.z || t.x == t.z) { return vec3<u32>(t.x, t.x, t.x); }
    return t;
}

// Whether triangle q of row j stays: not snapped away (`semi_uniform::push`) and not
// degenerate at a collapsed curve (`emit`'s rule, `engine::layout::degenerate_after_collapse`).
fn semi_uniform_keeps(input: LocalNumbering, n: u32, m: u32, j: u32, q: u32) -> bool {
    let t = semi_uniform_triangle(input, n, m, j, q);
    if (t.x == t.y) { return false; }
    var kept = 0u;
    emit(input, t, false, 0u, &kept);
    return kept == 1u;
}

// Kept triangles of row j: the first and last rows walked, the others' ends tested.
fn semi_uniform_row_kept(input: LocalNumbering, n: u32, m: u32, j: u32) -> u32 {
    let len = row_length(input.nc == 3u, n, j);
    var kept = 0u;
    if (j == 0u || j + 1u >= n) {
        for (var q = 0u; q < len; q = q + 1u) {
            kept = kept + select(0u, 1u, semi_uniform_keeps(input, n, m, j, q));
        }
        return kept;
    }
    // A middle row has at least 3 triangles; only its first two and last two touch the
    // boundary (quads: the ring's cells; triangles: those at i = 0 and at the hypotenuse).
    let tail = max(2u, len - 2u);
    kept = len - (2u + len - tail);
    for (var q = 0u; q < 2u; q = q + 1u) {
        kept = kept + select(0u, 1u, semi_uniform_keeps(input, n, m, j, q));
    }
    for (var q = tail; q < len; q = q + 1u) {
        kept = kept + select(0u, 1u, semi_uniform_keeps(input, n, m, j, q));
    }
    return kept;
}

// The count pass's PATCH_COUNTS: the uniform pattern's interior vertices (none move)
// and the kept triangles (`SemiUniform::counts`' 2I + B − 2 less those degenerate at a
// collapsed curve). Cost: O(n).
fn semi_uniform_patch_counts(p: u32) -> vec2<u32> {
    let input = local_numbering(p);
    let n = interior[p].x;
    let m = countTrailingZeros(n);
    var triangles = 0u;
    for (var j = 0u; j < n; j = j + 1u) {
        triangles = triangles + semi_uniform_row_kept(input, n, m, j);
    }
    return vec2<u32>(uniform_counts(input.nc == 3u, n).x, triangles);
}

// One invocation per block of a patch's rows (`Params::blocks` blocks a patch, of ⌈n / blocks⌉
// rows each; blocks past the patch's rows idle): the block's kept triangles, after those of
// the rows before it. Cost: O(n) for the rows before, O(n² / blocks) for its own.
@compute @workgroup_size(WORKGROUP)
fn write_semi_uniform_triangles(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let x = thread_index(wid, nwg, lid);
    let p = x / params.blocks;
    if (p >= params.patches) { return; }
    if (visible[p] == 0u) { return; }
    let n = interior[p].x;
    let per_block = (n + params.blocks - 1u) / params.blocks;
    let start = (x % params.blocks) * per_block;
    let end = min(n, start + per_block);
    if (start >= end) { return; }
    let m = countTrailingZeros(n);
    let input = local_numbering(p);
    var first = triangle_offsets[p];
    for (var r = 0u; r < start; r = r + 1u) {
        first = first + semi_uniform_row_kept(input, n, m, r);
    }
    var kept = 0u;
    for (var j = start; j < end; j = j + 1u) {
        for (var q = 0u; q < row_length(input.nc == 3u, n, j); q = q + 1u) {
            let t = semi_uniform_triangle(input, n, m, j, q);
            if (t.x != t.y) {
                emit(input, t, true, first, &kept);
            }
        }
    }
}
