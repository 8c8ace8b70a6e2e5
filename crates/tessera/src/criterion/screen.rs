//! Screen-space criteria: a pixel tolerance becomes an object-space one per patch, and
//! patches outside the view frustum or facing away are culled.
//!
//! Conversion (CudaTess): a displacement `δ` of a point at camera-space depth `z` moves its
//! projection by at most `f·δ·√(1 + (x/z)² + (y/z)²)/z` pixels (`f` the focal length in
//! pixels: the norm of the Jacobian of `(x/z, y/z)`). Over a patch's control-point box in
//! front of the eye, `z ≥ z_min` and `|x/z|`, `|y/z|` are largest at the box's corners
//! (the ratio is linear-fractional), so `ε = P·z_min / (f·√(1 + tx² + ty²))` keeps every
//! displacement inside the box — in particular between a mesh point and its surface point —
//! under `P` pixels.

use crate::camera::{Camera, View};
use crate::surface::{Patch, SurfaceSet};
use glam::DVec3;
use rayon::prelude::*;

/// What the screen criteria need of a patch that does not depend on the view, computed once
/// when a set is prepared: its control-point box, bounding sphere and normal cone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchView {
    /// Corners of the control points' axis-aligned box.
    pub lo: DVec3,
    pub hi: DVec3,
    /// A sphere around every control point: their centroid and largest distance from it.
    pub centre: DVec3,
    pub radius: f64,
    /// [`normal_cone`]: `(axis, half-angle)`, None when no cone narrower than a half-space
    /// is known.
    pub cone: Option<(DVec3, f64)>,
    /// Sine and cosine of the cone's half-angle.
    cone_sin_cos: (f64, f64),
}

impl PatchView {
    /// The patch's box, sphere and cone. Cost: O(control points²) for the cone.
    pub fn new(patch: &Patch) -> PatchView {
        let pts = patch.control_points();
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for &p in pts {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let centre = pts.iter().copied().sum::<DVec3>() / pts.len() as f64;
        let radius = pts.iter().map(|p| p.distance(centre)).fold(0.0, f64::max);
        let cone = normal_cone(patch);
        let cone_sin_cos = cone.map_or((0.0, 1.0), |(_, alpha)| alpha.sin_cos());
        PatchView { lo, hi, centre, radius, cone, cone_sin_cos }
    }

    /// [`patch_tolerance`] with the view-independent data precomputed: no allocation, eight
    /// point transforms ([`box_tolerance`] of the patch's box).
    #[inline(always)]
    pub fn tolerance(&self, patch: &Patch, view: &View, pixels: f64, cull: bool) -> Option<f64> {
        if cull && self.culled(patch, view) {
            return None;
        }
        Some(box_tolerance(self.lo, self.hi, view, pixels))
    }

    /// The patch's control-point box `[lo, hi]`, all [`box_tolerance`] reads.
    pub fn bounding_box(&self) -> [DVec3; 2] {
        [self.lo, self.hi]
    }

    /// [`culled`] with the view-independent data precomputed. The bounding sphere decides
    /// each frustum plane it lies wholly inside of; only the planes it reaches test the
    /// control points, so the answer is that of the control-point test.
    #[inline(always)]
    pub fn culled(&self, patch: &Patch, view: &View) -> bool {
        let t = view.half_tangents;
        let c = view.to_camera(self.centre);
        // Signed distances to the six planes, positive outside, each times its plane normal's
        // length (the side planes pass through the eye with normals (±1, 0, −t), of length
        // √(1+t²), in camera space), against the margin times that length: no division.
        let (nx, ny) = (view.side_norms.x, view.side_norms.y);
        let scaled = [
            view.near - c.z,
            c.z - view.far,
            c.x - t.x * c.z,
            -c.x - t.x * c.z,
            c.y - t.y * c.z,
            -c.y - t.y * c.z,
        ];
        // Rounding of the transforms is far below this margin.
        let margin_of = |length: f64| self.radius + 1e-9 * (self.radius + length + view.far);
        let lengths = [1.0, 1.0, nx, nx, ny, ny];
        // First with a margin at least the exact one, from a length at least `c.length()`
        // (its L1 norm, raised well past the rounding of both) and no square root: a
        // sphere wholly inside every plane by it is inside by the exact margin too, and
        // most patches in view are.
        let above = margin_of((c.x.abs() + c.y.abs() + c.z.abs()) * (1.0 + 1e-12));
        if scaled.iter().zip(lengths).all(|(&d, length)| d < -above * length) {
            return self.back_facing(view.eye);
        }
        let margin = margin_of(c.length());
        for (plane, (&d, length)) in scaled.iter().zip(lengths).enumerate() {
            // Where d < −margin every control point is inside this plane.
            if d >= -margin * length && all_outside(patch, view, plane) {
                return true;
            }
        }
        self.back_facing(view.eye)
    }

    /// [`back_facing`] with the cone and sphere precomputed. The angle test
    /// `γ > 90° + α + β` is done on cosines (no inverse trigonometry per frame), with a margin
    /// of 1e-12 so that rounding can only keep a patch, never cull it.
    #[inline(always)]
    pub fn back_facing(&self, eye: DVec3) -> bool {
        let Some((axis, _)) = self.cone else { return false };
        let to_eye = eye - self.centre;
        // The eye on the axis's side faces the patch: the test below could only find
        // `cos γ` within rounding (about 1e-15) of 0 or above, never below `−sin θ − 1e-12`
        // (`sin θ ≥ 0`), so the answer is the same, without two roots and four divisions
        // (about half the patches in view of a closed surface).
        if axis.dot(to_eye) >= 0.0 {
            return false;
        }
        self.beyond_cone(axis, to_eye)
    }

    /// The back-facing test in full, for the cone `axis` and the direction `to_eye` from
    /// the centre to the eye.
    #[inline]
    fn beyond_cone(&self, axis: DVec3, to_eye: DVec3) -> bool {
        let dist = to_eye.length();
        if dist <= self.radius {
            return false;
        }
        let (sin_a, cos_a) = self.cone_sin_cos;
        let sin_b = self.radius / dist;
        let cos_b = (1.0 - sin_b * sin_b).max(0.0).sqrt();
        // θ = α + β: at 90° or more no direction lies beyond 90° + θ.
        let (sin_t, cos_t) = (sin_a * cos_b + cos_a * sin_b, cos_a * cos_b - sin_a * sin_b);
        if cos_t <= 0.0 {
            return false;
        }
        let cos_g = axis.dot(to_eye / dist).clamp(-1.0, 1.0);
        cos_g < -sin_t - 1e-12
    }
}

/// Whether every control point of `patch` lies outside frustum plane `plane` of `view` (the
/// order of [`PatchView::culled`]'s distances). Not inlined: the patch itself (hundreds of
/// bytes) is read only here, for the few patches whose sphere reaches a plane; inlined, the
/// compiler read it for every patch ahead of the test, a cache miss per patch per frame.
#[inline(never)]
fn all_outside(patch: &Patch, view: &View, plane: usize) -> bool {
    let t = view.half_tangents;
    let outside = |p: DVec3| match plane {
        0 => p.z < view.near,
        1 => p.z > view.far,
        2 => p.x > t.x * p.z,
        3 => p.x < -t.x * p.z,
        4 => p.y > t.y * p.z,
        _ => p.y < -t.y * p.z,
    };
    patch.control_points().iter().all(|&p| outside(view.to_camera(p)))
}

/// The object-space tolerance for patch `p` seen by `camera` at `pixels` of error, or None
/// when the patch is culled (`cull`): outside the frustum, or back-facing by a conservative
/// normal cone. A per-frame loop prepares [`PatchView`]s once instead.
pub fn patch_tolerance(patch: &Patch, camera: &Camera, pixels: f64, cull: bool) -> Option<f64> {
    PatchView::new(patch).tolerance(patch, &camera.view(), pixels, cull)
}

/// True when the patch cannot be seen: every control point lies beyond one frustum plane
/// (the convex hull holds the patch), or it faces away (see [`back_facing`]).
pub fn culled(patch: &Patch, camera: &Camera) -> bool {
    PatchView::new(patch).culled(patch, &camera.view())
}

/// Cone of normal directions of a polynomial patch: `S_u × S_v` is a positive combination of
/// cross products of control-net differences `Δu × Δv`, so it lies in their cone. Returns
/// `(axis, half-angle)`, or None for rational patches and cones wider than a half-space.
pub fn normal_cone(patch: &Patch) -> Option<(DVec3, f64)> {
    if matches!(patch, Patch::Bicubic(b) if !b.is_polynomial())
        || matches!(patch, Patch::Subdivision(_) | Patch::Loop(_))
    {
        // (A piecewise subdivision patch has no single net whose differences bound its
        // normals; it is never culled by its cone.)
        return None;
    }
    // The cross products are visited twice (sum, then spread) rather than stored.
    let for_each_cross = |f: &mut dyn FnMut(DVec3)| match patch {
        Patch::Bicubic(b) => {
            for i in 0..3 {
                for j in 0..4 {
                    let du = b.point(i + 1, j) - b.point(i, j);
                    for k in 0..4 {
                        for l in 0..3 {
                            f(du.cross(b.point(k, l + 1) - b.point(k, l)));
                        }
                    }
                }
            }
        }
        Patch::Subdivision(_) | Patch::Loop(_) => {}
        Patch::BezierTriangle(_) | Patch::Pn(_) => {
            let t = match patch {
                Patch::BezierTriangle(t) => t,
                Patch::Pn(p) => &p.geometry,
                Patch::Bicubic(_) | Patch::Subdivision(_) | Patch::Loop(_) => unreachable!(),
            };
            // The six control-net differences along each parameter direction.
            let (mut du, mut dv) = ([DVec3::ZERO; 6], [DVec3::ZERO; 6]);
            let mut n = 0;
            for i in 0..=2usize {
                for j in 0..=2 - i {
                    let k = 2 - i - j;
                    du[n] = t.b(i, j + 1, k) - t.b(i + 1, j, k);
                    dv[n] = t.b(i, j, k + 1) - t.b(i + 1, j, k);
                    n += 1;
                }
            }
            for a in &du {
                for b in &dv {
                    f(a.cross(*b));
                }
            }
        }
    };
    let mut sum = DVec3::ZERO;
    for_each_cross(&mut |c| {
        if let Some(u) = c.try_normalize() {
            sum += u;
        }
    });
    let axis = sum.try_normalize()?;
    let mut cos_min = 1.0f64;
    for_each_cross(&mut |c| {
        if let Some(u) = c.try_normalize() {
            cos_min = cos_min.min(u.dot(axis));
        }
    });
    if cos_min <= 0.0 {
        return None;
    }
    Some((axis, cos_min.clamp(-1.0, 1.0).acos()))
}

/// The object-space tolerance of a patch whose control points lie in the world box
/// `lo..hi`, for `pixels` of screen error from `view`: the box's eight corners in camera
/// space, the nearest depth and the widest ratios to it bound every point's screen scale.
/// The rule of [`PatchView::tolerance`] and of [`tolerances_into`]. Cost: 18 products for
/// the eight corners, sixteen divisions.
#[inline(always)]
pub fn box_tolerance(lo: DVec3, hi: DVec3, view: &View, pixels: f64) -> f64 {
    let t = view.half_tangents;
    // Camera-space corners of the world-space box around the control points, one array per
    // coordinate. Each is `View::to_camera`'s sum of three products in its order, so the
    // same bits; but a product is formed once for each of the two values its axis takes
    // (18 products, not 72), and the ratios below divide whole arrays (vector lanes).
    let (dlo, dhi) = (lo - view.eye, hi - view.eye);
    let coordinate = |a: DVec3| -> [f64; 8] {
        let (x, y, z) = ([dlo.x * a.x, dhi.x * a.x], [dlo.y * a.y, dhi.y * a.y], [dlo.z * a.z, dhi.z * a.z]);
        std::array::from_fn(|i| x[i & 1] + y[(i >> 1) & 1] + z[i >> 2])
    };
    let (xs, ys, zs) = (coordinate(view.right), coordinate(view.up), coordinate(view.forward));
    let z_min = zs.iter().copied().fold(f64::INFINITY, f64::min);
    let (z, tx, ty) = if z_min >= view.near {
        let ratio = |us: &[f64; 8]| -> f64 {
            let r: [f64; 8] = std::array::from_fn(|i| (us[i] / zs[i]).abs());
            r.into_iter().fold(0.0, f64::max)
        };
        (z_min, ratio(&xs), ratio(&ys))
    } else {
        // The box reaches the near plane: only points inside the frustum are seen, where
        // z ≥ near and the ratios stay within the field of view.
        (view.near, t.x, t.y)
    };
    pixels * z / (view.focal_pixels * (1.0 + tx * tx + ty * ty).sqrt())
}

/// True when no point of the patch can face the eye: the normal cone (half-angle `α`) and the
/// directions towards the eye from the bounding sphere (half-angle `β`) are more than 90°
/// apart. Conservative: false when unsure.
pub fn back_facing(patch: &Patch, eye: DVec3) -> bool {
    PatchView::new(patch).back_facing(eye)
}

/// Tolerances for every patch of `set` (None = culled).
pub fn tolerances(set: &SurfaceSet, camera: &Camera, pixels: f64, cull: bool) -> Vec<Option<f64>> {
    set.patches.par_iter().map(|p| patch_tolerance(p, camera, pixels, cull)).collect()
}

/// [`tolerances`] from prepared [`PatchView`]s and their boxes (`boxes[p]` is
/// `views[p].bounding_box()`; one per patch), into `out` (resized; no allocation once it has
/// the capacity). Without `cull` only the boxes are read. Cost: O(P) box transforms,
/// parallel.
pub fn tolerances_into(
    set: &SurfaceSet,
    views: &[PatchView],
    boxes: &[[DVec3; 2]],
    camera: &View,
    pixels: f64,
    cull: bool,
    out: &mut Vec<Option<f64>>,
) {
    out.resize(set.patches.len(), None);
    if !cull {
        // The boxes alone, 48 bytes a patch: the views are 136, and this pass, streaming
        // them from memory, waited on their loads (the Catmull-Clark torus × 1563 at 0.5 px:
        // 1.8 → 1.25 ms, one thread).
        super::rows::fill(
            out,
            #[inline(always)]
            |p, o| {
                let [lo, hi] = boxes[p];
                *o = Some(box_tolerance(lo, hi, camera, pixels));
            },
        );
        return;
    }
    // Culling reads the views; their own boxes serve.
    super::rows::fill(
        out,
        #[inline(always)]
        |p, o| *o = views[p].tolerance(&set.patches[p], camera, pixels, cull),
    );
}

/// The plan's visibility row: 1 for every patch, or, with `cull`, 0 for the patches
/// [`culled`] for `camera`. Cost: O(P) cone tests.
pub fn visibility(set: &SurfaceSet, camera: &Camera, cull: bool) -> Vec<u32> {
    let views: Vec<PatchView> =
        if cull { set.patches.par_iter().map(PatchView::new).collect() } else { vec![] };
    let mut out = Vec::new();
    visibility_into(set, &views, &camera.view(), cull, &mut out);
    out
}

/// [`visibility`] from prepared [`PatchView`]s, into `out` (resized). Cost: O(P) plane and
/// cone tests, parallel.
pub fn visibility_into(set: &SurfaceSet, views: &[PatchView], camera: &View, cull: bool, out: &mut Vec<u32>) {
    out.resize(set.patches.len(), 1);
    if !cull {
        out.fill(1);
        return;
    }
    out.par_iter_mut().zip(&set.patches).zip(views).for_each(|((o, patch), v)| {
        *o = u32::from(!v.culled(patch, camera));
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::patches::read_patches;
    use crate::test_support::data;

    /// The control-point test, transforming every point and taking the angles with inverse
    /// trigonometry, as culling was first written: the oracle of the prepared form.
    fn culled_directly(patch: &Patch, camera: &Camera) -> (bool, bool) {
        let cam: Vec<DVec3> = patch.control_points().iter().map(|&p| camera.to_camera(p)).collect();
        let t = camera.half_tangents();
        let outside = |f: &dyn Fn(&DVec3) -> bool| cam.iter().all(f);
        let frustum = outside(&|c| c.z < camera.near)
            || outside(&|c| c.z > camera.far)
            || outside(&|c| c.x > t.x * c.z)
            || outside(&|c| c.x < -t.x * c.z)
            || outside(&|c| c.y > t.y * c.z)
            || outside(&|c| c.y < -t.y * c.z);
        let back = normal_cone(patch).is_some_and(|(axis, alpha)| {
            let pts = patch.control_points();
            let centre = pts.iter().copied().sum::<DVec3>() / pts.len() as f64;
            let radius = pts.iter().map(|p| p.distance(centre)).fold(0.0, f64::max);
            let to_eye = camera.eye - centre;
            let dist = to_eye.length();
            dist > radius && {
                let beta = (radius / dist).asin();
                let gamma = axis.dot(to_eye / dist).clamp(-1.0, 1.0).acos();
                gamma > std::f64::consts::FRAC_PI_2 + alpha + beta
            }
        });
        (frustum, back)
    }

    /// The culling tests' models: a patch model (the teapot) and PN triangles (spot).
    fn culling_models() -> [SurfaceSet; 2] {
        let teapot = SurfaceSet::from_patch_file(
            &read_patches(&data("patches/teapot.patches")).expect("test model"),
            Default::default(),
        );
        let path = data("meshes/spot.obj");
        let spot = SurfaceSet::pn_from_mesh(
            &crate::io::obj::read_obj(&path).expect("test model"),
            &path,
            Default::default(),
        )
        .expect("test model");
        [teapot, spot]
    }

    /// The prepared test culls exactly what the direct one does, over many cameras around and
    /// inside two models (a patch model and PN triangles): the sphere only skips planes it
    /// lies wholly inside, and the cosine form of the cone test agrees with the angles.
    #[test]
    fn prepared_culling_equals_the_control_point_test() {
        let [teapot, spot] = culling_models();
        let mut culled = [0usize; 2];
        for set in [&teapot, &spot] {
            let views: Vec<PatchView> = set.patches.iter().map(PatchView::new).collect();
            let (lo, hi) = set.bounds();
            let (centre, radius) = ((lo + hi) * 0.5, lo.distance(hi) * 0.5);
            for k in 0..40 {
                let a = k as f64 * 0.61;
                let mut camera = Camera::framing(lo, hi, 640, 480);
                let distance = radius * (0.3 + 0.15 * k as f64);
                camera.eye = centre + DVec3::new(a.cos(), (0.7 * a).sin(), a.sin()).normalize() * distance;
                camera.target = centre + DVec3::new(0.0, radius * 0.4 * (a * 1.3).sin(), 0.0);
                camera.near = distance * 0.05;
                for (patch, view) in set.patches.iter().zip(&views) {
                    let (frustum, back) = culled_directly(patch, &camera);
                    let v = camera.view();
                    assert_eq!(view.culled(patch, &v), frustum || back, "camera {k}");
                    culled[0] += usize::from(frustum);
                    culled[1] += usize::from(back && !frustum);
                }
            }
        }
        // Both kinds of culling happened, so both paths were compared.
        assert!(culled[0] > 100 && culled[1] > 100, "culled by frustum, by cone: {culled:?}");
    }

    /// The axis-side test changes no answer: eyes all around each patch of two models, and
    /// eyes on the plane through the patch's centre across its axis (where `axis · to_eye`
    /// is 0 up to rounding, either sign), also nudged off it by a few ulps. A first test
    /// that let eyes a little behind that plane through (`≥ −0.3 |to_eye|`) fails it.
    #[test]
    fn the_axis_side_test_gives_the_full_tests_answers() {
        let [teapot, spot] = culling_models();
        let mut rng = crate::test_support::Lcg(26);
        let (mut compared, mut back) = (0usize, 0usize);
        for set in [&teapot, &spot] {
            for view in set.patches.iter().map(PatchView::new) {
                let Some((axis, _)) = view.cone else { continue };
                // Two directions across the axis.
                let across = axis.any_orthonormal_vector();
                let other = axis.cross(across);
                for _ in 0..40 {
                    let r = view.radius * (1.0 + 20.0 * rng.unit53());
                    let a = std::f64::consts::TAU * rng.unit53();
                    let around = DVec3::new(rng.unit53() - 0.5, rng.unit53() - 0.5, rng.unit53() - 0.5);
                    let on_plane = view.centre + (across * a.cos() + other * a.sin()) * r;
                    let tiny = axis * (r * f64::EPSILON * (rng.unit53() - 0.5) * 8.0);
                    for eye in [view.centre + around.normalize_or_zero() * r, on_plane, on_plane + tiny] {
                        let full = view.beyond_cone(axis, eye - view.centre);
                        assert_eq!(view.back_facing(eye), full, "eye {eye} of a patch at {}", view.centre);
                        compared += 1;
                        back += usize::from(full);
                    }
                }
            }
        }
        assert!(compared > 10_000 && back > 1_000, "compared {compared}, back-facing {back}");
    }

    /// [`box_tolerance`] as first written: each corner transformed by `View::to_camera`.
    fn box_tolerance_by_corners(lo: DVec3, hi: DVec3, view: &View, pixels: f64) -> f64 {
        let t = view.half_tangents;
        let corners: [DVec3; 8] = std::array::from_fn(|i| {
            view.to_camera(DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            ))
        });
        let z_min = corners.iter().map(|c| c.z).fold(f64::INFINITY, f64::min);
        let (z, tx, ty) = if z_min >= view.near {
            let tx = corners.iter().map(|c| (c.x / c.z).abs()).fold(0.0, f64::max);
            let ty = corners.iter().map(|c| (c.y / c.z).abs()).fold(0.0, f64::max);
            (z_min, tx, ty)
        } else {
            (view.near, t.x, t.y)
        };
        pixels * z / (view.focal_pixels * (1.0 + tx * tx + ty * ty).sqrt())
    }

    /// The per-axis products give every corner the bits `View::to_camera` gives it, so the
    /// tolerance is the same to the last bit: boxes in front of, around and behind the eye,
    /// from seeded cameras.
    #[test]
    fn box_tolerance_equals_the_corner_by_corner_form_bit_for_bit() {
        let mut rng = crate::test_support::Lcg(2026);
        let mut next = move || rng.unit53() * 2.0 - 1.0;
        let (mut near_boxes, mut far_boxes) = (0, 0);
        for k in 0..200 {
            let mut camera = Camera::framing(DVec3::splat(-1.0), DVec3::splat(1.0), 1280, 1024);
            camera.eye = DVec3::new(next(), next(), next()) * 3.0 * (1 + k % 4) as f64;
            camera.target = DVec3::new(next(), next(), next()) * 0.5;
            let view = camera.view();
            for _ in 0..50 {
                let a = DVec3::new(next(), next(), next()) * 2.0;
                let b = a + DVec3::new(next().abs(), next().abs(), next().abs()) * 0.3;
                let pixels = 0.1 + next().abs();
                let (got, want) =
                    (box_tolerance(a, b, &view, pixels), box_tolerance_by_corners(a, b, &view, pixels));
                assert_eq!(got.to_bits(), want.to_bits(), "camera {k}: box {a} {b}");
                let corner =
                    |i: usize| DVec3::select(glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0), b, a);
                let z_min = (0..8).map(|i| view.to_camera(corner(i)).z).fold(f64::INFINITY, f64::min);
                if z_min >= view.near {
                    far_boxes += 1
                } else {
                    near_boxes += 1
                }
            }
        }
        // Both branches were compared.
        assert!(near_boxes > 100 && far_boxes > 100, "{near_boxes} {far_boxes}");
    }
}
