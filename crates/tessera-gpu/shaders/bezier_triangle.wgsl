// Evaluation of cubic Bézier triangles and PN triangles in f32: the GPU form of
// `tessera::surface::BezierTriangle::{position, derivatives, eval}` and
// `PnTriangle::{shading_normal, eval}`. Control points: slots 0..10 of the patch's 16,
// `BezierTriangle::index` order; a PN triangle's six normals (n200, n020, n002, n110, n011,
// n101) in slots 10..16. Barycentrics (1 − u − v, u, v).

fn ipow(x: f32, n: u32) -> f32 {
    var r = 1.0;
    for (var k = 0u; k < n; k = k + 1u) { r = r * x; }
    return r;
}

fn factorial(n: u32) -> f32 {
    return array<f32, 4>(1.0, 1.0, 2.0, 6.0)[n];
}

fn triangle_derivatives(p: u32, uv: vec2<f32>) -> Derivatives {
    let l = vec3<f32>(1.0 - uv.x - uv.y, uv.x, uv.y);
    var position = vec3<f32>(0.0);
    for (var i = 0u; i <= 3u; i = i + 1u) {
        for (var j = 0u; j <= 3u - i; j = j + 1u) {
            let k = 3u - i - j;
            let c = 6.0 / (factorial(i) * factorial(j) * factorial(k));
            position = position + tri_point(p, i, j) * (c * ipow(l.x, i) * ipow(l.y, j) * ipow(l.z, k));
        }
    }
    var du = vec3<f32>(0.0);
    var dv = vec3<f32>(0.0);
    for (var i = 0u; i <= 2u; i = i + 1u) {
        for (var j = 0u; j <= 2u - i; j = j + 1u) {
            let k = 2u - i - j;
            let c = 3.0 * (2.0 / (factorial(i) * factorial(j) * factorial(k))) * ipow(l.x, i) * ipow(l.y, j)
                * ipow(l.z, k);
            du = du + (tri_point(p, i, j + 1u) - tri_point(p, i + 1u, j)) * c;
            dv = dv + (tri_point(p, i, j) - tri_point(p, i + 1u, j)) * c;
        }
    }
    return Derivatives(position, du, dv);
}

// A triangle patch's derivatives: a Loop patch's (its tree's, `tree.wgsl`) or a cubic
// Bézier triangle's.
fn any_triangle_derivatives(p: u32, uv: vec2<f32>) -> Derivatives {
    if (patch_is_loop(p)) { return loop_derivatives(p, uv); }
    return triangle_derivatives(p, uv);
}

// The geometric normal of any triangle patch (`surface::triangle_point`, the one rule of the
// triangle kinds), a step towards the centroid where the derivatives are parallel (as
// `bicubic_eval` does; the CPU takes the limit). One call site of the evaluation (each is
// compiled inline, and a Loop patch's is a tree walk): step 0 is the point itself, then
// steps 1e-4, 1e-3, 1e-2 and 1e-1 inside, each taken only where the cross product vanishes.
fn triangle_eval(p: u32, uv: vec2<f32>) -> SurfacePoint {
    var position = vec3<f32>(0.0);
    var n = vec3<f32>(0.0);
    var step = 0.0;
    loop {
        let d = any_triangle_derivatives(p, uv + (vec2<f32>(1.0 / 3.0) - uv) * step);
        if (step == 0.0) { position = d.position; }
        n = cross(d.du, d.dv);
        let s2 = max(dot(d.du, d.du), dot(d.dv, d.dv));
        if (dot(n, n) > 1e-10 * s2 * s2 || step > 0.05) { break; }
        step = select(step * 10.0, 1e-4, step == 0.0);
    }
    let len2 = dot(n, n);
    if (!(len2 > 0.0)) { return SurfacePoint(position, vec3<f32>(0.0, 0.0, 1.0)); }
    return SurfacePoint(position, n * inverseSqrt(len2));
}

// `PnTriangle::eval`: the quadratic normal field where it does not vanish.
fn pn_eval(p: u32, uv: vec2<f32>) -> SurfacePoint {
    let l = vec3<f32>(1.0 - uv.x - uv.y, uv.x, uv.y);
    let b = p * CONTROL_POINTS + 10u;
    let n = control_points[b].xyz * (l.x * l.x) + control_points[b + 1u].xyz * (l.y * l.y)
        + control_points[b + 2u].xyz * (l.z * l.z) + control_points[b + 3u].xyz * (l.x * l.y)
        + control_points[b + 4u].xyz * (l.y * l.z) + control_points[b + 5u].xyz * (l.x * l.z);
    let len2 = dot(n, n);
    if (len2 > 0.0) {
        return SurfacePoint(triangle_derivatives(p, uv).position, n * inverseSqrt(len2));
    }
    return triangle_eval(p, uv);
}

// Any patch at uv: bicubic, Bézier triangle, PN triangle, Loop or Catmull-Clark
// subdivision patch (the patch row's kind bits).
fn eval_patch(p: u32, uv: vec2<f32>) -> SurfacePoint {
    if (patch_has_pn_normals(p)) { return pn_eval(p, uv); }
    if (patch_is_tri(p)) { return triangle_eval(p, uv); }
    if (patch_is_tree(p)) { return tree_eval(p, uv); }
    return bicubic_eval(p, uv);
}
