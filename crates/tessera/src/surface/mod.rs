//! Surfaces: evaluation of one patch at domain parameters.
//!
//! Two domains exist. A [`Domain::Quad`] patch is parametrised over `[0,1]²` with corners
//! `c0=(0,0)`, `c1=(1,0)`, `c2=(1,1)`, `c3=(0,1)`; a [`Domain::Tri`] patch over the triangle
//! `u,v ≥ 0, u+v ≤ 1` with corners `c0=(0,0)`, `c1=(1,0)`, `c2=(0,1)` (barycentric
//! `(1-u-v, u, v)`). In both, corners run counter-clockwise and edge `i` goes from corner `i`
//! to corner `i+1`; the front side of the patch is the side `∂S/∂u × ∂S/∂v` points to.
//!
//! Patterns never evaluate surfaces (the OpenSubdiv Bfr separation): the engine asks a
//! [`Patch`] for points at the parameters a pattern chose.

mod bezier_triangle;
mod bicubic;
mod gregory_patch;
mod gregory_triangle;
pub mod patch_tree;
mod pn_triangle;
pub(crate) mod polygon_mesh;
mod quartic_triangle;
mod set;
pub mod subdivision_tags;
pub mod triangle_tree;

/// The parameter domains live in [`crate::domain`]; re-exported here for the surfaces' users.
pub use crate::domain::Domain;
pub use bezier_triangle::BezierTriangle;
pub use bicubic::RationalBicubic;
pub use gregory_patch::GregoryPatch;
pub use gregory_triangle::GregoryTriangle;
pub use patch_tree::{PatchOrigin, PatchTree};
pub use pn_triangle::{crease_edge_point, pn_edge_points, PnTriangle};
pub use polygon_mesh::{PolygonFace, PolygonMesh};
pub use quartic_triangle::QuarticTriangle;
pub(crate) use set::corner_and_edge_points;
pub use set::{split_normal_vertices, BuildOptions, Orientation, Repairs, SurfaceSet};
pub use triangle_tree::TriangleTree;

use glam::{DVec2, DVec3};

/// A point on a surface with its unit normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub position: DVec3,
    /// Unit normal on the front side; never zero or NaN for a patch that is not collapsed to
    /// a point or a curve.
    pub normal: DVec3,
}

/// Position and first derivatives at one parameter point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceDerivatives {
    pub position: DVec3,
    pub du: DVec3,
    pub dv: DVec3,
}

/// One patch of any supported kind.
#[derive(Debug, Clone, PartialEq)]
pub enum Patch {
    /// A bicubic rational Bézier tensor-product patch over the unit square.
    Bicubic(RationalBicubic),
    /// A cubic Bézier triangle (normal from its derivatives).
    BezierTriangle(BezierTriangle),
    /// A PN triangle: cubic Bézier triangle geometry and a quadratic normal field.
    Pn(PnTriangle),
    /// The Catmull-Clark limit surface over a cage face (or a corner sub-face of a face that
    /// is not a quad) whose neighbourhood is not regular: the pieces of its feature-adaptive
    /// isolation, B-spline patches and Gregory end caps, over the unit square
    /// ([`crate::subdivision::isolation`], [`patch_tree`]).
    Subdivision(Box<PatchTree>),
    /// The Loop limit surface over a triangle of a cage: the pieces of its feature-adaptive
    /// isolation, quartic box-spline triangles and Gregory triangles, over the unit triangle
    /// ([`crate::subdivision::loop_isolation`], [`triangle_tree`]); a regular triangle is one
    /// piece.
    Loop(Box<TriangleTree>),
}

impl Patch {
    /// The patch's domain.
    pub fn domain(&self) -> Domain {
        match self {
            Patch::Bicubic(_) | Patch::Subdivision(_) => Domain::Quad,
            Patch::BezierTriangle(_) | Patch::Pn(_) | Patch::Loop(_) => Domain::Tri,
        }
    }

    /// Position and unit normal at `uv`. Cost: O(1), a few hundred flops.
    pub fn eval(&self, uv: DVec2) -> SurfacePoint {
        match self {
            Patch::Bicubic(p) => p.eval(uv),
            Patch::BezierTriangle(p) => p.eval(uv),
            Patch::Pn(p) => p.eval(uv),
            Patch::Subdivision(t) => subdivision_point(t, uv, t.derivatives(uv)),
            Patch::Loop(t) => loop_point(t, uv, t.derivatives(uv)),
        }
    }

    /// [`Patch::eval`] at each of `uvs`, handed to `each(k, point)` in order, with the same
    /// values; a subdivision patch looks its leaves up a block ahead
    /// ([`PatchTree::derivatives_each`]). Cost: as many [`Patch::eval`].
    #[inline(always)]
    pub fn eval_each(&self, uvs: &[DVec2], mut each: impl FnMut(usize, SurfacePoint)) {
        match self {
            Patch::Subdivision(t) => t.derivatives_each(uvs, |k, d| each(k, subdivision_point(t, uvs[k], d))),
            _ => uvs.iter().enumerate().for_each(|(k, &uv)| each(k, self.eval(uv))),
        }
    }

    /// Position only. Cost: O(1), cheaper than [`Patch::eval`].
    pub fn position(&self, uv: DVec2) -> DVec3 {
        match self {
            Patch::Bicubic(p) => p.position(uv),
            Patch::BezierTriangle(p) => p.position(uv),
            Patch::Pn(p) => p.geometry.position(uv),
            Patch::Subdivision(t) => t.position(uv),
            Patch::Loop(t) => t.position(uv),
        }
    }

    /// Position and first partial derivatives at `uv`.
    pub fn derivatives(&self, uv: DVec2) -> SurfaceDerivatives {
        match self {
            Patch::Bicubic(p) => p.derivatives(uv),
            Patch::BezierTriangle(p) => p.derivatives(uv),
            Patch::Pn(p) => p.geometry.derivatives(uv),
            Patch::Subdivision(t) => {
                let (position, du, dv) = t.derivatives(uv);
                SurfaceDerivatives { position, du, dv }
            }
            Patch::Loop(t) => t.derivatives(uv),
        }
    }

    /// The same surface with the opposite front side (reverses the parametrisation's
    /// orientation, so triangles emitted counter-clockwise in the domain flip too).
    pub fn flipped(&self) -> Patch {
        match self {
            Patch::Bicubic(p) => Patch::Bicubic(p.transposed()),
            Patch::BezierTriangle(p) => Patch::BezierTriangle(p.swapped_uv()),
            Patch::Pn(p) => Patch::Pn(p.flipped()),
            Patch::Subdivision(t) => Patch::Subdivision(Box::new(t.transposed())),
            Patch::Loop(t) => Patch::Loop(Box::new(t.swapped())),
        }
    }

    /// The control points (for bounding boxes and bounds); the surface lies in their convex hull.
    pub fn control_points(&self) -> &[DVec3] {
        match self {
            Patch::Bicubic(p) => &p.points,
            Patch::BezierTriangle(p) => &p.points,
            Patch::Pn(p) => &p.geometry.points,
            Patch::Subdivision(t) => t.control_points(),
            Patch::Loop(t) => t.control_points(),
        }
    }
}

/// The corners of the bounding box of `points` (corner `k` at the upper bound of x, y, z
/// where bit 0, 1, 2 of `k` is set): a hull of control points for a tree's
/// `control_points`. Cost: O(points).
pub(crate) fn box_corners<'a>(points: impl IntoIterator<Item = &'a DVec3>) -> [DVec3; 8] {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in points {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    std::array::from_fn(|k| {
        DVec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// A subdivision patch's point at `uv` from its position and derivatives there.
#[inline(always)]
pub(crate) fn subdivision_point(
    t: &PatchTree,
    uv: DVec2,
    (position, du, dv): (DVec3, DVec3, DVec3),
) -> SurfacePoint {
    let inside = DVec2::new(0.5 - uv.x, 0.5 - uv.y);
    let normal = robust_normal(
        du,
        dv,
        uv,
        inside,
        || DVec3::ZERO,
        |q| {
            let (_, du, dv) = t.derivatives(q);
            du.cross(dv)
        },
    );
    SurfacePoint { position, normal }
}

/// A Loop patch's point at `uv` from its position and derivatives `d` there
/// ([`triangle_point`]; a piecewise patch offers no single mixed derivative, so a degenerate
/// corner takes the nudged normal).
#[inline(always)]
pub(crate) fn loop_point(t: &TriangleTree, uv: DVec2, d: SurfaceDerivatives) -> SurfacePoint {
    triangle_point(d, uv, || DVec3::ZERO, |q| t.derivatives(q))
}

/// The point of a triangle patch at `uv` from its derivatives `d` there: the unit normal
/// `S_u × S_v`, or [`robust_normal`]'s limit normal where they are parallel, with `mixed` the
/// mixed derivative at `uv` and `derivatives` the patch's derivatives elsewhere. The one
/// normal rule of every triangle kind (cubic, quartic, Gregory, Loop).
#[inline]
pub(crate) fn triangle_point(
    d: SurfaceDerivatives,
    uv: DVec2,
    mixed: impl Fn() -> DVec3,
    derivatives: impl Fn(DVec2) -> SurfaceDerivatives,
) -> SurfacePoint {
    let inside = DVec2::splat(1.0 / 3.0) - uv;
    let normal = robust_normal(d.du, d.dv, uv, inside, mixed, |q| {
        let d = derivatives(q);
        d.du.cross(d.dv)
    });
    SurfacePoint { position: d.position, normal }
}

/// A unit normal from the first derivatives, falling back to the limit normal where they are
/// parallel (a boundary curve collapsed to a point, as at the teapot's lid apex).
///
/// `second` supplies the mixed derivative `S_uv` used by the limit: near a collapsed `u = u0`
/// boundary `S_v ≈ (u-u0)·S_uv`, so the normal tends to `±S_u × S_uv`, with the sign that
/// points the same way as the normals just inside the domain (and likewise for `v`).
/// `inside` gives the direction towards the domain's interior at `uv` (used for those signs
/// and for the last-resort nudge).
#[inline(always)]
pub(crate) fn robust_normal(
    du: DVec3,
    dv: DVec3,
    uv: DVec2,
    inside: DVec2,
    second: impl Fn() -> DVec3,
    nudged: impl Fn(DVec2) -> DVec3,
) -> DVec3 {
    let n = du.cross(dv);
    let scale = du.length_squared().max(dv.length_squared());
    if n.length_squared() > 1e-20 * scale * scale && n.is_finite() {
        return n.normalize();
    }
    let suv = second();
    let candidate = if dv.length_squared() <= du.length_squared() {
        // S_v vanished: a u-boundary collapsed; moving inside changes u by inside.x.
        du.cross(suv) * inside.x.signum()
    } else {
        suv.cross(dv) * inside.y.signum()
    };
    let s2 = candidate.length_squared();
    if s2 > 1e-30 && candidate.is_finite() {
        return candidate / s2.sqrt();
    }
    // Both derivatives vanish (a corner where two boundaries collapse): take the normal a
    // small step inside, which converges to the limit normal for smooth patches.
    for step in [1e-6, 1e-4, 1e-2] {
        let n = nudged(uv + inside * step);
        if n.length_squared() > 0.0 && n.is_finite() {
            return n.normalize();
        }
    }
    // The patch is collapsed to a curve or point: no normal exists. Keep the contract of
    // never returning zero; topology reports such patches.
    DVec3::Z
}
