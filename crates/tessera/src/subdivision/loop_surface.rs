//! Loop limit surfaces of a triangle cage as a [`SurfaceSet`]: one patch per triangle with a
//! limit surface, tied together by the cage's own edges, as [`super::catmull_clark`] does for
//! Catmull-Clark (the same orientation rule, the same edge keys, so the engines sample and
//! evaluate every cage edge once and both of its triangles read the same points).

use std::path::Path;

use rayon::prelude::*;

use super::cage::Cage;
use super::catmull_clark::{oriented_cage, CageOptions, Keys};
use super::isolation::IsolationLevels;
use super::loop_isolation::isolate_triangle;
use super::PatchOrigin;
use crate::error::{Error, Result};
use crate::surface::triangle_tree::TriangleTree;
use crate::surface::{Domain, Patch, PolygonMesh, SurfaceSet};
use crate::topology::{PatchKeys, Topology, NONE};

impl SurfaceSet {
    /// The Loop limit surface of the triangle cage `mesh` (with its OpenSubdiv tags), as
    /// OpenSubdiv's Bfr evaluates it with its default options (or the isolation depths of
    /// `options`): one patch per triangle with a limit surface, over the triangle's own
    /// parameters (Bfr's: `u` from corner 0 to corner 1, `v` from corner 0 to corner 2), the
    /// pieces of its feature-adaptive isolation ([`Patch::Loop`]). [`SurfaceSet::origins`]
    /// gives each patch's face. The faces keep their orientation unless `options` reverse
    /// them.
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] naming `file` and a face's line: a face that is not a triangle
    /// (Loop subdivides triangles only), a cage [`Cage::new`] refuses, or a cage with no face
    /// that has a limit surface.
    ///
    /// Cost: O(corners) for the adjacency and a local refinement of a few dozen triangles
    /// per level of isolation for every face (none for a regular one).
    pub fn from_loop_cage(mesh: &PolygonMesh, file: &Path, options: CageOptions) -> Result<SurfaceSet> {
        let (cage, repairs) = oriented_loop_cage(mesh, file, options)?;
        let trees: Vec<Option<TriangleTree>> =
            (0..cage.face_count()).into_par_iter().map(|f| loop_face(&cage, f, options.isolation)).collect();
        assemble(&cage, trees, repairs, file)
    }
}

/// The Loop cage of `mesh`, its faces oriented as `options` ask (as
/// [`super::catmull_clark`]'s `oriented_cage`). Errors as [`SurfaceSet::from_loop_cage`]
/// (before the last: a face that is not a triangle, a cage [`Cage::new`] refuses). Cost:
/// O(corners).
pub(super) fn oriented_loop_cage(
    mesh: &PolygonMesh,
    file: &Path,
    options: CageOptions,
) -> Result<(Cage, crate::surface::Repairs)> {
    if let Some(face) = mesh.faces.iter().find(|f| f.positions.len() != 3) {
        return Err(Error::unsupported(
            file,
            face.line,
            format!(
                "face has {} corners; Loop subdivision needs triangles (use --surface catmull-clark for this cage)",
                face.positions.len()
            ),
        ));
    }
    oriented_cage(mesh, file, options)
}

/// Triangle `f` of `cage` built: its tree, or None for a hole. The one rule for a Loop
/// face's surface, shared by [`SurfaceSet::from_loop_cage`] and the stencils
/// ([`super::stencils`]), which rely on it being linear in `cage.points`. Cost: that of
/// [`isolate_triangle`].
pub(super) fn loop_face(cage: &Cage, f: usize, isolation: IsolationLevels) -> Option<TriangleTree> {
    (!cage.holes[f]).then(|| isolate_triangle(cage, f, isolation))
}

/// The set of `cage`'s triangles in face order. Errors: [`Error::Unsupported`] when every
/// face is a hole. Cost: O(P).
pub(super) fn assemble(
    cage: &Cage,
    trees: Vec<Option<TriangleTree>>,
    repairs: crate::surface::Repairs,
    file: &Path,
) -> Result<SurfaceSet> {
    let mut keys = Keys::new(cage.points.len());
    let (mut patches, mut patch_keys, mut origins) = (Vec::new(), Vec::new(), Vec::new());
    for (f, tree) in trees.into_iter().enumerate() {
        let Some(tree) = tree else { continue };
        let c = cage.face(f);
        let mut k = PatchKeys {
            domain: Domain::Tri,
            corners: [c[0], c[1], c[2], NONE],
            edges: [[NONE; 4]; 4],
            normals: [0; 4],
        };
        for i in 0..3 {
            k.edges[i] = keys.curve(c[i], c[(i + 1) % 3]);
        }
        patches.push(Patch::Loop(Box::new(tree)));
        patch_keys.push(k);
        origins.push(PatchOrigin { face: f as u32, subface: 0, corners: 3, is_subface: false, rotation: 0 });
    }
    if patches.is_empty() {
        return Err(Error::unsupported(file, 0, "no face of the cage has a limit surface (all are holes)"));
    }
    let topology = Topology::build(&patch_keys);
    Ok(SurfaceSet { patches, keys: patch_keys, topology, repairs, up: Default::default(), origins })
}
