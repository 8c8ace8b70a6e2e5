// Stencil pass: one invocation per point recomputes it from the cage's vertices, the GPU form
// of `tessera::subdivision::SparseRows::apply_row`: row `r` is the point at `destinations[r]`
// of the control points (a regular face's control point, or a leaf point of a tree block;
// polynomial either way: w = 1).

struct Stencils {
    rows: u32,
}

@group(0) @binding(0) var<uniform> stencils: Stencils;
@group(0) @binding(1) var<storage, read> starts: array<u32>;
// (vertex, bitcast<u32>(weight)) per term.
@group(0) @binding(2) var<storage, read> terms: array<vec2<u32>>;
@group(0) @binding(3) var<storage, read> destinations: array<u32>;
@group(0) @binding(4) var<storage, read> cage: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> control_points: array<vec4<f32>>;

@compute @workgroup_size(WORKGROUP)
fn apply_stencils(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let r = thread_index(wid, nwg, lid);
    if (r >= stencils.rows) { return; }
    var sum = vec3<f32>(0.0);
    for (var k = starts[r]; k < starts[r + 1u]; k++) {
        let term = terms[k];
        sum += bitcast<f32>(term.y) * cage[term.x].xyz;
    }
    control_points[destinations[r]] = vec4<f32>(sum, 1.0);
}
