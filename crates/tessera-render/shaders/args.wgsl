// One invocation: turns `DrawIndexedIndirect` arguments (the GPU engine's, or the renderer's
// own for a CPU mesh) into the `DrawIndirect` arguments of `draw.wgsl`'s vertex pulling (one
// vertex invocation per index), and the first index and base vertex it reads. On the GPU, so
// that a GPU-tessellated frame is drawn with no read-back.

struct DrawIndexedIndirect {
    index_count: u32,
    instance_count: u32,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
};

@group(0) @binding(0) var<storage, read> indexed: DrawIndexedIndirect;
@group(0) @binding(1) var<storage, read_write> draw: array<u32, 4>;
@group(0) @binding(2) var<storage, read_write> info: array<u32, 4>;

@compute @workgroup_size(1)
fn convert() {
    // vertex_count, instance_count, first_vertex, first_instance.
    draw[0] = indexed.index_count;
    draw[1] = min(indexed.instance_count, 1u);
    draw[2] = 0u;
    draw[3] = 0u;
    info[0] = indexed.first_index;
    info[1] = u32(indexed.base_vertex);
    info[2] = 0u;
    info[3] = 0u;
}
