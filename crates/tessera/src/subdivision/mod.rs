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

/// The quarters of a quad's parameter square, by their lower-left corner: the children at
/// corners 0, 1, 2, 3.
pub const QUADRANTS: [glam::DVec2; 4] = [
    glam::DVec2::new(0.0, 0.0),
    glam::DVec2::new(0.5, 0.0),
    glam::DVec2::new(0.5, 0.5),
    glam::DVec2::new(0.0, 0.5),
];

/// Where a patch of a set built from a cage comes from
/// ([`crate::surface::SurfaceSet::origins`]).
///
/// A cage of quads gets one patch per face, over the face's own parameters. A cage with any
/// other face gets one patch per corner *sub-face* of every face (the faces of one level of
/// subdivision), because a face that is not a quad is parameterised by its sub-faces
/// (OpenSubdiv's `QUAD_SUBFACES`) and its neighbours must then meet it edge for edge; a
/// quad's sub-faces are the quarters of its square.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PatchOrigin {
    /// The cage face (0-based, file order).
    pub face: u32,
    /// The corner sub-face (0 for a whole quad).
    pub subface: u16,
    /// The face's corner count.
    pub corners: u16,
    /// Whether the patch is a sub-face (else the whole quad).
    pub is_subface: bool,
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

    /// Bfr's face parameters of the point `st` ∈ `[0,1]²` of this patch: a whole quad's
    /// are its own; a quad's quarter `q` covers [`QUADRANTS`]`[q]` + `[0,½]²`, `u` and `v`
    /// as the face's; another face's sub-face `i` covers the half-size square at its tile's
    /// origin, `s` along edge `i`, `t` back along edge `i−1`.
    pub fn face_uv(&self, st: glam::DVec2) -> glam::DVec2 {
        let i = self.subface as usize;
        if !self.is_subface {
            st
        } else if self.corners == 4 {
            QUADRANTS[i] + st * 0.5
        } else {
            let d = Self::tiles_per_row(self.corners as usize);
            glam::DVec2::new((i % d) as f64, (i / d) as f64) + st * 0.5
        }
    }

    /// Which patch of face `face` (`corners` corners, split into sub-faces or not) holds
    /// Bfr's face parameters `uv`, and where in its `[0,1]²` (the inverse of
    /// [`PatchOrigin::face_uv`]; a point on a border between sub-faces goes to the upper or
    /// right one).
    pub fn from_face_uv(
        face: u32,
        corners: usize,
        is_subface: bool,
        uv: glam::DVec2,
    ) -> (PatchOrigin, glam::DVec2) {
        let at = |subface: usize| PatchOrigin {
            face,
            subface: subface as u16,
            corners: corners as u16,
            is_subface,
        };
        if !is_subface {
            return (at(0), uv);
        }
        if corners == 4 {
            let q = match (uv.x >= 0.5, uv.y >= 0.5) {
                (false, false) => 0,
                (true, false) => 1,
                (true, true) => 2,
                (false, true) => 3,
            };
            return (at(q), (uv - QUADRANTS[q]) * 2.0);
        }
        let d = Self::tiles_per_row(corners);
        let (tx, ty) = (uv.x.floor().max(0.0) as usize, uv.y.floor().max(0.0) as usize);
        let subface = (tx + d * ty).min(corners - 1);
        let origin = glam::DVec2::new((subface % d) as f64, (subface / d) as f64);
        (at(subface), (uv - origin) * 2.0)
    }
}

/// Sharpness at or above this is infinitely sharp (OpenSubdiv's `SHARPNESS_INFINITE`).
pub const INFINITELY_SHARP: f32 = 10.0;
