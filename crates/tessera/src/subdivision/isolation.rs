//! Feature-adaptive isolation of one face, as OpenSubdiv's Bfr does it: the face's
//! neighbourhood is refined with Catmull-Clark's rules towards its irregular features, and the
//! pieces become bicubic B-spline patches where the refined mesh is regular and Gregory end
//! caps where refinement stops (`bfr/patchTreeBuilder.cpp`, `far/topologyRefiner.cpp`,
//! `far/patchBuilder.cpp`).
//!
//! Each step keeps only what the next needs. The *neighbourhood* of a face is the faces
//! around its corners. Refining a face `f` needs the points of its corners (whose rings are in
//! the neighbourhood), of the edges at its corners (whose faces are too) and of those faces;
//! and the children of the faces around `f`'s corners, taken at those corners, are exactly
//! the neighbourhoods of `f`'s children. So a local mesh of a few dozen faces per level
//! carries the whole isolation, and its *complete* vertices (the corners of the faces being
//! refined or made patches) are the only ones whose rules are ever applied.
//!
//! Depths and features are Bfr's defaults (`SurfaceFactory::Options`): smooth features (an
//! extraordinary vertex, a smooth boundary corner, an irregular crease or dart) are isolated
//! to level 2, sharp ones (semi-sharp edges and vertices, irregular infinitely sharp corners)
//! to level 6; see [`IsolationLevels`].

use glam::{DVec2, DVec3};

use super::cage::{Cage, FaceCorner};
use super::gregory::{GregoryCorner, GregoryPatch, GregorySource};
use super::sdc::{self, EdgeNeighborhood, VertexNeighborhood, VertexRule};
use super::INFINITELY_SHARP;
use crate::pattern::cache::WordMap;
use crate::surface::patch_tree::Slot;
pub use crate::surface::patch_tree::{Leaf, LeafPatch, PatchTree};

/// How deep feature-adaptive isolation refines (Bfr's `SurfaceFactory::Options`
/// `ApproxLevelSmooth` and `ApproxLevelSharp`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IsolationLevels {
    /// Depth for smooth features: extraordinary vertices, smooth boundary corners, irregular
    /// infinitely sharp creases and darts. Bfr's default 2.
    pub smooth: u8,
    /// Depth for sharp features: semi-sharp creases and corners, irregular infinitely sharp
    /// corners. Bfr's default 6; never below `smooth` in effect.
    ///
    /// Both take effect between 1 and [`MAX_ISOLATION_LEVEL`].
    pub sharp: u8,
}

impl Default for IsolationLevels {
    fn default() -> Self {
        IsolationLevels { smooth: 2, sharp: 6 }
    }
}

/// The most either level may be: each level quarters the leaves' size, and Bfr's own limit
/// is 10.
pub const MAX_ISOLATION_LEVEL: u8 = 10;

/// The subdivision scheme whose regular topology the tags and features below measure
/// against: OpenSubdiv's regular face size and vertex valences (`Sdc::SchemeTypeTraits`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scheme {
    /// Catmull-Clark: quads, 4 faces around an interior vertex, 2 at a boundary.
    Catmark,
    /// Loop: triangles, 6 faces around an interior vertex, 3 at a boundary.
    Loop,
}

impl Scheme {
    /// Corners of a regular face.
    pub(crate) fn face_size(self) -> usize {
        match self {
            Scheme::Catmark => 4,
            Scheme::Loop => 3,
        }
    }

    /// Faces around a regular interior vertex.
    fn interior_faces(self) -> usize {
        2 * self.boundary_faces()
    }

    /// Faces around a regular boundary vertex.
    fn boundary_faces(self) -> usize {
        match self {
            Scheme::Catmark => 2,
            Scheme::Loop => 3,
        }
    }
}

/// Builds the patch trees of face `face` of `cage`: one for a quad, one per corner sub-face
/// (in corner order) for any other face.
///
/// Precondition: the face has a limit surface (not a hole). Cost: a local refinement of a
/// few dozen faces per level, for as many levels as its features need.
pub fn isolate(cage: &Cage, face: usize, levels: IsolationLevels) -> Vec<PatchTree> {
    let (local, root) = neighbourhood(cage, face);
    // Depths from 1 (a face that is not regular is refined at least once, as Bfr forces a
    // level where a patch at the face itself is impossible) to the most Bfr allows.
    let sharp = levels.sharp.clamp(1, MAX_ISOLATION_LEVEL);
    let levels = IsolationLevels { smooth: levels.smooth.clamp(1, sharp), sharp };
    let has_irregular_faces = (0..local.face_count()).any(|f| local.face(f).len() != 4);
    let ctx = Context { levels, has_irregular_faces };
    let n = local.face(root).len();
    if n == 4 {
        return vec![TreeBuilder::with_scratch(|builder| {
            let root_slot = ctx.node(&local, root, 0, DVec2::ZERO, 1.0, builder);
            builder.finish(root_slot)
        })];
    }
    // A face that is not a quad: its children are the sub-faces, each a tree of its own, in
    // the sub-face's own orientation (Bfr's QUAD_SUBFACES parameterisation).
    let (child, children) = refine(&local, root, false);
    children
        .iter()
        .map(|&c| {
            TreeBuilder::with_scratch(|builder| {
                let slot = ctx.node(&child, c, 1, DVec2::ZERO, 1.0, builder);
                builder.finish(slot)
            })
        })
        .collect()
}

struct Context {
    levels: IsolationLevels,
    /// Whether the neighbourhood of the root has a face that is not a quad (Far's
    /// `_hasIrregFaces` of the local refiner).
    has_irregular_faces: bool,
}

#[derive(Default)]
struct TreeBuilder {
    leaves: Vec<Leaf>,
    nodes: Vec<[Slot; 4]>,
}

impl TreeBuilder {
    /// `build` with this thread's builder, emptied. Why: a tree's leaves (a few hundred
    /// bytes each, hundreds per face near a crease) grown by pushing into fresh vectors made
    /// every face reallocate through ever larger blocks, which glibc's per-thread arenas hand
    /// back to the kernel and fault in again, zeroed: on a 50,000-face creased cage, most of
    /// the load time was the kernel clearing pages. One growing scratch per thread and an
    /// exact copy per tree ([`TreeBuilder::finish`]) allocate each tree once.
    fn with_scratch<T>(build: impl FnOnce(&mut TreeBuilder) -> T) -> T {
        thread_local! {
            static SCRATCH: std::cell::RefCell<TreeBuilder> = std::cell::RefCell::default();
        }
        SCRATCH.with(|scratch| {
            // A tree is never built inside another's build; a fresh builder covers it anyway.
            match scratch.try_borrow_mut() {
                Ok(mut builder) => {
                    builder.leaves.clear();
                    builder.nodes.clear();
                    build(&mut builder)
                }
                Err(_) => build(&mut TreeBuilder::default()),
            }
        })
    }

    /// The tree of the leaves and nodes built so far, copied to exact sizes.
    fn finish(&mut self, root: Slot) -> PatchTree {
        PatchTree::from_parts(self.leaves.drain(..).collect(), self.nodes.clone(), root)
    }
}

impl Context {
    /// The subtree of face `f` of `mesh` at `level`, covering `origin + [0, size]²`.
    fn node(
        &self,
        mesh: &Cage,
        f: usize,
        level: u8,
        origin: DVec2,
        size: f64,
        out: &mut TreeBuilder,
    ) -> Slot {
        // Far's level `i` is made with the full feature set while `i` ≤ the smooth depth, with
        // the reduced one after; refining `f` makes level `level + 1`.
        let more = level < self.levels.sharp && {
            let full = level < self.levels.smooth;
            face_has_features(mesh, f, level, full, Scheme::Catmark)
        };
        if !more {
            let patch = if is_patch_regular(mesh, f, level, self.has_irregular_faces, Scheme::Catmark) {
                let grid = super::bspline::grid(mesh, f, boundary_mask(mesh, f));
                LeafPatch::Bezier(super::bspline::to_bezier(&grid))
            } else {
                LeafPatch::Gregory(Box::new(GregoryPatch::new(&gregory_source(mesh, f))))
            };
            out.leaves.push(Leaf { origin, size, level, patch });
            return Slot::Leaf((out.leaves.len() - 1) as u32);
        }
        let (child, children) = refine(mesh, f, true);
        let index = out.nodes.len();
        out.nodes.push([Slot::Leaf(0); 4]);
        let half = size * 0.5;
        let offsets = [DVec2::ZERO, DVec2::new(half, 0.0), DVec2::new(half, half), DVec2::new(0.0, half)];
        for (q, &c) in children.iter().enumerate() {
            let slot = self.node(&child, c, level + 1, origin + offsets[q], half, out);
            out.nodes[index][q] = slot;
        }
        Slot::Node(index as u32)
    }
}

/// `PatchBuilder::IsPatchRegular` (`far/patchBuilder.cpp`) with Bfr's options, for face `f`
/// of a local mesh of `scheme` at `level` (`has_irregular_faces`: the neighbourhood of the
/// root has a face of another size than the scheme's regular one).
pub(super) fn is_patch_regular(
    mesh: &Cage,
    f: usize,
    level: u8,
    has_irregular_faces: bool,
    scheme: Scheme,
) -> bool {
    let tags: Vec<VTag> = mesh.face(f).iter().map(|&v| vertex_tag(mesh, v as usize, scheme)).collect();
    let comp = VTag::union(&tags);
    if !comp.inf_sharp && !comp.inf_sharp_edges {
        return !comp.xordinary;
    }
    if !comp.xordinary && !comp.inf_irregular {
        return true;
    }
    let needs_extra_level = u8::from(comp.xordinary && has_irregular_faces);
    if level > needs_extra_level && !(comp.inf_irregular && comp.inf_sharp_edges) {
        return !comp.inf_irregular;
    }
    for (i, t) in tags.iter().enumerate() {
        if !t.xordinary && !t.inf_irregular {
            continue;
        }
        if t.xordinary && !t.inf_sharp_edges {
            return false;
        }
        if t.inf_irregular {
            if !t.inf_sharp_edges {
                return false;
            }
            if t.inf_sharp_crease && t.boundary {
                return false;
            }
            let span = corner_span(mesh, f, i);
            let wanted = if t.inf_sharp_crease { 2 } else { 1 };
            if span.faces != wanted {
                return false;
            }
        }
    }
    true
}

/// The tags Far keeps per vertex (`Vtr::internal::Level::VTag`), for the complete vertices
/// of a local mesh. They are recomputed from the vertex's ring at every level; Far inherits
/// them from level to level, which gives the same values for manifold cages.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct VTag {
    pub(super) boundary: bool,
    pub(super) corner: bool,
    pub(super) xordinary: bool,
    pub(super) inf_sharp: bool,
    pub(super) semi_sharp: bool,
    pub(super) inf_sharp_edges: bool,
    pub(super) semi_sharp_edges: bool,
    pub(super) inf_sharp_crease: bool,
    pub(super) inf_irregular: bool,
    pub(super) incident_irregular_face: bool,
    /// Bit set of the rules (`1` smooth, `2` dart, `4` crease, `8` corner), so that a union
    /// over corners says which rules occur, as Far's composite tag does.
    pub(super) rules: u8,
}

impl VTag {
    fn union(tags: &[VTag]) -> VTag {
        let mut c = VTag::default();
        for t in tags {
            c.boundary |= t.boundary;
            c.corner |= t.corner;
            c.xordinary |= t.xordinary;
            c.inf_sharp |= t.inf_sharp;
            c.semi_sharp |= t.semi_sharp;
            c.inf_sharp_edges |= t.inf_sharp_edges;
            c.semi_sharp_edges |= t.semi_sharp_edges;
            c.inf_sharp_crease |= t.inf_sharp_crease;
            c.inf_irregular |= t.inf_irregular;
            c.incident_irregular_face |= t.incident_irregular_face;
            c.rules |= t.rules;
        }
        c
    }
}

pub(super) const SMOOTH: u8 = 1;
pub(super) const DART: u8 = 2;
pub(super) const CREASE: u8 = 4;
pub(super) const CORNER: u8 = 8;

fn rule_bit(rule: VertexRule) -> u8 {
    match rule {
        VertexRule::Smooth => SMOOTH,
        VertexRule::Dart => DART,
        VertexRule::Crease => CREASE,
        VertexRule::Corner => CORNER,
    }
}

pub(super) fn is_infinite(s: f32) -> bool {
    s >= INFINITELY_SHARP
}

/// Far's vertex tags (`far/topologyRefinerFactory.cpp`, `prepareComponentTagsAndSharpness`)
/// of a complete vertex of a local mesh of `scheme`.
pub(super) fn vertex_tag(mesh: &Cage, v: usize, scheme: Scheme) -> VTag {
    let edges = mesh.vertex_edges(v);
    let faces = mesh.vertex_faces(v);
    let sharpness: Vec<f32> = edges.iter().map(|&e| mesh.edge_sharpness[e as usize]).collect();
    let inf_edges = sharpness.iter().filter(|&&s| is_infinite(s)).count();
    let semi_edges = sharpness.iter().filter(|&&s| s > 0.0 && !is_infinite(s)).count();
    let vs = mesh.vertex_sharpness[v];
    let boundary = mesh.is_boundary_vertex(v);
    let mut t = VTag {
        boundary,
        inf_sharp: is_infinite(vs),
        semi_sharp: vs > 0.0 && !is_infinite(vs),
        inf_sharp_edges: inf_edges > 0,
        semi_sharp_edges: semi_edges > 0,
        rules: rule_bit(VertexRule::from_sharp_edge_count(vs, inf_edges + semi_edges)),
        incident_irregular_face: faces
            .iter()
            .any(|fc| mesh.face(fc.face as usize).len() != scheme.face_size()),
        ..VTag::default()
    };
    t.corner = faces.len() == 1 && edges.len() == 2 && t.inf_sharp;
    t.xordinary = !t.corner
        && if boundary {
            faces.len() != scheme.boundary_faces()
        } else {
            faces.len() != scheme.interior_faces()
        };
    t.inf_irregular = t.inf_sharp || t.inf_sharp_edges;
    if t.inf_sharp_edges {
        let inf_rule = VertexRule::from_sharp_edge_count(if t.inf_sharp { vs } else { 0.0 }, inf_edges);
        match inf_rule {
            VertexRule::Crease => {
                t.inf_sharp_crease = true;
                if !t.xordinary {
                    // A regular crease bisects the ring: its sharp edges are opposite.
                    let opposite =
                        |a: usize| is_infinite(sharpness[a]) != is_infinite(sharpness[a + edges.len() / 2]);
                    t.inf_irregular = !boundary
                        && match scheme {
                            Scheme::Catmark => opposite(0),
                            Scheme::Loop => opposite(0) || opposite(1),
                        };
                }
            }
            // A regular set of infinitely sharp corners: every edge sharp, not a smooth corner.
            VertexRule::Corner if inf_edges == edges.len() && (edges.len() > 2 || t.inf_sharp) => {
                t.inf_irregular = false;
            }
            _ => {}
        }
    }
    t
}

/// `doesFaceHaveFeatures` (`far/topologyRefiner.cpp`) with Bfr's adaptive options
/// (`useInfSharpPatch`, no single-crease patches), for a face of a local mesh of `scheme`:
/// `full` is the feature set of the levels up to the smooth depth, else the reduced one of
/// the deeper levels.
pub(super) fn face_has_features(mesh: &Cage, f: usize, level: u8, full: bool, scheme: Scheme) -> bool {
    let corners = mesh.face(f);
    if corners.len() != scheme.face_size() {
        return true;
    }
    let tags: Vec<VTag> = corners.iter().map(|&v| vertex_tag(mesh, v as usize, scheme)).collect();
    let comp = VTag::union(&tags);
    if comp.incident_irregular_face && level == 0 {
        return true;
    }
    // Smooth extraordinary vertices: all corners smooth, or (the first two levels) one of
    // the extraordinary corners smooth.
    if comp.xordinary
        && full
        && (comp.rules == SMOOTH || (level < 2 && tags.iter().any(|t| t.xordinary && t.rules == SMOOTH)))
    {
        return true;
    }
    if comp.rules == SMOOTH {
        return false;
    }
    if comp.semi_sharp || comp.semi_sharp_edges {
        return true;
    }
    if comp.inf_sharp || comp.inf_sharp_edges {
        return inf_sharp_face_has_features(&comp, &tags, full);
    }
    false
}

/// `doesInfSharpVTagHaveFeatures`: whether an infinitely sharp feature is one the level
/// isolates (only irregular ones: Bfr uses infinitely sharp patches for the regular ones).
fn inf_sharp_tag_has_features(t: &VTag, full: bool) -> bool {
    if t.inf_irregular {
        if t.rules & CORNER != 0 {
            true
        } else if t.rules & CREASE != 0 {
            // An extraordinary boundary vertex, or an irregular crease: smooth features.
            full
        } else if t.rules & DART != 0 {
            full
        } else {
            false
        }
    } else {
        // Regular infinitely sharp creases and corners are never selected with
        // infinitely sharp patches.
        false
    }
}

/// `doesInfSharpFaceHaveFeatures`.
fn inf_sharp_face_has_features(comp: &VTag, tags: &[VTag], full: bool) -> bool {
    if comp.rules & SMOOTH != 0 {
        return inf_sharp_tag_has_features(comp, full);
    }
    tags.iter().any(|t| t.rules & SMOOTH == 0 && inf_sharp_tag_has_features(t, full))
}

/// `PatchBuilder::GetRegularPatchBoundaryMask`: the patch edges beyond which the B-spline
/// grid is replaced by phantom points (boundary and infinitely sharp edges), bit `k` for
/// edge `k`.
fn boundary_mask(mesh: &Cage, f: usize) -> u8 {
    let corners = mesh.face(f);
    let any_inf = corners.iter().any(|&v| vertex_tag(mesh, v as usize, Scheme::Catmark).inf_sharp_edges);
    if !any_inf {
        return 0;
    }
    let mut mask = 0;
    for (k, &e) in mesh.face_edges(f).iter().enumerate() {
        if mesh.is_boundary_edge(e) || is_infinite(mesh.edge_sharpness[e as usize]) {
            mask |= 1 << k;
        }
    }
    mask
}

/// The faces around a corner between the singular (boundary or infinitely sharp) edges that
/// enclose face `f` (`identifyManifoldCornerSpan`, `far/patchBuilder.cpp`).
pub(super) struct Span {
    /// Index into the vertex's faces of the span's first face (the one after its leading
    /// singular edge).
    pub(super) start: usize,
    pub(super) faces: usize,
    /// Where `f` is in the span.
    pub(super) corner_in_span: usize,
    /// No singular edge was found: the span is the whole (interior) ring.
    pub(super) periodic: bool,
}

pub(super) fn corner_span(mesh: &Cage, f: usize, corner: usize) -> Span {
    let v = mesh.face(f)[corner] as usize;
    let edges = mesh.vertex_edges(v);
    let n = edges.len();
    let singular = |e: u32| mesh.is_boundary_edge(e) || is_infinite(mesh.edge_sharpness[e as usize]);
    let lead_start = edges
        .iter()
        .position(|&e| e == mesh.face_edges(f)[corner])
        .expect("the face's edge is at its corner");
    let trail_start = (lead_start + 1) % n;
    let mut span = Span { start: 0, faces: 1, corner_in_span: 0, periodic: false };
    let mut lead = lead_start;
    while !singular(edges[lead]) {
        span.faces += 1;
        span.corner_in_span += 1;
        lead = (lead + n - 1) % n;
        if lead == trail_start {
            span.periodic = true;
            break;
        }
    }
    let mut trail = trail_start;
    if trail != lead {
        while !singular(edges[trail]) {
            span.faces += 1;
            trail = (trail + 1) % n;
            if trail == lead_start {
                break;
            }
        }
    }
    span.start = lead;
    if span.periodic {
        // The whole ring: Far counts the face once per step round; keep the ring's own size.
        span.faces = mesh.vertex_faces(v).len();
    }
    span
}

/// The fan of faces around corner `i` of face `f` that a Gregory end cap reads, and how the
/// corner is treated (`PatchBuilder::GetIrregularPatchCornerSpans`, `far/patchBuilder.cpp`):
/// the whole ring, or, where infinitely sharp edges cut it (and the vertex is not a dart),
/// the span between the two sharp edges around `f`, which is then an open fan.
pub(super) struct CornerFan {
    pub(super) faces: Vec<FaceCorner>,
    /// Where `f` is in `faces`.
    pub(super) patch_face: usize,
    /// The fan is open (the mesh's boundary, or a span).
    pub(super) boundary: bool,
    /// The corner is treated as infinitely sharp.
    pub(super) sharp: bool,
    /// The vertex is a dart with an infinitely sharp edge.
    pub(super) dart: bool,
}

/// [`CornerFan`] of corner `i` of face `f` of a local mesh of `scheme`. Cost: O(faces around
/// the corner).
pub(super) fn corner_fan(mesh: &Cage, f: usize, i: usize, scheme: Scheme) -> CornerFan {
    let v = mesh.face(f)[i] as usize;
    let t = vertex_tag(mesh, v, scheme);
    let fan = mesh.vertex_faces(v);
    let dart = t.rules & DART != 0 && t.inf_sharp_edges;
    let test_edges = t.inf_sharp_edges && t.rules != DART;
    let k = fan.iter().position(|fc| fc.face as usize == f).expect("the face is at its corner");
    let (faces, patch_face, boundary) = match test_edges.then(|| corner_span(mesh, f, i)) {
        Some(span) if !span.periodic => {
            let picked = (0..span.faces).map(|s| fan[(span.start + s) % fan.len()]).collect();
            (picked, span.corner_in_span, true)
        }
        _ => (fan.to_vec(), k, t.boundary),
    };
    let sharp = if t.corner {
        true
    } else if test_edges {
        !t.inf_sharp_crease
    } else {
        t.inf_sharp
    };
    CornerFan { faces, patch_face, boundary, sharp, dart }
}

impl CornerFan {
    /// The fan's 1-ring in OpenSubdiv's order (`SourcePatch::GetCornerRingPoints`): per face,
    /// its corners after the fan's vertex up to the one before it (a quad's far end of its
    /// leading edge and its diagonal vertex; a triangle's far end of its leading edge); an
    /// open fan adds the far end of its last face's trailing edge. Cost: O(ring).
    pub(super) fn ring(&self, mesh: &Cage) -> Vec<DVec3> {
        let mut ring = Vec::with_capacity(2 * self.faces.len() + 1);
        for fc in &self.faces {
            let q = mesh.face(fc.face as usize);
            let c = fc.corner as usize;
            ring.extend((1..q.len() - 1).map(|k| mesh.points[q[(c + k) % q.len()] as usize]));
        }
        if self.boundary {
            let last = self.faces.last().expect("a corner has a face");
            let q = mesh.face(last.face as usize);
            ring.push(mesh.points[q[(last.corner as usize + q.len() - 1) % q.len()] as usize]);
        }
        ring
    }
}

/// The source patch of a leaf for its Gregory end cap (`PatchBuilder::GetIrregularPatchCornerSpans`
/// and `assembleIrregularSourcePatch`, `far/patchBuilder.cpp`).
fn gregory_source(mesh: &Cage, f: usize) -> GregorySource {
    let corners: [GregoryCorner; 4] = std::array::from_fn(|i| {
        let v = mesh.face(f)[i] as usize;
        let fan = corner_fan(mesh, f, i, Scheme::Catmark);
        GregoryCorner {
            position: mesh.points[v],
            num_faces: fan.faces.len(),
            patch_face: fan.patch_face,
            boundary: fan.boundary,
            sharp: fan.sharp,
            dart: fan.dart,
            ring: fan.ring(mesh),
        }
    });
    GregorySource { corners }
}

/// One level of Catmull-Clark refinement around face `f` of `mesh`: the children of every
/// face around `f`'s corners, at those corners (the neighbourhoods of `f`'s children), with
/// their points, sharpness and completeness. Returns the child mesh and the indices of `f`'s
/// children in corner order. With `aligned`, a quad's children list their corners starting
/// from the one nearest `f`'s corner 0, so each child's parameters run the same way as
/// `f`'s (`u` along `f`'s edge 0); otherwise child `i` starts at `f`'s corner `i`
/// (the sub-face order of Bfr's `QUAD_SUBFACES`).
fn refine(mesh: &Cage, f: usize, aligned: bool) -> (Cage, Vec<usize>) {
    let options = mesh.options;
    // Child vertices, keyed by their parent component.
    #[derive(Clone, Copy, PartialEq, Eq, Hash)]
    enum Parent {
        Vertex(u32),
        Edge(u32),
        Face(u32),
    }
    let mut index: WordMap<Parent, u32> = Default::default();
    let mut parents: Vec<Parent> = Vec::new();
    let mut id = |p: Parent| -> u32 {
        *index.entry(p).or_insert_with(|| {
            parents.push(p);
            (parents.len() - 1) as u32
        })
    };
    let mut face_start = vec![0u32];
    let mut face_vertices = Vec::new();
    let mut children = Vec::new();
    let mut seen: WordMap<(u32, u32), ()> = Default::default();
    let corners = mesh.face(f).to_vec();
    // f's own children first, in corner order.
    let mut work: Vec<FaceCorner> =
        (0..corners.len()).map(|c| FaceCorner { face: f as u32, corner: c as u32 }).collect();
    for &v in &corners {
        work.extend(mesh.vertex_faces(v as usize).iter().copied());
    }
    for fc in work {
        if seen.insert((fc.face, fc.corner), ()).is_some() {
            continue;
        }
        let g = fc.face as usize;
        let v = mesh.face(g)[fc.corner as usize];
        let quad = [
            id(Parent::Vertex(v)),
            id(Parent::Edge(mesh.leading_edge(fc))),
            id(Parent::Face(g as u32)),
            id(Parent::Edge(mesh.trailing_edge(fc))),
        ];
        let quad = if g == f && aligned && corners.len() == 4 {
            let r = (4 - fc.corner as usize) % 4;
            [quad[r % 4], quad[(r + 1) % 4], quad[(r + 2) % 4], quad[(r + 3) % 4]]
        } else {
            quad
        };
        if g == f {
            children.push(face_start.len() - 1);
        }
        face_vertices.extend_from_slice(&quad);
        face_start.push(face_vertices.len() as u32);
    }

    // Points, sharpness and completeness of the children.
    // Each face point of the neighbourhood once: most are needed, several times over (as a
    // child vertex and by the edge and vertex points around it).
    let face_points: Vec<DVec3> = (0..mesh.face_count())
        .map(|g| sdc::face_point(&mesh.face(g).iter().map(|&v| mesh.points[v as usize]).collect::<Vec<_>>()))
        .collect();
    let face_point = |g: usize| face_points[g];
    let mut points = Vec::with_capacity(parents.len());
    let mut vertex_sharpness = Vec::with_capacity(parents.len());
    let mut complete = Vec::with_capacity(parents.len());
    let f_edges = mesh.face_edges(f);
    for &p in &parents {
        match p {
            Parent::Face(g) => {
                points.push(face_point(g as usize));
                vertex_sharpness.push(0.0);
                complete.push(g as usize == f);
            }
            Parent::Edge(e) => {
                let is_complete = f_edges.contains(&e);
                points.push(if corners.contains(&mesh.edge(e)[0]) || corners.contains(&mesh.edge(e)[1]) {
                    edge_point(mesh, e, &face_point)
                } else {
                    DVec3::ZERO
                });
                vertex_sharpness.push(0.0);
                complete.push(is_complete);
            }
            Parent::Vertex(v) => {
                points.push(vertex_point(mesh, v as usize, &face_point));
                vertex_sharpness.push(sdc::child_vertex_sharpness(mesh.vertex_sharpness[v as usize]));
                complete.push(true);
            }
        }
    }
    // Child edge sharpness: the halves of a parent edge get Sdc's child sharpness at their
    // end; edges inside a parent face are smooth.
    let sharpness_of = |a: u32, b: u32| -> f32 {
        let (pa, pb) = (parents[a as usize], parents[b as usize]);
        let (v, e) = match (pa, pb) {
            (Parent::Vertex(v), Parent::Edge(e)) | (Parent::Edge(e), Parent::Vertex(v)) => (v, e),
            _ => return 0.0,
        };
        child_sharpness(mesh, e, v)
    };
    let child =
        Cage::local(points, face_start, face_vertices, &complete, sharpness_of, vertex_sharpness, options);
    (child, children)
}

/// The sharpness of edge `e`'s child at its end `v` (a complete vertex): Sdc's rule for
/// semi-sharp edges (uniform or Chaikin), smooth and infinitely sharp edges unchanged.
pub(super) fn child_sharpness(mesh: &Cage, e: u32, v: u32) -> f32 {
    let s = mesh.edge_sharpness[e as usize];
    if s <= 0.0 || is_infinite(s) {
        return s;
    }
    let around: Vec<f32> =
        mesh.vertex_edges(v as usize).iter().map(|&x| mesh.edge_sharpness[x as usize]).collect();
    sdc::child_edge_sharpness(s, &around, mesh.options.crease_method)
}

/// Sdc's edge point of edge `e` (both its faces are in `mesh`).
fn edge_point(mesh: &Cage, e: u32, face_point: &dyn Fn(usize) -> DVec3) -> DVec3 {
    let [a, b] = mesh.edge(e);
    let s = mesh.edge_sharpness[e as usize];
    let faces = mesh.edge_faces(e);
    let face_points: Vec<DVec3> = faces.iter().map(|&g| face_point(g as usize)).collect();
    let face_sizes: Vec<usize> = faces.iter().map(|&g| mesh.face(g as usize).len()).collect();
    let child_at = |v: u32| child_sharpness(mesh, e, v);
    sdc::edge_point(
        &EdgeNeighborhood {
            ends: [mesh.points[a as usize], mesh.points[b as usize]],
            sharpness: s,
            child_sharpness: [child_at(a), child_at(b)],
            face_points: &face_points,
            face_sizes: &face_sizes,
        },
        mesh.options.triangles,
    )
}

/// Sdc's vertex point of complete vertex `v`.
fn vertex_point(mesh: &Cage, v: usize, face_point: &dyn Fn(usize) -> DVec3) -> DVec3 {
    let edges = mesh.vertex_edges(v);
    let ends: Vec<DVec3> = edges
        .iter()
        .map(|&e| {
            let [a, b] = mesh.edge(e);
            mesh.points[if a as usize == v { b } else { a } as usize]
        })
        .collect();
    let sharpness: Vec<f32> = edges.iter().map(|&e| mesh.edge_sharpness[e as usize]).collect();
    let face_points: Vec<DVec3> =
        mesh.vertex_faces(v).iter().map(|fc| face_point(fc.face as usize)).collect();
    sdc::vertex_point(
        &VertexNeighborhood {
            position: mesh.points[v],
            sharpness: mesh.vertex_sharpness[v],
            edge_ends: &ends,
            edge_sharpness: &sharpness,
            face_points: &face_points,
        },
        mesh.options.crease_method,
    )
}

/// The neighbourhood of face `face` of the cage as a local mesh (the faces around its
/// corners), and the face's index in it.
pub(super) fn neighbourhood(cage: &Cage, face: usize) -> (Cage, usize) {
    let corners = cage.face(face);
    let mut faces = vec![face as u32];
    for &v in corners {
        for fc in cage.vertex_faces(v as usize) {
            if !faces.contains(&fc.face) {
                faces.push(fc.face);
            }
        }
    }
    let mut local_of: WordMap<u32, u32> = Default::default();
    let mut global = Vec::new();
    let mut face_start = vec![0u32];
    let mut face_vertices = Vec::new();
    for &g in &faces {
        for &v in cage.face(g as usize) {
            let l = *local_of.entry(v).or_insert_with(|| {
                global.push(v);
                (global.len() - 1) as u32
            });
            face_vertices.push(l);
        }
        face_start.push(face_vertices.len() as u32);
    }
    let points = global.iter().map(|&v| cage.points[v as usize]).collect();
    let complete: Vec<bool> = global.iter().map(|v| corners.contains(v)).collect();
    let vertex_sharpness = global.iter().map(|&v| cage.vertex_sharpness[v as usize]).collect();
    let sharpness = |a: u32, b: u32| cage.edge_sharpness_between(global[a as usize], global[b as usize]);
    let local =
        Cage::local(points, face_start, face_vertices, &complete, sharpness, vertex_sharpness, cage.options);
    (local, 0)
}
