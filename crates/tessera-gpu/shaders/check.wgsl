// The a-posteriori check of an error-bounded transition or semi-uniform plan, from the camera
// alone: the GPU form of `tessera::criterion::tolerance::plan_limited` after its proposals
// (the pixel-error proposals and the first resolve are `factors.wgsl`'s).
//
// A patch's transition strips follow its edges, so a grid that meets the bound in the core
// can miss it next to a coarse edge: each patch builds its pattern and bounds every
// triangle (`check_patch`, `tolerance::check_patches`), raising its private interior until
// the bound holds. Where the interior alone cannot (the worst triangles follow an edge) the
// patch fails, and a *round* raises the failing patches' proposals, resolves the edges again
// by the maximum rule and re-checks the patches of changed edges, as the CPU's loop does.
//
// The rounds run without the CPU. A round is four dispatches: `round_open` (one invocation:
// does any patch fail?), `round_resolve` (per edge: the edges again from the grown proposals,
// the changed ones into the plan, their patches marked), `round_close` (one invocation: did
// any edge change?) and the re-check (`check_patches` again, per patch: the failing and
// marked patches, each growing its proposals when it fails, as the CPU's next round would
// first).
// The two decisions write the indirect arguments of the two passes after them: zero
// workgroups once the rounds have ended. The CPU ends the loop when no patch fails or
// when a round changes no edge (every failing patch at the cap), and so do they; a frame
// records `DEFAULT_CHECK_ROUNDS` rounds, and a plan that needs more is reported (`state.done` stays
// 0), never cut silently: the plan of the last round is still crack-free (the maximum rule
// holds every round), only some bounds are missed, as at the factor cap.
//
// f32 where the CPU computes in f64: a decision (a factor's `ceil`, a bound against its
// tolerance) can differ where the value lies within f32 rounding of the boundary; the tests
// count such cases. The constant growth steps (1.05 for interiors, 1.2 for proposals) are
// computed in integers, as they hit exact products (20 · 1.05 = 21) that f32 would round
// either way.

// Dispatch arguments of the round's two passes: per patch (x, y, z), then per edge (x, y, z).
// Bound only in the rounds' decisions (`round_open`, `round_close`), whose group 1 holds
// just the frame state and these: the passes they size read them as indirect arguments.
@group(1) @binding(5) var<storage, read_write> round_args: array<u32, 6>;

fn write_round_args(run: bool) {
    var per_patch = dispatch_grid(params.patches);
    var per_edge = dispatch_grid(params.edges);
    if (!run) {
        per_patch = vec2<u32>(0u);
        per_edge = vec2<u32>(0u);
    }
    round_args[0] = per_patch.x;
    round_args[1] = per_patch.y;
    round_args[2] = 1u;
    round_args[3] = per_edge.x;
    round_args[4] = per_edge.y;
    round_args[5] = 1u;
}

// `ceil(n · 1.05)` for a whole n, as f64 rounds it (n · 1.05 is a whole number only for
// multiples of 20, where f64's product is exact after rounding).
fn grown_105(n: u32) -> u32 {
    return (n * 105u + 99u) / 100u;
}

// `ceil(v · 1.2)` for a whole v ≥ 0 (whole only for multiples of 5, exact in f64).
fn grown_120(v: f32) -> f32 {
    return f32((u32(v) * 6u + 4u) / 5u);
}

// One patch's check (`tolerance::check_patches`): its first interior from its proposals and
// edges (`first`: CudaTess's core, the smaller of the patch's own grid and its edges per
// direction on a quad, the largest edge on a triangle, at least the minimum interior), then
// the interior raised like the square root of the excess until every triangle's bound meets
// the tolerance, the cap is reached, or a step brings no progress. Writes the plan's
// interior and the check row. A patch that misses its bound asks for finer edges at once:
// its proposals grown like the square root of the excess, at least by 1.2, within the cap
// (`plan_limited`'s round, which only a failing patch starts, so the growth is never
// wasted; proposals are read by nothing after the rounds). Returns whether the bound is
// missed. Cost: one pattern walk per step, serial.
fn check_patch(p: u32) -> bool {
    let cap = u32(view.cap);
    let nc = patch_corner_count(p);
    var s = vec4<u32>(1u);
    for (var l = 0u; l < nc; l = l + 1u) { s[l] = segments[patch_edge(p, l)]; }
    let minimum = patch_views[PATCH_VIEW_ROW * p + 7u];
    let level = view.interior_rule == INTERIOR_LEVEL;
    var first: vec2<u32>;
    if (level) {
        first = vec2<u32>(semi_uniform_first_level(p));
    } else if (nc == 3u) {
        let n = max(s.x, max(s.y, s.z));
        first = vec2<u32>(n, n);
    } else {
        let own = max(vec2<u32>(min(proposals[p].xy, vec2<f32>(view.cap))), vec2<u32>(1u));
        first = vec2<u32>(min(own.x, min(s.x, s.z)), min(own.y, min(s.y, s.w)));
    }
    if (!level) {
        first = max(first, vec2<u32>(minimum.xy));
    }
    let eps = checks[p].eps;
    if (eps < 0.0) {
        // Culled: the first interior, nothing to bound.
        interior[p] = first;
        checks[p].bound = 0.0;
        checks[p].flags = 0u;
        return false;
    }
    let errors = triangle_errors(patch_views[PATCH_VIEW_ROW * p + 5u].xyz);
    // With the expansion bound every triangle's bound is the smaller of the two.
    var x = no_expansion(p);
    if (view.bound == BOUND_EXPANSION) { x = expansion_of(p); }
    var factors = first;
    var previous = 3.0e38;
    var bound = 0.0;
    var missed = false;
    loop {
        if (level) {
            bound = semi_uniform_bound(p, factors.x, errors, x);
        } else {
            bound = transition_bound(p, factors, errors, x);
        }
        if (bound <= eps) { break; }
        // No progress means the worst triangles follow the edges, not the core.
        let stuck = bound >= previous;
        if (max(factors.x, factors.y) >= cap || stuck) {
            missed = true;
            break;
        }
        previous = bound;
        let grow = sqrt(bound / eps);
        var next = factors;
        for (var k = 0u; k < 2u; k = k + 1u) {
            let n = factors[k];
            var raised = grown_105(n);
            if (grow > 1.05) { raised = u32(ceil(f32(n) * grow)); }
            next[k] = clamp(raised, n + 1u, cap);
            if (level) { next[k] = min(next_power_of_two(next[k]), cap); }
        }
        factors = next;
    }
    interior[p] = factors;
    checks[p].bound = bound;
    checks[p].flags = select(0u, 1u, missed);
    if (missed) {
        let grow = sqrt(bound / eps);
        var wish = proposals[p];
        for (var l = 0u; l < 4u; l = l + 1u) {
            // Proposals at or past the cap stay there (the first ones are not capped).
            if (wish[l] >= view.cap) {
                wish[l] = view.cap;
                continue;
            }
            var raised = grown_120(wish[l]);
            if (grow > 1.2) { raised = ceil(wish[l] * grow); }
            wish[l] = min(raised, view.cap);
        }
        proposals[p] = wish;
    }
    return missed;
}

// The largest error bound over patch p's transition pattern with interior `factors`. Every
// core triangle is half a grid cell: one cell's triangle bounds them all
// (`Pattern::grid_cells`, `tolerance::grid_bound`), or with the expansion bound the walk
// over the grid's cells (`expansion_grid_error`: at most EXPANSION_WALK_CELLS); the walk
// takes the strips. The core is never walked triangle by triangle, which also keeps a check
// within lavapipe's 65,535 loop iterations an invocation (`local.wgsl`): a strip has at most
// 2 · 64 steps.
fn transition_bound(p: u32, factors: vec2<u32>, errors: TriangleErrors, x: Expansion) -> f32 {
    let input = pattern_input(p, factors);
    let l = input.core;
    var out = sink(SINK_CHECK, 0u);
    out.errors = errors;
    out.expansion = x;
    let core_cells = select((l.i_hi - l.i_lo) * (l.j_hi - l.j_lo), l.m, input.local.nc == 3u);
    if (core_cells > 0u) {
        let cell = vec2<f32>(1.0 / f32(l.nu), 1.0 / f32(l.nv));
        let hessian = triangle_error(errors, vec2<f32>(0.0), vec2<f32>(cell.x, 0.0), vec2<f32>(0.0, cell.y));
        out.worst = expansion_grid_error(x, input.local.nc == 3u, l.nu, l.nv, 3.0e38, hessian);
    }
    build_transition(input, &out);
    return out.worst;
}

// The largest error bound over patch p's semi-uniform pattern at level n (`params_bound` over
// `SemiUniform::build`'s triangles): the triangles with a corner on the boundary one by one,
// after the snap (those it collapses are not in the pattern); the others are halves of grid
// cells, bounded by one cell's triangle as `transition_bound` bounds a core — or, with the
// expansion bound, whose bound differs from triangle to triangle, one by one too. Cost: O(n)
// triangles (`semi_uniform.wgsl` says which ones can touch the boundary), O(n²) with the
// expansion bound (a level at most 64: 8,192 triangles).
fn semi_uniform_bound(p: u32, n: u32, errors: TriangleErrors, x: Expansion) -> f32 {
    let input = local_numbering(p);
    let m = countTrailingZeros(n);
    let tri = input.nc == 3u;
    var worst = 0.0;
    var cells = false;
    for (var j = 0u; j < n; j = j + 1u) {
        let len = row_length(tri, n, j);
        let whole = j == 0u || j + 1u >= n;
        for (var q = 0u; q < len; q = q + 1u) {
            if (!whole && q >= 2u && q + 2u < len && x.kind == EXPANSION_NONE) {
                // The middle of a middle row: off the boundary, jump to its last two.
                cells = true;
                q = len - 3u;
                continue;
            }
            let g = row_triangle(tri, j, q);
            let t = semi_uniform_triangle(input, n, m, j, q);
            if (t.x == t.y) { continue; }
            let a = semi_uniform_param(input, n, m, g[0].x, g[0].y);
            let b = semi_uniform_param(input, n, m, g[1].x, g[1].y);
            let c = semi_uniform_param(input, n, m, g[2].x, g[2].y);
            let e = triangle_error(errors, a, b, c);
            if (e > worst) { worst = max(worst, min(e, expansion_triangle_error(x, a, b, c))); }
        }
    }
    if (cells) {
        let h = 1.0 / f32(n);
        worst = max(worst, triangle_error(errors, vec2<f32>(0.0), vec2<f32>(h, 0.0), vec2<f32>(0.0, h)));
    }
    return worst;
}

// A round starts only while some patch fails (`plan_limited`: `failing.is_empty()`); its
// failing patches' proposals are already grown.
@compute @workgroup_size(1)
fn round_open() {
    if (atomicLoad(&state.failing) == 0u) { atomicStore(&state.done, 1u); }
    write_round_args(atomicLoad(&state.done) == 0u);
}

// The edges again from the grown proposals (`resolved_segments`); a changed edge goes into
// the plan at once (each invocation reads only its own edge's segments) and marks its
// patches for the re-check.
@compute @workgroup_size(WORKGROUP)
fn round_resolve(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let e = thread_index(wid, nwg, lid);
    if (e >= params.edges) { return; }
    let s = resolved_segments(e);
    if (s == segments[e]) { return; }
    segments[e] = s;
    atomicStore(&state.changed, 1u);
    for (var u = edge_first_use(e); u < edge_end_use(e); u = u + 1u) {
        atomicStore(&checks[use_patch(u)].marked, 1u);
    }
}

// The round goes on only if an edge changed (`plan_limited`: every failing patch at the cap
// otherwise, and then nothing changed in the plan); the re-check counts the failing patches
// again.
@compute @workgroup_size(1)
fn round_close() {
    if (atomicLoad(&state.done) == 0u) {
        if (atomicLoad(&state.changed) == 0u) {
            atomicStore(&state.done, 1u);
        } else {
            atomicStore(&state.changed, 0u);
            atomicStore(&state.failing, 0u);
            atomicAdd(&state.rounds, 1u);
        }
    }
    write_round_args(atomicLoad(&state.done) == 0u);
}

// The check: in the first check, after the first resolve, every patch (no fix round has
// run: the frame cleared `state.rounds`); in a round's re-check (`round_close` counted the
// round first) the failing patches and those of changed edges. One entry point for both, so
// that the driver compiles the check and its bound once (lavapipe inlines every call).
@compute @workgroup_size(WORKGROUP)
fn check_patches(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (p >= params.patches) { return; }
    if (atomicLoad(&state.rounds) != 0u) {
        let marked = atomicLoad(&checks[p].marked) != 0u;
        if (!marked && (checks[p].flags & 1u) == 0u) { return; }
    }
    atomicStore(&checks[p].marked, 0u);
    if (check_patch(p)) { atomicAdd(&state.failing, 1u); }
}
