// The ESC pattern (`tessera::pattern::esc::Esc`, paper 002) on bicubic patches, from the
// insertion decisions of a plan (`tessera::criterion::esc::plan`): the CPU module's doc
// describes the coarse triangles, rows, virtual vertices and strips this file follows.
//
// Data (`segments`, after the plan's segments and factors): `segments[2E + e]` is edge e's
// lattice mask, bit I set when numerator I of the lattice `3n` (canonical direction) is a
// sample; from `segments[4E]` on, ESC_GRID_WORDS words a patch hold its insertion grid,
// bit j·(3n + 1) + i for lattice point (i, j) (`PatchGrid::get`). A patch's `3n` is its
// interior factor (`Plan::interior`).
//
// One invocation a patch walks its 18 coarse triangles' strips in the CPU's order and
// decodes them as `mesh::strips::decode` does; the count pass runs the same walk without
// writing. Every lookup of the walk is loop-free once the patch's rows are loaded into
// private memory (`esc_load`): lavapipe stops an invocation's loops after 65,535 iterations.

// The largest lattice side 3n, and the grid words of a patch (`pipelines.rs`).
const ESC_MAX_SIDE: u32 = {{ESC_MAX_SIDE}}u;
const ESC_GRID_WORDS: u32 = {{ESC_GRID_WORDS}}u;
const ESC_ROWS: u32 = ESC_MAX_SIDE + 1u;

// The loaded patch: n (segments per coarse edge), s = 3n, its grid rows (bit i of row j),
// its first and last columns (bit j of column 0 and of column s), and the interior points
// before row j (row-major, the interior vertices' order).
var<private> esc_n: u32;
var<private> esc_s: u32;
var<private> esc_rows: array<u32, ESC_ROWS>;
var<private> esc_first_column: u32;
var<private> esc_last_column: u32;
var<private> esc_before: array<u32, ESC_ROWS>;

// Bits 0..count − 1.
fn low_bits(count: u32) -> u32 {
    return select((1u << count) - 1u, 0xffffffffu, count >= 32u);
}

// Bits 1..s − 1 of a row: its interior points.
fn esc_inner_bits() -> u32 {
    return low_bits(esc_s) & ~1u;
}

fn esc_load(p: u32) {
    esc_s = interior[p].x;
    esc_n = esc_s / 3u;
    let width = esc_s + 1u;
    let base = 4u * params.edges + ESC_GRID_WORDS * p;
    esc_first_column = 0u;
    esc_last_column = 0u;
    var before = 0u;
    for (var j = 0u; j <= esc_s; j = j + 1u) {
        let at = j * width;
        let shift = at % 32u;
        var bits = segments[base + at / 32u] >> shift;
        if (shift + width > 32u) {
            bits = bits | (segments[base + at / 32u + 1u] << (32u - shift));
        }
        bits = bits & low_bits(width);
        esc_rows[j] = bits;
        esc_first_column = esc_first_column | ((bits & 1u) << j);
        esc_last_column = esc_last_column | (((bits >> esc_s) & 1u) << j);
        esc_before[j] = before;
        if (j > 0u && j < esc_s) { before = before + countOneBits(bits & esc_inner_bits()); }
    }
}

fn esc_get(i: u32, j: u32) -> bool {
    return ((esc_rows[j] >> i) & 1u) != 0u;
}

// `PatchGrid::lattice`: lattice point of row vertex (k, q) of coarse triangle t (cell t / 2,
// lower triangle for even t).
fn esc_lattice(t: u32, k: u32, q: u32) -> vec2<u32> {
    let n = esc_n;
    let ci = (t / 2u) % 3u;
    let cj = (t / 2u) / 3u;
    if (t % 2u == 0u) { return vec2<u32>((ci + 1u) * n - (k - q), cj * n + q); }
    return vec2<u32>(ci * n + (k - q), (cj + 1u) * n - q);
}

fn esc_flag(t: u32, k: u32, q: u32) -> bool {
    let l = esc_lattice(t, k, q);
    return esc_get(l.x, l.y);
}

// `CoarseTriangle::row_present`.
fn esc_row_present(t: u32, k: u32) -> bool {
    return k == 0u || k == esc_n || esc_flag(t, k, 0u) || esc_flag(t, k, k);
}

// `CoarseTriangle::present`: corners always, edge candidates as decided, a row's interior
// with either of its extremes.
fn esc_present(t: u32, k: u32, q: u32) -> bool {
    let n = esc_n;
    if (k == 0u || (k == n && (q == 0u || q == n))) { return true; }
    if (k == n || q == 0u || q == k) { return esc_flag(t, k, q); }
    return esc_row_present(t, k);
}

// Row vertices travel packed: k · 8 + q (k, q ≤ 7).
fn esc_pack(k: u32, q: u32) -> u32 { return k * 8u + q; }

// `CoarseTriangle::stand_in`: the vertex itself when present, else its virtual vertex (the
// nearest present one on the same coarse edge, ties to the lower row; on the base towards
// B); bit 8 marks a virtual vertex.
fn esc_stand_in(t: u32, k: u32, q: u32) -> u32 {
    if (esc_present(t, k, q)) { return esc_pack(k, q); }
    let n = esc_n;
    if (k == n) {
        for (var d = 1u; d <= n; d = d + 1u) {
            if (q >= d && esc_flag(t, n, q - d)) { return esc_pack(n, q - d) | 256u; }
            if (q + d <= n && esc_flag(t, n, q + d)) { return esc_pack(n, q + d) | 256u; }
        }
        return esc_pack(n, 0u) | 256u; // not reached: the base corners are present
    }
    let left = q == 0u;
    for (var d = 1u; d <= n; d = d + 1u) {
        let r = k + d;
        if (r <= n && (r == n || esc_flag(t, r, select(r, 0u, left)))) {
            return esc_pack(r, select(r, 0u, left)) | 256u;
        }
        if (k >= d) {
            let r2 = k - d;
            if (r2 == 0u || esc_flag(t, r2, select(r2, 0u, left))) {
                return esc_pack(r2, select(r2, 0u, left)) | 256u;
            }
        }
    }
    return esc_pack(0u, 0u) | 256u; // not reached: the apex is present
}

// The local index of lattice point (i, j), which is present (`esc::layout`'s numbering:
// corners, each edge's present points in the patch's own direction, the interior row-major).
fn esc_local(input: LocalNumbering, i: u32, j: u32) -> u32 {
    let s = esc_s;
    if (j == 0u) {
        if (i == 0u) { return 0u; }
        if (i == s) { return 1u; }
        return boundary_local(input, 0u, countOneBits(esc_rows[0] & low_bits(i)));
    }
    if (j == s) {
        if (i == 0u) { return 3u; }
        if (i == s) { return 2u; }
        return boundary_local(input, 2u, countOneBits(esc_rows[s] >> (i + 1u)));
    }
    if (i == s) { return boundary_local(input, 1u, countOneBits(esc_last_column & low_bits(j))); }
    if (i == 0u) { return boundary_local(input, 3u, countOneBits(esc_first_column >> (j + 1u))); }
    return input.interior_base + esc_before[j] + countOneBits(esc_rows[j] & low_bits(i) & ~1u);
}

fn esc_row_local(input: LocalNumbering, t: u32, v: u32) -> u32 {
    let l = esc_lattice(t, (v >> 3u) & 7u, v & 7u);
    return esc_local(input, l.x, l.y);
}

// One strip of coarse triangle t, being built: `CoarseTriangle::strips`'s entries after the
// alternation rules (`alternate`), at most 2 · (2n + 1) of them.
var<private> esc_strip: array<u32, 32>;
var<private> esc_strip_len: u32;

// `alternate` for one entry v: rule 3 (a repeat is dropped) and rule 4 (two entries of one
// side get the entry before the last between them; at the start, the first is repeated).
fn esc_push(v: u32, upper: bool) {
    let len = esc_strip_len;
    if (len > 0u && esc_strip[len - 1u] == v) { return; }
    if ((len % 2u == 1u) != upper) {
        if (len == 0u) {
            esc_strip[0] = v;
        } else if (len == 1u) {
            esc_strip[1] = esc_strip[0];
        } else {
            esc_strip[len] = esc_strip[len - 2u];
        }
        esc_strip_len = len + 1u;
    }
    esc_strip[esc_strip_len] = v;
    esc_strip_len = esc_strip_len + 1u;
}

// `CoarseTriangle::upper_fill`: the b upper vacancies of strip b when the previous non-empty
// row is a (row b − 1's vertices, or row a spread uniformly with its virtual vertex once).
var<private> esc_fill: array<u32, 8>;

fn esc_upper_fill(t: u32, a: u32, b: u32) {
    if (a + 1u == b) {
        for (var q = 0u; q <= a; q = q + 1u) { esc_fill[q] = esc_stand_in(t, a, q) & 255u; }
        return;
    }
    var virtuals = 0u;
    for (var q = 0u; q <= a; q = q + 1u) { virtuals = virtuals + (esc_stand_in(t, a, q) >> 8u); }
    let spread = b - virtuals;
    let real = a + 1u - virtuals;
    var at = 0u;
    var r = 0u;
    for (var q = 0u; q <= a; q = q + 1u) {
        let v = esc_stand_in(t, a, q);
        var count = 1u;
        if ((v >> 8u) == 0u) {
            // ⌈(r + 1)·spread / real⌉ − ⌈r·spread / real⌉: earlier entries take the extra ones.
            count = ((r + 1u) * spread + real - 1u) / real - (r * spread + real - 1u) / real;
            r = r + 1u;
        }
        for (var c = 0u; c < count; c = c + 1u) {
            esc_fill[at] = v & 255u;
            at = at + 1u;
        }
    }
}

// Strip b of coarse triangle t, whose previous non-empty row is a, into esc_strip:
// `CoarseTriangle::strips`'s entries (row b's stand-ins interleaved with the upper fill)
// after the alternation rules.
fn esc_build_strip(t: u32, a: u32, b: u32) {
    esc_upper_fill(t, a, b);
    esc_strip_len = 0u;
    for (var i = 0u; i <= b; i = i + 1u) {
        let lower = esc_stand_in(t, b, i) & 255u;
        esc_push(lower, (lower >> 3u) <= a);
        if (i < b) {
            let upper = esc_fill[i];
            esc_push(upper, (upper >> 3u) <= a);
        }
    }
}

// Whether esc_strip draws a triangle (a window of three different vertices): the CPU keeps
// only such strips (`CoarseTriangle::strips`).
fn esc_strip_draws() -> bool {
    for (var w = 0u; w + 2u < esc_strip_len; w = w + 1u) {
        let x = esc_strip[w];
        let y = esc_strip[w + 1u];
        let z = esc_strip[w + 2u];
        if (x != y && y != z && x != z) { return true; }
    }
    return false;
}

// Every triangle of patch p in order, through `emit` (counted, and with `write` written from
// output triangle `first` on); returns the kept ones. Cost: O(n²) a coarse triangle, serial.
fn esc_walk(p: u32, write: bool, first: u32) -> u32 {
    esc_load(p);
    let input = local_numbering(p);
    let n = esc_n;
    var kept = 0u;
    for (var t = 0u; t < 18u; t = t + 1u) {
        var a = 0u;
        for (var b = 1u; b <= n; b = b + 1u) {
            if (!esc_row_present(t, b)) { continue; }
            esc_build_strip(t, a, b);
            // `mesh::strips::decode`: window w, flipped at odd w, kept with three corners.
            for (var w = 0u; w + 2u < esc_strip_len; w = w + 1u) {
                let x = esc_strip[w];
                let y = esc_strip[w + 1u];
                let z = esc_strip[w + 2u];
                if (x == y || y == z || x == z) { continue; }
                let lx = esc_row_local(input, t, x);
                let ly = esc_row_local(input, t, y);
                let lz = esc_row_local(input, t, z);
                var tri = vec3<u32>(lx, ly, lz);
                if (w % 2u == 1u) { tri = vec3<u32>(ly, lx, lz); }
                emit(input, tri, write, first, &kept);
            }
            a = b;
        }
    }
    return kept;
}

// The count pass's PATCH_COUNTS: the present interior lattice points and the kept triangles.
fn esc_patch_counts(p: u32) -> vec2<u32> {
    let triangles = esc_walk(p, false, 0u);
    return vec2<u32>(esc_before[esc_s], triangles);
}

// The vertex passes' EDGE_PARAM: the edge's k-th present lattice numerator over its lattice
// size (`sampling::param` of `SamplingKind::Lattice`).
fn esc_edge_param(e: u32, k: u32) -> f32 {
    if (k == segments[e]) { return 1.0; }
    var mask = segments[2u * params.edges + e];
    // Clear the k lowest set bits; the lowest left is numerator k.
    for (var c = 0u; c < k; c = c + 1u) { mask = mask & (mask - 1u); }
    return f32(firstTrailingBit(mask)) / edge_factor(e);
}

// The vertex passes' INTERIOR_POINT: interior vertex jj is the jj-th present interior lattice
// point, row-major, at (i / 3n, j / 3n).
fn esc_interior_point(p: u32, jj: u32) -> vec2<f32> {
    esc_load(p);
    var j = 1u;
    while (j + 1u < esc_s && esc_before[j + 1u] <= jj) { j = j + 1u; }
    var bits = esc_rows[j] & esc_inner_bits();
    for (var c = esc_before[j]; c < jj; c = c + 1u) { bits = bits & (bits - 1u); }
    let s = f32(esc_s);
    return vec2<f32>(f32(firstTrailingBit(bits)) / s, f32(j) / s);
}

// Triangle pass: one invocation per visible patch writes its pattern.
@compute @workgroup_size(WORKGROUP)
fn write_esc_triangles(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (p >= params.patches || visible[p] == 0u) { return; }
    _ = esc_walk(p, true, triangle_offsets[p]);
}
