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
mod gregory_shared;
pub mod isolation;
pub mod loop_gregory;
pub mod loop_isolation;
pub mod loop_sdc;
mod loop_surface;
pub mod moving_bounds;
pub mod sdc;
pub mod stencils;

pub use crate::surface::patch_tree::{PatchOrigin, QUADRANTS};
/// A cage's tags and rules are input data, read with its faces into a
/// [`crate::surface::PolygonMesh`]; they live beside it and are re-exported here.
pub use crate::surface::subdivision_tags::{
    self as tags, BoundaryInterpolation, Corner, Crease, CreaseMethod, SubdivisionOptions, SubdivisionTags,
    TriangleRule, UnknownTag, INFINITELY_SHARP,
};
pub use cage::Cage;
pub use catmull_clark::CageOptions;
pub use stencils::{CageStencils, SparseRows};
