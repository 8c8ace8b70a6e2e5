// Moving bounds pass: one invocation per patch refreshes its view rows (and a tree's culling
// box) for the cage's moved vertices, the GPU form of `tessera::subdivision::moving_bounds`
// (whose module doc proves the rule and `MovingBounds::moved` states it): the affine fit of
// the patch's vertices' motion, the rest box and sphere mapped by it, each rest bound times
// the fit's stretch plus Σⱼ |rⱼ| tⱼ over the patch's terms (rⱼ the residuals), the growth
// (the first sum) widening the box and the sphere; a patch that moved loses its normal cone.
// A patch whose vertices did not move keeps its rest rows bit for bit.

struct Moving {
    patches: u32,
}

@group(0) @binding(0) var<uniform> moving: Moving;
@group(0) @binding(1) var<storage, read> term_starts: array<u32>;
@group(0) @binding(2) var<storage, read> term_vertices: array<u32>;
// Two rows a term: (growth, uu, uv, vv), the four boundary curves'.
@group(0) @binding(3) var<storage, read> terms: array<vec4<f32>>;
// REST_ROWS a patch: the view rows 0..6 of the rest cage; row 2's w is 1 for a tree.
@group(0) @binding(4) var<storage, read> rest_rows: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> rest_cage: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> cage: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> patch_views: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> control_points: array<vec4<f32>>;

const REST_ROWS: u32 = {{REST_ROWS}}u;
const PATCH_VIEW_ROW: u32 = {{PATCH_VIEW_ROW}}u;
const CONTROL_POINTS: u32 = {{CONTROL_POINTS}}u;
// The sums in f32 are rounded up by a relative 1e-4, far above their rounding error (some
// dozens of terms): the increments stay upper bounds.
const ROUND_UP: f32 = 1.0001;

@compute @workgroup_size(WORKGROUP)
fn apply_moving_bounds(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (p >= moving.patches) { return; }
    let first = term_starts[p];
    let last = term_starts[p + 1u];
    let n = f32(max(last - first, 1u));
    var centroid = vec3<f32>(0.0);
    var t = vec3<f32>(0.0);
    var moved = false;
    for (var k = first; k < last; k++) {
        let v = term_vertices[k];
        centroid += rest_cage[v].xyz;
        t += cage[v].xyz - rest_cage[v].xyz;
        moved = moved || any(cage[v].xyz != rest_cage[v].xyz);
    }
    centroid /= n;
    t /= n;
    // The least-squares fit A = I + m of the displacements' variation (module doc).
    var m = mat3x3<f32>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    var reach = 0.0;
    if (moved) {
        var xx = m;
        var dx = m;
        for (var k = first; k < last; k++) {
            let v = term_vertices[k];
            let x = rest_cage[v].xyz - centroid;
            let d = cage[v].xyz - rest_cage[v].xyz - t;
            xx += outer(x, x);
            dx += outer(d, x);
            reach = max(reach, max_abs(rest_cage[v].xyz) + max_abs(cage[v].xyz));
        }
        let lambda = 1e-6 * (xx[0].x + xx[1].y + xx[2].z) + 1e-30;
        let fit = dx * inverse3(xx + mat3x3<f32>(vec3<f32>(lambda, 0.0, 0.0), vec3<f32>(0.0, lambda, 0.0), vec3<f32>(0.0, 0.0, lambda)));
        if (all_finite(fit)) { m = fit; }
    }
    // Each residual is rounded up by a few units in the last place of the coordinates.
    let slack = 2e-6 * reach;
    var bounds = vec4<f32>(0.0);
    var curves = vec4<f32>(0.0);
    if (moved) {
        for (var k = first; k < last; k++) {
            let v = term_vertices[k];
            let r = length(cage[v].xyz - rest_cage[v].xyz - t - m * (rest_cage[v].xyz - centroid)) + slack;
            bounds += r * terms[2u * k];
            curves += r * terms[2u * k + 1u];
        }
    }
    bounds *= ROUND_UP;
    curves *= ROUND_UP;
    var stretch = 1.0;
    if (moved) { stretch = stretch_of(m) * ROUND_UP; }
    let rest = REST_ROWS * p;
    let g = bounds.x;
    let out = PATCH_VIEW_ROW * p;
    var trig = rest_rows[rest + 2u];
    let tree = trig.w != 0.0;
    trig.w = 0.0;
    if (g > 0.0) { trig.z = 0.0; }
    let sphere = rest_rows[rest + 1u];
    // The rest box's corners mapped, their box grown.
    let rest_lo = rest_rows[rest + 3u].xyz;
    let rest_hi = rest_rows[rest + 4u].xyz;
    var lo = vec3<f32>(3.4e38);
    var hi = vec3<f32>(-3.4e38);
    for (var k = 0u; k < 8u; k++) {
        let q = mapped(box_corner(rest_lo, rest_hi, k), t, m, centroid);
        lo = min(lo, q);
        hi = max(hi, q);
    }
    lo -= vec3<f32>(g);
    hi += vec3<f32>(g);
    let r = rest_rows[rest + 5u];
    patch_views[out] = rest_rows[rest];
    patch_views[out + 1u] = vec4<f32>(mapped(sphere.xyz, t, m, centroid), stretch * sphere.w + g);
    patch_views[out + 2u] = trig;
    patch_views[out + 3u] = vec4<f32>(lo, 0.0);
    patch_views[out + 4u] = vec4<f32>(hi, 0.0);
    patch_views[out + 5u] = vec4<f32>(stretch * r.xyz + bounds.yzw, 0.0);
    patch_views[out + 6u] = stretch * rest_rows[rest + 6u] + curves;
    if (tree) {
        // A tree's 16 slots are its box's corners twice (`upload`: corner k at the upper
        // bound of x, y, z where bit 0, 1, 2 of k is set), which culling reads.
        for (var k = 0u; k < 8u; k++) {
            let corner = vec4<f32>(box_corner(lo, hi, k), 1.0);
            control_points[CONTROL_POINTS * p + k] = corner;
            control_points[CONTROL_POINTS * p + 8u + k] = corner;
        }
    }
}

// Corner k of the box lo..hi (at the upper bound of x, y, z where bit 0, 1, 2 of k is set).
fn box_corner(lo: vec3<f32>, hi: vec3<f32>, k: u32) -> vec3<f32> {
    return select(lo, hi, vec3<bool>((k & 1u) != 0u, (k & 2u) != 0u, (k & 4u) != 0u));
}

// The affine part: x + t + m (x − centroid); x itself where nothing moved (m = 0, t = 0).
fn mapped(x: vec3<f32>, t: vec3<f32>, m: mat3x3<f32>, centroid: vec3<f32>) -> vec3<f32> {
    return x + t + m * (x - centroid);
}

fn outer(a: vec3<f32>, b: vec3<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(a * b.x, a * b.y, a * b.z);
}

fn max_abs(x: vec3<f32>) -> f32 {
    let a = abs(x);
    return max(a.x, max(a.y, a.z));
}

fn all_finite(a: mat3x3<f32>) -> bool {
    var ok = true;
    for (var c = 0u; c < 3u; c++) {
        ok = ok && all(abs(a[c]) <= vec3<f32>(3.4e38));
    }
    return ok;
}

// The inverse by the adjugate (a symmetric positive definite matrix here).
fn inverse3(a: mat3x3<f32>) -> mat3x3<f32> {
    let c0 = cross(a[1], a[2]);
    let c1 = cross(a[2], a[0]);
    let c2 = cross(a[0], a[1]);
    let det = dot(a[0], c0);
    return transpose(mat3x3<f32>(c0, c1, c2)) * (1.0 / det);
}

// An upper bound of ‖I + m‖₂: the square root of the largest Gershgorin row sum of AᵀA.
fn stretch_of(m: mat3x3<f32>) -> f32 {
    let a = m + mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
    let b = transpose(a) * a;
    // b is symmetric: its columns' sums are its rows'.
    let sums = vec3<f32>(dot(abs(b[0]), vec3<f32>(1.0)), dot(abs(b[1]), vec3<f32>(1.0)), dot(abs(b[2]), vec3<f32>(1.0)));
    return sqrt(max(sums.x, max(sums.y, sums.z)));
}
