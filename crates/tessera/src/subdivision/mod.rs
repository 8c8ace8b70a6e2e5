//! Subdivision cages: the control meshes of Catmull-Clark and Loop surfaces, with the
//! sharpness and boundary tags that shape their limit surfaces, in OpenSubdiv's terms (Sdc).
//!
//! This module holds what a cage *says* — [`SubdivisionTags`]: semi-sharp and infinitely
//! sharp creases, corners, holes, the boundary interpolation, the crease method and
//! Catmull-Clark's triangle rule — as [`crate::io::obj`] reads it from OpenSubdiv's OBJ dialect
//! (`t NAME nint/nfloat/nstring ints floats strings`, vertex and face indices 0-based). Limit
//! surface evaluation builds on it.
//!
//! Defaults are those OpenSubdiv's own regression tools apply to a cage whose file does not
//! say ([`SubdivisionOptions::default`]); the shared `subdivision/` cages are those tools'
//! shapes, so their limit surfaces are defined by them.

pub mod bspline;
pub mod cage;
mod catmull_clark;
pub mod gregory;
pub mod isolation;
pub mod sdc;
pub mod tags;

pub use cage::Cage;
pub use catmull_clark::CageOptions;
pub use tags::{Corner, Crease, SubdivisionTags, UnknownTag};

/// Where a patch of a set built from a cage comes from
/// ([`crate::surface::SurfaceSet::origins`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PatchOrigin {
    /// The cage face (0-based, file order).
    pub face: u32,
    /// The corner sub-face of a face that is not a quad (OpenSubdiv's `QUAD_SUBFACES`
    /// parameterisation: sub-face `i` is the quad at corner `i`); 0 for a quad.
    pub subface: u16,
}

/// How the limit surface meets the cage's boundary (OpenSubdiv's `VtxBoundaryInterpolation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BoundaryInterpolation {
    /// No limit surface on faces at the boundary (tag value 0).
    None,
    /// Boundary edges are infinitely sharp; boundary vertices of one face stay smooth
    /// (tag value 2, and the default when a cage says nothing).
    #[default]
    EdgeOnly,
    /// Boundary edges are infinitely sharp and boundary vertices of one face are corners
    /// (tag value 1).
    EdgeAndCorner,
}

/// How semi-sharp creases lose sharpness from level to level (`Sdc::Options::CreasingMethod`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CreaseMethod {
    /// Sharpness drops by one a level (`normal`, the default).
    #[default]
    Uniform,
    /// Chaikin's rule: a crease's sharpness averages with its neighbours' (`chaikin`).
    Chaikin,
}

/// Catmull-Clark's rule for the face points of triangles (`Sdc::Options::TriangleSubdivision`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TriangleRule {
    /// Catmull-Clark's own rule (`catmark`, the default).
    #[default]
    Catmark,
    /// The smoother weights for triangles (`smooth`).
    Smooth,
}

/// The rules of a cage's limit surface that are not per edge or vertex.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SubdivisionOptions {
    /// The boundary rule (`t interpolateboundary`).
    pub boundary: BoundaryInterpolation,
    /// The crease method (`t creasemethod`).
    pub crease_method: CreaseMethod,
    /// Catmull-Clark's triangle rule (`t smoothtriangles`).
    pub triangles: TriangleRule,
}

impl PatchOrigin {
    /// How many sub-face tiles a row of a `corners`-sided face's parameter domain holds in
    /// Bfr's `QUAD_SUBFACES` parameterisation (`bfr/parameterization.cpp`): sub-face `i`'s
    /// tile has its origin at `(i mod D, i div D)`.
    pub fn tiles_per_row(corners: usize) -> usize {
        match corners {
            0..=4 => 2,
            5..=9 => 3,
            k => 1 + ((k - 1) as f64).sqrt().floor() as usize,
        }
    }

    /// Bfr's face parameters of the point `st` ∈ `[0,1]²` of this patch, for a face of
    /// `corners` corners (a quad's patch is its face; another face's sub-face `i` covers the
    /// half-size square at its tile's origin, `s` along edge `i`, `t` back along edge `i−1`).
    pub fn face_uv(&self, corners: usize, st: glam::DVec2) -> glam::DVec2 {
        if corners == 4 {
            return st;
        }
        let d = Self::tiles_per_row(corners);
        let i = self.subface as usize;
        glam::DVec2::new((i % d) as f64, (i / d) as f64) + st * 0.5
    }

    /// Which sub-face of a `corners`-sided face holds Bfr's face parameters `uv`, and where
    /// in its `[0,1]²` (the inverse of [`PatchOrigin::face_uv`]).
    pub fn from_face_uv(face: u32, corners: usize, uv: glam::DVec2) -> (PatchOrigin, glam::DVec2) {
        if corners == 4 {
            return (PatchOrigin { face, subface: 0 }, uv);
        }
        let d = Self::tiles_per_row(corners);
        let (tx, ty) = (uv.x.floor().max(0.0) as usize, uv.y.floor().max(0.0) as usize);
        let subface = (tx + d * ty).min(corners - 1);
        let origin = glam::DVec2::new((subface % d) as f64, (subface / d) as f64);
        (PatchOrigin { face, subface: subface as u16 }, (uv - origin) * 2.0)
    }
}

/// Sharpness at or above this is infinitely sharp (OpenSubdiv's `SHARPNESS_INFINITE`).
pub const INFINITELY_SHARP: f32 = 10.0;
