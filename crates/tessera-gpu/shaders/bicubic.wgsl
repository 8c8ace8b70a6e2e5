// Evaluation of a bicubic rational Bézier patch in f32: the GPU form of
// `tessera::surface::RationalBicubic::eval` (homogeneous sums, quotient rule, the same
// summation order over i then j).

struct SurfacePoint {
    position: vec3<f32>,
    normal: vec3<f32>,
}

struct Bernstein {
    b: vec4<f32>,
    d: vec4<f32>,
}

// Cubic Bernstein polynomials and their derivatives at t: `surface::bicubic::bernstein3`.
fn bernstein3(t: f32) -> Bernstein {
    let s = 1.0 - t;
    let b = vec4<f32>(s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t);
    let d = vec4<f32>(-3.0 * s * s, 3.0 * s * (s - 2.0 * t), 3.0 * t * (2.0 * s - t), 3.0 * t * t);
    return Bernstein(b, d);
}

struct Derivatives {
    position: vec3<f32>,
    du: vec3<f32>,
    dv: vec3<f32>,
}

fn bicubic_derivatives(p: u32, uv: vec2<f32>) -> Derivatives {
    let bu = bernstein3(uv.x);
    let bv = bernstein3(uv.y);
    var h = vec3<f32>(0.0);
    var hu = vec3<f32>(0.0);
    var hv = vec3<f32>(0.0);
    var w = 0.0;
    var wu = 0.0;
    var wv = 0.0;
    let base = p * CONTROL_POINTS;
    for (var i = 0u; i < 4u; i = i + 1u) {
        for (var j = 0u; j < 4u; j = j + 1u) {
            let q = control_points[base + 4u * i + j];
            let hq = q.xyz * q.w;
            let a = bu.b[i] * bv.b[j];
            let b = bu.d[i] * bv.b[j];
            let c = bu.b[i] * bv.d[j];
            h = h + hq * a;
            hu = hu + hq * b;
            hv = hv + hq * c;
            w = w + q.w * a;
            wu = wu + q.w * b;
            wv = wv + q.w * c;
        }
    }
    let position = h / w;
    return Derivatives(position, (hu - position * wu) / w, (hv - position * wv) / w);
}

// Position and unit normal at uv. Where ∂S/∂u × ∂S/∂v vanishes (a boundary curve collapsed
// to a point, as at the teapot's lid apex) the normal is taken a small step towards the
// domain centre, which tends to the limit normal; the CPU (`surface::robust_normal`) takes
// the limit itself, so the two agree to the step's size there.
fn bicubic_eval(p: u32, uv: vec2<f32>) -> SurfacePoint {
    let d = bicubic_derivatives(p, uv);
    var n = cross(d.du, d.dv);
    let scale = max(dot(d.du, d.du), dot(d.dv, d.dv));
    if (!(dot(n, n) > 1e-10 * scale * scale)) {
        for (var step = 1e-4; step < 0.5; step = step * 10.0) {
            let e = bicubic_derivatives(p, uv + (vec2<f32>(0.5) - uv) * step);
            n = cross(e.du, e.dv);
            let s2 = max(dot(e.du, e.du), dot(e.dv, e.dv));
            if (dot(n, n) > 1e-10 * s2 * s2) {
                break;
            }
        }
    }
    let len2 = dot(n, n);
    if (!(len2 > 0.0)) {
        return SurfacePoint(d.position, vec3<f32>(0.0, 0.0, 1.0));
    }
    return SurfacePoint(d.position, n * inverseSqrt(len2));
}
