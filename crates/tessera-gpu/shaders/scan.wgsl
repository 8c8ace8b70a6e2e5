// Exclusive scan of u32, reduce-then-scan: the GPU form of the scan in
// `tessera::engine::Layout::build` (offsets[i] = base + counts[0] + … + counts[i − 1]).
// `src/scan.rs` drives the levels: `reduce` writes one total per block of BLOCK elements into
// `sums`, the totals are scanned the same way (recursively), and `scan_blocks` scans each
// block in workgroup memory and adds its block's prefix. Portable: workgroup memory and
// barriers only, no subgroup operations.
//
// Sums saturate at 0xffffffff instead of wrapping (saturating addition is associative, so
// every level may add in any grouping): a frame whose counts pass the u32 range ends with a
// total of 0xffffffff, which no output buffer holds, so the frame is refused as overflowing
// (`indirect_args.wgsl`) instead of wrapping to a small total that would seem to fit.

struct Params {
    // Elements to scan.
    len: u32,
    // Added to every output (the first offset), at the top level only.
    base: u32,
    // 1 when `sums` holds the exclusive prefix of every block (the level has several blocks).
    has_prefix: u32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> data: array<u32>;
@group(0) @binding(2) var<storage, read_write> sums: array<u32>;

const WG: u32 = {{SCAN_WORKGROUP}}u;
const ITEMS: u32 = {{SCAN_ITEMS}}u;
const BLOCK: u32 = WG * ITEMS;

var<workgroup> partial: array<u32, WG>;
var<workgroup> tile: array<u32, BLOCK>;

// a + b, or 0xffffffff where that passes the u32 range.
fn add(a: u32, b: u32) -> u32 {
    return select(a + b, 0xffffffffu, b > 0xffffffffu - a);
}

// Workgroups are laid out in 2D when one dimension is not enough (65,535 at most).
fn block_index(wid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return wid.y * nwg.x + wid.x;
}

// Inclusive Hillis–Steele scan of `partial` across the workgroup. Called in uniform control
// flow (every invocation reaches every barrier).
fn scan_partial(lid: u32) {
    for (var offset = 1u; offset < WG; offset = offset * 2u) {
        var left = 0u;
        if (lid >= offset) {
            left = partial[lid - offset];
        }
        workgroupBarrier();
        partial[lid] = add(partial[lid], left);
        workgroupBarrier();
    }
}

@compute @workgroup_size(WG)
fn reduce(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let block = block_index(wid, nwg);
    let first = block * BLOCK;
    // Strided loads: neighbouring invocations read neighbouring elements.
    var total = 0u;
    for (var i = 0u; i < ITEMS; i = i + 1u) {
        let k = first + i * WG + lid;
        if (k < params.len) {
            total = add(total, data[k]);
        }
    }
    partial[lid] = total;
    workgroupBarrier();
    for (var stride = WG / 2u; stride > 0u; stride = stride / 2u) {
        if (lid < stride) {
            partial[lid] = add(partial[lid], partial[lid + stride]);
        }
        workgroupBarrier();
    }
    if (lid == 0u && first < params.len) {
        sums[block] = partial[0];
    }
}

@compute @workgroup_size(WG)
fn scan_blocks(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let block = block_index(wid, nwg);
    let first = block * BLOCK;
    for (var i = 0u; i < ITEMS; i = i + 1u) {
        let k = first + i * WG + lid;
        var x = 0u;
        if (k < params.len) {
            x = data[k];
        }
        tile[i * WG + lid] = x;
    }
    workgroupBarrier();
    // Each invocation owns ITEMS consecutive elements of the tile.
    var run = 0u;
    for (var i = 0u; i < ITEMS; i = i + 1u) {
        run = add(run, tile[lid * ITEMS + i]);
    }
    partial[lid] = run;
    workgroupBarrier();
    scan_partial(lid);
    // The exclusive prefix is the previous invocation's inclusive one (not the own one minus
    // `run`, which a saturated sum would not give back).
    var prefix = params.base;
    if (lid > 0u) {
        prefix = add(prefix, partial[lid - 1u]);
    }
    if (params.has_prefix != 0u && first < params.len) {
        prefix = add(prefix, sums[block]);
    }
    for (var i = 0u; i < ITEMS; i = i + 1u) {
        let x = tile[lid * ITEMS + i];
        tile[lid * ITEMS + i] = prefix;
        prefix = add(prefix, x);
    }
    workgroupBarrier();
    for (var i = 0u; i < ITEMS; i = i + 1u) {
        let k = first + i * WG + lid;
        if (k < params.len) {
            data[k] = tile[i * WG + lid];
        }
    }
}
