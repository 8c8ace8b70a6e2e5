//! Stencils of a subdivision cage, Catmull-Clark or Loop: every control point of its patches
//! as a fixed linear combination of the cage's vertices, so that an animated cage (same faces
//! and tags, moving vertices) gets its patches back by a sparse matrix product instead of a
//! rebuild.
//!
//! For fixed topology and tags, the surface a face builds is linear in the cage's points:
//! Catmull-Clark's (`Built::face`: a regular face's Bézier net, or the leaves of its isolation
//! with their Gregory end caps) and Loop's (`loop_face`: the quartic and Gregory triangle
//! leaves of a triangle's tree) alike. Subdivision, the change to Bézier form and the end
//! caps are fixed weighted sums, and no choice depends on a position (the faces' orientation
//! is decided once, when the stencils are made, as the set's builder decides it). So the
//! weights are *probed*, not derived a second time: the face is built, by the scheme's own
//! rule, from a cage whose points are zero except a unit coordinate on up to three of its
//! neighbourhood's vertices (x on one, y on the next, z on the third), and each output
//! coordinate is then that vertex's weight. There is no second copy of any subdivision rule,
//! and the weights are the rules' own; the probing, the rows and their application are one
//! for both schemes, which differ only in the face rule and in the shape the points are
//! poured back into.
//!
//! What a face reads is its neighbourhood: the vertices of the faces around its corners (the
//! local mesh [`super::isolation`] and [`super::loop_isolation`] refine). Probing costs about
//! a third of the neighbourhood's size in face builds per face, once per topology.

use std::path::Path;

use glam::DVec3;
use rayon::prelude::*;

use super::cage::Cage;
use super::catmull_clark::{assemble, is_split, oriented_cage, Built};
use super::isolation::PatchTree;
use super::loop_surface::{assemble as loop_assemble, loop_face, oriented_loop_cage};
use super::CageOptions;
use crate::error::{Error, Result};
use crate::surface::triangle_tree::TriangleTree;
use crate::surface::{Patch, PatchOrigin, PolygonMesh, RationalBicubic, SurfaceSet};

/// Sparse rows: row `r`'s terms are `vertices[k]` with `weights[k]` for `k` in
/// `starts[r]..starts[r + 1]`; `starts` has one more entry than there are rows.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SparseRows {
    /// Each row's first term, then the end of the last row.
    pub starts: Vec<u32>,
    /// Each term's cage vertex (0-based, the cage file's order).
    pub vertices: Vec<u32>,
    /// Each term's weight.
    pub weights: Vec<f64>,
}

impl SparseRows {
    /// How many rows.
    pub fn len(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    /// Whether there is no row.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Row `r` applied to `points`: `Σ weights[k] · points[vertices[k]]`. Precondition: every
    /// vertex of the row indexes `points`. Cost: the row's length.
    pub fn apply_row(&self, r: usize, points: &[DVec3]) -> DVec3 {
        let range = self.starts[r] as usize..self.starts[r + 1] as usize;
        self.vertices[range.clone()]
            .iter()
            .zip(&self.weights[range])
            .fold(DVec3::ZERO, |sum, (&v, &w)| sum + points[v as usize] * w)
    }

    fn push_row(&mut self, terms: &[(u32, f64)]) {
        if self.starts.is_empty() {
            self.starts.push(0);
        }
        for &(v, w) in terms {
            self.vertices.push(v);
            self.weights.push(w);
        }
        self.starts.push(self.vertices.len() as u32);
    }
}

/// What a face built, kept so that new points can be poured into the same structure.
#[derive(Debug, Clone)]
enum FaceShape {
    Hole,
    /// This many Bézier nets (1, or the 4 quarters of a split cage).
    Regular(usize),
    /// The isolation's trees (one per sub-face of a face that is not a quad).
    Isolated(Vec<PatchTree>),
    /// A Loop triangle's tree with this many leaf points (the patch's own tree takes the new
    /// ones: [`TriangleTree::with_leaf_points`]).
    Loop(usize),
}

/// One face's surface as a scheme builds it, seen by the stencils: its control points, and
/// the shape they are poured back into.
trait FaceSurface: Send {
    /// Appends the face's control points to `out` (the order of [`CageStencils::rows`]).
    fn points(&self, out: &mut Vec<DVec3>);
    fn shape(&self) -> FaceShape;
}

impl FaceSurface for Built {
    fn points(&self, out: &mut Vec<DVec3>) {
        Built::points(self, out);
    }

    fn shape(&self) -> FaceShape {
        match self {
            Built::Hole => FaceShape::Hole,
            Built::Regular(nets) => FaceShape::Regular(nets.len()),
            Built::Isolated(trees) => FaceShape::Isolated(trees.clone()),
        }
    }
}

/// A Loop triangle: its tree, or None for a hole ([`loop_face`]).
impl FaceSurface for Option<TriangleTree> {
    fn points(&self, out: &mut Vec<DVec3>) {
        if let Some(tree) = self {
            tree.leaf_points(out);
        }
    }

    fn shape(&self) -> FaceShape {
        self.as_ref().map_or(FaceShape::Hole, |tree| FaceShape::Loop(tree.leaf_point_count()))
    }
}

/// Which of its face's trees a subdivision patch views: the one tree of a quad (its quarters
/// are views of it), else its sub-face's.
fn tree_index(origin: &PatchOrigin) -> usize {
    if origin.corners == 4 {
        0
    } else {
        usize::from(origin.subface)
    }
}

/// The stencils of a cage's [`SurfaceSet`] ([`CageStencils::build`] for Catmull-Clark,
/// [`CageStencils::build_loop`] for Loop): one sparse row per control point of every face's
/// surface, over the cage's vertices.
#[derive(Debug, Clone)]
pub struct CageStencils {
    vertex_count: usize,
    patch_count: usize,
    shapes: Vec<FaceShape>,
    /// Face `f`'s rows are `face_rows[f]..face_rows[f + 1]`, in [`FaceSurface::points`] order.
    face_rows: Vec<u32>,
    rows: SparseRows,
}

impl CageStencils {
    /// The Catmull-Clark set of `mesh` ([`SurfaceSet::from_subdivision_cage`], the same set)
    /// and its stencils.
    ///
    /// Errors as [`SurfaceSet::from_subdivision_cage`]. Cost: that of building the set, plus
    /// about a third of each face's neighbourhood size in face builds; memory about 20
    /// weights per control point of a regular face (16 × 16 for the whole net), more around
    /// extraordinary vertices.
    pub fn build(
        mesh: &PolygonMesh,
        file: &Path,
        options: CageOptions,
    ) -> Result<(SurfaceSet, CageStencils)> {
        let (cage, repairs) = oriented_cage(mesh, file, options)?;
        let split = is_split(&cage);
        let (built, mut stencils) = Self::probe(&cage, |c, f| Built::face(c, f, split, options.isolation));
        let set = assemble(&cage, built, repairs, file)?;
        stencils.patch_count = set.patches.len();
        Ok((set, stencils))
    }

    /// The Loop set of the triangle cage `mesh` ([`SurfaceSet::from_loop_cage`], the same
    /// set) and its stencils: each triangle's rows are the leaf points of its tree.
    ///
    /// Errors as [`SurfaceSet::from_loop_cage`]. Cost: that of building the set, plus about
    /// a third of each triangle's neighbourhood size in triangle builds; memory about 12
    /// weights per control point of a regular triangle (its 12 box-spline points for each of
    /// its quartic's 15), more around extraordinary vertices.
    pub fn build_loop(
        mesh: &PolygonMesh,
        file: &Path,
        options: CageOptions,
    ) -> Result<(SurfaceSet, CageStencils)> {
        let (cage, repairs) = oriented_loop_cage(mesh, file, options)?;
        let (trees, mut stencils) = Self::probe(&cage, |c, f| loop_face(c, f, options.isolation));
        let set = loop_assemble(&cage, trees, repairs, file)?;
        stencils.patch_count = set.patches.len();
        Ok((set, stencils))
    }

    /// Every face of `cage` built by `face` (one scheme's rule, linear in the cage's points),
    /// and the stencils of those builds probed (module doc), with no patch count yet. Cost:
    /// the builds, plus about a third of each face's neighbourhood size in probing builds.
    fn probe<F: FaceSurface>(cage: &Cage, face: impl Fn(&Cage, usize) -> F + Sync) -> (Vec<F>, CageStencils) {
        let faces = cage.face_count();
        // Faces in chunks, each probing on its own zeroed copy of the cage.
        let chunk = faces.div_ceil(4 * rayon::current_num_threads()).max(16);
        let per_chunk: Vec<Vec<(F, FaceRowsOut)>> = (0..faces.div_ceil(chunk))
            .into_par_iter()
            .map(|c| {
                let mut probe = cage.clone();
                probe.points.iter_mut().for_each(|p| *p = DVec3::ZERO);
                (c * chunk..faces.min((c + 1) * chunk))
                    .map(|f| (face(cage, f), probe_face(cage, &mut probe, f, &face)))
                    .collect()
            })
            .collect();
        let mut built = Vec::with_capacity(faces);
        let mut shapes = Vec::with_capacity(faces);
        let mut face_rows = vec![0u32];
        let mut rows = SparseRows { starts: vec![0], ..Default::default() };
        for (surface, face_out) in per_chunk.into_iter().flatten() {
            shapes.push(surface.shape());
            for terms in &face_out {
                rows.push_row(terms);
            }
            face_rows.push(rows.len() as u32);
            built.push(surface);
        }
        let stencils =
            CageStencils { vertex_count: cage.points.len(), patch_count: 0, shapes, face_rows, rows };
        (built, stencils)
    }

    /// How many cage vertices the stencils read (the length of the positions
    /// [`CageStencils::apply`] takes: the cage file's vertex count).
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// Every face's control points' rows, face after face in [`SurfaceSet::origins`]' face
    /// order (none for a hole): a regular Catmull-Clark face's 16 net points (64, quarter
    /// after quarter, in a split cage), an isolated one's trees' [`PatchTree::leaf_points`]
    /// (16 for a Bézier leaf, 20 for a Gregory one), a Loop triangle's
    /// [`TriangleTree::leaf_points`] (15 for a quartic leaf, 18 for a Gregory triangle).
    pub fn rows(&self) -> &SparseRows {
        &self.rows
    }

    /// The set's patches for the cage vertices at `positions`: `set` (the set
    /// [`CageStencils::build`] or [`CageStencils::build_loop`] returned, or one this function
    /// updated) gets the surface of the moved cage — the same patches, parameters, keys and
    /// topology, new control points (a Loop patch's tree keeps its nodes, leaves' places and
    /// [`TriangleTree::is_swapped`]). Equal, to rounding, to building the moved cage from
    /// scratch with the orientation the stencils were made with.
    ///
    /// Errors: [`Error::InvalidParameter`] for positions of another count or not finite, or a
    /// set that is not this cage's (another cage's, or the other scheme's). Cost: O(stencil
    /// entries) multiply-adds, parallel, and a new copy of every isolated face's and every
    /// Loop triangle's leaves.
    pub fn apply(&self, positions: &[DVec3], set: &mut SurfaceSet) -> Result<()> {
        check_positions(positions, self.vertex_count)?;
        self.check_set(set)?;
        let points: Vec<DVec3> =
            (0..self.rows.len()).into_par_iter().map(|r| self.rows.apply_row(r, positions)).collect();
        // The isolated faces' trees refilled once each; the patches are views of them.
        let trees: Vec<Vec<PatchTree>> = self
            .shapes
            .par_iter()
            .enumerate()
            .map(|(f, shape)| match shape {
                FaceShape::Isolated(trees) => {
                    let mut at = self.face_rows[f] as usize;
                    trees
                        .iter()
                        .map(|t| {
                            let n = t.leaf_point_count();
                            at += n;
                            t.with_leaf_points(&points[at - n..at])
                        })
                        .collect()
                }
                _ => Vec::new(),
            })
            .collect();
        set.patches.par_iter_mut().zip(&set.origins).for_each(|(patch, origin)| {
            let f = origin.face as usize;
            let piece = usize::from(origin.subface);
            match patch {
                Patch::Bicubic(b) => {
                    let at = self.face_rows[f] as usize + 16 * piece;
                    *b = RationalBicubic::polynomial(std::array::from_fn(|k| points[at + k]));
                }
                Patch::Subdivision(tree) => **tree = tree.with_tree_of(&trees[f][tree_index(origin)]),
                Patch::Loop(tree) => {
                    let rows = self.face_rows[f] as usize..self.face_rows[f + 1] as usize;
                    **tree = tree.with_leaf_points(&points[rows]);
                }
                _ => unreachable!("checked by check_set"),
            }
        });
        Ok(())
    }

    /// Where each patch's points are among [`CageStencils::rows`], patch by patch: a bicubic
    /// patch's 16 control points (`points[4*i + j]`), or the leaf points of the isolated
    /// face's tree the patch views, in [`PatchTree::leaf_points`] order (the views of one
    /// tree — a split quad's quarters — have the same range); a Loop patch's range is its
    /// triangle's tree's leaf points, in [`TriangleTree::leaf_points`] order. For an engine
    /// that recomputes the points itself, e.g. the GPU's.
    ///
    /// Errors: [`Error::InvalidParameter`] when `set` is not this cage's. Cost: O(patches +
    /// leaves).
    pub fn point_ranges(&self, set: &SurfaceSet) -> Result<Vec<std::ops::Range<usize>>> {
        self.check_set(set)?;
        Ok(set
            .origins
            .iter()
            .map(|origin| {
                let f = origin.face as usize;
                let start = self.face_rows[f] as usize;
                match &self.shapes[f] {
                    FaceShape::Regular(_) => {
                        let first = start + 16 * usize::from(origin.subface);
                        first..first + 16
                    }
                    FaceShape::Isolated(trees) => {
                        let t = tree_index(origin);
                        let first = start + trees[..t].iter().map(PatchTree::leaf_point_count).sum::<usize>();
                        first..first + trees[t].leaf_point_count()
                    }
                    FaceShape::Loop(count) => start..start + count,
                    FaceShape::Hole => start..start,
                }
            })
            .collect())
    }

    /// Patch `patch` (of face `origin`, as built with these stencils) with its points at
    /// `points` instead, in [`CageStencils::point_ranges`]' order: a bicubic patch's 16, or
    /// every leaf point of the tree it views. For bounding what a cage's motion does to a
    /// patch ([`super::moving_bounds`]). Preconditions: `patch` is one of the set these
    /// stencils checked, and `points` has its range's length. Cost: a copy of the tree.
    pub(super) fn with_points(&self, patch: &Patch, origin: &PatchOrigin, points: &[DVec3]) -> Patch {
        match (patch, &self.shapes[origin.face as usize]) {
            (Patch::Bicubic(_), _) => {
                Patch::Bicubic(RationalBicubic::polynomial(std::array::from_fn(|k| points[k])))
            }
            (Patch::Subdivision(tree), FaceShape::Isolated(trees)) => Patch::Subdivision(Box::new(
                tree.with_tree_of(&trees[tree_index(origin)].with_leaf_points(points)),
            )),
            (Patch::Loop(tree), _) => Patch::Loop(Box::new(tree.with_leaf_points(points))),
            _ => unreachable!("a patch these stencils checked"),
        }
    }

    /// Whether `set` has the patches these stencils were made for: the count, and each
    /// patch's kind and face as built.
    fn check_set(&self, set: &SurfaceSet) -> Result<()> {
        let mismatch = |reason: String| Err(Error::InvalidParameter { name: "set", reason });
        if set.patches.len() != self.patch_count || set.origins.len() != self.patch_count {
            return mismatch(format!(
                "it has {} patches; the cage of these stencils has {}",
                set.patches.len(),
                self.patch_count
            ));
        }
        for (p, (patch, origin)) in set.patches.iter().zip(&set.origins).enumerate() {
            let fits = match (self.shapes.get(origin.face as usize), patch) {
                (Some(FaceShape::Regular(nets)), Patch::Bicubic(_)) => usize::from(origin.subface) < *nets,
                (Some(FaceShape::Isolated(trees)), Patch::Subdivision(_)) => {
                    origin.corners == 4 || usize::from(origin.subface) < trees.len()
                }
                (Some(FaceShape::Loop(count)), Patch::Loop(tree)) => tree.leaf_point_count() == *count,
                _ => false,
            };
            if !fits {
                return mismatch(format!(
                    "patch {p} is not what face {} of this cage built",
                    origin.face + 1
                ));
            }
        }
        Ok(())
    }
}

/// Whether `positions` can be the vertices of a cage of `vertex_count` vertices: one each,
/// all finite — what [`CageStencils::apply`] and any engine applying the stencils check.
/// Errors: [`Error::InvalidParameter`] naming the count, or the first vertex (1-based, as in
/// the file) that is not finite. Cost: O(V).
pub fn check_positions(positions: &[DVec3], vertex_count: usize) -> Result<()> {
    if positions.len() != vertex_count {
        return Err(Error::InvalidParameter {
            name: "positions",
            reason: format!("{} positions for a cage of {vertex_count} vertices", positions.len()),
        });
    }
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "positions",
            reason: format!("vertex {} is at {} (not finite)", i + 1, positions[i]),
        });
    }
    Ok(())
}

/// Rows of one face: per control point (in `Built::points` order), its `(vertex, weight)`
/// terms.
type FaceRowsOut = Vec<Vec<(u32, f64)>>;

/// The vertices face `f`'s surface reads: those of the faces around its corners.
fn neighbourhood_vertices(cage: &Cage, f: usize) -> Vec<u32> {
    let mut vertices = Vec::new();
    for &v in cage.face(f) {
        for fc in cage.vertex_faces(v as usize) {
            vertices.extend_from_slice(cage.face(fc.face as usize));
        }
    }
    vertices.sort_unstable();
    vertices.dedup();
    vertices
}

/// Probes face `f`, built by `face`, on `probe` (a copy of `cage` whose points are all
/// zero, left so).
fn probe_face<F: FaceSurface>(
    cage: &Cage,
    probe: &mut Cage,
    f: usize,
    face: impl Fn(&Cage, usize) -> F,
) -> FaceRowsOut {
    if cage.holes[f] {
        return Vec::new();
    }
    let mut rows: FaceRowsOut = Vec::new();
    let mut points = Vec::new();
    for chunk in neighbourhood_vertices(cage, f).chunks(3) {
        for (c, &v) in chunk.iter().enumerate() {
            probe.points[v as usize][c] = 1.0;
        }
        points.clear();
        face(probe, f).points(&mut points);
        rows.resize_with(points.len(), Vec::new);
        for (row, p) in rows.iter_mut().zip(&points) {
            for (c, &v) in chunk.iter().enumerate() {
                if p[c] != 0.0 {
                    row.push((v, p[c]));
                }
            }
        }
        for &v in chunk {
            probe.points[v as usize] = DVec3::ZERO;
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::obj::read_obj;
    use crate::test_support::{data, Lcg};

    /// The largest distance between two sets' patches, evaluated on a grid over each patch's
    /// domain (trees have no single net).
    fn largest_difference(a: &SurfaceSet, b: &SurfaceSet) -> f64 {
        assert_eq!(a.patches.len(), b.patches.len());
        let mut worst = 0.0f64;
        for (p, q) in a.patches.iter().zip(&b.patches) {
            assert_eq!(p.domain(), q.domain());
            for i in 0..=4 {
                for j in 0..=4 {
                    if p.domain() == crate::surface::Domain::Tri && i + j > 4 {
                        continue;
                    }
                    let uv = glam::DVec2::new(i as f64 / 4.0, j as f64 / 4.0);
                    worst = worst.max(p.position(uv).distance(q.position(uv)));
                }
            }
        }
        worst
    }

    fn moved(points: &[DVec3], seed: u64, amount: f64) -> Vec<DVec3> {
        let mut rng = Lcg(seed);
        points
            .iter()
            .map(|p| *p + DVec3::new(rng.unit53() - 0.5, rng.unit53() - 0.5, rng.unit53() - 0.5) * amount)
            .collect()
    }

    /// A scheme's two builders: its set's, and its set's with the stencils.
    struct Scheme {
        set: fn(&PolygonMesh, &Path, CageOptions) -> Result<SurfaceSet>,
        stencils: fn(&PolygonMesh, &Path, CageOptions) -> Result<(SurfaceSet, CageStencils)>,
    }

    const CATMULL_CLARK: Scheme =
        Scheme { set: SurfaceSet::from_subdivision_cage, stencils: CageStencils::build };
    const LOOP: Scheme = Scheme { set: SurfaceSet::from_loop_cage, stencils: CageStencils::build_loop };

    fn cage(name: &str) -> (std::path::PathBuf, PolygonMesh) {
        let path = data(&format!("subdivision/{name}"));
        let mesh = read_obj(&path).unwrap();
        (path, mesh)
    }

    /// Applying `scheme`'s stencils of `mesh` to moved vertices gives the set built from the
    /// moved cage (and the original vertices the set itself), to 1e-12 of the diagonal.
    fn expect_moved_surfaces(name: &str, path: &Path, mesh: &PolygonMesh, scheme: &Scheme) {
        let (mut set, stencils) = (scheme.stencils)(mesh, path, CageOptions::default()).unwrap();
        let built = (scheme.set)(mesh, path, CageOptions::default()).unwrap();
        let (lo, hi) = built.bounds();
        let diagonal = lo.distance(hi);
        assert_eq!(largest_difference(&set, &built), 0.0, "{name}: the same set");
        // The original positions through the stencils: the same surface to rounding.
        let mut again = set.clone();
        stencils.apply(&mesh.positions, &mut again).unwrap();
        assert!(largest_difference(&again, &built) < 1e-12 * diagonal, "{name}: identity");
        // The orientation is decided once, for the cage as given; a rebuild of the moved
        // cage is told the same.
        let same = CageOptions {
            orientation: crate::surface::Orientation::AsGiven,
            flip: built.repairs.flipped,
            ..CageOptions::default()
        };
        for seed in 1..=2 {
            let mut moved_mesh = mesh.clone();
            moved_mesh.positions = moved(&mesh.positions, seed, 0.2 * diagonal);
            let rebuilt = (scheme.set)(&moved_mesh, path, same).unwrap();
            stencils.apply(&moved_mesh.positions, &mut set).unwrap();
            let d = largest_difference(&set, &rebuilt);
            assert!(d < 1e-12 * diagonal, "{name} seed {seed}: {d:e}");
            assert_eq!(set.keys, rebuilt.keys, "{name}");
        }
    }

    /// Applying the stencils to moved vertices gives the set built from the moved cage, on
    /// cages with every feature the stencils must carry: extraordinary vertices, n-gons
    /// (split faces), creases, corners, boundaries, holes.
    #[test]
    fn stencils_give_the_moved_cage_surface() {
        for name in [
            "catmark_cube.obj",
            "catmark_torus_creases0.obj",
            "catmark_pole8.obj",
            "catmark_hole_test1.obj",
            "catmark_edgecorner.obj",
            "catmark_val2_interior.obj",
            "catmark_nonquads.obj",
        ] {
            let (path, mesh) = cage(name);
            expect_moved_surfaces(name, &path, &mesh, &CATMULL_CLARK);
        }
    }

    /// The same for Loop cages: creases (semi-sharp, Chaikin's rule too), corners,
    /// boundaries, extraordinary vertices (up to valence 8), and holes.
    #[test]
    fn loop_stencils_give_the_moved_cage_surface() {
        for name in [
            "loop_cube_creases0.obj",
            "loop_chaikin0.obj",
            "loop_xord_interior.obj",
            "loop_xord_boundary.obj",
            "loop_pole8.obj",
            "loop_triangle_edgecorner.obj",
            "loop_triangle_edgeonly.obj",
        ] {
            let (path, mesh) = cage(name);
            expect_moved_surfaces(name, &path, &mesh, &LOOP);
        }
        // Holes: faces without a surface have no rows, and their neighbours' rows skip them.
        let (path, mut mesh) = cage("loop_cube.obj");
        mesh.tags.holes = vec![0, 5, 11];
        expect_moved_surfaces("loop_cube.obj with holes", &path, &mesh, &LOOP);
    }

    /// A Loop patch's tree keeps its exchanged parameters (`Patch::flipped`) through
    /// `apply`: the flipped set moved is the moved set flipped.
    #[test]
    fn loop_stencils_keep_flipped_patches_flipped() {
        let (path, mesh) = cage("loop_xord_boundary.obj");
        let (mut set, stencils) = CageStencils::build_loop(&mesh, &path, CageOptions::default()).unwrap();
        set.patches.iter_mut().for_each(|p| *p = p.flipped());
        let mut moved_mesh = mesh.clone();
        moved_mesh.positions = moved(&mesh.positions, 7, 0.5);
        stencils.apply(&moved_mesh.positions, &mut set).unwrap();
        let same = CageOptions {
            orientation: crate::surface::Orientation::AsGiven,
            flip: set.repairs.flipped,
            ..CageOptions::default()
        };
        let mut rebuilt = SurfaceSet::from_loop_cage(&moved_mesh, &path, same).unwrap();
        rebuilt.patches.iter_mut().for_each(|p| *p = p.flipped());
        assert!(set.patches.iter().all(|p| matches!(p, Patch::Loop(t) if t.is_swapped())));
        let d = largest_difference(&set, &rebuilt);
        assert!(d < 1e-12, "{d:e}");
    }

    #[test]
    fn bad_positions_and_other_sets_are_refused() {
        let path = data("subdivision/catmark_cube.obj");
        let mesh = read_obj(&path).unwrap();
        let (mut set, stencils) = CageStencils::build(&mesh, &path, CageOptions::default()).unwrap();
        let short = stencils.apply(&mesh.positions[1..], &mut set).unwrap_err();
        assert!(short.to_string().contains("7 positions for a cage of 8 vertices"), "{short}");
        let mut nan = mesh.positions.clone();
        nan[3].y = f64::NAN;
        let e = stencils.apply(&nan, &mut set).unwrap_err();
        assert!(e.to_string().contains("vertex 4") && e.to_string().contains("not finite"), "{e}");
        let other = data("subdivision/catmark_torus.obj");
        let mut torus =
            SurfaceSet::from_subdivision_cage(&read_obj(&other).unwrap(), &other, CageOptions::default())
                .unwrap();
        let e = stencils.apply(&mesh.positions, &mut torus).unwrap_err();
        assert!(e.to_string().contains("patches"), "{e}");
        let e = stencils.point_ranges(&torus).unwrap_err();
        assert!(e.to_string().contains("patches"), "{e}");
    }

    #[test]
    fn loop_stencils_refuse_bad_positions_and_the_other_schemes_sets() {
        let (path, mesh) = cage("loop_cube_creases0.obj");
        let (mut set, stencils) = CageStencils::build_loop(&mesh, &path, CageOptions::default()).unwrap();
        let short = stencils.apply(&mesh.positions[1..], &mut set).unwrap_err();
        assert!(short.to_string().contains("7 positions for a cage of 8 vertices"), "{short}");
        let mut inf = mesh.positions.clone();
        inf[5].z = f64::INFINITY;
        let e = stencils.apply(&inf, &mut set).unwrap_err();
        assert!(e.to_string().contains("vertex 6") && e.to_string().contains("not finite"), "{e}");
        // The Catmull-Clark set of a triangle cage (a patch per corner of each of the
        // tetrahedron's 4 triangles) has as many patches as the cube's Loop set, of the
        // other kind: each scheme's stencils refuse the other's set.
        let (tet_path, tet) = cage("loop_tetrahedron.obj");
        let (mut cc_set, cc_stencils) = CageStencils::build(&tet, &tet_path, CageOptions::default()).unwrap();
        assert_eq!(cc_set.patches.len(), set.patches.len());
        let e = stencils.apply(&mesh.positions, &mut cc_set).unwrap_err();
        assert!(e.to_string().contains("patch 0 is not what face 1"), "{e}");
        let e = stencils.point_ranges(&cc_set).unwrap_err();
        assert!(e.to_string().contains("patch 0 is not what face 1"), "{e}");
        let e = cc_stencils.apply(&tet.positions, &mut set).unwrap_err();
        assert!(e.to_string().contains("patch 0 is not what face 1"), "{e}");
        // Another Loop cage's set, and a cage that is not made of triangles.
        let (other_path, other) = cage("loop_icosahedron.obj");
        let mut icosahedron =
            SurfaceSet::from_loop_cage(&other, &other_path, CageOptions::default()).unwrap();
        let e = stencils.apply(&mesh.positions, &mut icosahedron).unwrap_err();
        assert!(e.to_string().contains("20 patches"), "{e}");
        let (quad_path, quads) = cage("catmark_cube.obj");
        let e = CageStencils::build_loop(&quads, &quad_path, CageOptions::default()).unwrap_err();
        assert!(e.to_string().contains("Loop subdivision needs triangles"), "{e}");
    }

    /// Each patch's point ranges reproduce its points: a regular cage's control points, and
    /// the leaf points of isolated faces' trees (a split quad's quarters sharing one range).
    #[test]
    fn point_ranges_give_every_patchs_points() {
        for (name, scheme, split) in [
            ("catmark_torus", &CATMULL_CLARK, false),
            ("catmark_torus_creases0", &CATMULL_CLARK, false),
            ("catmark_pyramid_creases0", &CATMULL_CLARK, true),
            ("loop_cube_creases0", &LOOP, false),
            ("loop_xord_boundary", &LOOP, false),
        ] {
            let (path, mesh) = cage(&format!("{name}.obj"));
            let (set, stencils) = (scheme.stencils)(&mesh, &path, CageOptions::default()).unwrap();
            let ranges = stencils.point_ranges(&set).unwrap();
            assert_eq!(ranges.len(), set.patches.len());
            let rows = stencils.rows();
            let mut shared = 0;
            for (p, (patch, range)) in set.patches.iter().zip(&ranges).enumerate() {
                let mut want = Vec::new();
                match patch {
                    Patch::Bicubic(b) => want.extend_from_slice(&b.points),
                    Patch::Subdivision(t) => t.leaf_points(&mut want),
                    Patch::Loop(t) => t.leaf_points(&mut want),
                    _ => unreachable!("a cage's patches"),
                }
                assert_eq!(range.len(), want.len(), "{name} patch {p}");
                for (r, w) in range.clone().zip(&want) {
                    let d = rows.apply_row(r, &mesh.positions).distance(*w);
                    assert!(d < 1e-12, "{name} patch {p} row {r}: {d:e}");
                }
                shared += ranges[..p].iter().filter(|q| *q == range).count();
            }
            // Only the pyramid's quad (split, isolated: its corners have valence 3) has
            // quarters that view one tree; a Loop triangle is one patch.
            assert_eq!(shared > 0, split, "{name}: {shared} patches share an earlier one's range");
        }
    }
}
