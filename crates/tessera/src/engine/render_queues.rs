//! The instanced form of the semi-uniform scheme (paper 000, §4): the `M + 1` static
//! patterns `P^m` and the per-level *render queues*.
//!
//! On a GPU, every patch of level `m` is drawn by one instanced draw of the static `P^m`; a
//! vertex shader fetches the instance's queue entry (patch id and the levels of its edges),
//! snaps the pattern's boundary vertices with `φ` and evaluates the patch. Degenerate
//! triangles are left in and discarded by the rasteriser. This module builds that form and
//! draws it on the CPU exactly as the shader would, as the reference the GPU engine is
//! tested against; the compacted indexed mesh comes from the engine with
//! [`SemiUniform`](crate::pattern::semi_uniform::SemiUniform).
//!
//! The static patterns `P^m` and the snap `φ` are the pattern side, in
//! [`crate::pattern::semi_uniform`] (`StaticPattern`, `snap`).
//!
//! **Render queues** are built by counting and an exclusive scan per level, the prefix-sum
//! alternative to the HistoPyramid that §4.1 mentions: each patch's level is computed, a
//! parallel histogram counts the patches per level, an exclusive scan of the counts gives
//! each queue's range in one buffer, and a second, chunked pass writes every patch at its
//! level's offset plus its rank among the earlier patches of that level (itself an exclusive
//! scan, over chunks). The queues come out sorted by patch id, whatever the thread count.

use crate::criterion::Plan;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::surface::{Domain, SurfaceSet};
use rayon::prelude::*;

pub use crate::pattern::semi_uniform::MAX_LEVEL;
use crate::pattern::semi_uniform::{snap, StaticPattern};

/// One render-queue entry: a patch and the levels of its edges (in the patch's edge order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct QueueEntry {
    pub patch: u32,
    pub edge_levels: [u8; 4],
}

/// The render queues: for each level `m = 0..=M`, the patches of level `m`, stored as one
/// buffer with per-level ranges (`offsets[m]..offsets[m + 1]`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RenderQueues {
    pub entries: Vec<QueueEntry>,
    /// `M + 2` offsets: the exclusive scan of the per-level counts, then the total.
    pub offsets: Vec<usize>,
}

impl RenderQueues {
    /// The queue of level `m`.
    pub fn level(&self, m: u32) -> &[QueueEntry] {
        &self.entries[self.offsets[m as usize]..self.offsets[m as usize + 1]]
    }

    /// The highest level `M` the queues were built for.
    pub fn max_level(&self) -> u32 {
        (self.offsets.len() - 2) as u32
    }
}

/// The level of every patch: `log2` of its interior factor (the paper's `m = max_e p_e`, or
/// more where a tolerance plan raised the interior). Errors for a plan that is not dyadic.
fn patch_levels(set: &SurfaceSet, plan: &Plan, max_level: u32) -> Result<Vec<Option<u8>>> {
    let topo = &set.topology;
    (0..set.patches.len())
        .map(|p| {
            if !plan.is_visible(p) {
                return Ok(None);
            }
            let n = plan.interior[p][0];
            let nc = set.topology.patch_domains[p].corner_count();
            let edges_ok = (0..nc).all(|e| {
                let s = plan.segments(topo.patch_edges[p][e].edge as usize);
                s.is_power_of_two() && s <= n
            });
            if !n.is_power_of_two() || n.trailing_zeros() > max_level || !edges_ok {
                return Err(Error::PlanMismatch {
                    what: format!(
                        "patch {p}: the render queues need a dyadic plan with levels up to {max_level} \
                         (interior {n}); use the semi-uniform scheme"
                    ),
                });
            }
            Ok(Some(n.trailing_zeros() as u8))
        })
        .collect()
}

/// Builds the render queues of a dyadic plan (from [`crate::scheme::Scheme::SemiUniform`])
/// for levels `0..=max_level`; culled patches are in no queue. Cost: O(P) work in parallel.
pub fn build(set: &SurfaceSet, plan: &Plan, max_level: u32) -> Result<RenderQueues> {
    if max_level > MAX_LEVEL {
        return Err(Error::InvalidParameter {
            name: "render queues",
            reason: format!("level {max_level} beyond {MAX_LEVEL}"),
        });
    }
    let levels = patch_levels(set, plan, max_level)?;
    let buckets = max_level as usize + 1;
    const CHUNK: usize = 4096;
    // Count: a histogram per chunk of patches.
    let chunk_counts: Vec<Vec<usize>> = levels
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut c = vec![0usize; buckets];
            for m in chunk.iter().flatten() {
                c[*m as usize] += 1;
            }
            c
        })
        .collect();
    // Scan: per level over the chunks, and the levels over each other.
    let mut offsets = Vec::with_capacity(buckets + 1);
    let mut chunk_starts = vec![vec![0usize; buckets]; chunk_counts.len()];
    let mut total = 0usize;
    for m in 0..buckets {
        offsets.push(total);
        for (c, counts) in chunk_counts.iter().enumerate() {
            chunk_starts[c][m] = total;
            total += counts[m];
        }
    }
    offsets.push(total);
    // Write: each chunk at its own positions.
    let topo = &set.topology;
    let mut entries = vec![QueueEntry { patch: 0, edge_levels: [0; 4] }; total];
    let placed: Vec<Vec<(usize, QueueEntry)>> = levels
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let mut next = chunk_starts[c].clone();
            let mut out = Vec::new();
            for (i, m) in chunk.iter().enumerate() {
                let Some(m) = m else { continue };
                let p = c * CHUNK + i;
                let mut edge_levels = [0u8; 4];
                for (e, l) in
                    edge_levels.iter_mut().enumerate().take(set.topology.patch_domains[p].corner_count())
                {
                    *l = plan.segments(topo.patch_edges[p][e].edge as usize).trailing_zeros() as u8;
                }
                out.push((next[*m as usize], QueueEntry { patch: p as u32, edge_levels }));
                next[*m as usize] += 1;
            }
            out
        })
        .collect();
    for (slot, entry) in placed.into_iter().flatten() {
        entries[slot] = entry;
    }
    Ok(RenderQueues { entries, offsets })
}

/// Draws the instanced form on the CPU as the GPU does: for every level and every queue
/// entry, all of `P^m`'s vertices through `F ∘ φ` and all its triangles, degenerate ones
/// included. `patterns[d][m]` must be `P^m` of domain `d` (`0` = triangles, `1` = quads;
/// see [`StaticPattern::all`]). Each instance evaluates its own vertices, so positions on a
/// shared edge agree to rounding, not bit for bit; the compacted engine output is the
/// bit-exact one. Cost: O(Σ 4^m) evaluations.
pub fn draw(set: &SurfaceSet, queues: &RenderQueues, patterns: &[Vec<StaticPattern>; 2]) -> Mesh {
    let max = queues.max_level();
    let instances: Vec<(u32, QueueEntry)> =
        (0..=max).flat_map(|m| queues.level(m).iter().map(move |e| (m, *e))).collect();
    let parts: Vec<Mesh> = instances
        .par_iter()
        .map(|&(m, entry)| {
            let patch = &set.patches[entry.patch as usize];
            let domain = patch.domain();
            let pattern = &patterns[usize::from(domain == Domain::Quad)][m as usize];
            let mut part = Mesh::default();
            for v in &pattern.vertices {
                let uv = snap(domain, v, entry.edge_levels);
                let point = patch.eval(uv);
                part.positions.push(point.position.as_vec3().to_array());
                part.normals.push(point.normal.as_vec3().to_array());
                part.uvs.push(uv.as_vec2().to_array());
                part.vertex_patch.push(entry.patch);
            }
            part.indices = pattern.triangles.iter().flatten().copied().collect();
            part.triangle_patch = vec![entry.patch; pattern.triangles.len()];
            part
        })
        .collect();
    let mut mesh = Mesh::default();
    for part in parts {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(part.positions);
        mesh.normals.extend(part.normals);
        mesh.uvs.extend(part.uvs);
        mesh.vertex_patch.extend(part.vertex_patch);
        mesh.indices.extend(part.indices.iter().map(|i| i + base));
        mesh.triangle_patch.extend(part.triangle_patch);
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pattern::semi_uniform::snap_index;

    #[test]
    fn shader_snap_equals_the_exact_snap() {
        for domain in [Domain::Tri, Domain::Quad] {
            for m in 0..=6 {
                let pattern = StaticPattern::new(domain, m);
                let n = 1u32 << m;
                for v in &pattern.vertices {
                    let Some(e) = v.edge else { continue };
                    let k = (v.t * n as f32).round() as u32;
                    for p in 0..=m {
                        let mut levels = [0u8; 4];
                        levels[e as usize] = p as u8;
                        let got = snap(domain, v, levels);
                        let t = snap_index(p, m, k) as f64 / (1u64 << p) as f64;
                        let want = domain.edge_point(e as usize, t);
                        assert_eq!(got, want, "{domain:?} m={m} p={p} k={k}");
                    }
                }
            }
        }
    }

    #[test]
    fn static_patterns_have_uniform_counts() {
        for m in 0..=5 {
            let n = 1usize << m;
            let t = StaticPattern::new(Domain::Tri, m);
            assert_eq!((t.vertices.len(), t.triangles.len()), ((n + 1) * (n + 2) / 2, n * n));
            let q = StaticPattern::new(Domain::Quad, m);
            assert_eq!((q.vertices.len(), q.triangles.len()), ((n + 1) * (n + 1), 2 * n * n));
            // Corners and interior points are never tagged; the others are, on their edge.
            for v in &q.vertices {
                let on_boundary = v.uv.iter().any(|&x| x == 0.0 || x == 1.0);
                let corner = v.uv.iter().all(|&x| x == 0.0 || x == 1.0);
                assert_eq!(v.edge.is_some(), on_boundary && !corner, "{v:?}");
            }
        }
    }
}
