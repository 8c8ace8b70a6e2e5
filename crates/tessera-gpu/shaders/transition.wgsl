// The CudaTess transition pattern, `tessera::pattern::transition`, on quads (`QuadLayout`)
// and triangles (`TriLayout`), with its strip walk (`walk`), on the CPU's local vertex
// numbering (`tessera::pattern::PatternInput`), mapped to output vertices by the layout's
// rule (`engine` `LocalMap::vertex`). One invocation builds one patch, in the CPU's triangle
// order, so counting and writing agree with the CPU triangle for triangle; the a-posteriori
// check (`check.wgsl`) walks the same strips to bound their triangles.

// The core of either layout: the (possibly raised) core factors, which edges have strips
// (bit e) and the core's extent in grid indices. Quads (`QuadLayout`): the rectangle
// [i_lo, i_hi] × [j_lo, j_hi]. Triangles (`TriLayout`): nu = nv = n, the core triangle of
// side m with its corner at (i_lo, j_lo); i_hi and j_hi unused.
struct QuadLayout {
    nu: u32,
    nv: u32,
    strips: u32,
    i_lo: u32,
    i_hi: u32,
    j_lo: u32,
    j_hi: u32,
    m: u32,
}

// One patch's pattern input: its local numbering (`local.wgsl`), its core, and which of a
// quad's corners 0 and 2 are pinched (bit c; `PatternInput::pinched`, the corners the
// pattern reads: `transition` module doc, "Pinched corners").
struct PatchInput {
    local: LocalNumbering,
    core: QuadLayout,
    pinched: u32,
}

// `transition::strips_at_collapsed_edges` for N edges (3 or 4), updating in place as the
// CPU does.
fn strips_at_collapsed(strip: u32, collapsed: u32, n: u32) -> u32 {
    var s = strip;
    for (var round = 0u; round < n; round = round + 1u) {
        for (var e = 0u; e < n; e = e + 1u) {
            if (bit(collapsed, e) != 0u && (bit(s, (e + 1u) % n) != 0u || bit(s, (e + n - 1u) % n) != 0u)) {
                s = s | (1u << e);
            }
        }
    }
    return s;
}

// `QuadLayout::new`; `pinched` as `PatchInput`'s.
fn quad_layout(s: vec4<u32>, interior_factors: vec2<u32>, c: u32, pinched: u32) -> QuadLayout {
    var nu = max(interior_factors.x, 1u);
    var nv = max(interior_factors.y, 1u);
    let proper = select(0u, 1u, pinched != 0u);
    loop {
        var strip = select(0u, 1u, s.x != nu) | select(0u, 2u, s.y != nv) | select(0u, 4u, s.z != nu)
            | select(0u, 8u, s.w != nv);
        strip = strips_at_collapsed(strip, c, 4u);
        let keep_u = proper | (bit(strip, 0u) & bit(c, 0u)) | (bit(strip, 2u) & bit(c, 2u));
        let keep_v = proper | (bit(strip, 1u) & bit(c, 1u)) | (bit(strip, 3u) & bit(c, 3u));
        let need_u = bit(strip, 1u) + bit(strip, 3u) + keep_u;
        let need_v = bit(strip, 0u) + bit(strip, 2u) + keep_v;
        if (nu >= need_u && nv >= need_v) {
            return QuadLayout(nu, nv, strip, bit(strip, 3u), nu - bit(strip, 1u), bit(strip, 0u), nv - bit(strip, 2u), 0u);
        }
        nu = max(nu, need_u);
        nv = max(nv, need_v);
    }
    // Unreachable: the loop returns (both factors only grow, to at most 3).
    return QuadLayout(1u, 1u, 0u, 0u, 1u, 0u, 1u, 0u);
}

// `TriLayout::new`: the core factor n raised to the number of strips where needed.
fn tri_layout(s: vec4<u32>, interior_factor: u32, c: u32) -> QuadLayout {
    var n = max(interior_factor, 1u);
    loop {
        var strip = select(0u, 1u, s.x != n) | select(0u, 2u, s.y != n) | select(0u, 4u, s.z != n);
        strip = strips_at_collapsed(strip, c, 3u);
        let need = bit(strip, 0u) + bit(strip, 1u) + bit(strip, 2u);
        if (n >= need) {
            return QuadLayout(n, n, strip, bit(strip, 2u), 0u, bit(strip, 0u), 0u, n - need);
        }
        n = need;
    }
    // Unreachable: n only grows, to at most 3.
    return QuadLayout(1u, 1u, 0u, 0u, 0u, 0u, 0u, 1u);
}

// `engine::layout::pattern_input` for patch p, with its local bases and core.
fn patch_input(p: u32) -> PatchInput {
    return pattern_input(p, interior[p]);
}

// `engine::layout::pattern_input` for patch p with interior factors `interior_factors` (the
// check tries several before the plan has one).
fn pattern_input(p: u32, interior_factors: vec2<u32>) -> PatchInput {
    let local = local_numbering(p);
    var core: QuadLayout;
    var pinched = 0u;
    if (local.nc == 3u) {
        core = tri_layout(local.s, interior_factors.x, local.collapsed);
    } else {
        pinched = select(0u, 1u, patch_corner_pinched(p, 0u)) | select(0u, 4u, patch_corner_pinched(p, 2u));
        core = quad_layout(local.s, interior_factors, local.collapsed, pinched);
    }
    return PatchInput(local, core, pinched);
}

// The pattern's core factors, read by the interior vertex pass: on a quad the interior grid
// is (nu − 1) × (nv − 1) points at (i / nu, j / nv), rows of j (`QuadLayout::build`); on a
// triangle the n-grid's interior points (`TriLayout::build`), nu = nv = n.
fn transition_interior_grid(p: u32) -> vec2<u32> {
    let input = patch_input(p);
    return vec2<u32>(input.core.nu, input.core.nv);
}

// `QuadLayout::counts` and `TriLayout::counts`: interior vertices and pattern triangles.
fn transition_counts(input: PatchInput) -> vec2<u32> {
    let l = input.core;
    if (input.local.nc == 3u) {
        var triangles = l.m * l.m;
        for (var e = 0u; e < 3u; e = e + 1u) {
            if (bit(l.strips, e) != 0u) { triangles = triangles + input.local.s[e] + l.m; }
        }
        let n = l.nu;
        return vec2<u32>(select(0u, (n - 1u) * (n - 2u) / 2u, n >= 2u), triangles);
    }
    var triangles = 2u * (l.i_hi - l.i_lo) * (l.j_hi - l.j_lo);
    for (var e = 0u; e < 4u; e = e + 1u) {
        if (bit(l.strips, e) != 0u) { triangles = triangles + input.local.s[e] + inner_segments(input, e); }
    }
    return vec2<u32>((l.nu - 1u) * (l.nv - 1u), triangles);
}

// `QuadLayout::inner_segments`; a triangle's core sides all have m segments.
fn inner_segments(input: PatchInput, e: u32) -> u32 {
    let l = input.core;
    if (input.local.nc == 3u) { return l.m; }
    if (e % 2u == 0u) { return l.i_hi - l.i_lo; }
    return l.j_hi - l.j_lo;
}

// `QuadLayout::inner` and `TriLayout::inner`: grid point t of the core side facing edge e.
fn inner_point(input: PatchInput, e: u32, t: u32) -> vec2<u32> {
    let l = input.core;
    if (input.local.nc == 3u) {
        switch e {
            case 0u: { return vec2<u32>(l.i_lo + t, l.j_lo); }
            case 1u: { return vec2<u32>(l.i_lo + l.m - t, l.j_lo + t); }
            default: { return vec2<u32>(l.i_lo, l.j_lo + l.m - t); }
        }
    }
    switch e {
        case 0u: { return vec2<u32>(l.i_lo + t, l.j_lo); }
        case 1u: { return vec2<u32>(l.i_hi, l.j_lo + t); }
        case 2u: { return vec2<u32>(l.i_hi - t, l.j_hi); }
        default: { return vec2<u32>(l.i_lo, l.j_hi - t); }
    }
}

// `QuadLayout::local` and `TriLayout::local`: local index of core grid point (i, j).
fn grid_local(input: PatchInput, i: u32, j: u32) -> u32 {
    if (input.local.nc == 3u) {
        let n = input.core.nu;
        if (i == 0u && j == 0u) { return 0u; }
        if (i == n && j == 0u) { return 1u; }
        if (i == 0u && j == n) { return 2u; }
        if (j == 0u) { return input.local.base[0] + i - 1u; }
        if (i + j == n) { return input.local.base[1] + j - 1u; }
        if (i == 0u) { return input.local.base[2] + (n - j) - 1u; }
        // Interior rows 1 … j − 1 before this one hold n − 1 − r points each.
        let before = (j - 1u) * (n - 1u) - (j - 1u) * j / 2u;
        return input.local.interior_base + before + (i - 1u);
    }
    let nu = input.core.nu;
    let nv = input.core.nv;
    if (i == 0u && j == 0u) { return 0u; }
    if (i == nu && j == 0u) { return 1u; }
    if (i == nu && j == nv) { return 2u; }
    if (i == 0u && j == nv) { return 3u; }
    if (j == 0u) { return input.local.base[0] + i - 1u; }
    if (i == nu) { return input.local.base[1] + j - 1u; }
    if (j == nv) { return input.local.base[2] + (nu - i) - 1u; }
    if (i == 0u) { return input.local.base[3] + (nv - j) - 1u; }
    return input.local.interior_base + (j - 1u) * (nu - 1u) + (i - 1u);
}

// Domain position of outer point k of edge e (`Domain::edge_point(e, k / s)`), for ties only.
fn outer_position(input: PatchInput, e: u32, k: u32) -> vec2<f32> {
    return domain_edge_point(input.local.p, e, f32(k) / f32(input.local.s[e]));
}

// Domain position of core grid point (i, j): `(i·(1/nu), j·(1/nv))`, as the CPU builds the
// interior (`QuadLayout::build`, `TriLayout::build`).
fn grid_position(input: PatchInput, i: u32, j: u32) -> vec2<f32> {
    return vec2<f32>(f32(i) * (1.0 / f32(input.core.nu)), f32(j) * (1.0 / f32(input.core.nv)));
}

fn inner_position(input: PatchInput, e: u32, t: u32) -> vec2<f32> {
    let g = inner_point(input, e, t);
    return grid_position(input, g.x, g.y);
}

// What a pattern build does with each triangle: count it, write it (`emit`), or bound its
// error (the a-posteriori check, `check.wgsl`).
const SINK_COUNT: u32 = 0u;
const SINK_WRITE: u32 = 1u;
const SINK_CHECK: u32 = 2u;

// A build's triangle sink: its mode, the first output triangle (SINK_WRITE), the triangles
// taken, and for SINK_CHECK the largest error bound so far and the patch's bound data.
struct Sink {
    mode: u32,
    first: u32,
    kept: u32,
    worst: f32,
    errors: TriangleErrors,
    // The patch's expansion bound (`expansion.wgsl`; EXPANSION_NONE: the second-derivative
    // bound alone).
    expansion: Expansion,
}

fn sink(mode: u32, first: u32) -> Sink {
    return Sink(mode, first, 0u, 0.0, triangle_errors(vec3<f32>(0.0)), no_expansion(0u));
}

// Takes pattern triangle `tri` (local indices; ta, tb, tc its domain positions): counted or
// written by `emit`, or, for the check, its error bound taken — every triangle of the
// pattern, those a collapsed curve degenerates included, as `tolerance::params_bound` takes
// them over the built pattern.
fn take(input: PatchInput, tri: vec3<u32>, ta: vec2<f32>, tb: vec2<f32>, tc: vec2<f32>, out: ptr<function, Sink>) {
    if ((*out).mode == SINK_CHECK) {
        // The expansion bound, dearer, only where it could raise the largest so far
        // (`tolerance::triangles_bound`).
        let e = triangle_error((*out).errors, ta, tb, tc);
        if (e > (*out).worst) {
            (*out).worst = max((*out).worst, min(e, expansion_triangle_error((*out).expansion, ta, tb, tc)));
        }
        (*out).kept = (*out).kept + 1u;
        return;
    }
    take_core(input, tri, out);
}

// `take` of a core triangle, which the check never takes (it bounds the core's cells
// together): counted or written.
fn take_core(input: PatchInput, tri: vec3<u32>, out: ptr<function, Sink>) {
    // Through a local: naga 30's SPIR-V writer cannot pass a pointer to a member of a
    // pointed-to struct ("expression is not cached").
    var kept = (*out).kept;
    emit(input.local, tri, (*out).mode == SINK_WRITE, (*out).first, &kept);
    (*out).kept = kept;
}

fn inner_local(input: PatchInput, e: u32, t: u32) -> u32 {
    let g = inner_point(input, e, t);
    return grid_local(input, g.x, g.y);
}

// Relative difference below which the two diagonals of a tie count as equal. The CPU
// (f64) uses 1e-9; f32 positions carry ~1e-7 relative rounding, so equal diagonals (the
// symmetric case, common) must not be told apart by it.
const TIE_TOLERANCE: f32 = 1e-5;

// `transition::walk`: the strip along edge e between its s outer segments and the m inner
// ones, Bresenham-like, with `lead` / `trail` virtual segments (the two-region modification),
// its first or last step on the inner line where a pinched corner pins it
// (`transition::pinned_ends`: a pinched corner 0 or 2 without a strip on its other edge).
fn walk(input: PatchInput, e: u32, out: ptr<function, Sink>) {
    let l = input.core;
    let s = input.local.s[e];
    let m = inner_segments(input, e);
    let lead = bit(l.strips, (e + input.local.nc - 1u) % input.local.nc);
    let trail = bit(l.strips, (e + 1u) % input.local.nc);
    // `pinched` marks corners 0 and 2 only (triangles: none).
    let pin_start = bit(input.pinched, e) == 1u && lead == 0u;
    let pin_end = bit(input.pinched, (e + 1u) % input.local.nc) == 1u && trail == 0u;
    let span = i32(m + lead + trail);
    let s32 = i32(s);
    var d = span - (2 * i32(lead) + 1) * s32;
    var i = 0u;
    var j = 0u;
    var o0 = boundary_local(input.local, e, 0u);
    var o1 = boundary_local(input.local, e, 1u);
    var n0 = inner_local(input, e, 0u);
    var n1 = select(n0, inner_local(input, e, 1u), m > 0u);
    while (i < s || j < m) {
        var advance_outer = false;
        if (j == m) {
            advance_outer = true;
        } else if (i == s) {
            advance_outer = false;
        } else if (pin_start && i == 0u && j == 0u) {
            advance_outer = false;
        } else if (pin_end && j + 1u == m) {
            // The last inner step waits until the outer line is done.
            advance_outer = true;
        } else if (d != 0) {
            advance_outer = d < 0;
        } else {
            let o0p = outer_position(input, e, i);
            let o1p = outer_position(input, e, i + 1u);
            let n0p = inner_position(input, e, j);
            let n1p = inner_position(input, e, j + 1u);
            let via_outer = dot(o1p - n0p, o1p - n0p);
            let via_inner = dot(o0p - n1p, o0p - n1p);
            if (abs(via_outer - via_inner) > TIE_TOLERANCE * max(via_outer, via_inner)) {
                advance_outer = via_outer < via_inner;
            } else {
                advance_outer = 2u * i + 1u > s;
            }
        }
        // One `take` a step, after the choice: the check's bound (`expansion.wgsl`) is
        // compiled once a walk, not once a branch (every call is inlined).
        var tri: vec3<u32>;
        var tb: vec2<f32>;
        if (advance_outer) {
            tri = vec3<u32>(o0, o1, n0);
            tb = outer_position(input, e, i + 1u);
        } else {
            tri = vec3<u32>(o0, n1, n0);
            tb = inner_position(input, e, j + 1u);
        }
        take(input, tri, outer_position(input, e, i), tb, inner_position(input, e, j), out);
        if (advance_outer) {
            i = i + 1u;
            if (j < m && i < s) { d = d + 2 * span; }
            o0 = o1;
            if (i < s) { o1 = boundary_local(input.local, e, i + 1u); }
        } else {
            j = j + 1u;
            if (j < m && i < s) { d = d - 2 * s32; }
            n0 = n1;
            if (j < m) { n1 = inner_local(input, e, j + 1u); }
        }
    }
}

// `TriLayout::build`'s triangles: the core in the uniform pattern's loop and vertex order,
// shifted to the core's corner, then each strip's walk, into `out`. The check takes the
// strips only: every core triangle is half a grid cell, bounded once (`check.wgsl`).
fn build_tri_transition(input: PatchInput, out: ptr<function, Sink>) {
    let l = input.core;
    let i0 = l.i_lo;
    let j0 = l.j_lo;
    let m = select(l.m, 0u, (*out).mode == SINK_CHECK);
    for (var j = 0u; j < m; j = j + 1u) {
        for (var i = 0u; i < m - j; i = i + 1u) {
            let a = grid_local(input, i0 + i, j0 + j);
            let b = grid_local(input, i0 + i + 1u, j0 + j);
            let d = grid_local(input, i0 + i, j0 + j + 1u);
            take_core(input, vec3<u32>(a, b, d), out);
            if (i + j + 2u <= m) {
                take_core(input, vec3<u32>(b, grid_local(input, i0 + i + 1u, j0 + j + 1u), d), out);
            }
        }
    }
    for (var e = 0u; e < 3u; e = e + 1u) {
        if (bit(l.strips, e) != 0u) { walk(input, e, out); }
    }
}

// `QuadLayout::build`'s triangles: the core cells row after row, then each strip's walk
// (`build_tri_transition` on triangles), into `out`; the check takes the strips only (see
// there). Cost: O(pattern triangles), serial.
fn build_transition(input: PatchInput, out: ptr<function, Sink>) {
    if (input.local.nc == 3u) {
        build_tri_transition(input, out);
        return;
    }
    let l = input.core;
    let j_end = select(l.j_hi, l.j_lo, (*out).mode == SINK_CHECK);
    for (var j = l.j_lo; j < j_end; j = j + 1u) {
        for (var i = l.i_lo; i < l.i_hi; i = i + 1u) {
            let a = grid_local(input, i, j);
            let b = grid_local(input, i + 1u, j);
            let c = grid_local(input, i + 1u, j + 1u);
            let d = grid_local(input, i, j + 1u);
            take_core(input, vec3<u32>(a, b, c), out);
            take_core(input, vec3<u32>(a, c, d), out);
        }
    }
    for (var e = 0u; e < 4u; e = e + 1u) {
        if (bit(l.strips, e) != 0u) { walk(input, e, out); }
    }
}

// Counts of the transition pattern for the count pass (`count.wgsl`): a visible patch's
// `transition_counts`, its triangles rebuilt and counted where a corner repeats.
fn transition_patch_counts(p: u32) -> vec2<u32> {
    let input = patch_input(p);
    var counts = transition_counts(input);
    if (patch_repeated_corner(p)) {
        var out = sink(SINK_COUNT, 0u);
        build_transition(input, &out);
        counts.y = out.kept;
    }
    return counts;
}

// Triangle pass: one invocation per visible patch writes its pattern.
@compute @workgroup_size(WORKGROUP)
fn write_transition_triangles(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (p >= params.patches || visible[p] == 0u) { return; }
    var out = sink(SINK_WRITE, triangle_offsets[p]);
    build_transition(patch_input(p), &out);
}
