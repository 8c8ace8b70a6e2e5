// Evaluation of Catmull-Clark subdivision patches in f32: the GPU form of
// `tessera::surface::PatchTree::derivatives` (find the leaf by the quadtree, evaluate its
// Bézier piece or Gregory end cap, scale and turn the derivatives back) and of
// `Patch::eval`'s normal. The trees are `upload::pack_trees`' blocks in `control_points`;
// patch row `[12]` bit 3 marks such a patch and `[13]` is its view record. Needs
// [`BICUBIC`]'s `bernstein3` and `Derivatives` before it, and the includer's `patch_rows`.

const LEAF_SLOT: u32 = 0x80000000u;

fn patch_is_tree(p: u32) -> bool { return (patch_rows[p * PATCH_ROW + 12u] & 8u) != 0u; }

// A polynomial bicubic net `pts[4 i + j]` (`i` along u) and its first derivatives at `st`.
// The derivatives are sums over the net's differences (the hodograph), not the Bernstein
// derivatives' weights on the points: where a corner's first derivatives vanish (coincident
// points, as at a valence-2 vertex's end cap) f32 then still resolves them a step away, as
// the normal's fallback needs.
fn net_derivatives(pts: array<vec3<f32>, 16>, st: vec2<f32>) -> Derivatives {
    let bu = bernstein3(st.x).b;
    let bv = bernstein3(st.y).b;
    let qu = quadratic(st.x);
    let qv = quadratic(st.y);
    var position = vec3<f32>(0.0);
    var du = vec3<f32>(0.0);
    var dv = vec3<f32>(0.0);
    for (var i = 0u; i < 4u; i = i + 1u) {
        for (var j = 0u; j < 4u; j = j + 1u) {
            let q = pts[4u * i + j];
            position = position + q * (bu[i] * bv[j]);
            if (i < 3u) { du = du + (pts[4u * (i + 1u) + j] - q) * (3.0 * qu[i] * bv[j]); }
            if (j < 3u) { dv = dv + (pts[4u * i + j + 1u] - q) * (3.0 * bu[i] * qv[j]); }
        }
    }
    return Derivatives(position, du, dv);
}

// Quadratic Bernstein polynomials at t.
fn quadratic(t: f32) -> vec3<f32> {
    let s = 1.0 - t;
    return vec3<f32>(s * s, 2.0 * t * s, t * t);
}

// A Gregory end cap's points from `at` (`surface::gregory_patch`'s order) at `st`: the
// Bézier net with each interior point its corner's face-point pair blended rationally, whose
// derivatives are OpenSubdiv's approximate ones (as on the CPU).
fn gregory_net(at: u32, st: vec2<f32>) -> array<vec3<f32>, 16> {
    var g: array<vec3<f32>, 20>;
    for (var k = 0u; k < 20u; k = k + 1u) { g[k] = control_points[at + k].xyz; }
    let u = st.x;
    let v = st.y;
    let uc = 1.0 - u;
    let vc = 1.0 - v;
    // `bezier_net`'s `inv`: 1/d, or 1 where d ≤ 0 (at the corner, where the blend is
    // undefined, the weight on Fp is then 0: the point is Fm).
    let w0 = u * select(1.0, 1.0 / (u + v), u + v > 0.0);
    let w1 = v * select(1.0, 1.0 / (uc + v), uc + v > 0.0);
    let w2 = uc * select(1.0, 1.0 / (uc + vc), uc + vc > 0.0);
    let w3 = vc * select(1.0, 1.0 / (u + vc), u + vc > 0.0);
    let f0 = g[3] * w0 + g[4] * (1.0 - w0);
    let f1 = g[8] * w1 + g[9] * (1.0 - w1);
    let f2 = g[13] * w2 + g[14] * (1.0 - w2);
    let f3 = g[18] * w3 + g[19] * (1.0 - w3);
    // Rows along v of the CPU's net, stored column-major as pts[4 · column + row].
    return array<vec3<f32>, 16>(
        g[0], g[2], g[16], g[15],
        g[1], f0, f3, g[17],
        g[7], f1, f2, g[11],
        g[5], g[6], g[12], g[10],
    );
}

fn tree_derivatives(p: u32, uv_in: vec2<f32>) -> Derivatives {
    let view = control_points[patch_rows[p * PATCH_ROW + 13u]];
    let bits = bitcast<u32>(view.w);
    let transposed = (bits & 1u) != 0u;
    let rotation = (bits >> 1u) & 3u;
    let block = bits >> 3u;
    var uv = uv_in;
    if (transposed) { uv = uv.yx; }
    for (var r = 0u; r < rotation; r = r + 1u) { uv = vec2<f32>(1.0 - uv.y, uv.x); }
    uv = view.xy + uv * view.z;
    // Down the quadtree as `PatchTree::locate`: borders go to the upper (right) child.
    var slot = bitcast<u32>(control_points[block].x);
    var origin = vec2<f32>(0.0);
    var size = 1.0;
    loop {
        if ((slot & LEAF_SLOT) != 0u) { break; }
        size = size * 0.5;
        let right = uv.x >= origin.x + size;
        let up = uv.y >= origin.y + size;
        var q = select(0u, 1u, right);
        if (up) { q = select(3u, 2u, right); }
        origin = origin + vec2<f32>(select(0.0, size, right), select(0.0, size, up));
        slot = bitcast<u32>(control_points[block + 1u + slot][q]);
    }
    let at = block + (slot & ~LEAF_SLOT);
    let leaf = control_points[at];
    let st = (uv - leaf.xy) / leaf.z;
    var pts: array<vec3<f32>, 16>;
    if (bitcast<u32>(leaf.w) == 0u) {
        for (var k = 0u; k < 16u; k = k + 1u) { pts[k] = control_points[at + 1u + k].xyz; }
    } else {
        pts = gregory_net(at + 1u, st);
    }
    let d = net_derivatives(pts, st);
    var du = d.du * (view.z / leaf.z);
    var dv = d.dv * (view.z / leaf.z);
    // Back through the rotation: with (u, v) = (1 − v', u'), ∂/∂u' = ∂/∂v, ∂/∂v' = −∂/∂u.
    for (var r = 0u; r < rotation; r = r + 1u) {
        let t = du;
        du = dv;
        dv = -t;
    }
    if (transposed) { return Derivatives(d.position, dv, du); }
    return Derivatives(d.position, du, dv);
}

// Position and unit normal at uv, as `Patch::eval` for a subdivision patch: the cross
// product of the derivatives, or where it vanishes (to f32's precision) the normal a small
// step inside.
fn tree_eval(p: u32, uv: vec2<f32>) -> SurfacePoint {
    // One call site of the evaluation (each is compiled inline): step 0 is the point itself,
    // then `robust_normal`'s steps inside (a subdivision patch has no second-derivative
    // rule), each taken only where f32 resolves the cross product there. The bound is f32's,
    // not the CPU's 1e-20: the derivatives are differences of points about 1e-6 apart in
    // relative terms near a fold (parallel derivatives at a boundary corner), so a cross
    // product below 1e-4 of their lengths is noise, and the next step decides.
    var position = vec3<f32>(0.0);
    var n = vec3<f32>(0.0);
    var step = 0.0;
    loop {
        let d = tree_derivatives(p, uv + (vec2<f32>(0.5) - uv) * step);
        if (step == 0.0) { position = d.position; }
        n = cross(d.du, d.dv);
        let s2 = max(dot(d.du, d.du), dot(d.dv, d.dv));
        if (dot(n, n) > 1e-8 * s2 * s2 || step >= 1e-2) { break; }
        step = select(step * 100.0, 1e-6, step == 0.0);
    }
    let len2 = dot(n, n);
    if (!(len2 > 0.0)) {
        return SurfacePoint(position, vec3<f32>(0.0, 0.0, 1.0));
    }
    return SurfacePoint(position, n * inverseSqrt(len2));
}

// Loop subdivision patches: the GPU form of `tessera::surface::TriangleTree::derivatives`
// (Bfr's triangle quadtree walked to the leaf, its quartic Bézier piece or Gregory triangle
// evaluated, the derivatives scaled back and turned leaves' signs flipped). Patch row `[12]`
// bit 4 marks such a patch (with bit 1, a triangle); its view record is `(0, 0, 1, swapped |
// block << 3)` and its leaves' records carry kind bit 0 (Gregory triangle) and bit 1 (turned).

fn patch_is_loop(p: u32) -> bool { return (patch_rows[p * PATCH_ROW + 12u] & 16u) != 0u; }

// `QuarticTriangle::derivatives`: position and first derivatives of the quartic net `b`
// (`QuarticTriangle::index` order) at uv, by de Casteljau's steps down to the linear net
// (the same polynomial; straight-line code with constant indices, which compiles to a
// fraction of a Bernstein double loop's code on lavapipe).
fn quartic_derivatives(b: array<vec3<f32>, 15>, uv: vec2<f32>) -> Derivatives {
    let l = vec3<f32>(1.0 - uv.x - uv.y, uv.x, uv.y);
    let c = array<vec3<f32>, 10>(
        l.x * b[0] + l.y * b[1] + l.z * b[2],
        l.x * b[1] + l.y * b[3] + l.z * b[4],
        l.x * b[2] + l.y * b[4] + l.z * b[5],
        l.x * b[3] + l.y * b[6] + l.z * b[7],
        l.x * b[4] + l.y * b[7] + l.z * b[8],
        l.x * b[5] + l.y * b[8] + l.z * b[9],
        l.x * b[6] + l.y * b[10] + l.z * b[11],
        l.x * b[7] + l.y * b[11] + l.z * b[12],
        l.x * b[8] + l.y * b[12] + l.z * b[13],
        l.x * b[9] + l.y * b[13] + l.z * b[14],
    );
    let d = array<vec3<f32>, 6>(
        l.x * c[0] + l.y * c[1] + l.z * c[2],
        l.x * c[1] + l.y * c[3] + l.z * c[4],
        l.x * c[2] + l.y * c[4] + l.z * c[5],
        l.x * c[3] + l.y * c[6] + l.z * c[7],
        l.x * c[4] + l.y * c[7] + l.z * c[8],
        l.x * c[5] + l.y * c[8] + l.z * c[9],
    );
    let e0 = l.x * d[0] + l.y * d[1] + l.z * d[2];
    let e1 = l.x * d[1] + l.y * d[3] + l.z * d[4];
    let e2 = l.x * d[2] + l.y * d[4] + l.z * d[5];
    return Derivatives(l.x * e0 + l.y * e1 + l.z * e2, 4.0 * (e1 - e0), 4.0 * (e2 - e0));
}

// `GregoryTriangle::blend_weights`' pair: (a, b)/(a + b), or (1, 0) where a + b ≤ 0.
fn gregory_pair(a: f32, b: f32) -> vec2<f32> {
    if (a + b > 0.0) { return vec2<f32>(a / (a + b), b / (a + b)); }
    return vec2<f32>(1.0, 0.0);
}

// Where each point of a quartic net (`QuarticTriangle::index` order: b400, b310, b301, b220,
// b211, b202, b130, b121, b112, b103, b040, b031, b022, b013, b004) is among a Gregory
// triangle's 18 (OpenSubdiv's order); the interior points b211, b121, b112 are its face
// points Fp0, Fp1, Fp2, blended with Fm0, Fm1, Fm2 (points 4, 9, 14) by `loop_leaf_net`.
const QUARTIC_OF_GREGORY = array<u32, 15>(0u, 1u, 2u, 15u, 3u, 17u, 7u, 8u, 13u, 11u, 5u, 6u, 16u, 12u, 10u);

// The quartic net of the leaf whose points start at `at`: its 15 points, or a Gregory
// triangle's 18 as `GregoryTriangle::blended` makes them, the interior points blended at uv.
fn loop_leaf_net(at: u32, gregory: bool, uv: vec2<f32>) -> array<vec3<f32>, 15> {
    var b: array<vec3<f32>, 15>;
    for (var k = 0u; k < 15u; k = k + 1u) {
        b[k] = control_points[at + select(k, QUARTIC_OF_GREGORY[k], gregory)].xyz;
    }
    if (gregory) {
        let w = 1.0 - uv.x - uv.y;
        let w0 = gregory_pair(uv.x, uv.y);
        let w1 = gregory_pair(uv.y, w);
        let w2 = gregory_pair(w, uv.x);
        b[4] = b[4] * w0.x + control_points[at + 4u].xyz * w0.y;
        b[7] = b[7] * w1.x + control_points[at + 9u].xyz * w1.y;
        b[8] = b[8] * w2.x + control_points[at + 14u].xyz * w2.y;
    }
    return b;
}

fn loop_derivatives(p: u32, uv_in: vec2<f32>) -> Derivatives {
    let bits = bitcast<u32>(control_points[patch_rows[p * PATCH_ROW + 13u]].w);
    let swapped = (bits & 1u) != 0u;
    let block = bits >> 3u;
    var uv = uv_in;
    if (swapped) { uv = uv.yx; }
    // `TriangleTree::find`, Bfr's flag included (it stays set after a turned node's middle
    // child).
    var u = uv.x;
    var v = uv.y;
    var slot = bitcast<u32>(control_points[block].x);
    var median = 0.5;
    var turned = false;
    loop {
        if ((slot & LEAF_SLOT) != 0u) { break; }
        var q = 0u;
        if (!turned) {
            if (u >= median) {
                u = u - median;
                q = 1u;
            } else if (v >= median) {
                v = v - median;
                q = 2u;
            } else if (u + v >= median) {
                turned = true;
                q = 3u;
            }
        } else if (u < median) {
            v = v - median;
            q = 1u;
        } else if (v < median) {
            u = u - median;
            q = 2u;
        } else {
            u = u - median;
            v = v - median;
            q = select(0u, 3u, u + v < median);
        }
        slot = bitcast<u32>(control_points[block + 1u + slot][q]);
        median = median * 0.5;
    }
    let at = block + (slot & ~LEAF_SLOT);
    let leaf = control_points[at];
    let kind = bitcast<u32>(leaf.w);
    let leaf_turned = (kind & 2u) != 0u;
    var st = (uv - leaf.xy) / leaf.z;
    if (leaf_turned) { st = (leaf.xy + vec2<f32>(leaf.z) - uv) / leaf.z; }
    // The net moved to its first point: the derivatives are differences of the net's points,
    // which lose the bits the net's distance from the origin takes (a degenerate corner's
    // normal, a small step inside, needs them), and the position gets the point back.
    var net = loop_leaf_net(at + 1u, (kind & 1u) != 0u, st);
    let origin = net[0];
    for (var k = 0u; k < 15u; k = k + 1u) { net[k] = net[k] - origin; }
    var d = quartic_derivatives(net, st);
    d.position = d.position + origin;
    let scale = select(1.0, -1.0, leaf_turned) / leaf.z;
    if (swapped) { return Derivatives(d.position, d.dv * scale, d.du * scale); }
    return Derivatives(d.position, d.du * scale, d.dv * scale);
}
