// Moving bounds pass: one invocation per patch refreshes its view rows (and a tree's culling
// box) for the cage's moved vertices, the GPU form of `tessera::subdivision::moving_bounds`
// (whose module doc proves the rule and `MovingBounds::moved` states it): with t the mean
// displacement of the patch's vertices, the rest box and sphere moved by t, and the rest
// bounds plus Σⱼ |dⱼ − t| tⱼ over the patch's terms, the growth (the first sum) widening the
// box and the sphere; a patch that moved loses its normal cone. A patch whose vertices did
// not move keeps its rest rows bit for bit.

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
    var t = vec3<f32>(0.0);
    for (var k = first; k < last; k++) {
        let v = term_vertices[k];
        t += cage[v].xyz - rest_cage[v].xyz;
    }
    t /= f32(max(last - first, 1u));
    var bounds = vec4<f32>(0.0);
    var curves = vec4<f32>(0.0);
    for (var k = first; k < last; k++) {
        let v = term_vertices[k];
        let d = length(cage[v].xyz - rest_cage[v].xyz - t);
        bounds += d * terms[2u * k];
        curves += d * terms[2u * k + 1u];
    }
    bounds *= ROUND_UP;
    curves *= ROUND_UP;
    let rest = REST_ROWS * p;
    // The box and sphere are moved by t in f32: a few units in the last place of their
    // coordinates more growth covers that rounding (none for a patch that did not move).
    var g = bounds.x;
    if (g > 0.0 || any(t != vec3<f32>(0.0))) {
        let reach = max(abs(rest_rows[rest + 3u].xyz), abs(rest_rows[rest + 4u].xyz)) + abs(t);
        g += 5e-7 * max(reach.x, max(reach.y, reach.z));
    }
    let out = PATCH_VIEW_ROW * p;
    var trig = rest_rows[rest + 2u];
    let tree = trig.w != 0.0;
    trig.w = 0.0;
    if (g > 0.0) { trig.z = 0.0; }
    let sphere = rest_rows[rest + 1u];
    let lo = rest_rows[rest + 3u].xyz + t - vec3<f32>(g);
    let hi = rest_rows[rest + 4u].xyz + t + vec3<f32>(g);
    patch_views[out] = rest_rows[rest];
    patch_views[out + 1u] = vec4<f32>(sphere.xyz + t, sphere.w + g);
    patch_views[out + 2u] = trig;
    patch_views[out + 3u] = vec4<f32>(lo, 0.0);
    patch_views[out + 4u] = vec4<f32>(hi, 0.0);
    patch_views[out + 5u] = vec4<f32>(rest_rows[rest + 5u].xyz + bounds.yzw, 0.0);
    patch_views[out + 6u] = rest_rows[rest + 6u] + curves;
    if (tree) {
        // A tree's 16 slots are its box's corners twice (`upload`: corner k at the upper
        // bound of x, y, z where bit 0, 1, 2 of k is set), which culling reads.
        for (var k = 0u; k < 8u; k++) {
            let corner = vec4<f32>(
                select(lo.x, hi.x, (k & 1u) != 0u),
                select(lo.y, hi.y, (k & 2u) != 0u),
                select(lo.z, hi.z, (k & 4u) != 0u),
                1.0,
            );
            control_points[CONTROL_POINTS * p + k] = corner;
            control_points[CONTROL_POINTS * p + 8u + k] = corner;
        }
    }
}
