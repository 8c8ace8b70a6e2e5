//! The CPU engine: count → exclusive scan → parallel write (rayon).
//!
//! Output vertex layout: the corner entries of the topology first (one per vertex and normal
//! variant), then every edge's inner samples (`segments − 1` per normal variant), then every
//! patch's interior vertices. Counts are known before anything is evaluated, so each task
//! writes its own disjoint slice. A shared edge's inner vertices are evaluated once, by the
//! edge's owner patch, and every patch on the edge indexes them: the mesh is watertight bit
//! for bit without welding. Split-normal variants copy the owner's position bits and take
//! their normal from a patch of their own variant.

use crate::criterion::Plan;
use crate::error::{Error, Result};
use crate::mesh::strips::RESTART;
use crate::mesh::Mesh;
use crate::pattern::{LocalTessellation, Pattern, PatternInput, Slot};
use crate::surface::{Domain, SurfaceSet};
use glam::DVec2;
use rayon::prelude::*;

pub mod render_queues;
mod uniform_quads;

/// Engine options.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TessellateOptions {
    /// Fill [`Mesh::corner_params`] (needed to measure the approximation error).
    pub corner_params: bool,
    /// Refuse (with [`Error::OutputTooLarge`]) an output whose buffers would take more bytes
    /// than this, before allocating anything. `None`: no limit beyond the u32 index range.
    pub memory_limit: Option<u64>,
    /// Refuse (with [`Error::OutputTooLarge`]) an output of more triangles than this, before
    /// allocating anything. `None`: no limit.
    pub max_triangles: Option<u64>,
    /// Also fill [`Mesh::strips`], for patterns with a strip form ([`Pattern::strips`]);
    /// an error for the others.
    pub strips: bool,
}

/// Bytes the engine allocates for an output of this size (records, buffers, parameters).
pub fn output_bytes(vertices: u64, triangles: u64, corner_params: bool) -> u64 {
    let per_vertex = 2 * std::mem::size_of::<VertexRecord>() as u64; // records + final buffers
    let per_triangle = 12 + 4 + if corner_params { 24 } else { 0 };
    vertices.saturating_mul(per_vertex).saturating_add(triangles.saturating_mul(per_triangle))
}

#[derive(Clone, Copy, Default)]
struct VertexRecord {
    position: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
    patch: u32,
}

fn record(set: &SurfaceSet, patch: u32, uv: DVec2) -> VertexRecord {
    let p = set.patches[patch as usize].eval(uv);
    VertexRecord {
        position: p.position.as_vec3().to_array(),
        normal: p.normal.as_vec3().to_array(),
        uv: uv.as_vec2().to_array(),
        patch,
    }
}

/// Splits `data` into consecutive slices of the given lengths.
fn split_by_counts<'a, T>(mut data: &'a mut [T], counts: &[usize]) -> Vec<&'a mut [T]> {
    let mut out = Vec::with_capacity(counts.len());
    for &c in counts {
        let (head, tail) = data.split_at_mut(c);
        out.push(head);
        data = tail;
    }
    out
}

fn exclusive_scan(counts: &[usize]) -> (Vec<usize>, usize) {
    let mut offsets = Vec::with_capacity(counts.len());
    let mut sum = 0usize;
    for &c in counts {
        offsets.push(sum);
        sum += c;
    }
    (offsets, sum)
}

/// Per-patch mapping from local vertex indices to output vertices.
struct LocalMap<'a> {
    set: &'a SurfaceSet,
    plan: &'a Plan,
    input: PatternInput,
    patch: usize,
    edge_base: &'a [usize],
    interior_base: usize,
}

impl LocalMap<'_> {
    fn corner_vertex(&self, c: usize) -> u32 {
        self.set.topology.patch_corner_entries[self.patch][c]
    }

    /// Output vertex of local index `l`.
    fn vertex(&self, l: u32) -> u32 {
        match self.input.slot(l) {
            Slot::Corner(c) => self.corner_vertex(c),
            Slot::Interior(j) => (self.interior_base + j as usize) as u32,
            Slot::Edge(e, k) => {
                let pe = self.set.topology.patch_edges[self.patch][e];
                if self.set.topology.edges[pe.edge as usize].collapsed {
                    // Every sample of a collapsed curve is its single point: the corner.
                    return self.corner_vertex(e);
                }
                let segments = self.plan.edges[pe.edge as usize].segments();
                let kc = if pe.reversed { segments - k } else { k };
                let base = self.edge_base[pe.edge as usize] + pe.variant as usize * (segments as usize - 1);
                (base + kc as usize - 1) as u32
            }
        }
    }

    /// Parameters of local index `l` in this patch.
    fn param(&self, l: u32, local: &LocalTessellation) -> DVec2 {
        let d = self.input.domain;
        match self.input.slot(l) {
            Slot::Corner(c) => d.corner(c),
            Slot::Interior(j) => local.interior[j as usize],
            Slot::Edge(e, k) => {
                let pe = self.set.topology.patch_edges[self.patch][e];
                d.edge_point(e, self.plan.edges[pe.edge as usize].local_param(k, pe.reversed))
            }
        }
    }
}

fn pattern_input(set: &SurfaceSet, plan: &Plan, p: usize) -> PatternInput {
    let domain = set.patches[p].domain();
    let mut segments = [1; 4];
    let mut factors = [1.0; 4];
    for e in 0..domain.corner_count() {
        let sampling = &plan.edges[set.topology.patch_edges[p][e].edge as usize];
        segments[e] = sampling.segments();
        factors[e] = sampling.factor();
    }
    let collapsed = collapsed_edges(set, p);
    PatternInput { domain, segments, interior: plan.interior[p], factors, patch: p as u32, collapsed }
}

/// [`PatternInput::collapsed`] of patch `p`: which of its edges are boundary curves collapsed
/// to a point. Whoever builds a patch's pattern to predict the engine's output (the error-
/// bounded criteria) passes these too, or it predicts another triangulation. Cost: O(1).
pub(crate) fn collapsed_edges(set: &SurfaceSet, p: usize) -> [bool; 4] {
    let mut collapsed = [false; 4];
    for (e, c) in collapsed.iter_mut().enumerate().take(set.patches[p].domain().corner_count()) {
        *c = set.topology.edges[set.topology.patch_edges[p][e].edge as usize].collapsed;
    }
    collapsed
}

/// True when two corners of the patch are the same vertex (a collapsed curve, or a curve that
/// starts and ends at one point): only then can a pattern triangle degenerate.
fn has_repeated_corner(set: &SurfaceSet, p: usize) -> bool {
    let n = set.patches[p].domain().corner_count();
    let c = &set.topology.patch_corners[p][..n];
    (0..n).any(|i| (i + 1..n).any(|j| c[i] == c[j]))
}

/// Refuses an output of `vertices` and `triangles` that does not fit the index range, the
/// address space or the limits in `options`. Cost: O(1).
pub(crate) fn check_size(vertices: u64, triangles: u64, options: &TessellateOptions) -> Result<()> {
    let bytes = output_bytes(vertices, triangles, options.corner_params);
    if vertices > u32::MAX as u64
        || triangles.saturating_mul(3) > isize::MAX as u64 / 8
        || options.memory_limit.is_some_and(|limit| bytes > limit)
        || options.max_triangles.is_some_and(|limit| triangles > limit)
    {
        return Err(Error::OutputTooLarge { vertices, triangles, bytes });
    }
    Ok(())
}

/// Tessellates `set` with `pattern` following `plan`.
///
/// Preconditions: `plan` was made for `set` (one sampling per edge, one interior entry per
/// patch) and fits the pattern's requirements. Cost: O(output) work, parallel over corners,
/// edges and patches; memory O(output).
pub fn tessellate(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn Pattern,
    options: TessellateOptions,
) -> Result<Mesh> {
    let mut mesh = Mesh::default();
    tessellate_into(set, plan, pattern, options, &mut mesh)?;
    Ok(mesh)
}

/// [`tessellate`] into an existing mesh, whose buffers are reused where the engine can (the
/// uniform bicubic fast path): repeated calls then avoid faulting in fresh memory.
/// `out` is overwritten; on error its contents are unspecified.
pub fn tessellate_into(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn Pattern,
    options: TessellateOptions,
    out: &mut Mesh,
) -> Result<()> {
    if pattern.is_uniform() && !options.strips {
        if let Some(result) = uniform_quads::try_tessellate(set, plan, options, out) {
            out.strips = None;
            out.collapsed_triangles = 0;
            return result;
        }
    }
    *out = tessellate_generic(set, plan, pattern, options)?;
    Ok(())
}

/// The generic engine, for any pattern and surface kind.
fn tessellate_generic(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn Pattern,
    options: TessellateOptions,
) -> Result<Mesh> {
    let topo = &set.topology;
    if plan.edges.len() != topo.edges.len()
        || plan.interior.len() != set.patches.len()
        || plan.visible.len() != set.patches.len()
    {
        return Err(Error::InvalidArgument("plan does not match the surface set".into()));
    }

    // Count.
    let edge_counts: Vec<usize> = topo
        .edges
        .iter()
        .zip(&plan.edges)
        .enumerate()
        .map(|(i, (e, s))| {
            // Edges of culled patches only are not written: nothing refers to them.
            let seen = topo.edge_uses(i).iter().any(|u| plan.visible[u.patch as usize]);
            if e.collapsed || !seen {
                0
            } else {
                (s.segments() as usize - 1) * e.variants as usize
            }
        })
        .collect();
    // Pattern counts first, without building anything: a triangle count is an upper bound
    // (triangles collapsed at a repeated corner are dropped below), so an output that is too
    // large is refused here, before any pattern or buffer of its size exists.
    let upper: Vec<(usize, usize)> = (0..set.patches.len())
        .into_par_iter()
        .map(|p| {
            if !plan.visible[p] {
                return (0, 0);
            }
            let (vi, t) = pattern.counts(&pattern_input(set, plan, p));
            (vi as usize, t as usize)
        })
        .collect();
    let corner_count = topo.corner_entries.len();
    let (edge_offsets, edge_total) = exclusive_scan(&edge_counts);
    let interior_total: usize = upper.iter().map(|c| c.0).sum();
    let upper_triangles: usize = upper.iter().map(|c| c.1).sum();
    check_size((corner_count + edge_total + interior_total) as u64, upper_triangles as u64, &options)?;
    let patch_counts: Vec<(usize, usize)> = upper
        .par_iter()
        .enumerate()
        .map_init(LocalTessellation::default, |scratch, (p, &(vi, t))| {
            if t == 0 || !has_repeated_corner(set, p) {
                return (vi, t);
            }
            // Triangles with two corners on one vertex degenerate; count the ones that remain.
            let input = pattern_input(set, plan, p);
            pattern.build(&input, scratch);
            let map = LocalMap { set, plan, input, patch: p, edge_base: &[], interior_base: 0 };
            let kept = scratch.triangles.iter().filter(|t| !degenerate_after_collapse(&map, t)).count();
            (vi, kept)
        })
        .collect();

    // Scan.
    let interior_counts: Vec<usize> = patch_counts.iter().map(|c| c.0).collect();
    let tri_counts: Vec<usize> = patch_counts.iter().map(|c| c.1).collect();
    let (interior_offsets, interior_total) = exclusive_scan(&interior_counts);
    let (tri_offsets, tri_total) = exclusive_scan(&tri_counts);
    let vertex_total = corner_count + edge_total + interior_total;
    let edge_base: Vec<usize> = edge_offsets.iter().map(|o| corner_count + o).collect();
    let interior_base: Vec<usize> = interior_offsets.iter().map(|o| corner_count + edge_total + o).collect();
    let _ = tri_offsets;

    // Write vertices: corners, edges, interiors, each a disjoint range.
    let mut records = vec![VertexRecord::default(); vertex_total];
    let (corner_part, rest) = records.split_at_mut(corner_count);
    let (edge_part, interior_part) = rest.split_at_mut(edge_total);

    corner_part.par_iter_mut().enumerate().for_each(|(i, r)| {
        let e = &topo.corner_entries[i];
        let d = set.patches[e.owner_patch as usize].domain();
        *r = record(set, e.owner_patch, d.corner(e.owner_corner as usize));
    });
    // Split-normal entries take the position bits of their vertex's first entry.
    for i in 0..corner_count {
        let src = topo.corner_entries[i].position_entry as usize;
        if src != i {
            corner_part[i].position = corner_part[src].position;
        }
    }

    split_by_counts(edge_part, &edge_counts).into_par_iter().enumerate().for_each(|(e, out)| {
        if out.is_empty() {
            return;
        }
        let sampling = &plan.edges[e];
        let inner = sampling.segments() as usize - 1;
        let uses = topo.edge_uses(e);
        for variant in 0..topo.edges[e].variants as usize {
            let Some(u) = uses.iter().find(|u| u.variant as usize == variant) else { continue };
            let d = set.patches[u.patch as usize].domain();
            for k in 1..=inner {
                let t = sampling.param(k as u32);
                let local_t = if u.reversed { 1.0 - t } else { t };
                let uv = d.edge_point(u.local as usize, local_t);
                let mut r = record(set, u.patch, uv);
                if variant > 0 {
                    r.position = out[k - 1].position;
                }
                out[variant * inner + k - 1] = r;
            }
        }
    });

    // Interiors and triangles, one task per patch.
    let mut indices = vec![0u32; tri_total * 3];
    let mut triangle_patch = vec![0u32; tri_total];
    let mut corner_params = if options.corner_params { vec![[0f32; 2]; tri_total * 3] } else { Vec::new() };
    let tri3: Vec<usize> = tri_counts.iter().map(|c| c * 3).collect();
    let param_counts: Vec<usize> = if options.corner_params { tri3.clone() } else { vec![0; tri3.len()] };
    let interior_slices = split_by_counts(interior_part, &interior_counts);
    let index_slices = split_by_counts(&mut indices, &tri3);
    let patch_slices = split_by_counts(&mut triangle_patch, &tri_counts);
    let param_slices = split_by_counts(&mut corner_params, &param_counts);
    interior_slices
        .into_par_iter()
        .zip(index_slices)
        .zip(patch_slices)
        .zip(param_slices)
        .enumerate()
        .for_each_init(LocalTessellation::default, |scratch, (p, (((verts, idx), tp), params))| {
            if !plan.visible[p] {
                return;
            }
            let input = pattern_input(set, plan, p);
            pattern.build(&input, scratch);
            for (r, &uv) in verts.iter_mut().zip(&scratch.interior) {
                *r = record(set, p as u32, uv);
            }
            let map = LocalMap {
                set,
                plan,
                input,
                patch: p,
                edge_base: &edge_base,
                interior_base: interior_base[p],
            };
            let collapsed = has_repeated_corner(set, p);
            let mut t = 0;
            for tri in &scratch.triangles {
                if collapsed && degenerate_after_collapse(&map, tri) {
                    continue;
                }
                for c in 0..3 {
                    idx[3 * t + c] = map.vertex(tri[c]);
                    if !params.is_empty() {
                        params[3 * t + c] = map.param(tri[c], scratch).as_vec2().to_array();
                    }
                }
                tp[t] = p as u32;
                t += 1;
            }
            debug_assert_eq!(t, tp.len());
        });

    let strips =
        if options.strips { Some(strips_of(set, plan, pattern, &edge_base, &interior_base)?) } else { None };
    let mut mesh = Mesh {
        positions: records.par_iter().map(|r| r.position).collect(),
        normals: records.par_iter().map(|r| r.normal).collect(),
        uvs: records.par_iter().map(|r| r.uv).collect(),
        vertex_patch: records.par_iter().map(|r| r.patch).collect(),
        indices,
        triangle_patch,
        corner_params: None,
        strips,
        collapsed_triangles: upper_triangles - tri_total,
    };
    if options.corner_params {
        mesh.corner_params = Some(corner_params);
    }
    Ok(mesh)
}

/// The strip form of every visible patch, over output vertices, one [`RESTART`] between
/// patches. Triangles that degenerate at collapsed corners get a repeated index, so the
/// decoder drops them just as the list writer does.
fn strips_of(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn Pattern,
    edge_base: &[usize],
    interior_base: &[usize],
) -> Result<Vec<u32>> {
    let per_patch: Vec<Option<Vec<u32>>> = (0..set.patches.len())
        .into_par_iter()
        .map(|p| {
            if !plan.visible[p] {
                return Some(Vec::new());
            }
            let input = pattern_input(set, plan, p);
            let mut local = Vec::new();
            if !pattern.strips(&input, &mut local) {
                return None;
            }
            let map = LocalMap { set, plan, input, patch: p, edge_base, interior_base: interior_base[p] };
            for l in &mut local {
                if *l != RESTART {
                    *l = map.vertex(*l);
                }
            }
            Some(local)
        })
        .collect();
    let mut out = Vec::new();
    for strips in per_patch {
        let Some(strips) = strips else {
            return Err(Error::InvalidArgument("this scheme has no triangle-strip form".into()));
        };
        if strips.is_empty() {
            continue;
        }
        if !out.is_empty() {
            out.push(RESTART);
        }
        out.extend_from_slice(&strips);
    }
    Ok(out)
}

/// True when two corners of a pattern triangle land on the same output vertex because they lie
/// on a collapsed boundary curve (or at its ends). Decided from local indices only, so the
/// count pass and the write pass agree.
fn degenerate_after_collapse(map: &LocalMap<'_>, tri: &[u32; 3]) -> bool {
    // Corners and samples of collapsed curves are identified by their vertex; every other
    // local index is a distinct vertex of its own.
    let id = |l: u32| -> (bool, u32) {
        match map.input.slot(l) {
            Slot::Corner(c) => (true, map.corner_vertex(c)),
            Slot::Edge(e, _)
                if map.set.topology.edges[map.set.topology.patch_edges[map.patch][e].edge as usize]
                    .collapsed =>
            {
                (true, map.corner_vertex(e))
            }
            _ => (false, l),
        }
    };
    let [a, b, c] = tri.map(id);
    a == b || b == c || a == c
}

/// Number of triangles the uniform pattern gives a domain at factor `n` (for reports).
pub fn uniform_triangles(domain: Domain, n: u32) -> u64 {
    match domain {
        Domain::Quad => 2 * n as u64 * n as u64,
        Domain::Tri => n as u64 * n as u64,
    }
}
