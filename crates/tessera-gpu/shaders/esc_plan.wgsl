// ESC planned on the GPU from the camera (`tessera::criterion::esc::plan`, paper 002): each
// object's level, the distance test of equation (9) on every candidate, the candidates forced
// at collapsed curves, and the insertion grids `esc.wgsl` draws. Three passes, one after the
// other within the factors pass:
//
// 1. `esc_levels`, per patch: its object's level from the camera (or the fixed level), as
//    the patch's interior factors [3n, 3n]; every patch visible (ESC culls nothing).
// 2. `esc_edges`, per edge: its lattice mask, decided once from its first use (its owner)
//    in canonical order, with the candidates forced in any of its patches; its segments and
//    lattice size.
// 3. `esc_grids`, per patch: its grid — the boundary from its edges' masks, the inner cell
//    edges and diagonals by the distance test, the forced coarse triangles, the rows filled.
//
// The view uniform for ESC (`screen.rs`): `lo` the fixed level or −1, `hi` Lmax, `cap` the
// objects' near distance in diagonals, `pixels` the threshold (a fraction of the object's
// diagonal, or a distance when `edge_rule` is ESC_THRESHOLD_ABSOLUTE). An object's box and
// diagonal are the patch rows 8 and 9 (`patch_view_rows`).

const ESC_THRESHOLD_ABSOLUTE: u32 = {{ESC_THRESHOLD_ABSOLUTE}}u;

// `level_for_distance`: Lmax within the reference distance, one less per doubling beyond,
// at least 1 (or Lmax when that is 0).
fn esc_level_for_distance(distance: f32, reference: f32, max_level: u32) -> u32 {
    if (!(distance > reference) || reference <= 0.0) { return max_level; }
    let drop = min(u32(ceil(log2(distance / reference))), max_level);
    return max(max_level - drop, min(max_level, 1u));
}

fn esc_object_lo(p: u32) -> vec4<f32> { return patch_views[PATCH_VIEW_ROW * p + 8u]; }
fn esc_object_hi(p: u32) -> vec4<f32> { return patch_views[PATCH_VIEW_ROW * p + 9u]; }

// ρ of patch p's object.
fn esc_rho(p: u32) -> f32 {
    if (view.edge_rule == ESC_THRESHOLD_ABSOLUTE) { return view.pixels; }
    return view.pixels * esc_object_lo(p).w;
}

@compute @workgroup_size(WORKGROUP)
fn esc_levels(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (p >= params.patches) { return; }
    var level = u32(max(view.lo, 0.0));
    if (view.lo < 0.0) {
        let lo = esc_object_lo(p);
        let hi = esc_object_hi(p).xyz;
        let eye = view.eye.xyz;
        let distance = length(clamp(eye, lo.xyz, hi) - eye);
        level = esc_level_for_distance(distance, view.cap * lo.w, u32(view.hi));
    }
    let side = 3u * (level + 1u);
    interior[p] = vec2<u32>(side, side);
    visible[p] = 1u;
}

// Equation (9): is the candidate at lattice point (i, j) of patch p, a fraction s from the
// coarse vertex a to the coarse vertex b (lattice points on control points), further than ρ
// from the surface? The control mesh's point is `(1 − s)·P_a + s·P_b`.
fn esc_far(p: u32, ij: vec2<u32>, a: vec2<u32>, b: vec2<u32>, s: f32, rho: f32) -> bool {
    let n = esc_n;
    let side = f32(esc_s);
    let pa = control_points[p * CONTROL_POINTS + 4u * (a.x / n) + a.y / n].xyz;
    let pb = control_points[p * CONTROL_POINTS + 4u * (b.x / n) + b.y / n].xyz;
    let surface = eval_patch(p, vec2<f32>(f32(ij.x) / side, f32(ij.y) / side)).position;
    return distance(surface, pa * (1.0 - s) + pb * s) > rho;
}

// `edge_lattice`: lattice point kl along local edge e, in the edge's direction.
fn esc_edge_lattice(e: u32, kl: u32) -> vec2<u32> {
    let s = esc_s;
    switch e {
        case 0u: { return vec2<u32>(kl, 0u); }
        case 1u: { return vec2<u32>(s, kl); }
        case 2u: { return vec2<u32>(s - kl, s); }
        default: { return vec2<u32>(0u, s - kl); }
    }
}

// The level of patch p (its interior factors), into the private esc_n and esc_s.
fn esc_set_level(p: u32) {
    esc_s = interior[p].x;
    esc_n = esc_s / 3u;
}

// Whether lattice point (i, j) lies on coarse triangle t (`PatchGrid::lattice` inverted:
// some row vertex (k, q), 0 ≤ q ≤ k ≤ n, maps to it).
fn esc_in_triangle(t: u32, ij: vec2<u32>) -> bool {
    let n = i32(esc_n);
    let ci = i32((t / 2u) % 3u);
    let cj = i32((t / 2u) / 3u);
    let i = i32(ij.x);
    let j = i32(ij.y);
    var q = j - cj * n;
    var kq = (ci + 1) * n - i;
    if (t % 2u == 1u) {
        q = (cj + 1) * n - j;
        kq = i - ci * n;
    }
    return q >= 0 && kq >= 0 && q + kq <= n;
}

// `PatchGrid::coarse_triangle_on_edge`: an edge of coarse triangle t lies on patch edge e.
fn esc_triangle_on_edge(t: u32, e: u32) -> bool {
    let s = esc_s;
    let a = esc_lattice(t, 0u, 0u);
    let b = esc_lattice(t, esc_n, 0u);
    let c = esc_lattice(t, esc_n, esc_n);
    let on = array<bool, 4>(
        a.y == 0u && (b.y == 0u || c.y == 0u),
        a.x == s && (b.x == s || c.x == s),
        a.y == s && (b.y == s || c.y == s),
        a.x == 0u && (b.x == 0u || c.x == 0u),
    );
    return on[e];
}

// `forced_candidates`: bit t set for each coarse triangle of patch p with an edge on a
// boundary curve collapsed to a point (every candidate of it is inserted). Needs the level.
fn esc_forced_triangles(p: u32) -> u32 {
    var forced = 0u;
    for (var e = 0u; e < 4u; e = e + 1u) {
        if (!patch_edge_collapsed(p, e)) { continue; }
        for (var t = 0u; t < 18u; t = t + 1u) {
            if (esc_triangle_on_edge(t, e)) { forced = forced | (1u << t); }
        }
    }
    return forced;
}

fn esc_forced_at(forced: u32, ij: vec2<u32>) -> bool {
    for (var t = 0u; t < 18u; t = t + 1u) {
        if (((forced >> t) & 1u) != 0u && esc_in_triangle(t, ij)) { return true; }
    }
    return false;
}

// Edge e's lattice mask: the coarse vertices, the candidates forced in any patch on the
// edge, and the others by the distance test on its owner (its first use), in canonical
// order; then its segments and lattice size.
@compute @workgroup_size(WORKGROUP)
fn esc_edges(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let e = thread_index(wid, nwg, lid);
    if (e >= params.edges) { return; }
    let owner = edge_first_use(e);
    let p = use_patch(owner);
    esc_set_level(p);
    let n = esc_n;
    let side = esc_s;
    let le = use_local(owner);
    let rho = esc_rho(p);
    // Forced on the curve when forced in any patch on it (one object: one level), each
    // patch's forced coarse triangles found once.
    var mask = 0u;
    for (var u = owner; u < edge_end_use(e); u = u + 1u) {
        let forced = esc_forced_triangles(use_patch(u));
        if (forced == 0u) { continue; }
        for (var k = 0u; k <= side; k = k + 1u) {
            let kq = select(k, side - k, use_reversed(u));
            if (esc_forced_at(forced, esc_edge_lattice(use_local(u), kq))) { mask = mask | (1u << k); }
        }
    }
    for (var k = 0u; k <= side; k = k + 1u) {
        let kl = select(k, side - k, use_reversed(owner));
        var present = kl % n == 0u || ((mask >> k) & 1u) != 0u;
        if (!present) {
            let c = kl / n;
            let s = f32(kl % n) / f32(n);
            present = esc_far(p, esc_edge_lattice(le, kl), esc_edge_lattice(le, c * n),
                esc_edge_lattice(le, (c + 1u) * n), s, rho);
        }
        if (present) { mask = mask | (1u << k); }
    }
    segments[e] = countOneBits(mask) - 1u;
    segments[params.edges + e] = bitcast<u32>(f32(side));
    segments[2u * params.edges + e] = mask;
}

fn esc_set(i: u32, j: u32, value: bool) {
    let bit = 1u << i;
    esc_rows[j] = select(esc_rows[j] & ~bit, esc_rows[j] | bit, value);
}

// Patch p's insertion grid (`plan`'s grids, then `PatchGrid::insert_rows`), written as
// ESC_GRID_WORDS words after the plan's rows.
@compute @workgroup_size(WORKGROUP)
fn esc_grids(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (p >= params.patches) { return; }
    esc_set_level(p);
    let n = esc_n;
    let side = esc_s;
    let rho = esc_rho(p);
    for (var j = 0u; j <= side; j = j + 1u) { esc_rows[j] = 0u; }
    // The boundary: its edges' decisions.
    for (var le = 0u; le < 4u; le = le + 1u) {
        let edge = patch_edge(p, le);
        let mask = segments[2u * params.edges + edge];
        for (var kl = 0u; kl <= side; kl = kl + 1u) {
            let k = select(kl, side - kl, patch_edge_reversed(p, le));
            let ij = esc_edge_lattice(le, kl);
            esc_set(ij.x, ij.y, ((mask >> k) & 1u) != 0u);
        }
    }
    // The coarse vertices inside, then the inner cell edges and the cell diagonals
    // (`decide_inner`).
    for (var line = 1u; line < 3u; line = line + 1u) {
        esc_set(line * n, n, true);
        esc_set(line * n, 2u * n, true);
        let at = line * n;
        for (var t = 0u; t < side; t = t + 1u) {
            if (t % n == 0u) { continue; }
            let c = t / n;
            let s = f32(t % n) / f32(n);
            esc_set(at, t, esc_far(p, vec2<u32>(at, t), vec2<u32>(at, c * n), vec2<u32>(at, c * n + n), s, rho));
            esc_set(t, at, esc_far(p, vec2<u32>(t, at), vec2<u32>(c * n, at), vec2<u32>(c * n + n, at), s, rho));
        }
    }
    for (var cell = 0u; cell < 9u; cell = cell + 1u) {
        let ci = cell % 3u;
        let cj = cell / 3u;
        for (var k = 1u; k < n; k = k + 1u) {
            let ij = vec2<u32>(ci * n + k, cj * n + k);
            let a = vec2<u32>(ci * n, cj * n);
            esc_set(ij.x, ij.y, esc_far(p, ij, a, a + vec2<u32>(n, n), f32(k) / f32(n), rho));
        }
    }
    // The forced coarse triangles, whole.
    let forced = esc_forced_triangles(p);
    for (var t = 0u; t < 18u; t = t + 1u) {
        if (((forced >> t) & 1u) == 0u) { continue; }
        for (var k = 0u; k <= n; k = k + 1u) {
            for (var q = 0u; q <= k; q = q + 1u) {
                let ij = esc_lattice(t, k, q);
                esc_set(ij.x, ij.y, true);
            }
        }
    }
    // The rows of every coarse triangle: filled when either extreme is inserted.
    for (var t = 0u; t < 18u; t = t + 1u) {
        for (var k = 2u; k < n; k = k + 1u) {
            let row = esc_flag(t, k, 0u) || esc_flag(t, k, k);
            for (var q = 1u; q < k; q = q + 1u) {
                let ij = esc_lattice(t, k, q);
                esc_set(ij.x, ij.y, row);
            }
        }
    }
    // Packed row after row: bit j·(3n + 1) + i.
    let base = 4u * params.edges + ESC_GRID_WORDS * p;
    for (var w = 0u; w < ESC_GRID_WORDS; w = w + 1u) { segments[base + w] = 0u; }
    let width = side + 1u;
    for (var j = 0u; j <= side; j = j + 1u) {
        let at = j * width;
        let shift = at % 32u;
        segments[base + at / 32u] = segments[base + at / 32u] | (esc_rows[j] << shift);
        if (shift + width > 32u) {
            segments[base + at / 32u + 1u] = segments[base + at / 32u + 1u] | (esc_rows[j] >> (32u - shift));
        }
    }
}
