// The camera and the view-independent per-patch data of the view passes (group 1): culling
// (`cull.wgsl`) and the screen-space factors (`factors.wgsl`). Row formats:
// `src/tessellator/screen.rs` (`patch_view_rows`).

struct View {
    eye: vec4<f32>,
    // `Camera::basis`: right, up, forward (unit).
    right: vec4<f32>,
    up: vec4<f32>,
    forward: vec4<f32>,
    near: f32,
    far: f32,
    // `Camera::half_tangents`.
    tan_x: f32,
    tan_y: f32,
    // `Camera::focal_pixels`, the pixel error, the factor cap (`PlanOptions::max_factor`),
    // the interior rule (INTERIOR_GLOBAL, INTERIOR_CORE, INTERIOR_MAX_EDGE or INTERIOR_LEVEL;
    // with a pixel error, INTERIOR_CORE and INTERIOR_LEVEL mean the a-posteriori check of
    // `check.wgsl` decides the interiors).
    focal: f32,
    pixels: f32,
    cap: f32,
    interior_rule: u32,
    // The criterion (CRITERION_PIXEL_ERROR, CRITERION_SILHOUETTENESS, CRITERION_FIXED or one of
    // SD-2's level functions, CRITERION_DISTANCE_LINEAR, _QUADRATIC, CRITERION_VERTEX_SILHOUETTE) and
    // the view criterion's factor range [lo, hi] (`view::edge_factors_into`'s, the cap
    // applied; a fixed factor is lo = hi); the edge rule (EDGE_RULE_INTEGER,
    // EDGE_RULE_POWER_OF_TWO or EDGE_RULE_HARDWARE, whose partitioning is
    // `params.partitioning`). ESC (CRITERION_ESC) reads lo, hi, cap, pixels and edge_rule
    // its own way (`esc_plan.wgsl`).
    criterion: u32,
    lo: f32,
    hi: f32,
    edge_rule: u32,
    // The error bound of a pixel error's proposals and check: BOUND_HESSIAN (the prepared
    // second-derivative bounds alone) or BOUND_EXPANSION (also `expansion.wgsl`'s).
    bound: u32,
    // Where the expansion nets start in `patch_views` (`screen::expansion_rows`), once a
    // frame planned with BOUND_EXPANSION appended them.
    expansion_rows: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(1) @binding(0) var<uniform> view: View;
// Per patch, PATCH_VIEW_ROW vec4: the normal cone's axis and half-angle α; the bounding
// sphere's centre and radius; (sin α, cos α, 1 with a cone / 0 without, 0); the control
// points' box lo and hi (`screen::PatchView`); the second-derivative bound (uu, uv, vv, 0)
// (`Prepared::hessians`); the boundary curves' bounds (`Prepared::curves`); the minimum
// interior factors (`Prepared::minimum_interior`, as f32), 0, 0; its ESC object's box lo
// with the box's diagonal in w, and hi (`criterion::esc::Objects`). After the P patch rows,
// EDGE_VIEW_ROW vec4 per edge: its midpoint as its first patch sees it with the edge's
// minimum segments in w (`minimum_segments`), the normals there of its first and its last
// patch (`Prepared::edge_midpoints`). With the expansion bound, from `view.expansion_rows`
// CONTROL_POINTS vec4 per patch: its expansion net less its first point, the kind in the
// first row's w (`expansion.wgsl`).
@group(1) @binding(1) var<storage, read_write> patch_views: array<vec4<f32>>;
// Per patch, the factor it proposes for each local edge (0 for culled patches).
@group(1) @binding(2) var<storage, read_write> proposals: array<vec4<f32>>;
// The frame's planning state, zeroed before the factor passes; read back by name through
// Rust's `FrameState` (`src/tessellator/report.rs`, the same layout: the contract test).
struct FrameState {
    // The largest segment count and minimum interior of the frame (the global factor of
    // `InteriorRule::Global`).
    global_factor: atomic<u32>,
    // The a-posteriori check's rounds (`check.wgsl`): patches whose bound the last check
    // missed, whether the last resolve changed an edge, whether the rounds ended (1) and
    // how many fix rounds ran.
    failing: atomic<u32>,
    changed: atomic<u32>,
    done: atomic<u32>,
    rounds: atomic<u32>,
    // The frame's vertex depths for SD-2's distance level function, as `ordered_bits`: the
    // largest, and the complement of the smallest (both raised from the cleared 0).
    depth_far: atomic<u32>,
    depth_near_complement: atomic<u32>,
    _pad: u32,
}
@group(1) @binding(3) var<storage, read_write> state: FrameState;

// Per patch, the a-posteriori check's row (`check.wgsl`): the object-space tolerance (< 0:
// culled), the guaranteed bound of the last check, flags (bit 0: the bound is missed), and
// whether a changed edge asks for the patch's check again (set by any of its edges' resolve
// invocations, hence atomic).
struct CheckRow {
    eps: f32,
    bound: f32,
    flags: u32,
    marked: atomic<u32>,
}
@group(1) @binding(4) var<storage, read_write> checks: array<CheckRow>;

const PATCH_VIEW_ROW: u32 = {{PATCH_VIEW_ROW}}u;
const INTERIOR_GLOBAL: u32 = {{INTERIOR_GLOBAL}}u;
const INTERIOR_CORE: u32 = {{INTERIOR_CORE}}u;
const INTERIOR_MAX_EDGE: u32 = {{INTERIOR_MAX_EDGE}}u;
const INTERIOR_LEVEL: u32 = {{INTERIOR_LEVEL}}u;
const CRITERION_PIXEL_ERROR: u32 = {{CRITERION_PIXEL_ERROR}}u;
const CRITERION_SILHOUETTENESS: u32 = {{CRITERION_SILHOUETTENESS}}u;
const CRITERION_FIXED: u32 = {{CRITERION_FIXED}}u;
const CRITERION_DISTANCE_LINEAR: u32 = {{CRITERION_DISTANCE_LINEAR}}u;
const CRITERION_DISTANCE_QUADRATIC: u32 = {{CRITERION_DISTANCE_QUADRATIC}}u;
const CRITERION_VERTEX_SILHOUETTE: u32 = {{CRITERION_VERTEX_SILHOUETTE}}u;
// ESC's own criterion: its planning passes (`esc_plan.wgsl`) read the uniform their way.
const CRITERION_ESC: u32 = {{CRITERION_ESC}}u;
const EDGE_RULE_INTEGER: u32 = {{EDGE_RULE_INTEGER}}u;
const EDGE_RULE_HARDWARE: u32 = {{EDGE_RULE_HARDWARE}}u;
const EDGE_RULE_POWER_OF_TWO: u32 = {{EDGE_RULE_POWER_OF_TWO}}u;
const EDGE_RULE_SYMMETRIC: u32 = {{EDGE_RULE_SYMMETRIC}}u;
const EDGE_VIEW_ROW: u32 = {{EDGE_VIEW_ROW}}u;
const BOUND_HESSIAN: u32 = {{BOUND_HESSIAN}}u;
const BOUND_EXPANSION: u32 = {{BOUND_EXPANSION}}u;
const VERTEX_VIEW_ROW: u32 = {{VERTEX_VIEW_ROW}}u;

// `u32::next_power_of_two` (x ≤ 2³¹).
fn next_power_of_two(x: u32) -> u32 {
    if (x <= 1u) { return 1u; }
    return 1u << (32u - countLeadingZeros(x - 1u));
}

// `Prepared::minimum_segments` of edge e, kept in the w of its first edge row (a whole
// number, exact in f32).
fn minimum_segments(e: u32) -> u32 {
    return u32(patch_views[PATCH_VIEW_ROW * params.patches + EDGE_VIEW_ROW * e].w);
}
