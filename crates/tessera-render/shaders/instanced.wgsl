// The instanced semi-uniform draw (paper 000, Listing 1): one instanced draw per level m of
// the static pattern P^m; each instance is a render-queue entry (`queues.wgsl`), each vertex
// a pattern vertex, snapped with φ to its edge's level and evaluated on the instance's patch
// in the vertex shader. Degenerate triangles (snapped corners that meet) are left to the
// rasteriser. Concatenated after tessera-gpu's `bicubic.wgsl` and `bezier_triangle.wgsl`
// (the patch evaluation, `eval_patch`) and this crate's `draw.wgsl` (`Frame`, `Corner`, the
// shading and `fs`); the prelude below gives the evaluation its buffers.

const CONTROL_POINTS: u32 = {{CONTROL_POINTS}}u;
const PATCH_ROW: u32 = {{PATCH_ROW}}u;

// `tessera_gpu::upload::GpuSet`'s buffers.
@group(0) @binding(6) var<storage, read> control_points: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> patch_rows: array<u32>;
// `queues.wgsl`'s outputs.
@group(0) @binding(8) var<storage, read> queue_entries: array<u32>;
@group(0) @binding(9) var<storage, read> queue_slots: array<u32>;

// tessera-gpu `common.wgsl`'s patch-row accessors.
fn patch_is_tri(p: u32) -> bool { return (patch_rows[p * PATCH_ROW + 12u] & 2u) != 0u; }
fn patch_has_pn_normals(p: u32) -> bool { return (patch_rows[p * PATCH_ROW + 12u] & 4u) != 0u; }

struct DrawLevel {
    level: u32,
    // P + 1: the queue slots' stride per level.
    stride: u32,
    max_level: u32,
    // Vertices of P^level and its first vertex in the pattern buffer (for `expand`).
    vertices: u32,
    base_vertex: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(1) @binding(0) var<uniform> draw_level: DrawLevel;

// A static pattern vertex (`tessera::pattern::semi_uniform::PatternVertex`): uv, the edge
// parameter t and the snap offset, the edge (4: none).
struct PatternVertex {
    @location(0) uv: vec2<f32>,
    @location(1) snap: vec2<f32>,
    @location(2) edge: u32,
};

// `Domain::edge_point`: the convex combination of the edge's corners.
fn edge_point(tri: bool, e: u32, t: f32) -> vec2<f32> {
    let quad = array<vec2<f32>, 4>(vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0), vec2<f32>(0.0, 1.0));
    let tris = array<vec2<f32>, 4>(vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0), vec2<f32>(0.0, 0.0));
    let n = select(4u, 3u, tri);
    let f = (e + 1u) % n;
    var a = quad[e];
    var b = quad[f];
    if (tri) {
        a = tris[e];
        b = tris[f];
    }
    return a * (1.0 - t) + b * t;
}

// `tessera::pattern::semi_uniform::snap` (φ).
fn snap(tri: bool, v: PatternVertex, levels: u32) -> vec2<f32> {
    if (v.edge >= 4u) { return v.uv; }
    let s = f32(1u << ((levels >> (8u * v.edge)) & 255u));
    let t = floor(s * v.snap.x + v.snap.y) / s;
    return edge_point(tri, v.edge, t);
}

struct Instanced {
    point: SurfacePoint,
    patch_id: u32,
};

// The vertex `v` of instance `instance` of the current level: F(φ(v)).
fn instanced_point(instance: u32, v: PatternVertex) -> Instanced {
    let slot = queue_slots[draw_level.level * draw_level.stride] + instance;
    let p = queue_entries[2u * slot];
    let uv = snap(patch_is_tri(p), v, queue_entries[2u * slot + 1u]);
    return Instanced(eval_patch(p, uv), p);
}

@vertex
fn vs_instanced(v: PatternVertex, @builtin(instance_index) instance: u32) -> Corner {
    let x = instanced_point(instance, v);
    var out: Corner;
    out.clip = frame.view_proj * vec4<f32>(x.point.position, 1.0);
    out.world = x.point.position;
    out.normal = x.point.normal;
    // No barycentrics with shared pattern vertices: no wireframe on this path.
    out.bary = vec3<f32>(1.0);
    let level = f32(draw_level.level) / f32(max(draw_level.max_level, 1u));
    out.base = base_colour(frame.flags.x, x.patch_id, level);
    return out;
}

// For tests: the same vertices written out, instance after instance (4 floats each).
@group(0) @binding(10) var<storage, read> pattern: array<u32>;
@group(0) @binding(11) var<storage, read_write> expanded: array<vec4<f32>>;

@compute @workgroup_size(64)
fn expand(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = id.x + id.y * groups.x * 64u;
    let s = draw_level.level * draw_level.stride;
    let instances = queue_slots[s + draw_level.stride - 1u] - queue_slots[s];
    if (i >= instances * draw_level.vertices) { return; }
    let k = draw_level.base_vertex + i % draw_level.vertices;
    var v: PatternVertex;
    v.uv = vec2<f32>(bitcast<f32>(pattern[5u * k]), bitcast<f32>(pattern[5u * k + 1u]));
    v.snap = vec2<f32>(bitcast<f32>(pattern[5u * k + 2u]), bitcast<f32>(pattern[5u * k + 3u]));
    v.edge = pattern[5u * k + 4u];
    expanded[i] = vec4<f32>(instanced_point(i / draw_level.vertices, v).point.position, 1.0);
}

// One invocation: each level's `DrawIndexedIndirect` arguments from its queue's length.
// `level_table`: per level, index count, first index, base vertex of P^m.
@group(0) @binding(12) var<storage, read> level_table: array<u32>;
@group(0) @binding(13) var<storage, read_write> level_args: array<u32>;

@compute @workgroup_size(1)
fn write_level_args() {
    for (var m = 0u; m <= draw_level.max_level; m++) {
        let s = m * draw_level.stride;
        let instances = queue_slots[s + draw_level.stride - 1u] - queue_slots[s];
        level_args[5u * m] = level_table[3u * m];
        level_args[5u * m + 1u] = instances;
        level_args[5u * m + 2u] = level_table[3u * m + 1u];
        level_args[5u * m + 3u] = level_table[3u * m + 2u];
        level_args[5u * m + 4u] = 0u;
    }
}
