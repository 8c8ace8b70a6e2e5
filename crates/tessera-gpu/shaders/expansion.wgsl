// The expansion bound in f32: the GPU form of `tessera::criterion::taylor::TaylorBound::
// expansion` (`ErrorBound::Expansion`), which the CPU plans with too. A triangle's bound is
// the Taylor expansion about its centroid — `bubble_max` of its sides' second differences
// `|eᵀ H e|/8` plus the third-derivative remainder — and, on a cubic triangle whose remainder
// dominates, its error's control-point hull; a grid's is the walk over its cells (one
// expansion at each cell's centre) up to EXPANSION_WALK_CELLS cells, and past them the
// second-derivative nets' bound of every cell at once. Polynomial bicubics, cubic Bézier
// triangles and PN triangles (`taylor::ExpansionNet`); every other patch has none
// (EXPANSION_NONE: its plans keep the second-derivative bound).
//
// The nets are read from the patch view rows at `view.expansion_rows` (`screen::
// expansion_rows`): each patch's control net less its first point, differenced in f64, so
// the second and third differences keep f32's precision relative to the patch's size (from
// the absolute f32 control points a small PN triangle's bound was 1 % off the CPU's). A
// decision near its tolerance may still differ from the CPU's f64 one (the tests count such
// frames). No code here loops per cell or per triangle: lavapipe stops an invocation's loops
// after 65,535 iterations in all (`local.wgsl`), and a check walks up to
// EXPANSION_WALK_CELLS cells a step.

// The kinds of `screen::expansion_rows` (the first net row's w).
const EXPANSION_BICUBIC: u32 = {{EXPANSION_BICUBIC}}u;
const EXPANSION_TRIANGLE: u32 = {{EXPANSION_TRIANGLE}}u;
const EXPANSION_WALK_CELLS: u32 = {{EXPANSION_WALK_CELLS}}u;
// `taylor::HULL_WHEN` (its f32 bits: naga takes no bitcast in a constant): where a cubic
// triangle's remainder exceeds this share of its quadratic part, its error hull is taken too.
const HULL_WHEN_BITS: u32 = {{HULL_WHEN_BITS}}u;

// Row k of patch p's expansion net.
fn net_row(p: u32, k: u32) -> vec4<f32> {
    return patch_views[view.expansion_rows + p * CONTROL_POINTS + k];
}

// A bicubic's point b(i, j) (`i` along u), less b(0, 0).
fn net_point(p: u32, i: u32, j: u32) -> vec3<f32> {
    return net_row(p, 4u * i + j).xyz;
}

// A cubic triangle's point b(i, j, 3 − i − j) (`i` the exponent of λ0, `j` of u), less its
// first point (`tri_index` of `triangle_net.wgsl`).
fn tri_net_point(p: u32, i: u32, j: u32) -> vec3<f32> {
    return net_row(p, tri_index(i, j)).xyz;
}

// A bicubic's second differences at (i, j): Δ²_u b, Δ_uΔ_v b, Δ²_v b.
fn net_duu(p: u32, i: u32, j: u32) -> vec3<f32> {
    return net_point(p, i + 2u, j) - 2.0 * net_point(p, i + 1u, j) + net_point(p, i, j);
}

fn net_duv(p: u32, i: u32, j: u32) -> vec3<f32> {
    return net_point(p, i + 1u, j + 1u) - net_point(p, i, j + 1u) - net_point(p, i + 1u, j) + net_point(p, i, j);
}

fn net_dvv(p: u32, i: u32, j: u32) -> vec3<f32> {
    return net_point(p, i, j + 2u) - 2.0 * net_point(p, i, j + 1u) + net_point(p, i, j);
}

// A cubic triangle's second differences at base (i, j, k) of degree 1 (`taylor::triangle`).
fn tri_duu(p: u32, i: u32, j: u32) -> vec3<f32> {
    return tri_net_point(p, i, j + 2u) - 2.0 * tri_net_point(p, i + 1u, j + 1u) + tri_net_point(p, i + 2u, j);
}

fn tri_duv(p: u32, i: u32, j: u32) -> vec3<f32> {
    return tri_net_point(p, i, j + 1u) - tri_net_point(p, i + 1u, j) - tri_net_point(p, i + 1u, j + 1u)
        + tri_net_point(p, i + 2u, j);
}

fn tri_dvv(p: u32, i: u32, j: u32) -> vec3<f32> {
    return tri_net_point(p, i, j) - 2.0 * tri_net_point(p, i + 1u, j) + tri_net_point(p, i + 2u, j);
}

// `TaylorBound::expansion` of patch p: its kind and third-derivative bounds (`taylor::
// bicubic`, `taylor::triangle`). Loops of a few steps, once per check or proposal.
fn expansion_of(p: u32) -> Expansion {
    let kind = u32(net_row(p, 0u).w);
    if (kind == EXPANSION_TRIANGLE) {
        // (1, 0, 0) and its steps along u, (0, 1, 0), and v, (0, 0, 1).
        let uuu = length(tri_duu(p, 0u, 1u) - tri_duu(p, 1u, 0u));
        let uuv = length(tri_duu(p, 0u, 0u) - tri_duu(p, 1u, 0u));
        let uvv = length(tri_dvv(p, 0u, 1u) - tri_dvv(p, 1u, 0u));
        let vvv = length(tri_dvv(p, 0u, 0u) - tri_dvv(p, 1u, 0u));
        return Expansion(p, EXPANSION_TRIANGLE, 6.0 * vec4<f32>(uuu, uuv, uvv, vvv), vec3<f32>(0.0));
    }
    if (kind != EXPANSION_BICUBIC) {
        return no_expansion(p);
    }
    var third = vec4<f32>(0.0);
    var fourth = vec3<f32>(0.0);
    for (var j = 0u; j < 4u; j = j + 1u) {
        third.x = max(third.x, 6.0 * length(net_d3u(p, j)));
        third.w = max(third.w, 6.0 * length(net_d3v(p, j)));
    }
    for (var i = 0u; i < 2u; i = i + 1u) {
        for (var j = 0u; j < 3u; j = j + 1u) {
            third.y = max(third.y, 18.0 * length(net_d2u1v(p, i, j)));
            third.z = max(third.z, 18.0 * length(net_d1u2v(p, j, i)));
        }
    }
    for (var j = 0u; j < 3u; j = j + 1u) {
        fourth.x = max(fourth.x, 18.0 * length(net_d3u(p, j + 1u) - net_d3u(p, j)));
        fourth.z = max(fourth.z, 18.0 * length(net_d3v(p, j + 1u) - net_d3v(p, j)));
    }
    for (var i = 0u; i < 2u; i = i + 1u) {
        for (var j = 0u; j < 2u; j = j + 1u) {
            fourth.y = max(fourth.y, 36.0 * length(net_d2u1v(p, i, j + 1u) - net_d2u1v(p, i, j)));
        }
    }
    return Expansion(p, EXPANSION_BICUBIC, third, fourth);
}

// A bicubic's third differences (`taylor::ThirdDerivatives`): Δ³_u b at (0, j), Δ²_uΔ_v b at
// (i, j), Δ_uΔ²_v b at (i, j), Δ³_v b at (i, 0).
fn net_d3u(p: u32, j: u32) -> vec3<f32> { return net_duu(p, 1u, j) - net_duu(p, 0u, j); }
fn net_d2u1v(p: u32, i: u32, j: u32) -> vec3<f32> { return net_duu(p, i, j + 1u) - net_duu(p, i, j); }
fn net_d1u2v(p: u32, i: u32, j: u32) -> vec3<f32> { return net_dvv(p, i + 1u, j) - net_dvv(p, i, j); }
fn net_d3v(p: u32, i: u32) -> vec3<f32> { return net_dvv(p, i, 1u) - net_dvv(p, i, 0u); }

// `ThirdDerivatives::near`: bounds on the third derivatives over the box g ± delta, each at g
// plus its derivatives' bounds times the half-sides, unrolled.
fn third_near(x: Expansion, g: vec2<f32>, delta: vec2<f32>) -> vec4<f32> {
    let p = x.p;
    let w = bernstein_at(g);
    let uuu = 6.0 * row4(w.v3, net_d3u(p, 0u), net_d3u(p, 1u), net_d3u(p, 2u), net_d3u(p, 3u));
    let vvv = 6.0 * row4(w.u3, net_d3v(p, 0u), net_d3v(p, 1u), net_d3v(p, 2u), net_d3v(p, 3u));
    let uuv = 18.0 * row2(
        w.u1,
        row3(w.v2, net_d2u1v(p, 0u, 0u), net_d2u1v(p, 0u, 1u), net_d2u1v(p, 0u, 2u)),
        row3(w.v2, net_d2u1v(p, 1u, 0u), net_d2u1v(p, 1u, 1u), net_d2u1v(p, 1u, 2u)),
    );
    let uvv = 18.0 * row3(
        w.u2,
        row2(w.v1, net_d1u2v(p, 0u, 0u), net_d1u2v(p, 0u, 1u)),
        row2(w.v1, net_d1u2v(p, 1u, 0u), net_d1u2v(p, 1u, 1u)),
        row2(w.v1, net_d1u2v(p, 2u, 0u), net_d1u2v(p, 2u, 1u)),
    );
    let du = abs(delta.x);
    let dv = abs(delta.y);
    let f = x.fourth;
    return vec4<f32>(
        length(uuu) + f.x * dv,
        length(uuv) + f.x * du + f.y * dv,
        length(uvv) + f.y * du + f.z * dv,
        length(vvv) + f.z * du,
    );
}

// `TaylorBound::remainder_at`: the remainder about g, a bicubic's third derivatives bounded on
// the box g ± delta where that is smaller than the patch's bounds.
fn expansion_remainder_at(x: Expansion, g: vec2<f32>, delta: vec2<f32>) -> f32 {
    if (x.kind != EXPANSION_BICUBIC) { return expansion_remainder(x, delta); }
    var local = x;
    local.third = min(x.third, third_near(x, g, delta));
    return expansion_remainder(local, delta);
}

// The Bernstein weights of degree 1, 2 and 3 in u and in v at a point: what the nets of the
// second and third derivatives are summed with there.
struct Weights {
    u1: vec2<f32>,
    u2: vec3<f32>,
    u3: vec4<f32>,
    v1: vec2<f32>,
    v2: vec3<f32>,
    v3: vec4<f32>,
}

fn bernstein_at(at: vec2<f32>) -> Weights {
    return Weights(
        bernstein1(at.x), bernstein2(at.x), bernstein3w(at.x),
        bernstein1(at.y), bernstein2(at.y), bernstein3w(at.y),
    );
}

// Bernstein weights of degree 1, 2, 3 at t (`taylor::bernstein`).
fn bernstein1(t: f32) -> vec2<f32> { return vec2<f32>(1.0 - t, t); }
fn bernstein2(t: f32) -> vec3<f32> {
    let s = 1.0 - t;
    return vec3<f32>(s * s, 2.0 * s * t, t * t);
}
fn bernstein3w(t: f32) -> vec4<f32> {
    let s = 1.0 - t;
    return vec4<f32>(s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t);
}

fn row4(w: vec4<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, d: vec3<f32>) -> vec3<f32> {
    return a * w.x + b * w.y + c * w.z + d * w.w;
}

fn row3(w: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> vec3<f32> {
    return a * w.x + b * w.y + c * w.z;
}

fn row2(w: vec2<f32>, a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    return a * w.x + b * w.y;
}

// A cubic triangle's [S_uu, S_uv, S_vv] at corner c of its domain (`taylor::triangle`'s
// corners: (1, 0, 0), (0, 1, 0), (0, 0, 1) as (i, j)).
fn tri_corner_second(p: u32, i: u32, j: u32) -> array<vec3<f32>, 3> {
    return array<vec3<f32>, 3>(6.0 * tri_duu(p, i, j), 6.0 * tri_duv(p, i, j), 6.0 * tri_dvv(p, i, j));
}

// `TaylorBound::second_derivatives`: [S_uu, S_uv, S_vv] at x, unrolled (no loop).
fn expansion_second(x: Expansion, at: vec2<f32>) -> array<vec3<f32>, 3> {
    let p = x.p;
    if (x.kind == EXPANSION_TRIANGLE) {
        let l = vec3<f32>(1.0 - at.x - at.y, at.x, at.y);
        let c0 = tri_corner_second(p, 1u, 0u);
        let c1 = tri_corner_second(p, 0u, 1u);
        let c2 = tri_corner_second(p, 0u, 0u);
        return array<vec3<f32>, 3>(
            c0[0] * l.x + c1[0] * l.y + c2[0] * l.z,
            c0[1] * l.x + c1[1] * l.y + c2[1] * l.z,
            c0[2] * l.x + c1[2] * l.y + c2[2] * l.z,
        );
    }
    let w = bernstein_at(at);
    // S_uu: 6 Δ²_u b over B¹(u) B³(v); S_uv: 9 ΔuΔv b over B²(u) B²(v); S_vv: 6 Δ²_v b over
    // B³(u) B¹(v).
    let uu = row2(
        w.u1,
        row4(w.v3, net_duu(p, 0u, 0u), net_duu(p, 0u, 1u), net_duu(p, 0u, 2u), net_duu(p, 0u, 3u)),
        row4(w.v3, net_duu(p, 1u, 0u), net_duu(p, 1u, 1u), net_duu(p, 1u, 2u), net_duu(p, 1u, 3u)),
    );
    let uv = row3(
        w.u2,
        row3(w.v2, net_duv(p, 0u, 0u), net_duv(p, 0u, 1u), net_duv(p, 0u, 2u)),
        row3(w.v2, net_duv(p, 1u, 0u), net_duv(p, 1u, 1u), net_duv(p, 1u, 2u)),
        row3(w.v2, net_duv(p, 2u, 0u), net_duv(p, 2u, 1u), net_duv(p, 2u, 2u)),
    );
    let vv = row4(
        w.u3,
        row2(w.v1, net_dvv(p, 0u, 0u), net_dvv(p, 0u, 1u)),
        row2(w.v1, net_dvv(p, 1u, 0u), net_dvv(p, 1u, 1u)),
        row2(w.v1, net_dvv(p, 2u, 0u), net_dvv(p, 2u, 1u)),
        row2(w.v1, net_dvv(p, 3u, 0u), net_dvv(p, 3u, 1u)),
    );
    return array<vec3<f32>, 3>(6.0 * uu, 9.0 * uv, 6.0 * vv);
}

// `taylor::bubble_max`: the largest Σ a_i·4λ_jλ_k over a triangle.
fn bubble_max(a: vec3<f32>) -> f32 {
    let edges = max(a.x, max(a.y, a.z));
    let s = a.x + a.y + a.z;
    let l = a * (vec3<f32>(s) - 2.0 * a);
    let total = l.x + l.y + l.z;
    if (l.x > 0.0 && l.y > 0.0 && l.z > 0.0 && total > 0.0) {
        let w = l / total;
        let inside = 4.0 * (a.x * w.y * w.z + a.y * w.z * w.x + a.z * w.x * w.y);
        return max(edges, inside);
    }
    return edges;
}

// `TaylorBound::remainder`: f₃(Δ)/3.
fn expansion_remainder(x: Expansion, delta: vec2<f32>) -> f32 {
    let a = abs(delta.x);
    let b = abs(delta.y);
    let t = x.third;
    return (t.x * a * a * a + 3.0 * t.y * a * a * b + 3.0 * t.z * a * b * b + t.w * b * b * b) / 3.0;
}

// `|eᵀ H e|/8` for side e.
fn side_term(h: array<vec3<f32>, 3>, e: vec2<f32>) -> f32 {
    return length(h[0] * (e.x * e.x) + h[1] * (2.0 * e.x * e.y) + h[2] * (e.y * e.y)) / 8.0;
}

// A cubic triangle's points over a sub-triangle: one de Casteljau level at barycentric q,
// degree 3 to 2 (points listed by `net_index`: (i, j) with i the exponent of λ0, then j).
fn casteljau3(n: array<vec3<f32>, 10>, q: vec3<f32>) -> array<vec3<f32>, 6> {
    // Degree-3 list: (0,0) (0,1) (0,2) (0,3) (1,0) (1,1) (1,2) (2,0) (2,1) (3,0) → 0..9.
    // (i, j) of degree 2 reads (i+1, j), (i, j+1), (i, j) of degree 3 with q.x, q.y, q.z.
    return array<vec3<f32>, 6>(
        n[4] * q.x + n[1] * q.y + n[0] * q.z,
        n[5] * q.x + n[2] * q.y + n[1] * q.z,
        n[6] * q.x + n[3] * q.y + n[2] * q.z,
        n[7] * q.x + n[5] * q.y + n[4] * q.z,
        n[8] * q.x + n[6] * q.y + n[5] * q.z,
        n[9] * q.x + n[8] * q.y + n[7] * q.z,
    );
}

fn casteljau2(n: array<vec3<f32>, 6>, q: vec3<f32>) -> array<vec3<f32>, 3> {
    // Degree-2 list: (0,0) (0,1) (0,2) (1,0) (1,1) (2,0) → 0..5.
    return array<vec3<f32>, 3>(
        n[3] * q.x + n[1] * q.y + n[0] * q.z,
        n[4] * q.x + n[2] * q.y + n[1] * q.z,
        n[5] * q.x + n[4] * q.y + n[3] * q.z,
    );
}

fn casteljau1(n: array<vec3<f32>, 3>, q: vec3<f32>) -> vec3<f32> {
    // Degree-1 list: (0,0) (0,1) (1,0) → 0..2.
    return n[2] * q.x + n[1] * q.y + n[0] * q.z;
}

// The largest |blossom − L| over one sub-triangle (barycentric corners q0, q1, q2; L's
// values at its corners l0, l1, l2): `taylor::cubic_error_hull`'s inner loop, its blossom
// levels shared as `taylor::sub_net` shares them, unrolled.
fn sub_hull(
    n: array<vec3<f32>, 10>,
    q0: vec3<f32>, q1: vec3<f32>, q2: vec3<f32>,
    l0: vec3<f32>, l1: vec3<f32>, l2: vec3<f32>,
) -> f32 {
    let a0 = casteljau3(n, q0);
    let a1 = casteljau3(n, q1);
    let a2 = casteljau3(n, q2);
    let b00 = casteljau2(a0, q0);
    let b01 = casteljau2(a0, q1);
    let b02 = casteljau2(a0, q2);
    let b11 = casteljau2(a1, q1);
    let b12 = casteljau2(a1, q2);
    let b22 = casteljau2(a2, q2);
    // Exponents (i, j, k) of corners 0, 1, 2: the blossom at {0^i, 1^j, 2^k}, less L at the
    // Greville point (i·l0 + j·l1 + k·l2)/3.
    var worst = length(casteljau1(b00, q0) - l0);
    worst = max(worst, length(casteljau1(b11, q1) - l1));
    worst = max(worst, length(casteljau1(b22, q2) - l2));
    worst = max(worst, length(casteljau1(b00, q1) - (2.0 * l0 + l1) / 3.0));
    worst = max(worst, length(casteljau1(b00, q2) - (2.0 * l0 + l2) / 3.0));
    worst = max(worst, length(casteljau1(b01, q1) - (l0 + 2.0 * l1) / 3.0));
    worst = max(worst, length(casteljau1(b02, q2) - (l0 + 2.0 * l2) / 3.0));
    worst = max(worst, length(casteljau1(b11, q2) - (2.0 * l1 + l2) / 3.0));
    worst = max(worst, length(casteljau1(b12, q2) - (l1 + 2.0 * l2) / 3.0));
    worst = max(worst, length(casteljau1(b01, q2) - (l0 + l1 + l2) / 3.0));
    return worst;
}

// The cubic triangle's value at barycentric q (its blossom at q three times).
fn tri_value(n: array<vec3<f32>, 10>, q: vec3<f32>) -> vec3<f32> {
    return casteljau1(casteljau2(casteljau3(n, q), q), q);
}

// `taylor::cubic_error_hull` of patch p over the parameter triangle (t0, t1, t2).
fn cubic_error_hull(p: u32, t0: vec2<f32>, t1: vec2<f32>, t2: vec2<f32>) -> f32 {
    let n = array<vec3<f32>, 10>(
        tri_net_point(p, 0u, 0u), tri_net_point(p, 0u, 1u), tri_net_point(p, 0u, 2u), tri_net_point(p, 0u, 3u),
        tri_net_point(p, 1u, 0u), tri_net_point(p, 1u, 1u), tri_net_point(p, 1u, 2u),
        tri_net_point(p, 2u, 0u), tri_net_point(p, 2u, 1u),
        tri_net_point(p, 3u, 0u),
    );
    let q0 = vec3<f32>(1.0 - t0.x - t0.y, t0.x, t0.y);
    let q1 = vec3<f32>(1.0 - t1.x - t1.y, t1.x, t1.y);
    let q2 = vec3<f32>(1.0 - t2.x - t2.y, t2.x, t2.y);
    let m0 = (q1 + q2) / 2.0;
    let m1 = (q2 + q0) / 2.0;
    let m2 = (q0 + q1) / 2.0;
    let a0 = tri_value(n, q0);
    let a1 = tri_value(n, q1);
    let a2 = tri_value(n, q2);
    // L is affine: at a midpoint, the mean of its ends.
    let l0 = (a1 + a2) / 2.0;
    let l1 = (a2 + a0) / 2.0;
    let l2 = (a0 + a1) / 2.0;
    // The four sub-triangles in a loop around one call of `sub_hull` (every call is
    // inlined; `select`, not an array, picks the corners, so that the driver keeps the loop).
    var worst = 0.0;
    for (var s = 0u; s < 4u; s = s + 1u) {
        let c0 = select(select(select(m0, m1, s == 2u), m2, s == 1u), q0, s == 0u);
        let c1 = select(select(select(m1, m0, s == 2u), q1, s == 1u), m2, s == 0u);
        let c2 = select(select(select(m2, q2, s == 2u), m0, s == 1u), m1, s == 0u);
        let k0 = select(select(select(l0, l1, s == 2u), l2, s == 1u), a0, s == 0u);
        let k1 = select(select(select(l1, l0, s == 2u), a1, s == 1u), l2, s == 0u);
        let k2 = select(select(select(l2, a2, s == 2u), l0, s == 1u), l1, s == 0u);
        worst = max(worst, sub_hull(n, c0, c1, c2, k0, k1, k2));
    }
    return worst;
}

// `TaylorBound::triangle_error` of the expansion bound over (t0, t1, t2): the expansion about
// the centroid, and for a cubic triangle whose remainder dominates its hull too; +∞ for
// EXPANSION_NONE.
fn expansion_triangle_error(x: Expansion, t0: vec2<f32>, t1: vec2<f32>, t2: vec2<f32>) -> f32 {
    if (x.kind == EXPANSION_NONE) { return 3.0e38; }
    let g = (t0 + t1 + t2) / 3.0;
    let h = expansion_second(x, g);
    let m = vec3<f32>(side_term(h, t2 - t1), side_term(h, t0 - t2), side_term(h, t1 - t0));
    let delta = max(abs(t0 - g), max(abs(t1 - g), abs(t2 - g)));
    let quadratic = bubble_max(m);
    let remainder = expansion_remainder_at(x, g, delta);
    if (x.kind == EXPANSION_TRIANGLE && remainder > bitcast<f32>(HULL_WHEN_BITS) * quadratic) {
        return min(quadratic + remainder, cubic_error_hull(x.p, t0, t1, t2));
    }
    return quadratic + remainder;
}

// `TaylorBound::cell_error`: both halves of the cell of sides (hu, hv) centred at `centre`,
// either diagonal.
fn expansion_cell_error(x: Expansion, centre: vec2<f32>, hu: f32, hv: f32) -> f32 {
    let h = expansion_second(x, centre);
    let a = h[0] * (hu * hu);
    let b = h[1] * (2.0 * hu * hv);
    let c = h[2] * (hv * hv);
    let diagonal = max(length(a + c - b), length(a + c + b)) / 8.0;
    return bubble_max(vec3<f32>(diagonal, length(a) / 8.0, length(c) / 8.0))
        + expansion_remainder_at(x, centre, vec2<f32>(hu, hv) / 2.0);
}

// Degree elevation of one net row to degree 3 (`taylor::elevate_u` applied until cubic):
// entry i of a linear row (a, b), of a quadratic row (a, b, c).
fn elevate1(a: vec3<f32>, b: vec3<f32>, i: u32) -> vec3<f32> {
    let t = f32(i) / 3.0;
    return a * (1.0 - t) + b * t;
}

fn elevate2(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, i: u32) -> vec3<f32> {
    switch i {
        case 0u: { return a; }
        case 1u: { return (a + 2.0 * b) / 3.0; }
        case 2u: { return (2.0 * b + c) / 3.0; }
        default: { return c; }
    }
}

// `TaylorBound::nets_grid_error`: every cell of the nu × nv grid at once, from the largest
// control points of the second derivatives' nets (a bicubic's degree-elevated to 4 × 4, a
// triangle's corners). 16 iterations.
fn expansion_nets_grid_error(x: Expansion, tri: bool, nu: u32, nv: u32) -> f32 {
    let hu = 1.0 / f32(nu);
    let hv = 1.0 / f32(nv);
    var legs_u = 0.0;
    var legs_v = 0.0;
    var diagonal = 0.0;
    let p = x.p;
    let count = select(16u, 3u, x.kind == EXPANSION_TRIANGLE);
    for (var k = 0u; k < count; k = k + 1u) {
        var h: array<vec3<f32>, 3>;
        if (x.kind == EXPANSION_TRIANGLE) {
            h = tri_corner_second(p, select(0u, 1u, k == 0u), select(0u, 1u, k == 1u));
        } else {
            let i = k / 4u;
            let j = k % 4u;
            // Rows first along u (to degree 3), then the column along v as it is (degree 3).
            let uu_row = array<vec3<f32>, 4>(
                elevate1(net_duu(p, 0u, 0u), net_duu(p, 1u, 0u), i),
                elevate1(net_duu(p, 0u, 1u), net_duu(p, 1u, 1u), i),
                elevate1(net_duu(p, 0u, 2u), net_duu(p, 1u, 2u), i),
                elevate1(net_duu(p, 0u, 3u), net_duu(p, 1u, 3u), i),
            );
            let uv_col = array<vec3<f32>, 3>(
                elevate2(net_duv(p, 0u, 0u), net_duv(p, 1u, 0u), net_duv(p, 2u, 0u), i),
                elevate2(net_duv(p, 0u, 1u), net_duv(p, 1u, 1u), net_duv(p, 2u, 1u), i),
                elevate2(net_duv(p, 0u, 2u), net_duv(p, 1u, 2u), net_duv(p, 2u, 2u), i),
            );
            let vv = elevate1(net_dvv(p, i, 0u), net_dvv(p, i, 1u), j);
            h = array<vec3<f32>, 3>(
                6.0 * uu_row[j],
                9.0 * elevate2(uv_col[0], uv_col[1], uv_col[2], j),
                6.0 * vv,
            );
        }
        let a = h[0] * (hu * hu);
        let b = h[1] * (2.0 * hu * hv);
        let c = h[2] * (hv * hv);
        legs_u = max(legs_u, length(a));
        legs_v = max(legs_v, length(c));
        // A triangle's grid splits every cell along u + v = const; a quad's either way.
        var rising = 0.0;
        if (!tri) { rising = length(a + c + b); }
        diagonal = max(diagonal, max(length(a + c - b), rising));
    }
    return bubble_max(vec3<f32>(diagonal, legs_u, legs_v) / 8.0) + expansion_remainder(x, vec2<f32>(hu, hv) / 2.0);
}

// `TaylorBound::grid_error_above` of the expansion bound: the largest bound over every
// triangle of the nu × nv grid (a triangle's: nu = nv, the lattice the patterns build), each
// cell's at most `cap` (the second-derivative bound's), returning as soon as one exceeds
// `stop`. Past EXPANSION_WALK_CELLS cells the nets' bound; `cap` for EXPANSION_NONE. One
// iteration a cell, at most EXPANSION_WALK_CELLS.
fn expansion_grid_error(x: Expansion, tri: bool, nu: u32, nv: u32, stop: f32, cap: f32) -> f32 {
    if (x.kind == EXPANSION_NONE) { return cap; }
    if (nu * nv > EXPANSION_WALK_CELLS) {
        return min(expansion_nets_grid_error(x, tri, nu, nv), cap);
    }
    let hu = 1.0 / f32(nu);
    let hv = 1.0 / f32(nv);
    var worst = 0.0;
    for (var k = 0u; k < nu * nv; k = k + 1u) {
        let i = k / nv;
        let j = k % nv;
        if (tri && i + j >= nu) { continue; } // beyond the diagonal
        let a = vec2<f32>(f32(i) * hu, f32(j) * hv);
        let b = a + vec2<f32>(hu, 0.0);
        let c = a + vec2<f32>(0.0, hv);
        let d = a + vec2<f32>(hu, hv);
        if (!tri) {
            worst = max(worst, min(expansion_cell_error(x, (a + d) / 2.0, hu, hv), cap));
        } else {
            // The lower half, and off the diagonal the upper half: one call site in a loop
            // (every call is inlined), two steps a cell.
            let halves = select(1u, 2u, i + j + 2u <= nu);
            for (var h = 0u; h < halves; h = h + 1u) {
                let t0 = select(a, b, h == 1u);
                let t1 = select(b, d, h == 1u);
                worst = max(worst, min(expansion_triangle_error(x, t0, t1, c), cap));
            }
        }
        if (worst > stop) { return worst; }
    }
    return worst;
}

// Whether every triangle of the grid meets `eps` (`TaylorBound::grid_fits`), `cap` the
// grid's second-derivative bound.
fn expansion_grid_fits(x: Expansion, tri: bool, nu: u32, nv: u32, eps: f32, cap: f32) -> bool {
    return expansion_grid_error(x, tri, nu, nv, eps, cap) <= eps;
}
