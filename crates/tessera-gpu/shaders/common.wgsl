// Shared by every tessellation pass: the bindings of group 0 (the prepared set, the plan,
// the layout and the outputs) and their accessors. Row formats: `src/upload.rs`.

struct Params {
    // E, P and the corner entries of the set.
    edges: u32,
    patches: u32,
    corners: u32,
    // Room in the output buffers: the args pass refuses a frame past them (status.overflow).
    vertex_capacity: u32,
    triangle_capacity: u32,
    // The hardware pattern's partitioning (`hardware_partition.wgsl`'s PARTITIONING_*); 0 for
    // the other patterns.
    partitioning: u32,
    // Invocations a patch in the per-patch triangle pass: for the semi-uniform pattern up to
    // ROW_BLOCKS, each writing a block of its grid's rows (`semi_uniform.wgsl`); 1 for the
    // other patterns.
    blocks: u32,
    // 1 for a reverse-projected SD-2 plan (`SamplingKind::Warped`: the edge depths follow the
    // factors in `segments`, `sd2.wgsl`), else 0.
    warped: u32,
}

@group(0) @binding(0) var<uniform> params: Params;

// `wgpu::util::DrawIndexedIndirectArgs`: the draws the args and strip passes write.
struct DrawIndexedIndirect {
    index_count: u32,
    instance_count: u32,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}
// The prepared set (src/upload.rs).
@group(0) @binding(1) var<storage, read_write> control_points: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> patch_rows: array<u32>;
@group(0) @binding(3) var<storage, read_write> edge_rows: array<u32>;
@group(0) @binding(4) var<storage, read_write> edge_uses: array<u32>;
@group(0) @binding(5) var<storage, read_write> corner_rows: array<u32>;
// The plan: `tessera::criterion::Plan::{segments, interior, visible}` byte for byte;
// `segments[E..2E]` holds `Plan::factors` (the f32 bits, `edge_factor`), which the hardware
// and SD-2 patterns read, and `segments[2E..4E]` a warped plan's `Plan::depths` (SD-2's
// reverse projection); one buffer for all keeps the frame within 16 storage buffers.
@group(0) @binding(6) var<storage, read_write> segments: array<u32>;
@group(0) @binding(7) var<storage, read_write> interior: array<vec2<u32>>;
@group(0) @binding(8) var<storage, read_write> visible: array<u32>;
// The layout: `tessera::engine::Layout`. `vertex_offsets[0..=E]` is `edge_offsets`,
// `vertex_offsets[E..=E+P]` is `interior_offsets` (they share entry E); `triangle_offsets` is
// the layout's own. Counts before the scan, offsets after it.
@group(0) @binding(9) var<storage, read_write> vertex_offsets: array<u32>;
@group(0) @binding(10) var<storage, read_write> triangle_offsets: array<u32>;
// The outputs: VERTEX_FLOATS f32 per vertex (position, normal, uv), 3 u32 per triangle.
@group(0) @binding(11) var<storage, read_write> vertices: array<f32>;
@group(0) @binding(12) var<storage, read_write> indices: array<u32>;

const PATCH_ROW: u32 = {{PATCH_ROW}}u;
const EDGE_ROW: u32 = {{EDGE_ROW}}u;
const USE_ROW: u32 = {{USE_ROW}}u;
const CORNER_ROW: u32 = {{CORNER_ROW}}u;
const CONTROL_POINTS: u32 = {{CONTROL_POINTS}}u;
const VERTEX_FLOATS: u32 = {{VERTEX_FLOATS}}u;

const MAX_GROUPS_PER_DIMENSION: u32 = {{MAX_GROUPS_PER_DIMENSION}}u;

// Workgroups (x, y) for `threads` invocations, 2D past the per-dimension limit:
// `shader::grid`; (0, 0) for none.
fn dispatch_grid(threads: u32) -> vec2<u32> {
    let groups = (threads + WORKGROUP - 1u) / WORKGROUP;
    if (threads == 0u) { return vec2<u32>(0u, 0u); }
    if (groups > MAX_GROUPS_PER_DIMENSION) {
        return vec2<u32>(MAX_GROUPS_PER_DIMENSION, (groups + MAX_GROUPS_PER_DIMENSION - 1u) / MAX_GROUPS_PER_DIMENSION);
    }
    return vec2<u32>(groups, 1u);
}

// `thread_index` is in threads.wgsl, which `shader::sources::COMMON` puts before this file.

// Patch rows.
fn patch_edge(p: u32, e: u32) -> u32 { return patch_rows[p * PATCH_ROW + e]; }
fn patch_edge_reversed(p: u32, e: u32) -> bool { return (patch_rows[p * PATCH_ROW + 4u + e] & 1u) != 0u; }
fn patch_edge_collapsed(p: u32, e: u32) -> bool { return (patch_rows[p * PATCH_ROW + 4u + e] & 2u) != 0u; }
fn patch_corner_pinched(p: u32, c: u32) -> bool { return (patch_rows[p * PATCH_ROW + 4u + c] & 4u) != 0u; }
fn patch_edge_variant(p: u32, e: u32) -> u32 { return (patch_rows[p * PATCH_ROW + 4u + e] >> 8u) & 255u; }
fn patch_corner_entry(p: u32, c: u32) -> u32 { return patch_rows[p * PATCH_ROW + 8u + c]; }
fn patch_repeated_corner(p: u32) -> bool { return (patch_rows[p * PATCH_ROW + 12u] & 1u) != 0u; }
fn patch_is_tri(p: u32) -> bool { return (patch_rows[p * PATCH_ROW + 12u] & 2u) != 0u; }
fn patch_has_pn_normals(p: u32) -> bool { return (patch_rows[p * PATCH_ROW + 12u] & 4u) != 0u; }
fn patch_corner_count(p: u32) -> u32 { return select(4u, 3u, patch_is_tri(p)); }
// Control points of the patch's geometry (the rest of its 16 slots hold PN normals).
fn patch_point_count(p: u32) -> u32 { return select(16u, 10u, patch_is_tri(p)); }

// The plan's real factor of edge e (`Plan::factors`).
fn edge_factor(e: u32) -> f32 { return bitcast<f32>(segments[params.edges + e]); }

// Edge rows and uses.
fn edge_first_use(e: u32) -> u32 { return edge_rows[e * EDGE_ROW]; }
fn edge_end_use(e: u32) -> u32 { return edge_rows[e * EDGE_ROW + 1u]; }
fn edge_variants(e: u32) -> u32 { return edge_rows[e * EDGE_ROW + 2u]; }
fn edge_collapsed(e: u32) -> bool { return edge_rows[e * EDGE_ROW + 3u] != 0u; }
fn use_patch(u: u32) -> u32 { return edge_uses[u * USE_ROW]; }
fn use_local(u: u32) -> u32 { return edge_uses[u * USE_ROW + 1u] & 255u; }
fn use_reversed(u: u32) -> bool { return ((edge_uses[u * USE_ROW + 1u] >> 8u) & 1u) != 0u; }
fn use_variant(u: u32) -> u32 { return (edge_uses[u * USE_ROW + 1u] >> 16u) & 255u; }

// The largest i in [lo, hi) with offsets[i] <= x, where `offsets` is one of the layout's
// prefix sums: the edge or patch whose range holds output element x (empty ranges, equal
// neighbours, are skipped because the last of equal entries is taken).
fn find_vertex_range(lo: u32, hi: u32, x: u32) -> u32 {
    var a = lo;
    var b = hi;
    while (b - a > 1u) {
        let mid = (a + b) / 2u;
        if (vertex_offsets[mid] <= x) { a = mid; } else { b = mid; }
    }
    return a;
}

fn find_triangle_range(lo: u32, hi: u32, x: u32) -> u32 {
    var a = lo;
    var b = hi;
    while (b - a > 1u) {
        let mid = (a + b) / 2u;
        if (triangle_offsets[mid] <= x) { a = mid; } else { b = mid; }
    }
    return a;
}

// The two triangle passes of a pattern that drops triangles only where a patch has a
// repeated corner (uniform, SD-2): output triangle t's patch, or params.patches when t is past
// the frame or its patch has a repeated corner (the per-patch pass writes those); and whether
// patch p is one that pass writes (visible, with a repeated corner).
fn plain_triangle_patch(t: u32) -> u32 {
    if (t >= triangle_offsets[params.patches]) { return params.patches; }
    let p = find_triangle_range(0u, params.patches, t);
    return select(p, params.patches, patch_repeated_corner(p));
}

fn collapsed_patch(p: u32) -> bool {
    return p < params.patches && visible[p] != 0u && patch_repeated_corner(p);
}

// Corner c of the quad domain: `tessera::domain::Domain::corner`.
fn quad_corner(c: u32) -> vec2<f32> {
    switch c {
        case 0u: { return vec2<f32>(0.0, 0.0); }
        case 1u: { return vec2<f32>(1.0, 0.0); }
        case 2u: { return vec2<f32>(1.0, 1.0); }
        default: { return vec2<f32>(0.0, 1.0); }
    }
}

// Corner c of patch p's domain: `Domain::corner` (triangles: (0,0), (1,0), (0,1)).
fn domain_corner(p: u32, c: u32) -> vec2<f32> {
    if (patch_is_tri(p)) {
        return array<vec2<f32>, 3>(vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0))[c];
    }
    return quad_corner(c);
}

// `Domain::edge_point` on patch p's domain.
fn domain_edge_point(p: u32, e: u32, t: f32) -> vec2<f32> {
    let n = patch_corner_count(p);
    return domain_corner(p, e) * (1.0 - t) + domain_corner(p, (e + 1u) % n) * t;
}

// The point at t along local edge e: `Domain::edge_point`, a convex combination so that
// t = 0 and t = 1 give the corners exactly.
fn quad_edge_point(e: u32, t: f32) -> vec2<f32> {
    return quad_corner(e) * (1.0 - t) + quad_corner((e + 1u) % 4u) * t;
}

// Parameter k of `segments` equal steps: `tessera::sampling::uniform_param`.
fn uniform_param(segments: u32, k: u32) -> f32 {
    if (k == segments) { return 1.0; }
    return f32(k) / f32(segments);
}

// The output vertex of the patch's own sample k of local edge e: `LocalMap::edge_vertex`
// (a collapsed curve's samples are its corner) with `Layout::edge_vertex`'s formula.
fn edge_sample_vertex(p: u32, e: u32, k: u32) -> u32 {
    if (patch_edge_collapsed(p, e)) {
        return patch_corner_entry(p, e);
    }
    let edge = patch_edge(p, e);
    let s = segments[edge];
    var kc = k;
    if (patch_edge_reversed(p, e)) { kc = s - k; }
    return vertex_offsets[edge] + patch_edge_variant(p, e) * (s - 1u) + kc - 1u;
}

// Edge e's inner vertices: `(segments − 1) · variants`, none for a collapsed edge or one no
// visible patch uses (`engine::Layout::build`).
fn edge_count(e: u32) -> u32 {
    var seen = false;
    for (var u = edge_first_use(e); u < edge_end_use(e); u = u + 1u) {
        seen = seen || visible[use_patch(u)] != 0u;
    }
    if (!seen || edge_collapsed(e)) { return 0u; }
    return (segments[e] - 1u) * edge_variants(e);
}

// Writes vertex v.
fn store_vertex(v: u32, position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>) {
    let o = v * VERTEX_FLOATS;
    vertices[o] = position.x;
    vertices[o + 1u] = position.y;
    vertices[o + 2u] = position.z;
    vertices[o + 3u] = normal.x;
    vertices[o + 4u] = normal.y;
    vertices[o + 5u] = normal.z;
    vertices[o + 6u] = uv.x;
    vertices[o + 7u] = uv.y;
}
