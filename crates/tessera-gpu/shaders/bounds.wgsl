// The error bound of one parameter triangle: the GPU form of
// `tessera::criterion::bounds::{HessianBound::triangle_errors, TriangleErrors::error,
// enclosing_radius}` in f32. `|S − L| ≤ Λ·R²/2` on a triangle whose smallest enclosing disc
// has radius R, Λ the largest eigenvalue of the second-derivative bound, taken in three
// scalings of the domain; on cells whose legs follow the u and v axes also Filip's
// `(hu²·Muu + 2·hu·hv·Muv + hv²·Mvv)/8`; the smallest of these.

// What depends only on a patch's bound (uu, uv, vv), computed once per patch.
struct TriangleErrors {
    m: vec3<f32>,
    scale0: vec2<f32>,
    scale1: vec2<f32>,
    // Largest eigenvalue in the coordinates of scale0, scale1 and the unscaled domain.
    lambda: vec3<f32>,
}

// `HessianBound::lambda`.
fn hessian_lambda(uu: f32, uv: f32, vv: f32) -> f32 {
    return 0.5 * ((uu + vv) + sqrt((uu - vv) * (uu - vv) + 4.0 * uv * uv));
}

fn scaled_lambda(m: vec3<f32>, s: vec2<f32>) -> f32 {
    return hessian_lambda(m.x / (s.x * s.x), m.y / (s.x * s.y), m.z / (s.y * s.y));
}

// `HessianBound::triangle_errors`. The CPU's `1e-300` keeps a zero bound's scalings
// positive; 1e-30 does that in f32 (its square is still a normal f32).
fn triangle_errors(m: vec3<f32>) -> TriangleErrors {
    let tiny = 1e-30 + 1e-12 * (m.x + m.y + m.z);
    let s0 = vec2<f32>(sqrt(m.x + tiny), sqrt(m.z + tiny));
    let s1 = vec2<f32>(sqrt(m.x + m.y + tiny), sqrt(m.z + m.y + tiny));
    let lambda = vec3<f32>(scaled_lambda(m, s0), scaled_lambda(m, s1), hessian_lambda(m.x, m.y, m.z));
    return TriangleErrors(m, s0, s1, lambda);
}

// `bounds::enclosing_radius`: half the longest side of a right or obtuse triangle, else the
// circumradius (from the side lengths, not their squares, whose product could underflow f32
// in a strongly scaled domain).
fn enclosing_radius(a: vec2<f32>, b: vec2<f32>, c: vec2<f32>) -> f32 {
    let sa = dot(b - c, b - c);
    let sb = dot(c - a, c - a);
    let sc = dot(a - b, a - b);
    let longest = max(sa, max(sb, sc));
    if (2.0 * longest >= sa + sb + sc) {
        return sqrt(longest) / 2.0;
    }
    let ab = b - a;
    let ac = c - a;
    let area2 = abs(ab.x * ac.y - ab.y * ac.x);
    return sqrt(sa) * sqrt(sb) * sqrt(sc) / (2.0 * area2);
}

// Relative skew below which a side counts as following an axis. The CPU's 1e-12 tells f64
// parameters k/n along an edge from i·(1/n) inside; f32 parameters differ by up to ~1e-7
// (about 1e-5 of a side of 1/64). A side that does not follow an axis is skewed by at
// least 1/(64·64) of its length in a pattern whose factors are at most 64 (a strip triangle
// joins a sample k/s of an edge to a grid point i/n one row inside), which the check's
// frames keep to (`CHECK_MAX_FACTOR` in `tessellator/screen.rs`): 1e-4 classifies as exact
// arithmetic does.
const AXIS_SKEW: f32 = 1e-4;

fn follows_axis(x: f32, side: f32) -> bool {
    return abs(x) <= AXIS_SKEW * abs(side);
}

// Filip's bound when the legs from corner o, along a and b, follow the u and v axes (either
// way round); a negative value otherwise.
fn axis_legs_error(m: vec3<f32>, a: vec2<f32>, b: vec2<f32>) -> f32 {
    var legs = vec2<f32>(-1.0);
    if (follows_axis(a.y, a.x) && follows_axis(b.x, b.y)) {
        legs = vec2<f32>(a.x, b.y);
    } else if (follows_axis(a.x, a.y) && follows_axis(b.y, b.x)) {
        legs = vec2<f32>(b.x, a.y);
    } else {
        return -1.0;
    }
    let hu = abs(legs.x);
    let hv = abs(legs.y);
    return (hu * hu * m.x + 2.0 * hu * hv * m.y + hv * hv * m.z) / 8.0;
}

// `HessianBound::axis_aligned_error`: Filip's bound for a right triangle whose legs follow
// the u and v axes, tried at each corner in turn; a negative value for other triangles.
// Without a loop: lavapipe stops every loop of an invocation after 65,535 iterations in all
// (`local.wgsl`), and the check calls this for every strip triangle.
fn axis_aligned_error(m: vec3<f32>, t0: vec2<f32>, t1: vec2<f32>, t2: vec2<f32>) -> f32 {
    let e0 = axis_legs_error(m, t1 - t0, t2 - t0);
    if (e0 >= 0.0) { return e0; }
    let e1 = axis_legs_error(m, t2 - t1, t0 - t1);
    if (e1 >= 0.0) { return e1; }
    return axis_legs_error(m, t0 - t2, t1 - t2);
}

// `TriangleErrors::error`: the bound over the parameter triangle (t0, t1, t2).
fn triangle_error(errors: TriangleErrors, t0: vec2<f32>, t1: vec2<f32>, t2: vec2<f32>) -> f32 {
    let r0 = enclosing_radius(t0 * errors.scale0, t1 * errors.scale0, t2 * errors.scale0);
    let r1 = enclosing_radius(t0 * errors.scale1, t1 * errors.scale1, t2 * errors.scale1);
    let r2 = enclosing_radius(t0, t1, t2);
    var general = min(
        errors.lambda.x * r0 * r0 / 2.0,
        min(errors.lambda.y * r1 * r1 / 2.0, errors.lambda.z * r2 * r2 / 2.0),
    );
    let aligned = axis_aligned_error(errors.m, t0, t1, t2);
    if (aligned >= 0.0) { general = min(general, aligned); }
    return general;
}
