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
use rayon::prelude::*;

use super::bspline::{regular_face_grid, to_bezier};
use super::cage::Cage;
use super::isolation::{isolate, IsolationLevels};
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
    /// How deep irregular faces are isolated (Bfr's defaults unless changed).
    pub isolation: IsolationLevels,
}

/// One face's surface before it becomes patches.
#[derive(Default)]
pub(super) enum Built {
    #[default]
    Hole,
    /// A regular face's Bézier net: the whole face's, or its four quarters' (in
    /// [`super::QUADRANTS`] order) in a cage whose faces are split into sub-faces.
    Regular(Vec<[DVec3; 16]>),
    /// The trees of a face's isolation (one per sub-face of a face that is not a quad).
    Isolated(Vec<super::isolation::PatchTree>),
}

impl Built {
    /// Face `f` of `cage` built: a hole, a regular face's net (its quarters when `split`),
    /// or the isolation of any other face. The one rule for a face's surface, shared by
    /// [`SurfaceSet::from_subdivision_cage`] and the stencils ([`super::stencils`]), which
    /// rely on it being linear in `cage.points`. Cost: O(1) for a regular face, a local
    /// refinement per level of isolation otherwise.
    pub(super) fn face(cage: &Cage, f: usize, split: bool, isolation: IsolationLevels) -> Built {
        if cage.holes[f] {
            Built::Hole
        } else if cage.face(f).len() == 4 && cage.is_regular_face(f) {
            let net = to_bezier(&regular_face_grid(cage, f));
            Built::Regular(if split { (0..4).map(|q| bezier_quadrant(&net, q)).collect() } else { vec![net] })
        } else {
            Built::Isolated(isolate(cage, f, isolation))
        }
    }

    /// Appends the face's control points to `out`: the nets' in order, or every tree's
    /// leaves' points (16 for a Bézier leaf, 20 for a Gregory one) in leaf order.
    pub(super) fn points(&self, out: &mut Vec<DVec3>) {
        match self {
            Built::Hole => {}
            Built::Regular(nets) => nets.iter().for_each(|n| out.extend_from_slice(n)),
            Built::Isolated(trees) => trees.iter().for_each(|t| t.leaf_points(out)),
        }
    }
}

/// Keys for the topology: cage vertices keep their index; every curve between two keyed
/// points gets two inner keys of its own, read in the curve's direction.
pub(super) struct Keys {
    next: u32,
    curves: HashMap<(u32, u32), u32>,
}

impl Keys {
    /// Keys after the first `points` (those of the cage's vertices and of any other keyed
    /// point).
    pub(super) fn new(points: usize) -> Keys {
        Keys { next: points as u32, curves: HashMap::new() }
    }

    pub(super) fn curve(&mut self, a: u32, b: u32) -> [u32; 4] {
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

/// The quarter `q` ([`super::QUADRANTS`]) of a polynomial bicubic Bézier net, exactly
/// (de Casteljau at ½ in `u`, then in `v`).
fn bezier_quadrant(points: &[DVec3; 16], q: usize) -> [DVec3; 16] {
    let half = |c: [DVec3; 4], upper: bool| {
        let (a, b, d) = ((c[0] + c[1]) * 0.5, (c[1] + c[2]) * 0.5, (c[2] + c[3]) * 0.5);
        let (e, f) = ((a + b) * 0.5, (b + d) * 0.5);
        let m = (e + f) * 0.5;
        if upper {
            [m, f, d, c[3]]
        } else {
            [c[0], a, e, m]
        }
    };
    let (upper_u, upper_v) = (q == 1 || q == 2, q >= 2);
    let mut out = *points;
    for j in 0..4 {
        let row = half([out[j], out[4 + j], out[8 + j], out[12 + j]], upper_u);
        for i in 0..4 {
            out[4 * i + j] = row[i];
        }
    }
    for i in 0..4 {
        let col = half([out[4 * i], out[4 * i + 1], out[4 * i + 2], out[4 * i + 3]], upper_v);
        out[4 * i..4 * i + 4].copy_from_slice(&col);
    }
    out
}

impl SurfaceSet {
    /// The Catmull-Clark limit surface of the cage `mesh` (with its OpenSubdiv tags), as
    /// OpenSubdiv's Bfr evaluates it with its default options (or the isolation depths of
    /// `options`).
    ///
    /// Patches: a cage of quads gets one per face with a limit surface, over the face's own
    /// parameters; a cage with any other face gets one per corner sub-face of every such
    /// face ([`PatchOrigin`]). [`SurfaceSet::origins`] gives each patch's face and sub-face,
    /// [`PatchOrigin::face_uv`] Bfr's face parameters of its points. A face that is regular in
    /// Bfr's sense becomes the bicubic Bézier form of its B-spline patch, exactly (its quarters
    /// exactly too); any other face the pieces of its feature-adaptive isolation
    /// ([`Patch::Subdivision`]). The faces keep their orientation unless `options` reverse
    /// them (the patches' parameters are then those of the reversed faces).
    ///
    /// The patches meet along the cage's own edges (or their halves), which the topology
    /// takes from the cage: no welding, and the engines' shared edge points make the output
    /// watertight bit for bit.
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] naming `file` and a face's line: a cage [`Cage::new`] refuses,
    /// or a cage with no face that has a limit surface.
    ///
    /// Cost: O(corners) for the adjacency, O(1) per regular face, a local refinement of a few
    /// dozen faces per level of isolation for every other face.
    pub fn from_subdivision_cage(
        mesh: &PolygonMesh,
        file: &Path,
        options: CageOptions,
    ) -> Result<SurfaceSet> {
        let (cage, repairs) = oriented_cage(mesh, file, options)?;
        let split = is_split(&cage);
        // Each face's surface on its own (in parallel: isolation is most of the work).
        let built: Vec<Built> = (0..cage.face_count())
            .into_par_iter()
            .map(|f| Built::face(&cage, f, split, options.isolation))
            .collect();
        assemble(&cage, built, repairs, file)
    }
}

/// The cage of `mesh` with the faces oriented as `options` ask (reported in the repairs).
/// Errors as [`Cage::new`]. Cost: O(corners).
pub(super) fn oriented_cage(
    mesh: &PolygonMesh,
    file: &Path,
    options: CageOptions,
) -> Result<(Cage, Repairs)> {
    let mut repairs = Repairs::default();
    let reverse = (options.orientation == Orientation::Outward && signed_volume(mesh) < 0.0) != options.flip;
    if !reverse {
        return Ok((Cage::new(mesh, file)?, repairs));
    }
    repairs.flipped = true;
    let mut m = mesh.clone();
    for f in &mut m.faces {
        f.positions[1..].reverse();
    }
    Ok((Cage::new(&m, file)?, repairs))
}

/// Whether the cage's faces become corner sub-faces (any face is not a quad): then every
/// face, quads too, is split so that neighbours' edges halve alike.
pub(super) fn is_split(cage: &Cage) -> bool {
    (0..cage.face_count()).any(|f| cage.face(f).len() != 4)
}

/// The set of `cage`'s faces, `built` by [`Built::face`]: the patches and their keys in face
/// order. Errors: [`Error::Unsupported`] when every face is a hole. Cost: O(P).
pub(super) fn assemble(
    cage: &Cage,
    mut built: Vec<Built>,
    repairs: Repairs,
    file: &Path,
) -> Result<SurfaceSet> {
    let split = is_split(cage);
    let (vertices, edges) = (cage.points.len() as u32, cage.edge_count() as u32);
    let mid = |e: u32| vertices + e;
    let centre = |f: usize| vertices + edges + f as u32;
    let mut keys = Keys::new(vertices as usize + edges as usize + cage.face_count());
    let mut patches = Vec::new();
    let mut patch_keys = Vec::new();
    let mut origins = Vec::new();
    let mut push = |patch: Patch, corners: [u32; 4], origin: PatchOrigin| {
        let mut k = PatchKeys { domain: Domain::Quad, corners, edges: [[0; 4]; 4], normals: [0; 4] };
        for i in 0..4 {
            k.edges[i] = keys.curve(corners[i], corners[(i + 1) % 4]);
        }
        patches.push(patch);
        patch_keys.push(k);
        origins.push(origin);
    };
    for (f, face) in built.iter_mut().enumerate() {
        let c = cage.face(f);
        let n = c.len();
        let e = cage.face_edges(f);
        let origin = |subface: usize| PatchOrigin {
            face: f as u32,
            subface: subface as u16,
            corners: n as u16,
            is_subface: split,
            rotation: 0,
        };
        // A quad's quarters, corners listed from the one at the quarter's (0,0).
        let quarter = |q: usize| match q {
            0 => [c[0], mid(e[0]), centre(f), mid(e[3])],
            1 => [mid(e[0]), c[1], mid(e[1]), centre(f)],
            2 => [centre(f), mid(e[1]), c[2], mid(e[2])],
            _ => [mid(e[3]), centre(f), mid(e[2]), c[3]],
        };
        let trees = match std::mem::take(face) {
            Built::Regular(nets) => {
                for (q, net) in nets.into_iter().enumerate() {
                    let corners = if split { quarter(q) } else { [c[0], c[1], c[2], c[3]] };
                    push(Patch::Bicubic(RationalBicubic::polynomial(net)), corners, origin(q));
                }
                continue;
            }
            Built::Isolated(trees) => trees,
            Built::Hole => continue,
        };
        if n == 4 && split {
            for q in 0..4 {
                push(Patch::Subdivision(Box::new(trees[0].quadrant(q))), quarter(q), origin(q));
            }
        } else if n == 4 {
            push(Patch::Subdivision(Box::new(trees[0].clone())), [c[0], c[1], c[2], c[3]], origin(0));
        } else {
            for (i, tree) in trees.into_iter().enumerate() {
                let corners = [c[i], mid(e[i]), centre(f), mid(e[(i + n - 1) % n])];
                push(Patch::Subdivision(Box::new(tree)), corners, origin(i));
            }
        }
    }
    if patches.is_empty() {
        return Err(Error::unsupported(file, 0, "no face of the cage has a limit surface (all are holes)"));
    }
    turn_corners_off_valence_two(cage, &mut patches, &mut patch_keys, &mut origins);
    let topology = Topology::build(&patch_keys);
    Ok(SurfaceSet { patches, keys: patch_keys, topology, repairs, up: Default::default(), origins })
}

/// At an interior vertex of valence 2 its two faces share both edges there, and a pattern
/// that cuts the corner's cell along the chord between the first samples of those edges (the
/// uniform grid does at corners 1 and 3) gives both faces the same triangle — covered twice.
/// Every pattern is corrected for that where it happens (`pattern::cut_pinched_corners`, by
/// flips); such a patch is also turned a quarter (its parameters, not its surface) so that the
/// vertex is at corner 0 or 2, where the uniform grid already cuts the cells through the
/// corner and needs no flip.
fn turn_corners_off_valence_two(
    cage: &Cage,
    patches: &mut [Patch],
    keys: &mut [PatchKeys],
    origins: &mut [PatchOrigin],
) {
    let valence_two: std::collections::HashSet<u32> = (0..cage.points.len())
        .filter(|&v| cage.vertex_faces(v).len() == 2 && !cage.is_boundary_vertex(v))
        .map(|v| v as u32)
        .collect();
    if valence_two.is_empty() {
        return;
    }
    for p in 0..patches.len() {
        let c = keys[p].corners;
        let at = |i: usize| valence_two.contains(&c[i]);
        if !(at(1) || at(3)) || at(0) || at(2) {
            continue;
        }
        // Faces at such a vertex are never regular: they are isolated patch trees.
        let Patch::Subdivision(tree) = &patches[p] else { continue };
        patches[p] = Patch::Subdivision(Box::new(tree.rotated(1)));
        let k = &mut keys[p];
        k.corners = [c[1], c[2], c[3], c[0]];
        k.edges = [k.edges[1], k.edges[2], k.edges[3], k.edges[0]];
        origins[p].rotation = 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    #[test]
    fn quarters_of_a_bezier_net_are_the_same_surface() {
        let mut rng = crate::test_support::Lcg(3);
        let net: [DVec3; 16] = std::array::from_fn(|_| DVec3::new(rng.unit53(), rng.unit53(), rng.unit53()));
        let whole = RationalBicubic::polynomial(net);
        for q in 0..4 {
            let part = RationalBicubic::polynomial(bezier_quadrant(&net, q));
            for k in 0..20 {
                let st = DVec2::new(rng.unit53(), rng.unit53());
                let d = part.position(st) - whole.position(super::super::QUADRANTS[q] + st * 0.5);
                assert!(d.length() < 1e-14, "quarter {q} sample {k}: {d}");
            }
        }
    }
}
