//! PN triangles (Vlachos, Peters, Boyd, Mitchell 2001; paper 001 section 2): cubic Bézier
//! geometry built from a triangle's corner positions and normals, plus a quadratic normal field.

use super::{BezierTriangle, SurfacePoint};
use glam::{DVec2, DVec3};

/// A PN triangle. Build it with [`PnTriangle::new`] (the paper's construction) or
/// [`PnTriangle::from_edge_points`] when the edge control points were agreed with the
/// neighbours (creases, see `build::pn`).
#[derive(Debug, Clone, PartialEq)]
pub struct PnTriangle {
    /// The cubic geometry.
    pub geometry: BezierTriangle,
    /// Quadratic normal coefficients `n200, n020, n002, n110, n011, n101`; the normal is
    /// `normalize(n200 λ0² + n020 λ1² + n002 λ2² + n110 λ0λ1 + n011 λ1λ2 + n101 λ0λ2)`.
    pub normals: [DVec3; 6],
}

/// The two inner control points of the PN edge from `p0` to `p1`: each corner's neighbour is
/// the point a third of the way along the edge, projected into that corner's tangent plane.
pub fn pn_edge_points(p0: DVec3, n0: DVec3, p1: DVec3, n1: DVec3) -> [DVec3; 2] {
    let w01 = (p1 - p0).dot(n0);
    let w10 = (p0 - p1).dot(n1);
    [(2.0 * p0 + p1 - w01 * n0) / 3.0, (2.0 * p1 + p0 - w10 * n1) / 3.0]
}

/// The inner control point next to `p0` on an edge that is a crease at `p0`: the point a third
/// of the way along the crease tangent `t` (the unit vector along `nA × nB`), so both faces of
/// the crease get the same boundary curve.
pub fn crease_edge_point(p0: DVec3, p1: DVec3, t: DVec3) -> DVec3 {
    p0 + t * ((p1 - p0).dot(t) / 3.0)
}

fn mid_normal(p0: DVec3, n0: DVec3, p1: DVec3, n1: DVec3) -> DVec3 {
    let d = p1 - p0;
    let len2 = d.length_squared();
    let v = if len2 > 0.0 { 2.0 * d.dot(n0 + n1) / len2 } else { 0.0 };
    (n0 + n1 - v * d).try_normalize().unwrap_or(n0)
}

impl PnTriangle {
    /// The paper's construction from corner positions and unit normals.
    pub fn new(p: [DVec3; 3], n: [DVec3; 3]) -> Self {
        let e = [0, 1, 2].map(|i| pn_edge_points(p[i], n[i], p[(i + 1) % 3], n[(i + 1) % 3]));
        Self::from_edge_points(p, n, e)
    }

    /// Construction from corner positions, unit corner normals and the inner control points of
    /// each edge `e` (from corner `e` to corner `e+1`). The centre point follows the paper:
    /// `b111 = E + (E − V)/2`, `E` the mean of the six edge points, `V` of the corners.
    pub fn from_edge_points(p: [DVec3; 3], n: [DVec3; 3], e: [[DVec3; 2]; 3]) -> Self {
        use BezierTriangle as B;
        let mut pts = [DVec3::ZERO; 10];
        pts[B::index(3, 0, 0)] = p[0];
        pts[B::index(0, 3, 0)] = p[1];
        pts[B::index(0, 0, 3)] = p[2];
        // Edge 0: c0 → c1 (λ0 → λ1); edge 1: c1 → c2; edge 2: c2 → c0.
        pts[B::index(2, 1, 0)] = e[0][0];
        pts[B::index(1, 2, 0)] = e[0][1];
        pts[B::index(0, 2, 1)] = e[1][0];
        pts[B::index(0, 1, 2)] = e[1][1];
        pts[B::index(1, 0, 2)] = e[2][0];
        pts[B::index(2, 0, 1)] = e[2][1];
        let edge_mean = (e[0][0] + e[0][1] + e[1][0] + e[1][1] + e[2][0] + e[2][1]) / 6.0;
        let corner_mean = (p[0] + p[1] + p[2]) / 3.0;
        pts[B::index(1, 1, 1)] = edge_mean + (edge_mean - corner_mean) / 2.0;
        let normals = [
            n[0],
            n[1],
            n[2],
            mid_normal(p[0], n[0], p[1], n[1]),
            mid_normal(p[1], n[1], p[2], n[2]),
            mid_normal(p[2], n[2], p[0], n[0]),
        ];
        PnTriangle { geometry: BezierTriangle { points: pts }, normals }
    }

    /// The interpolated (quadratic) normal at `uv`, normalised.
    pub fn shading_normal(&self, uv: DVec2) -> Option<DVec3> {
        let l = [1.0 - uv.x - uv.y, uv.x, uv.y];
        let [n200, n020, n002, n110, n011, n101] = self.normals;
        let n = n200 * (l[0] * l[0])
            + n020 * (l[1] * l[1])
            + n002 * (l[2] * l[2])
            + n110 * (l[0] * l[1])
            + n011 * (l[1] * l[2])
            + n101 * (l[0] * l[2]);
        n.try_normalize()
    }

    /// Position (cubic) and normal (quadratic field; the geometric normal where that field
    /// vanishes, which only opposite corner normals can cause).
    pub fn eval(&self, uv: DVec2) -> SurfacePoint {
        match self.shading_normal(uv) {
            Some(normal) => SurfacePoint { position: self.geometry.position(uv), normal },
            None => self.geometry.eval(uv),
        }
    }

    /// [`PnTriangle::eval`] at corner `c` (0, 1, 2 at `uv` = (0,0), (1,0), (0,1)) without the
    /// sums: the corner's control point and its normalised normal coefficient, which is what
    /// the sums give there. Cost: one normalisation.
    pub fn corner(&self, c: usize) -> SurfacePoint {
        let (point, normal) = match c {
            0 => (self.geometry.b(3, 0, 0), self.normals[0]),
            1 => (self.geometry.b(0, 3, 0), self.normals[1]),
            _ => (self.geometry.b(0, 0, 3), self.normals[2]),
        };
        match normal.try_normalize() {
            Some(normal) => SurfacePoint { position: point, normal },
            None => self.eval(super::Domain::Tri.corner(c)),
        }
    }

    /// The same patch with corners 1 and 2 exchanged (opposite orientation).
    pub fn swapped_uv(&self) -> Self {
        let [n200, n020, n002, n110, n011, n101] = self.normals;
        PnTriangle { geometry: self.geometry.swapped_uv(), normals: [n200, n002, n020, n101, n011, n110] }
    }

    /// The opposite front side: corners 1 and 2 exchanged and every normal negated.
    pub fn flipped(&self) -> Self {
        let mut out = self.swapped_uv();
        out.normals = out.normals.map(|n| -n);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_are_the_evaluation_at_the_corners() {
        let p = [DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, 2.5, 3.0), DVec3::new(1.5, 6.0, 2.0)];
        let n = [DVec3::new(0.1, 0.2, 1.0), DVec3::new(-0.3, 0.1, 1.0), DVec3::new(0.0, -0.4, 1.0)];
        let t = PnTriangle::new(p, n.map(|n| n.normalize()));
        for (c, &corner) in p.iter().enumerate() {
            let uv = crate::domain::Domain::Tri.corner(c);
            assert_eq!(t.corner(c), t.eval(uv), "corner {c}");
            assert_eq!(t.corner(c).position, corner);
        }
    }
}
