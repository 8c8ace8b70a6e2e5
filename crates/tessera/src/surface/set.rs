//! A set of patches with the topology that ties them together, and the builders that make
//! one from a patch file or a triangle mesh.

use super::PolygonMesh;
use super::{pn_triangle, BezierTriangle, Domain, Patch, PnTriangle};
use crate::error::{Error, Result};
use crate::topology::weld::{collapse_unresolved_curves, weld, Weld};
use crate::topology::{PatchKeys, Topology, NONE};
use glam::{DVec2, DVec3};
use std::collections::HashMap;
use std::path::Path;

/// How a surface set is oriented.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Orientation {
    /// Outward: the signed volume enclosed relative to the bounding-box centre is made
    /// non-negative (for closed inputs, normals point out). For meshes that carry their own
    /// normals, the winding is made to agree with those normals instead.
    #[default]
    Outward,
    /// Keep the input's orientation.
    AsGiven,
}

/// Options for building a [`SurfaceSet`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BuildOptions {
    pub weld: Weld,
    pub orientation: Orientation,
    /// Reverse the orientation after `orientation` was applied (`--flip-normals`).
    pub flip: bool,
}

/// What the builder changed in the input, so the CLI can report it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Repairs {
    /// Points merged into another by welding.
    pub welded_points: usize,
    /// Faces dropped because two of their corners are the same (welded) vertex.
    pub dropped_degenerate_faces: usize,
    /// Faces dropped because an earlier face has the same three vertices (in any order or
    /// winding): a copy adds no surface, only coincident triangles.
    pub dropped_duplicate_faces: usize,
    /// Faces dropped because their three (distinct) vertices are collinear: a face of zero
    /// area has no normal and no surface.
    pub dropped_zero_area_faces: usize,
    /// Patches dropped because all their control points are one point (after welding): they
    /// have no surface, and their triangles would all degenerate.
    pub dropped_collapsed_patches: usize,
    /// Input faces of more than three corners split into triangles (fans from their first
    /// corner; OBJ and PLY alike), since PN triangles need triangles.
    pub split_polygons: usize,
    /// glTF primitives left out because they are no surface (`POINTS`, `LINES`).
    pub skipped_primitives: usize,
    /// OpenSubdiv tag lines of an OBJ cage (creases, corners, holes, rules) that PN
    /// triangles, which interpolate the mesh rather than subdivide it, do not use.
    pub ignored_tag_lines: usize,
    /// Tag lines of a subdivision cage whose names tessera does not know (OpenSubdiv's
    /// face-varying options, for instance), ignored.
    pub unknown_tag_lines: usize,
    /// The orientation was reversed (by `Outward` or by `flip`).
    pub flipped: bool,
}

impl Repairs {
    /// Every counted kind of repair as `(key, count, what it means)`, zeros included, in a
    /// fixed order; `collapsed_triangles` is the engine's count of triangles not emitted where
    /// a boundary curve is one point ([`crate::mesh::Mesh::collapsed_triangles`]), the one
    /// repair made while tessellating. The keys are `--stats`' `repairs` object's and the
    /// Python package's `report["repairs"]`'s; the sentences are `tessera mesh`'s `repair:`
    /// lines. [`Repairs::flipped`] is the one repair that is not a count. Cost: O(1).
    pub fn counted(&self, collapsed_triangles: usize) -> [(&'static str, usize, &'static str); 10] {
        [
            (
                "split_polygons",
                self.split_polygons,
                "input polygons split into triangles (fans from their first corner) for PN triangles",
            ),
            ("skipped_primitives", self.skipped_primitives, "glTF primitives left out: POINTS or LINES, not surfaces"),
            (
                "ignored_tag_lines",
                self.ignored_tag_lines,
                "OpenSubdiv tag lines (creases, corners, holes) not used: PN triangles interpolate the cage, they do not subdivide it",
            ),
            ("unknown_tag_lines", self.unknown_tag_lines, "OpenSubdiv tag lines of unknown names ignored"),
            ("welded_points", self.welded_points, "input points merged into coincident ones by welding"),
            (
                "dropped_degenerate_faces",
                self.dropped_degenerate_faces,
                "input faces dropped: two of their corners are one vertex",
            ),
            (
                "dropped_duplicate_faces",
                self.dropped_duplicate_faces,
                "input faces dropped: exact duplicates of earlier faces",
            ),
            (
                "dropped_zero_area_faces",
                self.dropped_zero_area_faces,
                "input faces dropped: zero area (three collinear vertices)",
            ),
            (
                "dropped_collapsed_patches",
                self.dropped_collapsed_patches,
                "input patches dropped: all their control points are one point",
            ),
            (
                "collapsed_triangles",
                collapsed_triangles,
                "triangles not emitted: they collapse where a boundary curve is a single point",
            ),
        ]
    }
}

/// Patches plus their shared-edge topology: the input of every criterion, pattern and engine.
#[derive(Debug, Clone)]
pub struct SurfaceSet {
    pub patches: Vec<Patch>,
    pub keys: Vec<PatchKeys>,
    pub topology: Topology,
    pub repairs: Repairs,
    /// The model's up axis, for default cameras: +Z unless the loader knows the format's
    /// convention ([`crate::io::load`] sets it by [`crate::io::up_axis_of`]).
    pub up: crate::camera::UpAxis,
    /// For a set built from a subdivision cage
    /// ([`SurfaceSet::from_subdivision_cage`](crate::surface::SurfaceSet::from_subdivision_cage)):
    /// patch `p`'s base face and sub-face; empty for every other input.
    pub origins: Vec<crate::surface::PatchOrigin>,
}

/// Control-point indices of each corner and each edge (corner `e` → `e+1`) of a patch kind.
pub(crate) fn corner_and_edge_points(domain: Domain) -> (&'static [usize], &'static [[usize; 4]]) {
    use BezierTriangle as B;
    const QUAD_CORNERS: [usize; 4] = [0, 12, 15, 3];
    const QUAD_EDGES: [[usize; 4]; 4] = [[0, 4, 8, 12], [12, 13, 14, 15], [15, 11, 7, 3], [3, 2, 1, 0]];
    const TRI_CORNERS: [usize; 3] = [B::index(3, 0, 0), B::index(0, 3, 0), B::index(0, 0, 3)];
    const TRI_EDGES: [[usize; 4]; 3] = [
        [B::index(3, 0, 0), B::index(2, 1, 0), B::index(1, 2, 0), B::index(0, 3, 0)],
        [B::index(0, 3, 0), B::index(0, 2, 1), B::index(0, 1, 2), B::index(0, 0, 3)],
        [B::index(0, 0, 3), B::index(1, 0, 2), B::index(2, 0, 1), B::index(3, 0, 0)],
    ];
    match domain {
        Domain::Quad => (&QUAD_CORNERS, &QUAD_EDGES),
        Domain::Tri => (&TRI_CORNERS, &TRI_EDGES),
    }
}

/// The points [`SurfaceSet::from_patches`] welds for patch `p`, laid out as
/// [`corner_and_edge_points`] reads them: a Bézier patch's own control points; for a
/// subdivision patch (whose points are its pieces', not one net) a net of its limit surface's
/// boundary points — the corners and each edge at a third and two thirds — with the centre
/// elsewhere. Cost: none, or 10–16 evaluations.
fn key_net(p: &Patch) -> std::borrow::Cow<'_, [DVec3]> {
    match p {
        Patch::Bicubic(_) | Patch::BezierTriangle(_) | Patch::Pn(_) => p.control_points().into(),
        Patch::Subdivision(_) | Patch::Loop(_) => {
            let d = p.domain();
            let centre = p.position(match d {
                Domain::Quad => DVec2::splat(0.5),
                Domain::Tri => DVec2::splat(1.0 / 3.0),
            });
            let (_, edges) = corner_and_edge_points(d);
            let mut net = vec![centre; if d == Domain::Quad { 16 } else { 10 }];
            for (e, edge) in edges.iter().enumerate() {
                for (k, &i) in edge.iter().enumerate() {
                    net[i] = p.position(d.edge_point(e, k as f64 / 3.0));
                }
            }
            net.into()
        }
    }
}

/// Signed volume enclosed by the patches relative to `centre`, from a coarse 4×4 sampling.
fn signed_volume(patches: &[Patch], centre: DVec3) -> f64 {
    const N: usize = 4;
    let mut vol = 0.0;
    let tri = |a: DVec3, b: DVec3, c: DVec3| (a - centre).dot((b - centre).cross(c - centre)) / 6.0;
    for p in patches {
        let at = |i: usize, j: usize| p.position(DVec2::new(i as f64 / N as f64, j as f64 / N as f64));
        match p.domain() {
            Domain::Quad => {
                for i in 0..N {
                    for j in 0..N {
                        let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                        vol += tri(a, b, c) + tri(a, c, d);
                    }
                }
            }
            Domain::Tri => {
                for i in 0..N {
                    for j in 0..N - i {
                        vol += tri(at(i, j), at(i + 1, j), at(i, j + 1));
                        if i + j + 1 < N {
                            vol += tri(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                        }
                    }
                }
            }
        }
    }
    vol
}

fn bbox_centre(points: impl Iterator<Item = DVec3>) -> DVec3 {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in points {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    if lo.is_finite() && hi.is_finite() {
        (lo + hi) * 0.5
    } else {
        DVec3::ZERO
    }
}

impl SurfaceSet {
    /// Builds a set from patches given by their control points; neighbours are found by
    /// welding control points (`options.weld`), so they need not share indices. Subdivision
    /// patches have no one net: they are welded by their limit surface's boundary points (the
    /// corners and the edges' thirds), so neighbours taken from one cage meet where those
    /// evaluations weld; a cage's own topology is `io::load`'s (its edges, not welding).
    /// Preconditions: finite control points, positive weights. Cost: O(P) hashing.
    pub fn from_patches(mut patches: Vec<Patch>, options: BuildOptions) -> SurfaceSet {
        let mut repairs = Repairs::default();
        let mut flip = options.flip;
        if options.orientation == Orientation::Outward {
            let centre = bbox_centre(patches.iter().flat_map(|p| p.control_points().iter().copied()));
            if signed_volume(&patches, centre) < 0.0 {
                flip = !flip;
            }
        }
        if flip {
            patches = patches.iter().map(Patch::flipped).collect();
            repairs.flipped = true;
        }

        // Weld all control points; a patch's keys are the welded ids of its corner and
        // boundary-curve control points.
        let mut points = Vec::new();
        let mut weights = Vec::new();
        let nets: Vec<_> = patches.iter().map(key_net).collect();
        for (p, net) in patches.iter().zip(&nets) {
            points.extend_from_slice(net);
            match p {
                Patch::Bicubic(b) => weights.extend_from_slice(&b.weights),
                _ => weights.extend(std::iter::repeat_n(1.0, net.len())),
            }
        }
        let counts: Vec<usize> = nets.iter().map(|n| n.len()).collect();
        drop(nets);
        let mut welded = weld(&points, &weights, options.weld);
        if !matches!(options.weld, Weld::Off) {
            let mut base = 0;
            let curves = patches.iter().zip(&counts).flat_map(|(p, &count)| {
                let b = base;
                base += count;
                corner_and_edge_points(p.domain()).1.iter().map(move |e| e.map(|c| b + c))
            });
            welded.merged += collapse_unresolved_curves(&points, curves, &mut welded.ids);
        }
        repairs.welded_points = welded.merged;
        let mut keys = Vec::with_capacity(patches.len());
        let mut kept = Vec::with_capacity(patches.len());
        let mut base = 0;
        for (mut p, count) in patches.into_iter().zip(counts) {
            let ids = &welded.ids[base..base + count];
            base += count;
            if ids.iter().all(|&i| i == ids[0]) {
                repairs.dropped_collapsed_patches += 1;
                continue;
            }
            if matches!(options.weld, Weld::Within(_)) {
                // Snap to the cluster representative so both neighbours get the same curve.
                let snapped: Vec<DVec3> = ids.iter().map(|&i| points[i as usize]).collect();
                match &mut p {
                    Patch::Bicubic(b) => b.points.copy_from_slice(&snapped),
                    Patch::BezierTriangle(b) => b.points.copy_from_slice(&snapped),
                    Patch::Pn(b) => b.geometry.points.copy_from_slice(&snapped),
                    // A subdivision patch's points are its pieces', not one net to snap;
                    // cages are tied by their own topology, not by welding.
                    Patch::Subdivision(_) | Patch::Loop(_) => {}
                }
            }
            let (corners, edges) = corner_and_edge_points(p.domain());
            let mut k =
                PatchKeys { domain: p.domain(), corners: [NONE; 4], edges: [[NONE; 4]; 4], normals: [0; 4] };
            for (i, &c) in corners.iter().enumerate() {
                k.corners[i] = ids[c];
            }
            for (e, edge) in edges.iter().enumerate() {
                k.edges[e] = edge.map(|c| ids[c]);
            }
            keys.push(k);
            kept.push(p);
        }
        let patches = kept;
        let topology = Topology::build(&keys);
        SurfaceSet { patches, keys, topology, repairs, up: Default::default(), origins: Vec::new() }
    }

    /// Builds PN triangles from a triangle mesh.
    ///
    /// Vertices with identical positions at f32 precision are welded (or within `options.weld`); faces that
    /// then repeat a vertex, and faces that repeat an earlier face's vertices, are dropped and
    /// counted in [`Repairs`]. Normals: the file's when
    /// every corner of a face has one, else angle-weighted averages of the face normals.
    ///
    /// Split normals: where the faces around a vertex use different normals, the vertex keeps
    /// one position but every distinct normal gets its own output vertex (same position bits,
    /// so the mesh stays watertight under position welding). An edge whose end normals differ
    /// between its faces is a crease: its inner control points are placed along the crease
    /// tangent `nA × nB` (not in either face's tangent plane) so that both faces get the same
    /// boundary curve.
    pub fn pn_from_mesh(mesh: &PolygonMesh, file: &Path, options: BuildOptions) -> Result<SurfaceSet> {
        let tris = mesh.triangles(file)?;
        let mut repairs = Repairs::default();
        let welded = weld(&mesh.positions, &vec![1.0; mesh.positions.len()], options.weld);
        repairs.welded_points = welded.merged;
        let pos = |i: u32| mesh.positions[welded.ids[i as usize] as usize];

        // Corner normals: from the file where a face has them.
        let normal_welded = weld(&mesh.normals, &vec![1.0; mesh.normals.len()], Weld::Exact);
        let mut faces: Vec<([u32; 3], Option<[u32; 3]>)> = Vec::with_capacity(tris.len());
        let mut seen: std::collections::HashSet<[u32; 3]> = Default::default();
        for (f, t) in mesh.faces.iter().zip(&tris) {
            let v = t.map(|i| welded.ids[i as usize]);
            if v[0] == v[1] || v[1] == v[2] || v[0] == v[2] {
                repairs.dropped_degenerate_faces += 1;
                continue;
            }
            let mut sorted = v;
            sorted.sort_unstable();
            if !seen.insert(sorted) {
                repairs.dropped_duplicate_faces += 1;
                continue;
            }
            let [a, b, c] = v.map(pos);
            if (b - a).cross(c - a) == DVec3::ZERO {
                repairs.dropped_zero_area_faces += 1;
                continue;
            }
            let n = f.normals.as_ref().and_then(|n| {
                let n = [n[0], n[1], n[2]].map(|i| normal_welded.ids[i as usize]);
                n.iter().all(|&i| mesh.normals[i as usize].length_squared() > 0.0).then_some(n)
            });
            faces.push((v, n));
        }
        if faces.is_empty() {
            return Err(Error::unsupported(file, 0, "no usable triangle (every face is degenerate)"));
        }

        let face_normal = |v: [u32; 3]| (pos(v[1]) - pos(v[0])).cross(pos(v[2]) - pos(v[0]));
        let has_file_normals = faces.iter().any(|f| f.1.is_some());
        let mut reverse = false;
        if options.orientation == Orientation::Outward {
            reverse = if has_file_normals {
                // Make the winding agree with the normals the author gave.
                let agree: f64 = faces
                    .iter()
                    .filter_map(|(v, n)| {
                        let n = n.as_ref()?;
                        let avg: DVec3 = n.iter().map(|&i| mesh.normals[i as usize]).sum();
                        Some(face_normal(*v).dot(avg).signum())
                    })
                    .sum();
                agree < 0.0
            } else {
                let centre = bbox_centre(faces.iter().flat_map(|f| f.0.iter().map(|&i| pos(i))));
                let vol: f64 = faces
                    .iter()
                    .map(|(v, _)| {
                        let [a, b, c] = v.map(|i| pos(i) - centre);
                        a.dot(b.cross(c))
                    })
                    .sum();
                vol < 0.0
            };
        }
        // A user flip turns file normals round too; computed normals follow the winding.
        let normal_sign = if options.flip { -1.0 } else { 1.0 };
        if reverse != options.flip {
            repairs.flipped = true;
            for f in &mut faces {
                f.0.swap(1, 2);
                if let Some(n) = &mut f.1 {
                    n.swap(1, 2);
                }
            }
        }

        // Angle-weighted vertex normals for faces without file normals.
        let mut computed = vec![DVec3::ZERO; mesh.positions.len()];
        for (v, _) in &faces {
            let p = v.map(pos);
            let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            for c in 0..3 {
                let a = (p[(c + 1) % 3] - p[c]).normalize_or_zero();
                let b = (p[(c + 2) % 3] - p[c]).normalize_or_zero();
                let angle = a.dot(b).clamp(-1.0, 1.0).acos();
                computed[v[c] as usize] += n * angle;
            }
        }
        let corner_normal = |f: &([u32; 3], Option<[u32; 3]>), c: usize| -> (DVec3, u32) {
            match f.1 {
                Some(n) => ((mesh.normals[n[c] as usize] * normal_sign).normalize(), n[c] + 1),
                None => {
                    let v = f.0[c];
                    let n = computed[v as usize].try_normalize().or_else(|| face_normal(f.0).try_normalize());
                    (n.unwrap_or(DVec3::Z), 0)
                }
            }
        };

        let keys: Vec<PatchKeys> = faces
            .iter()
            .map(|f| PatchKeys {
                domain: Domain::Tri,
                corners: [f.0[0], f.0[1], f.0[2], NONE],
                edges: [0, 1, 2, 3].map(|e| {
                    if e < 3 {
                        [f.0[e], NONE, NONE, f.0[(e + 1) % 3]]
                    } else {
                        [NONE; 4]
                    }
                }),
                normals: [corner_normal(f, 0).1, corner_normal(f, 1).1, corner_normal(f, 2).1, 0],
            })
            .collect();
        let topology = Topology::build(&keys);

        // Agreed inner control points per canonical edge: [near start, near end].
        let mut edge_points: Vec<[DVec3; 2]> = Vec::with_capacity(topology.edges.len());
        for (e, edge) in topology.edges.iter().enumerate() {
            let ends = [edge.key[0], edge.key[3]];
            let mut inner = [DVec3::ZERO; 2];
            for side in 0..2 {
                let (here, there) = (pos(ends[side]), pos(ends[1 - side]));
                // The normals the edge's faces use at this end, distinct by key.
                let mut normals: Vec<(u32, DVec3)> = Vec::new();
                for u in topology.edge_uses(e) {
                    let f = &faces[u.patch as usize];
                    let corner = (0..3).find(|&c| f.0[c] == ends[side]).unwrap_or(0);
                    let (n, key) = corner_normal(f, corner);
                    if !normals.iter().any(|&(k, _)| k == key) {
                        normals.push((key, n));
                    }
                }
                inner[side] = match normals.as_slice() {
                    [(_, n)] => pn_triangle::pn_edge_points(here, *n, there, *n)[0],
                    [(_, a), (_, b), ..] => match a.cross(*b).try_normalize() {
                        Some(t) => pn_triangle::crease_edge_point(here, there, t),
                        None => {
                            let n = (*a + *b).normalize_or_zero();
                            pn_triangle::pn_edge_points(here, n, there, n)[0]
                        }
                    },
                    [] => here + (there - here) / 3.0,
                };
            }
            edge_points.push(inner);
        }

        let patches = faces
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let p = f.0.map(pos);
                let n = [0, 1, 2].map(|c| corner_normal(f, c).0);
                let e = [0, 1, 2].map(|l| {
                    let pe = topology.patch_edges[i][l];
                    let [a, b] = edge_points[pe.edge as usize];
                    if pe.reversed {
                        [b, a]
                    } else {
                        [a, b]
                    }
                });
                Patch::Pn(PnTriangle::from_edge_points(p, n, e))
            })
            .collect();
        Ok(SurfaceSet { patches, keys, topology, repairs, up: Default::default(), origins: Vec::new() })
    }

    /// Axis-aligned bounds of all control points (the surface lies inside them).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for p in &self.patches {
            for &c in p.control_points() {
                lo = lo.min(c);
                hi = hi.max(c);
            }
        }
        (lo, hi)
    }
}

/// Number of distinct corner normals per vertex, for reports.
pub fn split_normal_vertices(set: &SurfaceSet) -> usize {
    let mut per_vertex: HashMap<u32, u32> = HashMap::new();
    for e in &set.topology.corner_entries {
        *per_vertex.entry(e.vertex).or_default() += 1;
    }
    per_vertex.values().filter(|&&c| c > 1).count()
}
