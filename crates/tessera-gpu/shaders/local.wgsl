// A patch's local vertex numbering, `tessera::pattern::PatternInput`'s: corners
// (`0..corner_count`), then the inner samples of edge 0, 1, … in the patch's own direction,
// then the pattern's interior vertices; mapped to output vertices by the layout's rule
// (`engine` `LocalMap::vertex`), and the rule that leaves out a triangle degenerate at a
// collapsed curve (`engine::layout::degenerate_after_collapse`). Shared by the patterns that
// build a patch in one invocation (`transition.wgsl`, `hardware.wgsl`).

// One patch's pattern input as far as the numbering needs it: its segments, which edges are
// collapsed (bit e), the first local index of each edge's inner samples
// (`PatternInput::edge_base`) and of the interior (`PatternInput::interior_base`); nc is the
// domain's corner count (3 for a triangle domain).
struct LocalNumbering {
    p: u32,
    nc: u32,
    s: vec4<u32>,
    collapsed: u32,
    base: vec4<u32>,
    interior_base: u32,
}

// Bit e of `mask`.
fn bit(mask: u32, e: u32) -> u32 { return (mask >> e) & 1u; }

// Component i of v, by selects: a vector indexed by a variable may become a memory copy on
// some drivers, at every use in a long serial walk.
fn pick4(v: vec4<u32>, i: u32) -> u32 {
    return select(select(select(v.x, v.y, i == 1u), v.z, i == 2u), v.w, i == 3u);
}

// `engine::layout::pattern_input` for patch p, as far as the numbering reads it.
fn local_numbering(p: u32) -> LocalNumbering {
    let nc = patch_corner_count(p);
    let quad = nc == 4u;
    let s = vec4<u32>(
        segments[patch_edge(p, 0u)],
        segments[patch_edge(p, 1u)],
        segments[patch_edge(p, 2u)],
        select(0u, segments[patch_edge(p, 3u)], quad),
    );
    var collapsed = 0u;
    for (var e = 0u; e < nc; e = e + 1u) {
        if (patch_edge_collapsed(p, e)) { collapsed = collapsed | (1u << e); }
    }
    let b1 = nc + s.x - 1u;
    let b2 = b1 + s.y - 1u;
    let b3 = b2 + s.z - 1u;
    let interior_base = select(b3, b3 + s.w - 1u, quad);
    return LocalNumbering(p, nc, s, collapsed, vec4<u32>(nc, b1, b2, b3), interior_base);
}

// `PatternInput::boundary_vertex`: the local index of boundary point k of edge e.
fn boundary_local(input: LocalNumbering, e: u32, k: u32) -> u32 {
    if (k == 0u) { return e; }
    if (k == pick4(input.s, e)) { return (e + 1u) % input.nc; }
    return pick4(input.base, e) + k - 1u;
}

// The local edge whose inner samples hold local index l (nc ≤ l < interior_base). Without a
// loop: lavapipe (llvmpipe) stops every loop of an invocation once its loops have iterated
// 65,535 times in all, and a per-patch walk calls this for every triangle corner.
fn local_edge(input: LocalNumbering, l: u32) -> u32 {
    return select(0u, 1u, l >= input.base.y) + select(0u, 1u, l >= input.base.z)
        + select(0u, 1u, input.nc == 4u && l >= input.base.w);
}

// `LocalMap::vertex`: the output vertex of local index l.
fn local_vertex(input: LocalNumbering, l: u32) -> u32 {
    if (l < input.nc) { return patch_corner_entry(input.p, l); }
    if (l < input.interior_base) {
        let e = local_edge(input, l);
        return edge_sample_vertex(input.p, e, l - pick4(input.base, e) + 1u);
    }
    return vertex_offsets[params.edges + input.p] + (l - input.interior_base);
}

// The identity `degenerate_after_collapse` compares for local index l: corners and samples
// of collapsed curves are their corner entry (x = 1), any other index is itself (x = 0).
fn local_collapse_id(input: LocalNumbering, l: u32) -> vec2<u32> {
    if (l < input.nc) { return vec2<u32>(1u, patch_corner_entry(input.p, l)); }
    if (l < input.interior_base) {
        let e = local_edge(input, l);
        if (bit(input.collapsed, e) != 0u) { return vec2<u32>(1u, patch_corner_entry(input.p, e)); }
    }
    return vec2<u32>(0u, l);
}

// Takes pattern triangle `tri` (local indices): left out if it degenerates at a collapsed
// curve, else counted and, with `write`, written as output triangle `first + *kept` (the
// engine's `Writer::patch`).
fn emit(input: LocalNumbering, tri: vec3<u32>, write: bool, first: u32, kept: ptr<function, u32>) {
    if (patch_repeated_corner(input.p)) {
        let a = local_collapse_id(input, tri.x);
        let b = local_collapse_id(input, tri.y);
        let c = local_collapse_id(input, tri.z);
        if (all(a == b) || all(b == c) || all(a == c)) { return; }
    }
    if (write) {
        let t = first + *kept;
        indices[3u * t] = local_vertex(input, tri.x);
        indices[3u * t + 1u] = local_vertex(input, tri.y);
        indices[3u * t + 2u] = local_vertex(input, tri.z);
    }
    *kept = *kept + 1u;
}
