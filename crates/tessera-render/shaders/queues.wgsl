// The render queues of the instanced semi-uniform path (paper 000, §4.1: counting and an
// exclusive scan per level, the prefix-sum alternative to the HistoPyramid), on the GPU. The
// GPU form of `tessera::engine::render_queues::build`:
//
// 1. `count`: one flag per (level m, patch p) slot, level-major with a stride of P + 1
//    (the extra slot per level is always 0), set when patch p is visible and of level m;
// 2. the crate `tessera_gpu::scan::Scan` turns the flags in place into their exclusive
//    scan: slot (m, p) then holds the queue position of patch p, slot (m, 0) the start of
//    level m's queue and slot (m, P) its end — the queues come out sorted by patch id, as
//    on the CPU;
// 3. `scatter`: every visible patch writes its entry (patch id, its edges' levels) there.
//
// A patch's level is `log2` of its interior factor; edges' levels are `log2` of their
// segments (`render_queues::patch_levels`). A plan that is not dyadic raises `status[0]`.

struct Params {
    patches: u32,
    max_level: u32,
    stride: u32,
    slots: u32,
};

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> segments: array<u32>;
// `Plan::interior`: two u32 per patch.
@group(0) @binding(2) var<storage, read> interior: array<u32>;
@group(0) @binding(3) var<storage, read> visible: array<u32>;
// Four canonical edge ids per patch (`Topology::patch_edges`); NONE past a triangle's three.
@group(0) @binding(4) var<storage, read> patch_edges: array<u32>;
@group(0) @binding(5) var<storage, read_write> slots: array<u32>;
// Two u32 per entry: patch, edge levels (one byte each, edge 0 lowest).
@group(0) @binding(6) var<storage, read_write> entries: array<u32>;
@group(0) @binding(7) var<storage, read_write> status: array<u32>;

const NONE: u32 = 0xffffffffu;

fn is_power_of_two(n: u32) -> bool {
    return n != 0u && (n & (n - 1u)) == 0u;
}

// The patch's level, or -1 when culled; a non-dyadic patch raises the status flag.
fn level_of(p: u32) -> i32 {
    if (visible[p] == 0u) { return -1; }
    let n = interior[2u * p];
    var ok = is_power_of_two(n) && countTrailingZeros(n) <= params.max_level;
    for (var e = 0u; e < 4u; e++) {
        let edge = patch_edges[4u * p + e];
        if (edge != NONE) {
            let s = segments[edge];
            ok = ok && is_power_of_two(s) && s <= n;
        }
    }
    if (!ok) {
        status[0] = 1u;
        return -1;
    }
    return i32(countTrailingZeros(n));
}

fn index(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.x + id.y * groups.x * 64u;
}

@compute @workgroup_size(64)
fn count(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = index(id, groups);
    if (i >= params.slots) { return; }
    let m = i / params.stride;
    let p = i % params.stride;
    var flag = 0u;
    if (p < params.patches && level_of(p) == i32(m)) { flag = 1u; }
    slots[i] = flag;
}

@compute @workgroup_size(64)
fn scatter(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let p = index(id, groups);
    if (p >= params.patches) { return; }
    let m = level_of(p);
    if (m < 0) { return; }
    let slot = slots[u32(m) * params.stride + p];
    var levels = 0u;
    for (var e = 0u; e < 4u; e++) {
        let edge = patch_edges[4u * p + e];
        if (edge != NONE) {
            levels |= countTrailingZeros(segments[edge]) << (8u * e);
        }
    }
    entries[2u * slot] = p;
    entries[2u * slot + 1u] = levels;
}
