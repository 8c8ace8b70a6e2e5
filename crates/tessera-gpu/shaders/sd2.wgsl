// The SD-2 pattern (`tessera::pattern::sd2::Sd2`, paper 001) on triangle domains with at most
// two different edge factors: the two *same* edges meet at the tip, a bundle of lines
// parallel to the *diff* edge cuts them at their samples (rows i = 0 at the tip … ns at the
// diff edge), radial lines run from the tip to the diff edge's samples (j = 0 … nd), and each
// radial sector is one strip from the tip outwards. Edges are cut by the symmetric remainder
// (`sampling::symmetric_param`). Numbered as every pattern is (`local.wgsl`). With the
// reverse projection (`--warp`, `params.warped`), the edge points and the interior are warped
// by the plan's depths (§3.3).
//
// No compaction: triangle t of a patch is strip triangle t mod (2ns − 1) of sector
// t div (2ns − 1), so the triangle pass runs one invocation per output triangle; only the
// patches with a repeated corner (whose degenerate triangles are left out) take the per-patch
// walk, as the uniform pattern's do.

// `sampling::symmetric_param`: point k of the cut of an edge with real factor f ≥ 1 into
// n = ⌈f⌉ segments, the inner ones 1/f long and the remainder shared by the first and last;
// the second half mirrors the first, so the cut needs no direction.
fn symmetric_param(factor: f32, k: u32) -> f32 {
    let f = max(factor, 1.0);
    let n = u32(ceil(f));
    if (k == 0u) { return 0.0; }
    if (k >= n) { return 1.0; }
    if (2u * k == n) { return 0.5; }
    let mirrored = 2u * k > n;
    let kk = select(k, n - k, mirrored);
    let remainder = f - f32(n - 1u);
    let t = f32(kk) / f - 0.5 * (1.0 - remainder) / f;
    return select(t, 1.0 - t, mirrored);
}

// Edge e's depths at its canonical ends (`Plan::depths`, after the factors).
fn edge_depths(e: u32) -> vec2<f32> {
    let at = 2u * params.edges + 2u * e;
    return vec2<f32>(bitcast<f32>(segments[at]), bitcast<f32>(segments[at + 1u]));
}

// `sampling::warped_param`: t warped by reverse projection between ends of depths za and zb.
fn warped_param(t: f32, za: f32, zb: f32) -> f32 {
    if (t <= 0.0) { return 0.0; }
    if (t >= 1.0) { return 1.0; }
    let a = (1.0 - t) / za;
    let b = t / zb;
    return b / (a + b);
}

// The depth at patch p's corner c: its local edge c's depth where that edge starts
// (`sd2::plan`'s corner depths are the same f32 values).
fn corner_depth(p: u32, c: u32) -> f32 {
    let z = edge_depths(patch_edge(p, c));
    return select(z.x, z.y, patch_edge_reversed(p, c));
}

// `Sd2::warp`: a domain point's barycentric weights divided by the corner depths, normalised.
fn sd2_warp(p: u32, q: vec2<f32>) -> vec2<f32> {
    let w = vec3<f32>(1.0 - q.x - q.y, q.x, q.y)
        / vec3<f32>(corner_depth(p, 0u), corner_depth(p, 1u), corner_depth(p, 2u));
    let s = w.x + w.y + w.z;
    return vec2<f32>(w.y / s, w.z / s);
}

// One SD-2 triangle's layout (`sd2::Layout`): the diff edge d (corner d → d + 1; the tip is
// corner d + 2), the segments of the same edges (ns) and of the diff edge (nd), and their
// real factors.
struct Sd2Layout {
    d: u32,
    ns: u32,
    nd: u32,
    fs: f32,
    fd: f32,
}

// `sd2::diff_edge` on patch p's edge factors (the plan's, which `prepare` checked hold at
// most two different values): edges 1 and 2 agree → 0, 2 and 0 → 1, else 2.
fn sd2_layout(p: u32) -> Sd2Layout {
    let f = vec3<f32>(
        edge_factor(patch_edge(p, 0u)),
        edge_factor(patch_edge(p, 1u)),
        edge_factor(patch_edge(p, 2u)),
    );
    var d = 2u;
    if (f.y == f.z) {
        d = 0u;
    } else if (f.z == f.x) {
        d = 1u;
    }
    let same = (d + 1u) % 3u;
    return Sd2Layout(d, segments[patch_edge(p, same)], segments[patch_edge(p, d)], f[same], f[d]);
}

// The local index of row i (from the tip), radial line j (`sd2::Layout::vertex`).
fn sd2_vertex(input: LocalNumbering, l: Sd2Layout, i: u32, j: u32) -> u32 {
    if (i == 0u) { return (l.d + 2u) % 3u; }
    if (i == l.ns) { return boundary_local(input, l.d, j); }
    // Edge d + 2 runs from the tip to corner d: its sample i is row i.
    if (j == 0u) { return boundary_local(input, (l.d + 2u) % 3u, i); }
    // Edge d + 1 runs from corner d + 1 to the tip: row i is its sample ns − i.
    if (j == l.nd) { return boundary_local(input, (l.d + 1u) % 3u, l.ns - i); }
    return input.interior_base + (i - 1u) * (l.nd - 1u) + (j - 1u);
}

// Triangle k of sector j's strip (tip, (1, j), (1, j + 1), (2, j), …) as the strip decodes:
// even k [v_k, v_k+1, v_k+2], odd k [v_k+1, v_k, v_k+2] (`mesh::strips::decode`).
fn sd2_triangle(input: LocalNumbering, l: Sd2Layout, j: u32, k: u32) -> vec3<u32> {
    let a = sd2_strip_vertex(input, l, j, k);
    let b = sd2_strip_vertex(input, l, j, k + 1u);
    let c = sd2_strip_vertex(input, l, j, k + 2u);
    if (k % 2u == 0u) { return vec3<u32>(a, b, c); }
    return vec3<u32>(b, a, c);
}

// Strip vertex m of sector j: the tip, then (i, j) at odd m = 2i − 1 and (i, j + 1) at even
// m = 2i.
fn sd2_strip_vertex(input: LocalNumbering, l: Sd2Layout, j: u32, m: u32) -> u32 {
    if (m == 0u) { return (l.d + 2u) % 3u; }
    return sd2_vertex(input, l, (m + 1u) / 2u, select(j + 1u, j, m % 2u == 1u));
}

// Every triangle of patch p in order, through `emit` (counted, and with `write` written from
// output triangle `first` on); returns the kept ones. Cost: O(nd · ns), serial.
fn sd2_walk(p: u32, write: bool, first: u32) -> u32 {
    let input = local_numbering(p);
    let l = sd2_layout(p);
    var kept = 0u;
    for (var j = 0u; j < l.nd; j = j + 1u) {
        for (var k = 0u; k < 2u * l.ns - 1u; k = k + 1u) {
            emit(input, sd2_triangle(input, l, j, k), write, first, &kept);
        }
    }
    return kept;
}

// The count pass's PATCH_COUNTS: `Sd2::counts`, (ns − 1)(nd − 1) interior vertices and
// nd (2ns − 1) triangles, less those degenerate at a collapsed curve.
fn sd2_patch_counts(p: u32) -> vec2<u32> {
    let l = sd2_layout(p);
    var triangles = l.nd * (2u * l.ns - 1u);
    if (patch_repeated_corner(p)) { triangles = sd2_walk(p, false, 0u); }
    return vec2<u32>((l.ns - 1u) * (l.nd - 1u), triangles);
}

// The vertex passes' EDGE_PARAM: the symmetric cut of the edge's real factor, warped with
// the edge's depths in a warped plan (`sampling::param` of `SamplingKind::Warped`).
fn sd2_edge_param(e: u32, k: u32) -> f32 {
    let t = symmetric_param(edge_factor(e), k);
    if (params.warped != 0u) {
        let z = edge_depths(e);
        return warped_param(t, z.x, z.y);
    }
    return t;
}

// The vertex passes' INTERIOR_POINT: interior vertex jj is row i, radial line j, at fraction
// r of the way from the tip to the diff edge's point s (`Sd2::triangulate`).
fn sd2_interior_point(p: u32, jj: u32) -> vec2<f32> {
    let l = sd2_layout(p);
    let i = jj / (l.nd - 1u) + 1u;
    let j = jj % (l.nd - 1u) + 1u;
    let r = symmetric_param(l.fs, i);
    let s = symmetric_param(l.fd, j);
    let tip = domain_corner(p, (l.d + 2u) % 3u);
    let on_diff = domain_corner(p, l.d) * (1.0 - s) + domain_corner(p, (l.d + 1u) % 3u) * s;
    let q = tip * (1.0 - r) + on_diff * r;
    if (params.warped != 0u) { return sd2_warp(p, q); }
    return q;
}

// One invocation per output triangle, for the patches without a repeated corner (every
// pattern triangle kept, so output triangle t is pattern triangle t).
@compute @workgroup_size(WORKGROUP)
fn write_sd2_triangles(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let t = thread_index(wid, nwg, lid);
    let p = plain_triangle_patch(t);
    if (p == params.patches) { return; }
    let l = sd2_layout(p);
    let local = t - triangle_offsets[p];
    let per_sector = 2u * l.ns - 1u;
    let input = local_numbering(p);
    let tri = sd2_triangle(input, l, local / per_sector, local % per_sector);
    indices[3u * t] = local_vertex(input, tri.x);
    indices[3u * t + 1u] = local_vertex(input, tri.y);
    indices[3u * t + 2u] = local_vertex(input, tri.z);
}

// One invocation per patch with a repeated corner: its kept triangles in pattern order.
@compute @workgroup_size(WORKGROUP)
fn write_sd2_collapsed_triangles(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (!collapsed_patch(p)) { return; }
    _ = sd2_walk(p, true, triangle_offsets[p]);
}
