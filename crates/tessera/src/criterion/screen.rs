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

use crate::camera::Camera;
use crate::surface::{Patch, SurfaceSet};
use glam::DVec3;
use rayon::prelude::*;

/// The object-space tolerance for patch `p` seen by `camera` at `pixels` of error, or None
/// when the patch is culled (`cull`): outside the frustum, or back-facing by a conservative
/// normal cone.
pub fn patch_tolerance(patch: &Patch, camera: &Camera, pixels: f64, cull: bool) -> Option<f64> {
    if cull && culled(patch, camera) {
        return None;
    }
    let pts = patch.control_points();
    let t = camera.half_tangents();
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for &p in pts {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    // Camera-space corners of the world-space box around the control points.
    let corners: Vec<DVec3> = (0..8)
        .map(|i| {
            let p = DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            camera.to_camera(p)
        })
        .collect();
    let z_min = corners.iter().map(|c| c.z).fold(f64::INFINITY, f64::min);
    let (z, tx, ty) = if z_min >= camera.near {
        let tx = corners.iter().map(|c| (c.x / c.z).abs()).fold(0.0, f64::max);
        let ty = corners.iter().map(|c| (c.y / c.z).abs()).fold(0.0, f64::max);
        (z_min, tx, ty)
    } else {
        // The box reaches the near plane: only points inside the frustum are seen, where
        // z ≥ near and the ratios stay within the field of view.
        (camera.near, t.x, t.y)
    };
    Some(pixels * z / (camera.focal_pixels() * (1.0 + tx * tx + ty * ty).sqrt()))
}

/// True when the patch cannot be seen: every control point lies beyond one frustum plane
/// (the convex hull holds the patch), or it faces away (see [`back_facing`]).
pub fn culled(patch: &Patch, camera: &Camera) -> bool {
    let cam: Vec<DVec3> = patch.control_points().iter().map(|&p| camera.to_camera(p)).collect();
    let t = camera.half_tangents();
    let outside = |f: &dyn Fn(&DVec3) -> bool| cam.iter().all(f);
    outside(&|c| c.z < camera.near)
        || outside(&|c| c.z > camera.far)
        || outside(&|c| c.x > t.x * c.z)
        || outside(&|c| c.x < -t.x * c.z)
        || outside(&|c| c.y > t.y * c.z)
        || outside(&|c| c.y < -t.y * c.z)
        || back_facing(patch, camera.eye)
}

/// Cone of normal directions of a polynomial patch: `S_u × S_v` is a positive combination of
/// cross products of control-net differences `Δu × Δv`, so it lies in their cone. Returns
/// `(axis, half-angle)`, or None for rational patches and cones wider than a half-space.
pub fn normal_cone(patch: &Patch) -> Option<(DVec3, f64)> {
    let mut crosses = Vec::with_capacity(144);
    match patch {
        Patch::Bicubic(b) => {
            if !b.is_polynomial() {
                return None;
            }
            for i in 0..3 {
                for j in 0..4 {
                    let du = b.point(i + 1, j) - b.point(i, j);
                    for k in 0..4 {
                        for l in 0..3 {
                            crosses.push(du.cross(b.point(k, l + 1) - b.point(k, l)));
                        }
                    }
                }
            }
        }
        Patch::BezierTriangle(_) | Patch::Pn(_) => {
            let t = match patch {
                Patch::BezierTriangle(t) => t,
                Patch::Pn(p) => &p.geometry,
                Patch::Bicubic(_) => unreachable!(),
            };
            let mut du = Vec::new();
            let mut dv = Vec::new();
            for i in 0..=2usize {
                for j in 0..=2 - i {
                    let k = 2 - i - j;
                    du.push(t.b(i, j + 1, k) - t.b(i + 1, j, k));
                    dv.push(t.b(i, j, k + 1) - t.b(i + 1, j, k));
                }
            }
            for a in &du {
                for b in &dv {
                    crosses.push(a.cross(*b));
                }
            }
        }
    }
    let units: Vec<DVec3> = crosses.iter().filter_map(|c| c.try_normalize()).collect();
    let axis = units.iter().copied().sum::<DVec3>().try_normalize()?;
    let cos_min = units.iter().map(|u| u.dot(axis)).fold(1.0f64, f64::min);
    if cos_min <= 0.0 {
        return None;
    }
    Some((axis, cos_min.clamp(-1.0, 1.0).acos()))
}

/// True when no point of the patch can face the eye: the normal cone (half-angle `α`) and the
/// directions towards the eye from the bounding sphere (half-angle `β`) are more than 90°
/// apart. Conservative: false when unsure.
pub fn back_facing(patch: &Patch, eye: DVec3) -> bool {
    let Some((axis, alpha)) = normal_cone(patch) else { return false };
    let pts = patch.control_points();
    let centre = pts.iter().copied().sum::<DVec3>() / pts.len() as f64;
    let radius = pts.iter().map(|p| p.distance(centre)).fold(0.0, f64::max);
    let to_eye = eye - centre;
    let dist = to_eye.length();
    if dist <= radius {
        return false;
    }
    let beta = (radius / dist).asin();
    let gamma = axis.dot(to_eye / dist).clamp(-1.0, 1.0).acos();
    gamma > std::f64::consts::FRAC_PI_2 + alpha + beta
}

/// Tolerances for every patch of `set` (None = culled).
pub fn tolerances(set: &SurfaceSet, camera: &Camera, pixels: f64, cull: bool) -> Vec<Option<f64>> {
    set.patches.par_iter().map(|p| patch_tolerance(p, camera, pixels, cull)).collect()
}

/// The plan's visibility row: 1 for every patch, or, with `cull`, 0 for the patches
/// [`culled`] for `camera`. Cost: O(P) cone tests.
pub fn visibility(set: &SurfaceSet, camera: &Camera, cull: bool) -> Vec<u32> {
    if !cull {
        return vec![1; set.patches.len()];
    }
    set.patches.par_iter().map(|p| u32::from(!culled(p, camera))).collect()
}
