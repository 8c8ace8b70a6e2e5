// The Direct3D 11 hardware tessellator's patterns (`integer`, `pow2`, `fractional_odd`,
// `fractional_even`), the GPU form of `tessera::pattern::hardware` as the engine draws it
// (`Hardware`'s `Pattern` impl): the same factor processing, rings and stitches, on the CPU's
// local vertex numbering (`local.wgsl`), so counts, interior points and triangles are the
// CPU's — the points bit for bit (16.16 fixed point, `hardware_partition.wgsl`), the
// triangles index for index.
//
// Points of the hardware's own order ("hardware points" h): the outer ring first (each
// Direct3D edge's points but its last), then the interior points ring by ring; the outer ring
// maps to the patch's boundary slots (`Hardware::build`'s local table), interior point j to
// the patch's interior vertex j. A ring is a cycle of hardware points split into sides that
// share their end points (`mod.rs`'s `Ring`); every ring but the degenerate one is a run of
// consecutive points, so rings are computed, not stored.
//
// Parallelism: the count and vertex passes are parallel over patches and vertices (a point's
// place is O(rings) to find); the triangle pass runs one invocation per patch, walking its
// bands and stitches serially in the CPU's order (`write_hardware_triangles`).

// Direct3D edge and inside factors of one patch, in Direct3D's order (quad `U==0, V==0,
// U==1, V==1`; tri `U==0, V==0, W==0`; inside quad `[U, V]`, tri `[inside, inside]`).
struct HardwareFactors {
    edges: vec4<f32>,
    inside: vec2<f32>,
}

// `Hardware::factors`: the plan's edge factors in Direct3D's order and the inside factors by
// Direct3D's `max` reduction (for fractional_odd quads each raised to at least the other's,
// capped at 3). The plan's interior factors are not read, as on the CPU.
fn hardware_factors(p: u32) -> HardwareFactors {
    let nc = patch_corner_count(p);
    let f = vec4<f32>(
        edge_factor(patch_edge(p, 0u)),
        edge_factor(patch_edge(p, 1u)),
        edge_factor(patch_edge(p, 2u)),
        select(1.0, edge_factor(patch_edge(p, 3u)), nc == 4u),
    );
    // Direct3D edge (e + 1) mod nc is tessera edge e (`pattern::hardware::d3d_edge`).
    var edges = vec4<f32>(f.z, f.x, f.y, 1.0);
    if (nc == 4u) { edges = vec4<f32>(f.w, f.x, f.y, f.z); }
    var inside: vec2<f32>;
    if (nc == 4u) {
        inside = vec2<f32>(max(edges[1], edges[3]), max(edges[0], edges[2]));
        if (params.partitioning == PARTITIONING_FRACTIONAL_ODD) {
            inside = vec2<f32>(max(inside.x, min(inside.y, 3.0)), max(inside.y, min(inside.x, 3.0)));
        }
    } else {
        let m = max(max(edges[0], edges[1]), edges[2]);
        inside = vec2<f32>(m, m);
    }
    return HardwareFactors(edges, inside);
}

// `pattern::hardware::Processed`: the factors of one patch processed.
struct Processed {
    nc: u32,
    // All factors 1 (integer and odd modes): the bare domain, 2 (1) triangles.
    minimum: bool,
    // Edge partitions in Direct3D's edge order.
    outer: array<Axis, 4>,
    // Inside partitions (quad `U, V`; tri `[inside, inside]`), at least 4 points (odd) or 3
    // (even).
    inside: array<Axis, 2>,
}

// `Processed::new` for positive edge factors (tessera's are at least 1, so the hardware never
// culls here). Arrays and vectors are indexed by constants only (see `pick4`).
fn processed(nc: u32, mode: u32, factors: HardwareFactors) -> Processed {
    let range = partitioning_range(mode);
    let quad = nc == 4u;
    let raw = factors.edges;
    let e = vec4<f32>(
        clamp_factor(raw.x, range.x, range.y, mode),
        clamp_factor(raw.y, range.x, range.y, mode),
        clamp_factor(raw.z, range.x, range.y, mode),
        select(1.0, clamp_factor(raw.w, range.x, range.y, mode), quad),
    );
    let frame_threshold = 1.0 + FIXED_EPSILON / 2.0;
    var frame = e.x > frame_threshold || e.y > frame_threshold || e.z > frame_threshold
        || (quad && e.w > frame_threshold);
    // Quads also look at the raw inside factors; triangles have only one.
    if (quad) {
        frame = frame || factors.inside.x > frame_threshold || factors.inside.y > frame_threshold;
    }
    frame = frame && mode == PARTITIONING_FRACTIONAL_ODD;
    let inside_lo = select(range.x, 1.0 + FIXED_EPSILON, frame);
    let iu = clamp_factor(factors.inside.x, inside_lo, range.y, mode);
    // A triangle's one inside factor serves both.
    let iv = select(iu, clamp_factor(factors.inside.y, inside_lo, range.y, mode), quad);
    let one = vec4<u32>(FIXED_ONE);
    let fixed_edges = vec4<u32>(to_fixed(e.x), to_fixed(e.y), to_fixed(e.z), select(FIXED_ONE, to_fixed(e.w), quad));
    let minimum = (partitioning_is_integer(mode) || mode == PARTITIONING_FRACTIONAL_ODD)
        && all(fixed_edges == one) && to_fixed(iu) == FIXED_ONE && to_fixed(iv) == FIXED_ONE;
    var pre: Processed;
    pre.nc = nc;
    pre.minimum = minimum;
    pre.outer[0] = axis_new(fixed_edges.x, parity_odd(e.x, mode, false));
    pre.outer[1] = axis_new(fixed_edges.y, parity_odd(e.y, mode, false));
    pre.outer[2] = axis_new(fixed_edges.z, parity_odd(e.z, mode, false));
    pre.outer[3] = axis_new(fixed_edges.w, select(true, parity_odd(e.w, mode, false), quad));
    pre.inside[0] = inside_axis_new(iu, mode);
    pre.inside[1] = inside_axis_new(iv, mode);
    return pre;
}

// An inside partition: at least 4 points (odd) or 3 (even); fewer would leave no interior,
// and the transition regions degenerate instead.
fn inside_axis_new(f: f32, mode: u32) -> Axis {
    var a = axis_new(to_fixed(f), parity_odd(f, mode, true));
    a.points = max(a.points, select(3u, 4u, a.odd));
    return a;
}

// `pre.outer[e]` (Direct3D edge e), by constant indices (see `pick4`).
fn outer_axis(pre: Processed, e: u32) -> Axis {
    switch e {
        case 0u: { return pre.outer[0]; }
        case 1u: { return pre.outer[1]; }
        case 2u: { return pre.outer[2]; }
        default: { return pre.outer[3]; }
    }
}

// `pre.inside[k]`.
fn inside_axis(pre: Processed, k: u32) -> Axis {
    if (k == 0u) { return pre.inside[0]; }
    return pre.inside[1];
}

// Points on each Direct3D edge.
fn edge_points(pre: Processed) -> vec4<u32> {
    return vec4<u32>(pre.outer[0].points, pre.outer[1].points, pre.outer[2].points, pre.outer[3].points);
}

// Patch p's processed factors.
fn patch_processed(p: u32) -> Processed {
    return processed(patch_corner_count(p), params.partitioning, hardware_factors(p));
}

// `Processed::outer_points`: points of the outer ring.
fn outer_points(pre: Processed) -> u32 {
    var n = 0u;
    let points = edge_points(pre);
    for (var e = 0u; e < pre.nc; e = e + 1u) { n = n + pick4(points, e) - 1u; }
    return n;
}

// `Processed::centre_strip`: the strip of quads left in the middle of a quad whose smaller
// inside partition is odd, `(quads, 1 along u / 0 along v)`; `(0, 0)` when there is none.
fn centre_strip(pre: Processed) -> vec2<u32> {
    let u = pre.inside[0];
    let v = pre.inside[1];
    if (u.points > v.points && v.odd) {
        return vec2<u32>(((u.points >> 1u) - (v.points >> 1u)) * 2u + select(2u, 1u, u.odd), 1u);
    }
    if (v.points >= u.points && u.odd) {
        return vec2<u32>(((v.points >> 1u) - (u.points >> 1u)) * 2u + select(2u, 1u, v.odd), 0u);
    }
    return vec2<u32>(0u, 0u);
}

// `Processed::counts`: points (the outer ring's included) and triangles. Cost: O(rings).
fn processed_counts(pre: Processed) -> vec2<u32> {
    let nc = pre.nc;
    if (pre.minimum) { return vec2<u32>(nc, nc - 2u); }
    let outer = outer_points(pre);
    var tris = 0u;
    if (nc == 4u) {
        let n0 = pre.inside[0].points;
        let n1 = pre.inside[1].points;
        let interior = (n0 - 2u) * (n1 - 2u);
        let rings = min((n0 + 1u) >> 1u, (n1 + 1u) >> 1u);
        for (var r = 1u; r < rings; r = r + 1u) {
            for (var e = 0u; e < 4u; e = e + 1u) {
                // Side e of ring r has n[axis(e)] − 2r points; axis(e) = (e + 1) & 1.
                let n = select(n1, n0, (e & 1u) == 1u);
                var out = n - 2u * (r - 1u);
                if (r == 1u) { out = pick4(edge_points(pre), e); }
                tris = tris + (n - 2u * r) + out - 2u;
            }
        }
        tris = tris + 2u * centre_strip(pre).x;
        return vec2<u32>(outer + interior, tris);
    }
    let n = pre.inside[0].points;
    let k = (n >> 1u) - 1u;
    var interior = 3u * k * (k + 1u) + 1u;
    if (pre.inside[0].odd) { interior = 3u * (k * (k + 1u) - k); }
    let rings = (n + 1u) >> 1u;
    for (var r = 1u; r < rings; r = r + 1u) {
        for (var e = 0u; e < 3u; e = e + 1u) {
            var out = n - 2u * (r - 1u);
            if (r == 1u) { out = pick4(edge_points(pre), e); }
            tris = tris + (n - 2u * r) + out - 2u;
        }
    }
    if (pre.inside[0].odd) { tris = tris + 1u; }
    return vec2<u32>(outer + interior, tris);
}

// One ring as a cycle of hardware points (`mod.rs`'s `Ring`): a run `start..start + len`, or,
// with `line` = m > 0, the degenerate ring's cycle along a line of m consecutive points and
// back; `sides` holds each side's points (ends included).
struct Ring {
    start: u32,
    len: u32,
    line: u32,
    sides: vec4<u32>,
}

// `Ring::point`: point i of the cycle (wrapping).
fn ring_point(ring: Ring, i: u32) -> u32 {
    let j = i % ring.len;
    if (ring.line == 0u || j < ring.line) { return ring.start + j; }
    return ring.start + 2u * ring.line - 2u - j;
}

// One side of a ring, read forwards or backwards (`Ring::side_into`, reversed for the centre
// strip's inner row).
struct Side {
    ring: Ring,
    offset: u32,
    count: u32,
    reversed: bool,
}

// Side e of a ring (`Ring::side_into`): it starts where the sides before it end.
fn ring_side(ring: Ring, e: u32, reversed: bool) -> Side {
    let s = ring.sides - vec4<u32>(1u);
    let offset = select(0u, s.x, e >= 1u) + select(0u, s.y, e >= 2u) + select(0u, s.z, e >= 3u);
    return Side(ring, offset, pick4(ring.sides, e), reversed);
}

// Point j of a side.
fn side_point(side: Side, j: u32) -> u32 {
    var k = j;
    if (side.reversed) { k = side.count - 1u - j; }
    return ring_point(side.ring, side.offset + k);
}

// The outer ring (`outer_ring`): each edge's points but its last.
fn outer_ring(pre: Processed) -> Ring {
    var sides = edge_points(pre);
    if (pre.nc == 3u) { sides.w = 1u; }
    return Ring(0u, outer_points(pre), 0u, sides);
}

// Whether a quad's inside partitions end in a degenerate ring, and along which axis
// (`quad`'s `degenerate`): 1 a row along u, 2 a column along v, 0 none.
fn quad_degenerate(pre: Processed) -> u32 {
    let n0 = pre.inside[0].points;
    let n1 = pre.inside[1].points;
    if (n0 > n1 && !pre.inside[1].odd) { return 1u; }
    if (n1 >= n0 && !pre.inside[0].odd) { return 2u; }
    return 0u;
}

// Ring r of a quad (`quad`): the outer ring, the inner rings 1 … point_rings − 1 (side e of
// ring r has n[(e + 1) & 1] − 2r points, n − 1 − 2r of its own), then the degenerate ring if
// any. Ring r starts after the outer ring and the points of rings 1 … r − 1, which sum to
// (r − 1)(2(n0 + n1) − 4 − 4r).
fn quad_ring(pre: Processed, r: u32) -> Ring {
    if (r == 0u) { return outer_ring(pre); }
    let n0 = pre.inside[0].points;
    let n1 = pre.inside[1].points;
    let point_rings = min(n0, n1) >> 1u;
    let start = outer_points(pre) + (r - 1u) * (2u * (n0 + n1) - 4u - 4u * r);
    if (r < point_rings) {
        let len = 2u * (n0 - 1u - 2u * r) + 2u * (n1 - 1u - 2u * r);
        return Ring(start, len, 0u, vec4<u32>(n1 - 2u * r, n0 - 2u * r, n1 - 2u * r, n0 - 2u * r));
    }
    // The degenerate ring: a row (or column, or one point) through the middle, its sides
    // running along it and back.
    let along_u = quad_degenerate(pre) == 1u;
    let m = select(n1, n0, along_u) - 2u * r;
    if (m == 1u) { return Ring(start, 1u, 1u, vec4<u32>(1u)); }
    var sides = vec4<u32>(m, 1u, m, 1u);
    if (along_u) { sides = vec4<u32>(1u, m, 1u, m); }
    return Ring(start, 2u * m - 2u, m, sides);
}

// Ring r of a triangle (`tri`): the outer ring, inner rings 1 … n/2 − 1 (each side n − 2r
// points, n − 1 − 2r of its own; rings 1 … r − 1 hold 3(r − 1)(n − 1 − r) points), then the
// centre point of an even partition.
fn tri_ring(pre: Processed, r: u32) -> Ring {
    if (r == 0u) { return outer_ring(pre); }
    let n = pre.inside[0].points;
    let start = outer_points(pre) + 3u * (r - 1u) * (n - 1u - r);
    if (r < (n >> 1u)) {
        let side = n - 2u * r;
        return Ring(start, 3u * (side - 1u), 0u, vec4<u32>(side, side, side, 1u));
    }
    return Ring(start, 1u, 1u, vec4<u32>(1u));
}

// `pattern::hardware::reversed`: whether Direct3D edge d's points run against its partition.
fn d3d_edge_reversed(nc: u32, d: u32) -> bool {
    if (nc == 4u) { return !(d == 1u || d == 2u); }
    return d % 2u == 0u;
}

// The local index of hardware point h (`Hardware::build`'s local table), for a patch of nc
// corners whose Direct3D edges have `edge_points` points: an outer-ring point is boundary
// point k of tessera edge e (`tessera_edge`: quad e = (d + 3) mod 4, against the partition for
// e ≥ 2; tri e = (d + 2) mod 3, against it for e ≥ 1), an interior one the patch's interior
// vertex.
fn hardware_local(input: LocalNumbering, edge_points: vec4<u32>, h: u32) -> u32 {
    let nc = input.nc;
    // Where each Direct3D edge's points start on the outer ring, and where the ring ends.
    let ends = edge_points - vec4<u32>(1u);
    let start1 = ends.x;
    let start2 = start1 + ends.y;
    let start3 = start2 + ends.z;
    let outer = select(start3, start3 + ends.w, nc == 4u);
    if (h >= outer) { return input.interior_base + (h - outer); }
    // No loop (see `local_edge`): the edge by comparisons.
    let d = select(0u, 1u, h >= start1) + select(0u, 1u, h >= start2) + select(0u, 1u, nc == 4u && h >= start3);
    let rest = h - pick4(vec4<u32>(0u, start1, start2, start3), d);
    let end = pick4(ends, d);
    var q = rest;
    if (d3d_edge_reversed(nc, d)) { q = end - rest; }
    var e = (d + 2u) % 3u;
    var against = e >= 1u;
    if (nc == 4u) {
        e = (d + 3u) % 4u;
        against = e >= 2u;
    }
    var k = q;
    if (against) { k = end - q; }
    return boundary_local(input, e, k);
}

// `stitch.rs`'s FINAL_POINT_POSITION[i] (0 ≤ i ≤ 32): where vertex i of the half edge ends up
// at the largest factor, in ruler-function split order — the table 0, 32, 16, 8, 17, 4, 18, 9,
// 19, 2, 20, 10, 21, 5, 22, 11, 23, 1, 24, 12, 25, 6, 26, 13, 27, 3, 28, 14, 29, 7, 30, 15, 31
// in closed form (an array indexed by a variable would be a stack copy at every use, see
// `pick4`): even i ≥ 2 gives 15 + i/2; odd i ≥ 3 with z trailing zeros in i − 1 gives
// 16/2^z + (i − 1)/2^(z+1); 0 and 1 give 0 and 32.
fn final_point_position(i: u32) -> u32 {
    if (i == 0u) { return 0u; }
    if (i == 1u) { return 32u; }
    if ((i & 1u) == 0u) { return 15u + i / 2u; }
    let z = countTrailingZeros(i - 1u);
    return (16u >> z) + ((i - 1u) >> (z + 1u));
}

// The stitches of `stitch.rs`, each run as a generator of triangles (`stitch_step`), so that
// the walk has one place that emits a triangle: the GPU compiler inlines every call, and a
// walk calling `emit` from each of the CPU's emission sites compiles to a shader many times
// larger (tens of seconds to compile on lavapipe, and slower to run). Nothing the walk calls
// per triangle loops (`local_edge`): lavapipe ends all loops of an invocation after 65,535
// iterations in all, and a patch at factor 64 has 8,192 triangles.
const STITCH_TRANSITION: u32 = 0u;
const STITCH_REGULAR: u32 = 1u;
// One or two fixed triangles: (inner 0, inner 1, outer 1), then (inner 1, outer 0, outer 1).
const STITCH_FIXED: u32 = 2u;

// `stitch::Diagonals`.
const INSIDE_TO_OUTSIDE: u32 = 0u;
const INSIDE_TO_OUTSIDE_EXCEPT_MIDDLE: u32 = 1u;
const MIRRORED: u32 = 2u;

// A triangle of a stitch as three references to its rows: point k of the inner row, or with
// OUTER_ROW set point k of the outer row. DONE: the stitch has no more triangles.
const OUTER_ROW: u32 = 0x80000000u;
const DONE: u32 = 0xffffffffu;

// One stitch between an inner and an outer row and how far it has got.
struct Stitch {
    kind: u32,
    inner: Side,
    outer: Side,
    // Transition: the rows' half points (less one for odd) and parities.
    inner_half: u32,
    outer_half: u32,
    inner_odd: bool,
    outer_odd: bool,
    // Regular: one triangle at each end, the diagonals. Fixed: the triangles.
    trapezoid: bool,
    diagonals: u32,
    count: u32,
    // Progress: the phase, the table position or quad, the triangle within a step, and the
    // next point of each row.
    phase: u32,
    x: u32,
    sub: u32,
    i: u32,
    o: u32,
}

// A stitch of `kind` between the rows `inner` and `outer`, at its start.
fn stitch_new(kind: u32, inner: Side, outer: Side) -> Stitch {
    return Stitch(kind, inner, outer, 0u, 0u, false, false, false, 0u, 0u, 0u, 0u, 0u, 0u, 0u);
}

// `Emit::transition`'s "advance outer" triangle (also each end of `Emit::regular`'s
// trapezoid): outer points o, o + 1 and inner point i.
fn advance_outer(st: ptr<function, Stitch>) -> vec3<u32> {
    let o = (*st).o;
    (*st).o = o + 1u;
    return vec3<u32>(OUTER_ROW | o, OUTER_ROW | (o + 1u), (*st).i);
}

// `Emit::transition`'s "advance inner" triangle: inner points i, i + 1 and outer point o.
fn advance_inner(st: ptr<function, Stitch>) -> vec3<u32> {
    let i = (*st).i;
    (*st).i = i + 1u;
    return vec3<u32>(i, OUTER_ROW | (*st).o, i + 1u);
}

// The next triangle of `Emit::transition`: the ruler-function transition between rows of any
// two factors, walked from both ends towards the middle. Phases: 0 the first outer step, 1
// the table forwards (inner, then outer, at each position), 2 the middle, 3 the table
// backwards (outer, then inner), 4 the last outer step.
fn transition_step(st: ptr<function, Stitch>) -> vec3<u32> {
    loop {
        switch (*st).phase {
            case 0u: {
                (*st).phase = 1u;
                (*st).x = 1u;
                (*st).sub = 0u;
                if (final_point_position(0u) < (*st).outer_half) { return advance_outer(st); }
            }
            case 1u: {
                let position = final_point_position(min((*st).x, 32u));
                if ((*st).x == 33u) {
                    (*st).phase = 2u;
                    (*st).sub = 0u;
                } else if ((*st).sub == 0u) {
                    (*st).sub = 1u;
                    if (position < (*st).inner_half) { return advance_inner(st); }
                } else {
                    (*st).sub = 0u;
                    (*st).x = (*st).x + 1u;
                    if (position < (*st).outer_half) { return advance_outer(st); }
                }
            }
            case 2u: {
                let inner_odd = (*st).inner_odd;
                let outer_odd = (*st).outer_odd;
                let i = (*st).i;
                let o = (*st).o;
                if ((*st).sub == 0u && (inner_odd != outer_odd || inner_odd)) {
                    (*st).sub = 1u;
                    if (inner_odd == outer_odd) {
                        // Both odd: a quad in the middle, its second triangle next.
                        return vec3<u32>(i, OUTER_ROW | o, i + 1u);
                    }
                    (*st).phase = 3u;
                    (*st).x = 32u;
                    (*st).sub = 0u;
                    if (!inner_odd) {
                        // A triangle pointing inside.
                        (*st).o = o + 1u;
                        return vec3<u32>(i, OUTER_ROW | o, OUTER_ROW | (o + 1u));
                    }
                    // A triangle pointing outside.
                    (*st).i = i + 1u;
                    return vec3<u32>(i, OUTER_ROW | o, i + 1u);
                }
                let both_odd = (*st).sub == 1u;
                (*st).phase = 3u;
                (*st).x = 32u;
                (*st).sub = 0u;
                if (both_odd) {
                    (*st).i = i + 1u;
                    (*st).o = o + 1u;
                    return vec3<u32>(i + 1u, OUTER_ROW | o, OUTER_ROW | (o + 1u));
                }
            }
            case 3u: {
                let position = final_point_position((*st).x);
                if ((*st).x == 0u) {
                    (*st).phase = 4u;
                } else if ((*st).sub == 0u) {
                    (*st).sub = 1u;
                    if (position < (*st).outer_half) { return advance_outer(st); }
                } else {
                    (*st).sub = 0u;
                    (*st).x = (*st).x - 1u;
                    if (position < (*st).inner_half) { return advance_inner(st); }
                }
            }
            case 4u: {
                (*st).phase = 5u;
                if (final_point_position(0u) < (*st).outer_half) { return advance_outer(st); }
            }
            default: { return vec3<u32>(DONE); }
        }
    }
    return vec3<u32>(DONE);
}

// The next triangle of `Emit::regular`: a band between rows whose point counts differ by 2
// (`trapezoid`: one triangle at each end) or are equal (a strip of quads), each quad's
// diagonal as `diagonals` says. Phases: 0 the first end, 1 the quads (two triangles each),
// 2 the last end.
fn regular_step(st: ptr<function, Stitch>) -> vec3<u32> {
    let n = (*st).inner.count;
    loop {
        switch (*st).phase {
            case 0u: {
                (*st).phase = 1u;
                (*st).x = 0u;
                (*st).sub = 0u;
                if ((*st).trapezoid) { return advance_outer(st); }
            }
            case 1u: {
                let q = (*st).x;
                if (q + 1u >= n) {
                    (*st).phase = 2u;
                    // On to the last end: the rest of this case is for quads.
                    break;
                }
                // Which diagonal quad q takes: 0 inside to outside, 1 forward, 2 backward.
                var shape = 0u;
                if ((*st).diagonals == INSIDE_TO_OUTSIDE_EXCEPT_MIDDLE) {
                    shape = select(1u, 2u, q == max(n / 2u, 1u) - 1u);
                } else if ((*st).diagonals == MIRRORED && q < n / 2u) {
                    shape = 2u;
                }
                let i = (*st).i;
                let o = (*st).o;
                let half = (*st).sub;
                if (half == 0u) {
                    (*st).sub = 1u;
                } else {
                    (*st).sub = 0u;
                    (*st).x = q + 1u;
                    (*st).i = i + 1u;
                    (*st).o = o + 1u;
                }
                let o0 = OUTER_ROW | o;
                let o1 = OUTER_ROW | (o + 1u);
                if (shape == 0u) {
                    if (half == 0u) { return vec3<u32>(i, o0, o1); }
                    return vec3<u32>(i, o1, i + 1u);
                }
                if (shape == 1u) {
                    if (half == 0u) { return vec3<u32>(o0, o1, i); }
                    return vec3<u32>(i, o1, i + 1u);
                }
                if (half == 0u) { return vec3<u32>(o0, i + 1u, i); }
                return vec3<u32>(o0, o1, i + 1u);
            }
            case 2u: {
                (*st).phase = 3u;
                if ((*st).trapezoid) { return advance_outer(st); }
            }
            default: { return vec3<u32>(DONE); }
        }
    }
    return vec3<u32>(DONE);
}

// The next fixed triangle (`Emit::tri` in `tessellate_into`'s minimum case and `tri`'s
// centre).
fn fixed_step(st: ptr<function, Stitch>) -> vec3<u32> {
    let t = (*st).x;
    (*st).x = t + 1u;
    if (t >= (*st).count) { return vec3<u32>(DONE); }
    if (t == 0u) { return vec3<u32>(0u, 1u, OUTER_ROW | 1u); }
    return vec3<u32>(1u, OUTER_ROW, OUTER_ROW | 1u);
}

// The next triangle of any stitch (`Emit::transition`, `Emit::regular`, `Emit::tri`).
fn stitch_step(st: ptr<function, Stitch>) -> vec3<u32> {
    if ((*st).kind == STITCH_TRANSITION) { return transition_step(st); }
    if ((*st).kind == STITCH_REGULAR) { return regular_step(st); }
    return fixed_step(st);
}

// The hardware point a stitch's row reference names.
fn row_point(st: Stitch, r: u32) -> u32 {
    if ((r & OUTER_ROW) != 0u) { return side_point(st.outer, r & ~OUTER_ROW); }
    return side_point(st.inner, r);
}

// Ring r of the patch (`quad_ring` or `tri_ring`).
fn patch_ring(pre: Processed, r: u32) -> Ring {
    if (pre.nc == 4u) { return quad_ring(pre, r); }
    return tri_ring(pre, r);
}

// Band rings (`stitch_bands`' count): the outer ring and the inner ones, the degenerate ring
// included.
fn band_rings(pre: Processed) -> u32 {
    if (pre.nc == 4u) {
        return min((pre.inside[0].points + 1u) >> 1u, (pre.inside[1].points + 1u) >> 1u);
    }
    return (pre.inside[0].points + 1u) >> 1u;
}

// Stitches of the patch in the CPU's order: the minimum case's fixed triangles; or the bands
// (`stitch_bands`, side by side) then the quad's centre strip or the odd triangle's centre
// triangle.
fn stitch_count(pre: Processed) -> u32 {
    if (pre.minimum) { return 1u; }
    var last = 0u;
    if (pre.nc == 4u) {
        last = select(0u, 1u, centre_strip(pre).x > 0u);
    } else {
        last = select(0u, 1u, pre.inside[0].odd);
    }
    return (band_rings(pre) - 1u) * pre.nc + last;
}

// Stitch s of the patch (`stitch_count`'s order).
fn stitch_at(pre: Processed, s: u32) -> Stitch {
    let nc = pre.nc;
    if (pre.minimum) {
        // The bare domain: quad (0, 1, 3), (1, 2, 3); triangle (0, 1, 2).
        let ring = outer_ring(pre);
        var st = stitch_new(STITCH_FIXED, ring_side(ring, 0u, false), ring_side(ring, nc - 2u, false));
        st.count = nc - 2u;
        return st;
    }
    let bands = (band_rings(pre) - 1u) * nc;
    if (s < bands) {
        let r = 1u + s / nc;
        let e = s % nc;
        let inner = ring_side(patch_ring(pre, r), e, false);
        let outer = ring_side(patch_ring(pre, r - 1u), e, false);
        if (r == 1u) {
            // The transition from the outer edges (`inside(e)` the partition along side e).
            var st = stitch_new(STITCH_TRANSITION, inner, outer);
            let inner_axis = inside_axis(pre, select(0u, (e + 1u) & 1u, nc == 4u));
            let outer_axis = outer_axis(pre, e);
            st.inner_half = inner_axis.half_points - select(0u, 1u, inner_axis.odd);
            st.outer_half = outer_axis.half_points - select(0u, 1u, outer_axis.odd);
            st.inner_odd = inner_axis.odd;
            st.outer_odd = outer_axis.odd;
            return st;
        }
        var st = stitch_new(STITCH_REGULAR, inner, outer);
        st.trapezoid = true;
        st.diagonals = MIRRORED;
        return st;
    }
    let last = patch_ring(pre, band_rings(pre) - 1u);
    if (nc == 3u) {
        // The odd triangle's centre: points 0, 1, 2 of the last ring.
        var st = stitch_new(STITCH_FIXED, ring_side(last, 0u, false), ring_side(last, 1u, false));
        st.count = 1u;
        return st;
    }
    // The quad's centre strip, between two opposite sides of the last ring.
    let horizontal = centre_strip(pre).y == 1u;
    let outer = ring_side(last, select(0u, 1u, horizontal), false);
    let inner = ring_side(last, select(2u, 3u, horizontal), true);
    var st = stitch_new(STITCH_REGULAR, inner, outer);
    st.diagonals = INSIDE_TO_OUTSIDE;
    if (!horizontal && pre.inside[1].odd) { st.diagonals = INSIDE_TO_OUTSIDE_EXCEPT_MIDDLE; }
    return st;
}

// `tessellate_into` with `quad`, `tri` and `stitch_bands`, as `Hardware::build` maps it:
// patch p's triangles in the CPU's order, left out at collapsed curves as the engine does,
// written from output triangle `first` with `write`. Returns the triangles kept. Cost:
// O(pattern triangles · corner count), serial.
fn build_hardware(p: u32, write: bool, first: u32) -> u32 {
    let pre = patch_processed(p);
    let input = local_numbering(p);
    let edge_points = edge_points(pre);
    var kept = 0u;
    let stitches = stitch_count(pre);
    for (var s = 0u; s < stitches; s = s + 1u) {
        var st = stitch_at(pre, s);
        loop {
            let refs = stitch_step(&st);
            if (refs.x == DONE) { break; }
            // Rows to hardware points (`Emit::tri`'s order, Direct3D's clockwise, which is
            // counter-clockwise in (u, v)) to local indices.
            let tri = vec3<u32>(
                hardware_local(input, edge_points, row_point(st, refs.x)),
                hardware_local(input, edge_points, row_point(st, refs.y)),
                hardware_local(input, edge_points, row_point(st, refs.z)),
            );
            emit(input, tri, write, first, &kept);
        }
    }
    return kept;
}

// Counts of the hardware pattern for the count pass (`count.wgsl`): `Hardware::counts`
// (interior points, pattern triangles), the triangles rebuilt and counted where a corner
// repeats (the engine leaves out those that degenerate).
fn hardware_patch_counts(p: u32) -> vec2<u32> {
    let pre = patch_processed(p);
    var counts = processed_counts(pre);
    counts.x = counts.x - outer_points(pre);
    if (patch_repeated_corner(p)) {
        counts.y = build_hardware(p, false, 0u);
    }
    return counts;
}

// Parameter k of edge e in canonical orientation: `Plan::param` of a
// `SamplingKind::Fractional(Spacing::Hardware(_))` plan, `sampling::hardware::edge_param` of
// the plan's f32 factor.
fn hardware_plan_edge_param(e: u32, k: u32) -> f32 {
    return hardware_edge_param(edge_factor(e), params.partitioning, k);
}

// A fixed-point domain point as f32, exactly (`sampling::hardware::to_f64`).
fn fixed_point(u: u32, v: u32) -> vec2<f32> {
    return vec2<f32>(f32(u), f32(v)) * (1.0 / f32(FIXED_ONE));
}

// Interior point j of a quad (`quad`): ring r ≥ 1 side e point p at (perp, x) or (x, perp),
// then the degenerate ring's line. Cost: O(rings).
fn quad_interior_point(pre: Processed, j: u32) -> vec2<f32> {
    let n = vec2<u32>(pre.inside[0].points, pre.inside[1].points);
    let point_rings = min(n.x, n.y) >> 1u;
    var rest = j;
    for (var r = 1u; r < point_rings; r = r + 1u) {
        let end = n - vec2<u32>(1u + r);
        for (var e = 0u; e < 4u; e = e + 1u) {
            let across = e & 1u;
            let along = (e + 1u) & 1u;
            let along_v = along == 1u;
            let count = select(n.x, n.y, along_v) - 1u - 2u * r;
            if (rest < count) {
                let q0 = r + rest;
                var q = select(end.x, end.y, along_v) - (q0 - r);
                if (e == 1u || e == 2u) { q = q0; }
                var perp_point = select(end.x, end.y, across == 1u);
                if (e < 2u) { perp_point = r; }
                let perp = axis_place(inside_axis(pre, across), perp_point);
                let x = axis_place(inside_axis(pre, along), q);
                if (along == 1u) { return fixed_point(perp, x); }
                return fixed_point(x, perp);
            }
            rest = rest - count;
        }
    }
    let r = point_rings;
    if (quad_degenerate(pre) == 1u) {
        return fixed_point(axis_place(pre.inside[0], r + rest), FIXED_HALF);
    }
    return fixed_point(FIXED_HALF, axis_place(pre.inside[1], n.y - 1u - r - rest));
}

// Interior point j of a triangle (`tri`): ring r's distance from each side scaled to
// barycentric size and its along-side parameters pushed in by half of it, then the centre.
// Cost: O(rings).
fn tri_interior_point(pre: Processed, j: u32) -> vec2<f32> {
    let axis = pre.inside[0];
    let n = axis.points;
    var rest = j;
    for (var r = 1u; r < (n >> 1u); r = r + 1u) {
        let count = n - 1u - 2u * r;
        if (rest < 3u * count) {
            let e = rest / count;
            let q0 = r + rest % count;
            let end = n - 1u - r;
            var q = end - (q0 - r);
            if (e % 2u == 1u) { q = q0; }
            let perp = (axis_place(axis, r) * FIXED_TWO_THIRDS + FIXED_HALF) >> FRACTION_BITS;
            let shift = (perp + 1u) / 2u;
            let x = i32(axis_place(axis, q)) - i32(shift);
            let fixed = 1.0 / f32(FIXED_ONE);
            if (e == 0u) { return vec2<f32>(f32(perp), f32(x)) * fixed; }
            if (e == 1u) { return vec2<f32>(f32(x), f32(perp)) * fixed; }
            return vec2<f32>(f32(x), f32(i32(FIXED_ONE) - x - i32(perp))) * fixed;
        }
        rest = rest - 3u * count;
    }
    return fixed_point(FIXED_ONE_THIRD, FIXED_ONE_THIRD);
}

// Interior vertex j of patch p: the hardware's interior point j (its points after the outer
// ring), as `Hardware::build` hands them to the engine.
fn hardware_interior_point(p: u32, j: u32) -> vec2<f32> {
    let pre = patch_processed(p);
    if (pre.nc == 4u) { return quad_interior_point(pre, j); }
    return tri_interior_point(pre, j);
}

// Triangle pass: one invocation per visible patch writes its pattern (the engine's
// `Writer::patch` with `Hardware::build`).
@compute @workgroup_size(WORKGROUP)
fn write_hardware_triangles(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (p >= params.patches || visible[p] == 0u) { return; }
    build_hardware(p, true, triangle_offsets[p]);
}
