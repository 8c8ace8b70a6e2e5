// The one-invocation pass after the scans: reads the totals from the layout and writes the
// indirect arguments of the write passes and of the draw, so that nothing goes back to the
// CPU. A frame whose totals exceed the output buffers writes no work at all and raises
// `status.overflow` (never a truncated mesh); the host sizes buffers from a worst-case bound
// beforehand, so this is a guard, not a path.

struct Status {
    overflow: u32,
    vertices: u32,
    triangles: u32,
    _pad: u32,
}

@group(1) @binding(0) var<storage, read_write> draw: DrawIndexedIndirect;
// x, y, z of the edge-vertex, interior-vertex, per-triangle and per-patch write passes, in
// that order.
@group(1) @binding(1) var<storage, read_write> dispatch: array<u32, 12>;
@group(1) @binding(2) var<storage, read_write> status: Status;

// Dispatch `slot`'s workgroups for `threads` invocations (`dispatch_grid`).
fn set_grid(slot: u32, threads: u32) {
    let grid = dispatch_grid(threads);
    dispatch[3u * slot] = grid.x;
    dispatch[3u * slot + 1u] = grid.y;
    dispatch[3u * slot + 2u] = 1u;
}

@compute @workgroup_size(1)
fn write_args() {
    let edges = params.edges;
    let vertices_total = vertex_offsets[edges + params.patches];
    let triangles_total = triangle_offsets[params.patches];
    let overflow = vertices_total > params.vertex_capacity || triangles_total > params.triangle_capacity;
    status.vertices = vertices_total;
    status.triangles = triangles_total;
    status.overflow = select(0u, 1u, overflow);
    if (overflow) {
        set_grid(0u, 0u);
        set_grid(1u, 0u);
        set_grid(2u, 0u);
        set_grid(3u, 0u);
        draw = DrawIndexedIndirect(0u, 0u, 0u, 0, 0u);
        return;
    }
    set_grid(0u, vertex_offsets[edges] - params.corners);
    set_grid(1u, vertices_total - vertex_offsets[edges]);
    set_grid(2u, triangles_total);
    set_grid(3u, params.patches * params.blocks);
    draw = DrawIndexedIndirect(3u * triangles_total, 1u, 0u, 0, 0u);
}
