// Triangle strips written by the GPU for the patterns with a strip form (`Pattern::strips`:
// SD-2's radial sectors, ESC's virtual-vertex strips), over output vertices, as the CPU
// engine's `strips_of` writes them: every visible patch's strips in patch order, RESTART
// between a patch's strips and one between patches; a vertex of a collapsed curve is its
// corner's, so the triangles degenerate there repeat an index and decode to nothing, as the
// triangle list leaves them out. The patch's walk is `{{PATCH_STRIPS}}` below, named by the
// pipeline's table (`src/tessellator/strips.rs`).
//
// Output: entry 0 of `strip_indices` is a RESTART, then each patch with strips writes a
// RESTART and its strips from its offset on: a patch's count is 1 + its strips' length
// (0 without strips), scanned into `strip_offsets`; the draw starts at entry 1.

const RESTART: u32 = 0xffffffffu;

// Per patch, then the trailing entry: counts, offsets after the scan.
@group(1) @binding(0) var<storage, read_write> strip_offsets: array<u32>;
@group(1) @binding(1) var<storage, read_write> strip_indices: array<u32>;
// The strip draw's `DrawIndexedIndirect` (5 u32), then whether the strips overflowed, their
// entries (the scan's total) and the room in `strip_indices` (written by the host).
struct StripState {
    draw: DrawIndexedIndirect,
    overflow: u32,
    entries: u32,
    capacity: u32,
}
@group(1) @binding(2) var<storage, read_write> strip_state: StripState;
// The frame's status (`indirect_args.wgsl`): a frame whose triangles overflowed draws no
// strips either.
@group(1) @binding(3) var<storage, read_write> frame_status: array<u32, 4>;

// The walk's cursor: entries are counted, and written from `strip_at` on when writing.
var<private> strip_write: bool;
var<private> strip_at: u32;

fn strip_emit(v: u32) {
    if (strip_write) { strip_indices[strip_at] = v; }
    strip_at = strip_at + 1u;
}

// `Sd2::walk`: each radial sector's strip (the tip, then rows 1 … ns on lines j and j + 1),
// RESTART between sectors.
fn sd2_strips(p: u32) {
    let input = local_numbering(p);
    let l = sd2_layout(p);
    for (var j = 0u; j < l.nd; j = j + 1u) {
        if (j > 0u) { strip_emit(RESTART); }
        for (var m = 0u; m <= 2u * l.ns; m = m + 1u) {
            strip_emit(local_vertex(input, sd2_strip_vertex(input, l, j, m)));
        }
    }
}

// `esc::layout`'s strips: every coarse triangle's strips that draw, RESTART between strips.
fn esc_strips(p: u32) {
    esc_load(p);
    let input = local_numbering(p);
    var any = false;
    for (var t = 0u; t < 18u; t = t + 1u) {
        var a = 0u;
        for (var b = 1u; b <= esc_n; b = b + 1u) {
            if (!esc_row_present(t, b)) { continue; }
            esc_build_strip(t, a, b);
            a = b;
            if (!esc_strip_draws()) { continue; }
            if (any) { strip_emit(RESTART); }
            any = true;
            for (var w = 0u; w < esc_strip_len; w = w + 1u) {
                strip_emit(local_vertex(input, esc_row_local(input, t, esc_strip[w])));
            }
        }
    }
}

// Count pass: x < P, patch x's count; x = P, the trailing 0.
@compute @workgroup_size(WORKGROUP)
fn count_strips(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (p > params.patches) { return; }
    var count = 0u;
    if (p < params.patches && visible[p] != 0u) {
        strip_write = false;
        strip_at = 0u;
        {{PATCH_STRIPS}}(p);
        count = select(0u, strip_at + 1u, strip_at > 0u);
    }
    strip_offsets[p] = count;
}

// After the scan: the draw of entries 1 … total − 1, or nothing when the strips pass their
// room or the frame overflowed.
@compute @workgroup_size(1)
fn strip_args() {
    let total = strip_offsets[params.patches];
    let overflow = total > strip_state.capacity;
    strip_state.overflow = u32(overflow);
    strip_state.entries = total;
    let drawn = !overflow && frame_status[0] == 0u && total > 1u;
    strip_state.draw = DrawIndexedIndirect(select(0u, total - 1u, drawn), 1u, 1u, 0, 0u);
}

// Write pass: one invocation a patch writes its RESTART and strips at its offset.
@compute @workgroup_size(WORKGROUP)
fn write_strips(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = thread_index(wid, nwg, lid);
    if (p >= params.patches || strip_state.overflow != 0u || frame_status[0] != 0u) { return; }
    let start = strip_offsets[p];
    if (strip_offsets[p + 1u] == start) { return; }
    strip_indices[start] = RESTART;
    strip_write = true;
    strip_at = start + 1u;
    {{PATCH_STRIPS}}(p);
}
