// Screen-space factors from the camera alone, the GPU form of `tessera::scheme::Scheme::
// plan_into` for four kinds of criteria:
//
// - `Criterion::PixelError`: per visible patch the object-space tolerance of
//   `screen::PatchView::tolerance` and its proposals (`tolerance::plan_limited`:
//   `uniform_factor`, or for the transition scheme's quads `quad_grid`, and `curve_factor`
//   from the prepared bounds); the transition and semi-uniform schemes' interiors then come
//   from the a-posteriori check (`check.wgsl`);
// - `Criterion::View` with `ViewCriterion::Silhouetteness` (`view::edge_factors_into`): every
//   patch proposes each of its edges' silhouetteness factor in [lo, hi] (for the semi-uniform
//   scheme taken between the levels of lo and hi, `view::plan_into`);
// - `Criterion::Factor` for the hardware schemes (`view::EdgeFactors::Fixed`): every patch
//   proposes the factor for each of its edges;
// - SD-2's level functions (`criterion::sd2::plan`): each edge's factor from its two end
//   vertices, the larger of their distance factors or the silhouette's crossing;
//
// then per edge the maximum over the patches sharing it, read through the topology's edge
// uses, within the cap and the minimum segments (`resolve::edges`, `EdgeRule::Integer`,
// `EdgeRule::PowerOfTwo` for the semi-uniform scheme, `EdgeRule::Fractional(Spacing::Symmetric)`
// for SD-2 or, for the hardware schemes, `EdgeRule::Fractional(Spacing::Hardware(_))`: the hull shader's
// pow2 rounding and `settled_factor`, segments by the partition), then the interiors
// (`resolve::interiors`): the global factor on every edge and patch (`InteriorRule::Global`),
// CudaTess's core rule (`InteriorRule::Core`), the largest edge (`InteriorRule::MaxEdge`) or
// the semi-uniform level (`InteriorRule::Level`).
//
// f32 where the CPU computes in f64: a pixel-error factor is `ceil` of a square root, a
// silhouetteness factor is rounded, so the two can differ by one where that value lies within
// f32 rounding (about 1e-6 relative) of an integer (of a half-integer). The tests count such
// cases and allow no other difference. The hardware schemes keep the real factor: where the
// silhouetteness lies strictly between 0 and 1 it is computed from f32 copies of the CPU's
// f64 midpoints and normals, so its last bits may differ from the CPU's f32 factor (the tests
// count and bound these); at silhouetteness 0 or 1, and for a fixed factor, the factor is
// the CPU's bit for bit.

// `screen::PatchView::tolerance` for the view's pixel error.
fn patch_tolerance(p: u32) -> f32 {
    let lo = patch_views[PATCH_VIEW_ROW * p + 3u].xyz;
    let hi = patch_views[PATCH_VIEW_ROW * p + 4u].xyz;
    var z_min = 3.0e38;
    var tx = 0.0;
    var ty = 0.0;
    for (var i = 0u; i < 8u; i = i + 1u) {
        let corner = vec3<f32>(
            select(lo.x, hi.x, (i & 1u) != 0u),
            select(lo.y, hi.y, (i & 2u) != 0u),
            select(lo.z, hi.z, (i & 4u) != 0u),
        );
        let c = to_camera(corner);
        z_min = min(z_min, c.z);
        tx = max(tx, abs(c.x / c.z));
        ty = max(ty, abs(c.y / c.z));
    }
    var z = z_min;
    if (!(z_min >= view.near)) {
        // The box reaches the near plane: only points inside the frustum are seen.
        z = view.near;
        tx = view.tan_x;
        ty = view.tan_y;
    }
    return view.pixels * z / (view.focal * sqrt(1.0 + tx * tx + ty * ty));
}

// `tolerance::uniform_factor` and `tolerance::curve_factor`.
fn uniform_factor(m: vec4<f32>, eps: f32) -> f32 {
    return max(ceil(sqrt((m.x + 2.0 * m.y + m.z) / (8.0 * eps))), 1.0);
}

fn curve_factor(m_edge: f32, eps: f32) -> f32 {
    return max(ceil(sqrt(m_edge / (8.0 * eps))), 1.0);
}

// `tolerance::quad_grid`: the grid (nu, nv) with the fewest cells whose cells meet Filip's
// bound `(hu²·Muu + 2·hu·hv·Muv + hv²·Mvv)/8 ≤ ε`, both factors at most `cap`; (cap, cap)
// when none does (`plan_limited`'s fallback).
fn quad_grid(m: vec3<f32>, eps: f32, cap: u32) -> vec2<f32> {
    var best = vec2<u32>(0u, 0u);
    var found = false;
    for (var nu = 1u; nu <= cap; nu = nu + 1u) {
        let hu = 1.0 / f32(nu);
        let a = m.z;
        let b = 2.0 * m.y * hu;
        let c = m.x * hu * hu - 8.0 * eps;
        if (c > 0.0) { continue; }
        var hv = 1.0;
        if (a > 0.0) {
            hv = (-b + sqrt(b * b - 4.0 * a * c)) / (2.0 * a);
        } else if (b > 0.0) {
            hv = -c / b;
        }
        if (!(hv > 0.0)) { continue; } // hu alone takes the whole budget (`quad_grid`)
        var nv = 1u;
        if (hv < 1.0) {
            let cells = ceil(1.0 / hv);
            if (!(cells <= f32(cap))) { continue; }
            nv = u32(cells);
        }
        if (!found || nu * nv < best.x * best.y) {
            best = vec2<u32>(nu, nv);
            found = true;
        }
        if (nv == 1u) { break; } // larger nu only adds cells
    }
    if (!found) { return vec2<f32>(f32(cap), f32(cap)); }
    return vec2<f32>(best);
}

// The expansion bound's proposal from `start`, the second-derivative bound's (each side at
// least 1): `start` where the expansion bound does not meet `eps` on its grid, else
// - for a quad's core (`quad`): `tolerance::taylor_quad_grid` without the walk's search, the
//   grid scaled by the square root of the bound's slack at `start`, grown by 5 % until it
//   meets `eps` (at `start` at the latest);
// - else `tolerance::taylor_uniform_factor`: the smallest n up to `start.x` whose n × n grid
//   meets `eps` (bisection).
// Both searches in one loop around one call of the grid bound: lavapipe inlines every call,
// and its compilation time grows with each copy of the bound. At most EXPANSION_WALK_CELLS
// iterations a grid bound; the quad search stays within lavapipe's loop budget while the
// bound at `start` is above 1/400 of the tolerance (47 steps).
fn expansion_proposal(x: Expansion, errors: TriangleErrors, tri: bool, quad: bool, start: vec2<f32>, eps: f32) -> vec2<f32> {
    let top = vec2<u32>(max(start, vec2<f32>(1.0)));
    var n = top;
    var first = true;
    var scale = 0.0;
    var lo = 1u;
    var hi = top.x;
    loop {
        // The quad search's first step takes the whole bound (its slack sets the scale).
        let stop = select(eps, 3.0e38, first && quad);
        let bound = expansion_grid_error(x, tri, n.x, n.y, stop, hessian_cell(errors, n));
        let fits = bound <= eps;
        if (first) {
            if (!fits) { return start; }
            first = false;
            if (quad) { scale = sqrt(bound / eps); }
        } else if (quad) {
            if (fits) { return vec2<f32>(n); }
            scale = scale * 1.05;
        } else if (fits) {
            hi = n.x;
        } else {
            lo = n.x + 1u;
        }
        if (quad) {
            n = clamp(vec2<u32>(ceil(vec2<f32>(top) * scale)), vec2<u32>(1u), top);
            if (all(n == top)) { return start; }
        } else {
            if (lo >= hi) { return vec2<f32>(f32(hi)); }
            n = vec2<u32>((lo + hi) / 2u);
        }
    }
    return start;
}

// The second-derivative bound of every triangle of the n.x × n.y grid
// (`tolerance::grid_bound` without a Taylor bound): one cell's triangle.
fn hessian_cell(errors: TriangleErrors, n: vec2<u32>) -> f32 {
    let cell = vec2<f32>(1.0) / vec2<f32>(n);
    return triangle_error(errors, vec2<f32>(0.0), vec2<f32>(cell.x, 0.0), vec2<f32>(0.0, cell.y));
}

// `view::edge_factors_into`'s silhouetteness factor of edge e: s = 1 where the two normals
// at the midpoint face opposite ways from the eye, 1 − (c·nL)(c·nR)/β near it (β = 1/4).
fn silhouetteness_factor(e: u32) -> f32 {
    let row = PATCH_VIEW_ROW * params.patches + EDGE_VIEW_ROW * e;
    let mid = patch_views[row].xyz;
    let nl = patch_views[row + 1u].xyz;
    let nr = patch_views[row + 2u].xyz;
    // `DVec3::normalize_or_zero`.
    let d = mid - view.eye.xyz;
    let len = length(d);
    var c = vec3<f32>(0.0);
    if (len > 0.0) { c = d / len; }
    let product = dot(c, nl) * dot(c, nr);
    var s = 1.0;
    if (product > 0.0) { s = clamp(1.0 - product / 0.25, 0.0, 1.0); }
    // At s = 1 the CPU's f64 lo + (hi − lo) rounds to hi; in f32 it might not.
    if (s == 1.0) { return view.hi; }
    return clamp(view.lo + s * (view.hi - view.lo), view.lo, view.hi);
}

// `view::plan_into` for `EdgeRule::PowerOfTwo`: the factor f's place in [lo, hi] taken
// between the levels of lo and hi (paper 000: level ⌈s·M⌉ for silhouetteness s), as a factor.
fn between_levels(f: f32) -> f32 {
    let span = view.hi - view.lo;
    var t = 1.0;
    if (span > 0.0) { t = clamp((f - view.lo) / span, 0.0, 1.0); }
    let lo = log2(view.lo);
    return exp2(lo + t * (log2(view.hi) - lo));
}

// SD-2's level functions (`criterion::sd2::plan`) from the vertex rows after the edge rows
// (`patch_view_rows`): the depth along the view direction mapped by g onto [hi, lo] over the
// frame's depth range (linear or quadratic), or the vertices' front/back classification.

// An f32's bits as a u32 in the same order (atomics on depths): negative numbers
// complemented, positive ones with the top bit set.
fn ordered_bits(x: f32) -> u32 {
    let b = bitcast<u32>(x);
    return select(b | 0x80000000u, ~b, (b & 0x80000000u) != 0u);
}

fn from_ordered_bits(o: u32) -> f32 {
    return bitcast<f32>(select(~o, o & 0x7fffffffu, (o & 0x80000000u) != 0u));
}

fn vertex_row(v: u32) -> u32 {
    return PATCH_VIEW_ROW * params.patches + EDGE_VIEW_ROW * params.edges + VERTEX_VIEW_ROW * v;
}

// The vertex's depth along the view direction (`sd2::plan`'s `depth`).
fn vertex_depth(v: u32) -> f32 {
    return dot(patch_views[vertex_row(v)].xyz - view.eye.xyz, view.forward.xyz);
}

// Per topology vertex: its depth into the frame's range (the distance level function's).
@compute @workgroup_size(WORKGROUP)
fn vertex_depths(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let v = thread_index(wid, nwg, lid);
    if (v >= (arrayLength(&patch_views) - vertex_row(0u)) / VERTEX_VIEW_ROW) { return; }
    let d = ordered_bits(vertex_depth(v));
    atomicMax(&state.depth_far, d);
    atomicMax(&state.depth_near_complement, ~d);
}

// The distance level function's factor of vertex v: g of its depth, linear
// `hi (dmax − d)/span + lo (d − dmin)/span` or quadratic `(hi − lo)((d − dmax)/span)² + lo`,
// within [lo, hi].
fn level_factor(v: u32) -> f32 {
    let d = vertex_depth(v);
    let dmin = from_ordered_bits(~atomicLoad(&state.depth_near_complement));
    let dmax = from_ordered_bits(atomicLoad(&state.depth_far));
    let span = max(dmax - dmin, 1e-30);
    var f: f32;
    if (view.criterion == CRITERION_DISTANCE_LINEAR) {
        f = view.hi * (dmax - d) / span + view.lo * (d - dmin) / span;
    } else {
        let x = (d - dmax) / span;
        f = (view.hi - view.lo) * x * x + view.lo;
    }
    return clamp(f, view.lo, view.hi);
}

// `n · (eye − v) ≥ 0`: the vertex faces the eye.
fn vertex_front(v: u32) -> bool {
    let r = vertex_row(v);
    return dot(patch_views[r + 1u].xyz, view.eye.xyz - patch_views[r].xyz) >= 0.0;
}

// SD-2's factor of edge e from its end vertices (in the w of its second and third rows): the
// larger of their level factors (g decreases with depth: g of the nearer end), or hi for an
// edge the silhouette crosses and lo otherwise. Never three different in a triangle.
fn level_edge_factor(e: u32) -> f32 {
    let ends = edge_ends(e);
    if (view.criterion == CRITERION_VERTEX_SILHOUETTE) {
        return select(view.lo, view.hi, vertex_front(ends.x) != vertex_front(ends.y));
    }
    return max(level_factor(ends.x), level_factor(ends.y));
}

// Edge e's end vertices, canonical order (in the w of its second and third view rows).
fn edge_ends(e: u32) -> vec2<u32> {
    let row = PATCH_VIEW_ROW * params.patches + EDGE_VIEW_ROW * e;
    return vec2<u32>(bitcast<u32>(patch_views[row + 1u].w), bitcast<u32>(patch_views[row + 2u].w));
}

fn is_level_function(criterion: u32) -> bool {
    return criterion == CRITERION_DISTANCE_LINEAR || criterion == CRITERION_DISTANCE_QUADRATIC
        || criterion == CRITERION_VERTEX_SILHOUETTE;
}

// Per patch: its proposal for each local edge, and its minimum interior into the global
// factor.
@compute @workgroup_size(WORKGROUP)
fn patch_proposals(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (p >= params.patches) { return; }
    let row = PATCH_VIEW_ROW * p;
    let minimum = patch_views[row + 7u];
    if (view.interior_rule == INTERIOR_GLOBAL) {
        atomicMax(&state.global_factor, u32(max(minimum.x, minimum.y)));
    }
    var out = vec4<f32>(0.0);
    if (view.criterion == CRITERION_FIXED) {
        // Every patch, culled or not, proposes the factor (`from_edge_factors`).
        out = vec4<f32>(view.lo);
    } else if (is_level_function(view.criterion)) {
        // Every patch, culled or not, proposes its edges' factors (`from_edge_factors`).
        for (var l = 0u; l < patch_corner_count(p); l = l + 1u) {
            out[l] = level_edge_factor(patch_edge(p, l));
        }
    } else if (view.criterion == CRITERION_SILHOUETTENESS) {
        // Every patch, culled or not, proposes its edges' factors (`from_edge_factors`).
        for (var l = 0u; l < patch_corner_count(p); l = l + 1u) {
            out[l] = silhouetteness_factor(patch_edge(p, l));
            if (view.edge_rule == EDGE_RULE_POWER_OF_TWO) { out[l] = between_levels(out[l]); }
        }
    } else if (visible[p] != 0u) {
        let eps = patch_tolerance(p);
        let m = patch_views[row + 5u];
        // With the expansion bound, its proposals from the second-derivative bound's.
        var x = no_expansion(p);
        if (view.bound == BOUND_EXPANSION) { x = expansion_of(p); }
        let errors = triangle_errors(m.xyz);
        // CudaTess's quads: the cheapest grid that meets the bound, its core; else one
        // factor for every edge and the interior.
        let quad = view.interior_rule == INTERIOR_CORE && !patch_is_tri(p);
        var proposal = vec2<f32>(uniform_factor(m, eps));
        if (quad) { proposal = quad_grid(m.xyz, eps, u32(view.cap)); }
        if (x.kind != EXPANSION_NONE) {
            // One call site (see `expansion_proposal`).
            let start = select(min(proposal, vec2<f32>(view.cap)), proposal, quad);
            proposal = expansion_proposal(x, errors, patch_is_tri(p), quad, start, eps);
        }
        if (quad) {
            out = vec4<f32>(proposal.x, proposal.y, proposal.x, proposal.y);
        } else {
            for (var l = 0u; l < patch_corner_count(p); l = l + 1u) { out[l] = proposal.x; }
        }
        let curves = patch_views[row + 6u];
        for (var l = 0u; l < patch_corner_count(p); l = l + 1u) {
            out[l] = max(out[l], curve_factor(curves[l], eps));
        }
        checks[p].eps = eps;
    } else {
        checks[p].eps = -1.0;
    }
    proposals[p] = out;
}

// `resolve::interiors` with `InteriorRule::Level` for patch p (and the a-posteriori check's
// first level, `check_patches`' `first`): its largest edge or minimum interior, the next
// power of two, within the cap.
fn semi_uniform_first_level(p: u32) -> u32 {
    var largest = 1u;
    for (var l = 0u; l < patch_corner_count(p); l = l + 1u) {
        largest = max(largest, segments[patch_edge(p, l)]);
    }
    let minimum = patch_views[PATCH_VIEW_ROW * p + 7u];
    let n = max(largest, max(u32(minimum.x), u32(minimum.y)));
    return min(next_power_of_two(n), u32(view.cap));
}

// `resolve::edges`' wish for edge e: the maximum of the proposals over its uses, capped.
fn wanted_factor(e: u32) -> f32 {
    var wanted = 0.0;
    for (var u = edge_first_use(e); u < edge_end_use(e); u = u + 1u) {
        wanted = max(wanted, proposals[use_patch(u)][use_local(u)]);
    }
    return min(wanted, view.cap);
}

// `resolve::edges` with `EdgeRule::Integer` for edge e: its wish rounded half away from zero
// as `f64::round`, at least the minimum; with `EdgeRule::PowerOfTwo`: the level of its wish
// rounded up, `⌈log2 f⌉` (the CPU's margin of 1e-9 is 1e-5 in f32: a whole wish of a pixel
// error is still exactly its next power of two, up to the largest cap), at least the
// minimum, within the cap (a power of two).
fn resolved_segments(e: u32) -> u32 {
    let minimum = max(minimum_segments(e), 1u);
    if (view.edge_rule == EDGE_RULE_POWER_OF_TWO) {
        let level = u32(max(ceil(log2(max(wanted_factor(e), 1.0)) - 1e-5), 0.0));
        return min(next_power_of_two(max(1u << level, minimum)), u32(view.cap));
    }
    return max(u32(floor(wanted_factor(e) + 0.5)), minimum);
}

// Per edge: `resolve::edges` — the maximum over its uses, capped; then `EdgeRule::Integer`
// (`resolved_segments`), or `EdgeRule::Fractional(Spacing::Hardware(_))`: at least the
// minimum, the hull shader's rounding (`hull_factor`), settled (`settled_factor`), the real
// factor kept in the plan's factor row and its segments by the partition (`edge_segments`).
@compute @workgroup_size(WORKGROUP)
fn edge_segments(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let e = thread_index(wid, nwg, lid);
    if (e >= params.edges) { return; }
    if (view.edge_rule == EDGE_RULE_HARDWARE) {
        let mode = params.partitioning;
        let minimum = f32(max(minimum_segments(e), 1u));
        let f = settled_factor(hull_factor(max(wanted_factor(e), minimum), mode), mode);
        segments[e] = hardware_edge_segments(f, mode);
        segments[params.edges + e] = bitcast<u32>(f);
        return;
    }
    if (view.edge_rule == EDGE_RULE_SYMMETRIC) {
        // `EdgeRule::Fractional(Spacing::Symmetric)`: the real factor kept, at least the
        // minimum; segments by the symmetric cut (`symmetric_segments`).
        let f = max(wanted_factor(e), f32(max(minimum_segments(e), 1u)));
        segments[e] = u32(ceil(max(f, 1.0)));
        segments[params.edges + e] = bitcast<u32>(f);
        if (params.warped != 0u) {
            // SD-2's reverse projection: the ends' depths, clamped to the near plane
            // (`Plan::depths` of `sd2::plan`).
            let ends = edge_ends(e);
            let at = 2u * params.edges + 2u * e;
            segments[at] = bitcast<u32>(max(vertex_depth(ends.x), view.near));
            segments[at + 1u] = bitcast<u32>(max(vertex_depth(ends.y), view.near));
        }
        return;
    }
    let s = resolved_segments(e);
    segments[e] = s;
    if (view.interior_rule == INTERIOR_GLOBAL) {
        atomicMax(&state.global_factor, s);
    }
}

// `resolve::interiors`. `InteriorRule::Global`: the frame's largest factor on every edge and
// patch interior. `InteriorRule::Core`: a quad takes the smaller segments of its two edges
// along each direction (at least its minimum), a triangle its largest edge.
// `InteriorRule::MaxEdge`: every patch its largest edge (the hardware pattern itself reads
// only the edges' factors). `InteriorRule::Level`: the largest edge or the minimum interior,
// the next power of two, within the cap.
@compute @workgroup_size(WORKGROUP)
fn interiors(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let x = thread_index(wid, nwg, lid);
    if (view.interior_rule == INTERIOR_GLOBAL) {
        let n = atomicLoad(&state.global_factor);
        if (x < params.edges) { segments[x] = n; }
        if (x < params.patches) { interior[x] = vec2<u32>(n, n); }
        return;
    }
    if (x >= params.patches) { return; }
    let s0 = segments[patch_edge(x, 0u)];
    let s1 = segments[patch_edge(x, 1u)];
    let s2 = segments[patch_edge(x, 2u)];
    if (view.interior_rule == INTERIOR_LEVEL) {
        interior[x] = vec2<u32>(semi_uniform_first_level(x));
        return;
    }
    if (view.interior_rule == INTERIOR_MAX_EDGE && !patch_is_tri(x)) {
        let n = max(max(s0, s1), max(s2, segments[patch_edge(x, 3u)]));
        interior[x] = vec2<u32>(n, n);
        return;
    }
    if (patch_is_tri(x)) {
        let n = max(s0, max(s1, s2));
        interior[x] = vec2<u32>(n, n);
        return;
    }
    let s3 = segments[patch_edge(x, 3u)];
    let minimum = patch_views[PATCH_VIEW_ROW * x + 7u];
    interior[x] = vec2<u32>(max(min(s0, s2), u32(minimum.x)), max(min(s1, s3), u32(minimum.y)));
}
