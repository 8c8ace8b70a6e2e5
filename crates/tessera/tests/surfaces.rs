//! Evaluators against independent de Casteljau implementations, exact rational conics, and
//! the PN-triangle interpolation properties.

use glam::{DVec2, DVec3, DVec4};
use proptest::prelude::*;
use tessera::scene::sphere_octant;
use tessera::surface::{BezierTriangle, Patch, PnTriangle, RationalBicubic};

/// Rational de Casteljau in homogeneous coordinates: rows in v first, then the column in u.
fn de_casteljau_bicubic(p: &RationalBicubic, uv: DVec2) -> DVec3 {
    let curve = |pts: [DVec4; 4], t: f64| -> DVec4 {
        let mut q = pts;
        for r in 1..4 {
            for i in 0..4 - r {
                q[i] = q[i] * (1.0 - t) + q[i + 1] * t;
            }
        }
        q[0]
    };
    let mut column = [DVec4::ZERO; 4];
    for (i, c) in column.iter_mut().enumerate() {
        let row = [0, 1, 2, 3].map(|j| {
            let w = p.weights[4 * i + j];
            (p.points[4 * i + j] * w).extend(w)
        });
        *c = curve(row, uv.y);
    }
    let h = curve(column, uv.x);
    h.truncate() / h.w
}

/// De Casteljau on a cubic Bézier triangle, written over (i, j, k) triples.
fn de_casteljau_triangle(t: &BezierTriangle, uv: DVec2) -> DVec3 {
    let l = [1.0 - uv.x - uv.y, uv.x, uv.y];
    let mut level: Vec<((usize, usize, usize), DVec3)> = Vec::new();
    for i in 0..=3 {
        for j in 0..=3 - i {
            level.push(((i, j, 3 - i - j), t.b(i, j, 3 - i - j)));
        }
    }
    for degree in (0..3).rev() {
        let get = |lv: &Vec<((usize, usize, usize), DVec3)>, key| lv.iter().find(|e| e.0 == key).unwrap().1;
        let mut next = Vec::new();
        for i in 0..=degree {
            for j in 0..=degree - i {
                let k = degree - i - j;
                let p = get(&level, (i + 1, j, k)) * l[0]
                    + get(&level, (i, j + 1, k)) * l[1]
                    + get(&level, (i, j, k + 1)) * l[2];
                next.push(((i, j, k), p));
            }
        }
        level = next;
    }
    level[0].1
}

fn arb_point() -> impl Strategy<Value = DVec3> {
    (-10.0..10.0f64, -10.0..10.0f64, -10.0..10.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

fn arb_bicubic() -> impl Strategy<Value = RationalBicubic> {
    (prop::array::uniform16(arb_point()), prop::array::uniform16(0.2..5.0f64))
        .prop_map(|(points, weights)| RationalBicubic { points, weights })
}

fn arb_triangle() -> impl Strategy<Value = BezierTriangle> {
    prop::array::uniform10(arb_point()).prop_map(|points| BezierTriangle { points })
}

fn arb_tri_uv() -> impl Strategy<Value = DVec2> {
    (0.0..1.0f64, 0.0..1.0f64).prop_map(|(a, b)| {
        if a + b > 1.0 {
            DVec2::new(1.0 - a, 1.0 - b)
        } else {
            DVec2::new(a, b)
        }
    })
}

fn close(a: DVec3, b: DVec3, tol: f64) -> bool {
    a.distance(b) <= tol * (1.0 + a.length().max(b.length()))
}

proptest! {
    #[test]
    fn bicubic_matches_de_casteljau(p in arb_bicubic(), u in 0.0..=1.0f64, v in 0.0..=1.0f64) {
        let uv = DVec2::new(u, v);
        let reference = de_casteljau_bicubic(&p, uv);
        prop_assert!(close(p.position(uv), reference, 1e-12));
        prop_assert!(close(p.eval(uv).position, reference, 1e-12));
        prop_assert!(close(p.derivatives(uv).position, reference, 1e-12));
    }

    #[test]
    fn bicubic_derivatives_match_finite_differences(p in arb_bicubic(), u in 0.01..0.99f64, v in 0.01..0.99f64) {
        let h = 1e-6;
        let d = p.derivatives(DVec2::new(u, v));
        let fu = (de_casteljau_bicubic(&p, DVec2::new(u + h, v)) - de_casteljau_bicubic(&p, DVec2::new(u - h, v))) / (2.0 * h);
        let fv = (de_casteljau_bicubic(&p, DVec2::new(u, v + h)) - de_casteljau_bicubic(&p, DVec2::new(u, v - h))) / (2.0 * h);
        prop_assert!(close(d.du, fu, 1e-5), "du {} vs {}", d.du, fu);
        prop_assert!(close(d.dv, fv, 1e-5), "dv {} vs {}", d.dv, fv);
    }

    #[test]
    fn bezier_triangle_matches_de_casteljau(t in arb_triangle(), uv in arb_tri_uv()) {
        prop_assert!(close(t.position(uv), de_casteljau_triangle(&t, uv), 1e-12));
        let h = 1e-6;
        let uv = uv.clamp(DVec2::splat(0.1), DVec2::splat(0.4));
        let d = t.derivatives(uv);
        let fu = (de_casteljau_triangle(&t, uv + DVec2::X * h) - de_casteljau_triangle(&t, uv - DVec2::X * h)) / (2.0 * h);
        let fv = (de_casteljau_triangle(&t, uv + DVec2::Y * h) - de_casteljau_triangle(&t, uv - DVec2::Y * h)) / (2.0 * h);
        prop_assert!(close(d.du, fu, 1e-5));
        prop_assert!(close(d.dv, fv, 1e-5));
    }

    #[test]
    fn pn_triangle_interpolates_corners_and_normals(
        p in prop::array::uniform3(arb_point()),
        n in prop::array::uniform3(arb_point()),
    ) {
        let n = n.map(|v| v.try_normalize().unwrap_or(DVec3::Z));
        let pn = PnTriangle::new(p, n);
        for (c, uv) in [DVec2::ZERO, DVec2::X, DVec2::Y].into_iter().enumerate() {
            let s = pn.eval(uv);
            prop_assert!(close(s.position, p[c], 1e-12));
            prop_assert!(close(s.normal, n[c], 1e-12));
        }
    }

    #[test]
    fn normals_are_unit_and_finite(p in arb_bicubic(), u in 0.0..=1.0f64, v in 0.0..=1.0f64) {
        let n = p.eval(DVec2::new(u, v)).normal;
        prop_assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-9);
    }
}

#[test]
fn rational_sphere_octant_is_exact_and_has_limit_normal_at_pole() {
    let s = sphere_octant();
    for i in 0..=20 {
        for j in 0..=20 {
            let uv = DVec2::new(i as f64 / 20.0, j as f64 / 20.0);
            let e = s.eval(uv);
            assert!((e.position.length() - 1.0).abs() < 1e-6, "off the sphere at {uv}: {}", e.position);
            // The outward sphere normal is the position itself (up to orientation).
            let n = e.normal;
            assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-9);
            assert!(n.dot(e.position).abs() > 1.0 - 1e-6, "normal {n} not radial at {uv}");
        }
    }
    // The whole v = 1 boundary is the pole; the normal there is the limit normal ±z.
    let pole = s.eval(DVec2::new(0.3, 1.0));
    assert!(pole.position.distance(DVec3::Z) < 1e-12);
    assert!(pole.normal.cross(DVec3::Z).length() < 1e-9, "pole normal {}", pole.normal);
    // Orientation: consistent with the normals just inside.
    let inside = s.eval(DVec2::new(0.3, 0.999));
    assert!(pole.normal.dot(inside.normal) > 0.99);
}

#[test]
fn rational_cylinder_pieces_are_exact() {
    let file = tessera::scene::cylinder(2.0);
    let set = tessera::surface::SurfaceSet::from_patch_file(&file, Default::default());
    for patch in &set.patches {
        for i in 0..=16 {
            for j in 0..=16 {
                let uv = DVec2::new(i as f64 / 16.0, j as f64 / 16.0);
                let p = patch.eval(uv);
                assert!((p.position.truncate().length() - 1.0).abs() < 1e-6);
                assert!((p.position.z - 2.0 * uv.y).abs() < 1e-12);
                assert!(p.normal.z.abs() < 1e-9 && (p.normal.truncate().length() - 1.0).abs() < 1e-9);
                // Outward: the normal is the radial direction.
                assert!(p.normal.truncate().dot(p.position.truncate()) > 1.0 - 1e-6, "{uv}");
            }
        }
    }
    // The seams are shared: a closed tube, open only at its two rims.
    assert_eq!(set.topology.report.boundary_edges, 8);
    assert_eq!(set.topology.report.nonmanifold_edges, 0);
}

#[test]
fn flipping_reverses_the_normal_and_keeps_the_surface() {
    let s = Patch::Bicubic(sphere_octant());
    let f = s.flipped();
    for uv in [DVec2::new(0.2, 0.3), DVec2::new(0.7, 0.1), DVec2::new(0.5, 1.0)] {
        let a = s.eval(uv);
        let b = f.eval(DVec2::new(uv.y, uv.x));
        assert!(a.position.distance(b.position) < 1e-12);
        assert!(a.normal.dot(b.normal) < -0.999);
    }
    let pn = Patch::Pn(PnTriangle::new([DVec3::ZERO, DVec3::X, DVec3::Y], [DVec3::Z; 3]));
    let f = pn.flipped();
    let a = pn.eval(DVec2::new(0.2, 0.3));
    let b = f.eval(DVec2::new(0.3, 0.2));
    assert!(a.position.distance(b.position) < 1e-12 && a.normal.dot(b.normal) < -0.999);
}

/// The engine's f32 kernels on the exact rational conics: every output vertex on the sphere or
/// cylinder to f32 precision, every normal radial to 1e-5 (the sphere's pole, where the f32
/// kernels fall back, its limit normal), for a uniform grid (the grid kernels) and a
/// transition plan (the point kernels on its strips); the cylinder's tube closed but for its
/// two rims, without welding.
#[test]
fn tessellated_rational_conics_stay_exact() {
    use tessera::engine::{tessellate, EngineOptions};
    use tessera::scheme::{Criterion, PlanOptions, Scheme};
    use tessera::surface::SurfaceSet;
    let sphere = SurfaceSet::from_patches(vec![Patch::Bicubic(sphere_octant())], Default::default());
    let cylinder = SurfaceSet::from_patch_file(&tessera::scene::cylinder(2.0), Default::default());
    let cases = [(Scheme::Uniform, Criterion::Factor(9.0)), (Scheme::Transition, Criterion::Tolerance(1e-4))];
    for (scheme, criterion) in cases {
        for (name, set) in [("sphere", &sphere), ("cylinder", &cylinder)] {
            let planned = scheme.plan(set, &criterion, &PlanOptions::default()).unwrap();
            let mesh = tessellate(set, &planned.plan, &planned.pattern, EngineOptions::default()).unwrap();
            let what = format!("{name} {scheme:?} {criterion:?}");
            for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
                let (p, n) = (glam::Vec3::from(*p).as_dvec3(), glam::Vec3::from(*n).as_dvec3());
                let radial = if name == "sphere" { p } else { p.with_z(0.0) };
                assert!((radial.length() - 1.0).abs() < 1e-6, "{what}: {p} off the surface");
                assert!((n - radial.normalize()).length() < 1e-5, "{what}: normal {n} at {p}");
            }
            if name == "cylinder" {
                let w = tessera::verify::watertight(&mesh);
                assert_eq!(w.nonmanifold_edges + w.misoriented_edges, 0, "{what}");
                let rims = 2
                    * (0..4)
                        .map(|p| planned.plan.segments(set.topology.patch_edges[p][0].edge as usize))
                        .sum::<u32>();
                assert_eq!(w.boundary_edges, rims as usize, "{what}");
            }
        }
    }
}
