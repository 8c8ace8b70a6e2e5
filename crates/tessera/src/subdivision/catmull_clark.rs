//! Catmull-Clark limit surfaces of a cage as a [`SurfaceSet`]: one patch per face (one per
//! corner sub-face of a face that is not a quad), tied together by the cage's own edges.
//!
//! The patches' shared edges come from the cage's topology, not from welding control
//! points: the two faces of a cage edge name the same edge key, so the engines sample and
//! evaluate it once and both faces read the same points — watertight bit for bit however the
//! two faces' patches were computed.

use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;

use super::bspline::{regular_face_grid, to_bezier};
use super::cage::Cage;
use super::PatchOrigin;
use crate::error::{Error, Result};
use crate::surface::{Domain, Orientation, Patch, PolygonMesh, RationalBicubic, Repairs, SurfaceSet};
use crate::topology::{PatchKeys, Topology};

/// How a cage becomes a [`SurfaceSet`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CageOptions {
    /// `Outward` reverses every face of a cage whose faces enclose a negative volume
    /// (as seen from its bounding box's centre); `AsGiven` keeps OpenSubdiv's orientation,
    /// so patch parameters are Bfr's.
    pub orientation: Orientation,
    /// Reverse the faces after `orientation` was applied (`--flip-normals`).
    pub flip: bool,
}

/// Keys for the topology: cage vertices keep their index; every curve between two keyed
/// points gets two inner keys of its own, read in the curve's direction.
struct Keys {
    next: u32,
    curves: HashMap<(u32, u32), u32>,
}

impl Keys {
    fn new(points: usize) -> Keys {
        Keys { next: points as u32, curves: HashMap::new() }
    }

    fn curve(&mut self, a: u32, b: u32) -> [u32; 4] {
        let next = &mut self.next;
        let inner = *self.curves.entry((a.min(b), a.max(b))).or_insert_with(|| {
            *next += 2;
            *next - 2
        });
        if a < b {
            [a, inner, inner + 1, b]
        } else {
            [a, inner + 1, inner, b]
        }
    }
}

/// Signed volume of the cage's faces (fans) relative to the centre of their bounding box.
fn signed_volume(mesh: &PolygonMesh) -> f64 {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in &mesh.positions {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let centre = (lo + hi) * 0.5;
    let at = |i: u32| mesh.positions[i as usize] - centre;
    let mut volume = 0.0;
    for face in &mesh.faces {
        let c = &face.positions;
        for k in 1..c.len() - 1 {
            volume += at(c[0]).dot(at(c[k]).cross(at(c[k + 1])));
        }
    }
    volume / 6.0
}

impl SurfaceSet {
    /// The Catmull-Clark limit surface of the cage `mesh` (with its OpenSubdiv tags), as
    /// OpenSubdiv's Bfr evaluates it with its default options.
    ///
    /// Each face with a limit surface becomes one patch (faces that are not quads: one patch
    /// per corner sub-face, in corner order); [`SurfaceSet::origins`] gives each patch's base
    /// face and sub-face. A face that is regular in Bfr's sense becomes the bicubic Bézier
    /// form of its B-spline patch, exactly. Patch parameters are Bfr's face parameters when
    /// the faces keep their orientation.
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] naming `file` and a face's line: a cage [`Cage::new`] refuses,
    /// a face that is not regular (feature-adaptive isolation comes next), or a cage with no
    /// face that has a limit surface.
    ///
    /// Cost: O(corners) to build the adjacency, O(1) per regular face.
    pub fn from_subdivision_cage(
        mesh: &PolygonMesh,
        file: &Path,
        options: CageOptions,
    ) -> Result<SurfaceSet> {
        let mut repairs = Repairs::default();
        let reverse =
            (options.orientation == Orientation::Outward && signed_volume(mesh) < 0.0) != options.flip;
        let reversed;
        let mesh = if reverse {
            repairs.flipped = true;
            let mut m = mesh.clone();
            for f in &mut m.faces {
                f.positions[1..].reverse();
            }
            reversed = m;
            &reversed
        } else {
            mesh
        };
        let cage = Cage::new(mesh, file)?;
        let mut keys = Keys::new(cage.points.len());
        let mut patches = Vec::new();
        let mut patch_keys = Vec::new();
        let mut origins = Vec::new();
        for f in 0..cage.face_count() {
            if cage.holes[f] {
                continue;
            }
            if !cage.is_regular_face(f) {
                return Err(Error::unsupported(
                    file,
                    cage.face_line(f),
                    "face is not a regular Catmull-Clark patch (an extraordinary vertex, a crease, a \
                     non-quad or a smooth boundary corner touches it); tessera evaluates regular faces only so far",
                ));
            }
            let corners = cage.face(f);
            let bezier = to_bezier(&regular_face_grid(&cage, f));
            patches.push(Patch::Bicubic(RationalBicubic::polynomial(bezier)));
            let mut k =
                PatchKeys { domain: Domain::Quad, corners: [0; 4], edges: [[0; 4]; 4], normals: [0; 4] };
            for i in 0..4 {
                k.corners[i] = corners[i];
                k.edges[i] = keys.curve(corners[i], corners[(i + 1) % 4]);
            }
            patch_keys.push(k);
            origins.push(PatchOrigin { face: f as u32, subface: 0 });
        }
        if patches.is_empty() {
            return Err(Error::unsupported(
                file,
                0,
                "no face of the cage has a limit surface (all are holes)",
            ));
        }
        let topology = Topology::build(&patch_keys);
        Ok(SurfaceSet { patches, keys: patch_keys, topology, repairs, up: Default::default(), origins })
    }
}
