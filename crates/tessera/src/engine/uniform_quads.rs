//! Fast path of the CPU engine: polynomial bicubic patches at one uniform factor `n`.
//!
//! This is the engine's heaviest common job (a dense uniform mesh of a patch model), and the
//! generic path pays for its generality at every vertex: a pattern builds local triangles, each
//! local index is decoded into a corner, edge or interior slot, every vertex is evaluated on
//! its own in f64 with the rational formula, and the vertices go through a record buffer that
//! is scattered into the mesh in a second pass. Here the layout is known in closed form, so
//! none of that is needed.
//!
//! **Same mesh.** The output is the generic engine's, element for element: the corner entries
//! first, then each edge's `n − 1` inner samples in topology order and canonical orientation,
//! then each patch's `(n − 1)²` interior vertices row by row; two triangles per grid cell, split
//! along the `(i, j) → (i+1, j+1)` diagonal, in the uniform pattern's order. Every count and
//! offset follows from `n` and the topology's sizes, so each task writes its own disjoint slice
//! of the final buffers directly. Vertex and triangle indices come from a few arithmetic cases
//! (corner, one of four edges read forwards or backwards, interior) instead of per-triangle
//! slot decoding. `uvs`, `vertex_patch`, `triangle_patch` and `corner_params` are computed
//! with the generic path's own f64 formulas and rounded the same way, so they are identical.
//!
//! **Watertight by construction, as in the generic path.** Each corner and each edge sample is
//! evaluated once, by its owner patch, and every patch on it refers to it by index; no
//! position is ever computed twice, so neighbours meet bit for bit.
//!
//! **Positions and normals** differ from the generic f64 evaluation only by rounding. The
//! Bernstein basis of the `n + 1` parameters `i / n` is the same for every patch, so it is
//! tabulated once. A patch is moved to a local frame (its control points minus their bounding
//! box centre, divided by a power of two) and rounded to f32 there: f32 then carries the
//! patch's own detail at full relative precision, whatever the model's size or offset, and the
//! final `origin + scale · local` only adds rounding at the output's own magnitude. A row (or,
//! for edges along `v`, a column) is reduced to a cubic curve and its cross derivative once;
//! its points are then evaluated [`LANES`] at a time in structure-of-arrays form, which the
//! compiler vectorizes. Where the derivatives are nearly parallel (a pole, or a pinched
//! corner), f32 would lose the normal's direction, so such points take the generic f64
//! evaluation instead ([`MIN_SIN2`]).
//!
//! **Kernels.** The evaluation and index kernels are written once, generic over whether
//! multiply-adds are fused, and compiled twice: for the baseline target (SSE2 on x86-64) and,
//! on x86-64 CPUs that have them, for AVX2 and FMA, chosen at run time. The wider registers
//! hold a whole block of lanes and remove the spills of the baseline build (about 1.5× less
//! time per vertex on one core). Calling the AVX2 build is the module's only `unsafe`.
//!
//! **Work split.** Everything is written in one parallel pass without barriers: the corners
//! and edges beside tasks of whole grid rows of about [`TASK_TRIANGLES`] triangles (a few
//! patches each at moderate factors, part of a patch at large ones), so both cores stay busy
//! whatever the patch count. A task's rows are one contiguous range of every output buffer,
//! split off the final `Mesh` buffers before the pass: no intermediate records, no second
//! scatter pass, no allocation per patch or vertex.
//!
//! The path applies when every patch is a visible polynomial bicubic (culling leaves gaps in
//! the layout), every edge is sampled `Uniform { n }` and every interior factor is `[n, n]`,
//! no edge is collapsed, no patch repeats a corner (so no triangle degenerates and none is
//! dropped), and every edge has one normal variant. Otherwise, and also when the generic path
//! would refuse the output's size (so that it reports the error), it declines and the generic
//! path runs.

use super::TessellateOptions;
use crate::criterion::Plan;
use crate::error::Result;
use crate::mesh::Mesh;
use crate::sampling::EdgeSampling;
use crate::surface::{Domain, Patch, RationalBicubic, SurfacePoint, SurfaceSet};
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// Points evaluated together: 8 f32 lanes fill one AVX register (two SSE registers).
const LANES: usize = 8;

/// Below this squared sine of the angle between `∂S/∂u` and `∂S/∂v`, the f32 cross product
/// no longer gives the normal to about 1e-5, and the point is evaluated in f64.
const MIN_SIN2: f32 = 1e-4;

/// Aim for tasks of about this many triangles: small enough for both cores to share the work
/// of a few patches, large enough that scheduling costs nothing.
const TASK_TRIANGLES: usize = 4096;

/// Tessellates `set` with the uniform pattern, or returns `None` when the fast path does not
/// apply (see the module doc), leaving `out` untouched.
///
/// `out` is overwritten; its allocations are reused, so a caller that tessellates repeatedly
/// into the same mesh avoids page faults on fresh memory. Cost: O(output), parallel.
pub(crate) fn try_tessellate(
    set: &SurfaceSet,
    plan: &Plan,
    options: TessellateOptions,
    out: &mut Mesh,
) -> Option<Result<()>> {
    tessellate_with(set, plan, options, out, has_avx2_fma())
}

/// [`try_tessellate`] with the kernels chosen by the caller (`avx2_fma` only where the CPU
/// has both).
fn tessellate_with(
    set: &SurfaceSet,
    plan: &Plan,
    options: TessellateOptions,
    out: &mut Mesh,
    avx2_fma: bool,
) -> Option<Result<()>> {
    let n = uniform_factor(set, plan)?;
    let sizes = Sizes::new(set, n, options)?;
    let ctx = Context::new(set, n, options.corner_params, avx2_fma);
    let Sizes { corners, edge_vertices, interior_vertices, triangles } = sizes;
    let vertices = corners + edge_vertices + interior_vertices;

    reuse(&mut out.positions, vertices, [0.0; 3]);
    reuse(&mut out.normals, vertices, [0.0; 3]);
    reuse(&mut out.uvs, vertices, [0.0; 2]);
    reuse(&mut out.vertex_patch, vertices, 0);
    reuse(&mut out.indices, 3 * triangles, 0);
    reuse(&mut out.triangle_patch, triangles, 0);
    let mut no_params = Vec::new();
    let params = if options.corner_params {
        let params = out.corner_params.get_or_insert_with(Vec::new);
        reuse(params, 3 * triangles, [0.0; 2]);
        params
    } else {
        out.corner_params = None;
        &mut no_params
    };

    let (corner_pos, rest) = out.positions.split_at_mut(corners);
    let (edge_pos, interior_pos) = rest.split_at_mut(edge_vertices);
    let (corner_nrm, rest) = out.normals.split_at_mut(corners);
    let (edge_nrm, interior_nrm) = rest.split_at_mut(edge_vertices);
    let (corner_uv, rest) = out.uvs.split_at_mut(corners);
    let (edge_uv, interior_uv) = rest.split_at_mut(edge_vertices);
    let (corner_vp, rest) = out.vertex_patch.split_at_mut(corners);
    let (edge_vp, interior_vp) = rest.split_at_mut(edge_vertices);
    let corner_part = VertexSlices { pos: corner_pos, nrm: corner_nrm, uv: corner_uv, patch: corner_vp };
    let edge_part = VertexSlices { pos: edge_pos, nrm: edge_nrm, uv: edge_uv, patch: edge_vp };
    let row_tasks = ctx.row_tasks(
        VertexSlices { pos: interior_pos, nrm: interior_nrm, uv: interior_uv, patch: interior_vp },
        &mut out.indices,
        &mut out.triangle_patch,
        params,
    );

    // Corners and edges are small; running them beside the patch rows lets the two cores
    // share one pool of work instead of waiting for each other at a barrier in between.
    rayon::join(
        || {
            ctx.corners(corner_part);
            ctx.edges(edge_part);
        },
        || {
            row_tasks.into_par_iter().for_each_init(|| Scratch::new(ctx.n), |s, task| ctx.rows(task, s));
        },
    );
    Some(Ok(()))
}

/// The factor `n` when the fast path applies to `set` and `plan` (see the module doc).
fn uniform_factor(set: &SurfaceSet, plan: &Plan) -> Option<u32> {
    let topo = &set.topology;
    if plan.edges.len() != topo.edges.len()
        || plan.interior.len() != set.patches.len()
        || plan.visible.len() != set.patches.len()
    {
        return None; // The generic path reports the mismatch.
    }
    let n = plan.interior.first()?[0];
    let applies = n >= 1
        && plan.visible.iter().all(|&v| v)
        && plan.interior.iter().all(|&f| f == [n, n])
        && plan.edges.iter().all(|s| *s == EdgeSampling::Uniform { segments: n })
        && topo.edges.iter().all(|e| !e.collapsed && e.variants == 1)
        && set.patches.iter().all(|p| matches!(p, Patch::Bicubic(b) if b.is_polynomial()))
        && (0..set.patches.len()).all(|p| !super::has_repeated_corner(set, p));
    applies.then_some(n)
}

/// Element counts of the output.
struct Sizes {
    corners: usize,
    edge_vertices: usize,
    interior_vertices: usize,
    triangles: usize,
}

impl Sizes {
    /// `None` when the generic path would refuse the output, so that it reports why.
    fn new(set: &SurfaceSet, n: u32, options: TessellateOptions) -> Option<Sizes> {
        let (n, m) = (n as u64, n as u64 - 1);
        let corners = set.topology.corner_entries.len() as u64;
        let edge_vertices = (set.topology.edges.len() as u64).checked_mul(m)?;
        let interior_vertices = (set.patches.len() as u64).checked_mul(m.checked_mul(m)?)?;
        let triangles = (set.patches.len() as u64).checked_mul(n.checked_mul(2 * n)?)?;
        let vertices = corners.checked_add(edge_vertices)?.checked_add(interior_vertices)?;
        super::check_size(vertices, triangles, &options).ok()?;
        Some(Sizes {
            corners: corners as usize,
            edge_vertices: edge_vertices as usize,
            interior_vertices: interior_vertices as usize,
            triangles: triangles as usize,
        })
    }
}

/// Makes `v` hold `len` elements, every one of which the caller then overwrites.
fn reuse<T: Copy>(v: &mut Vec<T>, len: usize, zero: T) {
    if v.capacity() < len {
        // A fresh zeroed allocation arrives as lazily zeroed pages: nothing is written here,
        // and the parallel pass faults the pages in; growing in place would first fill the
        // whole buffer on one thread.
        *v = Vec::new();
        *v = vec![zero; len];
    } else {
        // Only a grown tail is written here; a buffer of the right length is left as is.
        v.resize(len, zero);
    }
}

/// Parallel vertex buffers of one part of the output.
struct VertexSlices<'a> {
    pos: &'a mut [[f32; 3]],
    nrm: &'a mut [[f32; 3]],
    uv: &'a mut [[f32; 2]],
    patch: &'a mut [u32],
}

impl<'a> VertexSlices<'a> {
    /// Splits off the first `k` vertices.
    fn take_front(&mut self, k: usize) -> VertexSlices<'a> {
        VertexSlices {
            pos: take_front(&mut self.pos, k),
            nrm: take_front(&mut self.nrm, k),
            uv: take_front(&mut self.uv, k),
            patch: take_front(&mut self.patch, k),
        }
    }
}

/// Splits off the first `k` elements of `s`, leaving the rest in `s`.
fn take_front<'a, T>(s: &mut &'a mut [T], k: usize) -> &'a mut [T] {
    let (head, tail) = std::mem::take(s).split_at_mut(k);
    *s = tail;
    head
}

/// Cubic Bernstein polynomials and their derivatives at `t`, in f64 (rounded once to f32 by
/// the caller).
fn bernstein3(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    let b = [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t];
    let d = [-3.0 * s * s, 3.0 * s * (s - 2.0 * t), 3.0 * t * (2.0 * s - t), 3.0 * t * t];
    (b, d)
}

/// `B_k(i / n)` and `B_k'(i / n)` for `i = 0..=n`, padded by [`LANES`] copies of the values at
/// `n`, so that a block of lanes may start at any `i ≤ n` and its spare lanes hold a real point
/// (whose result is ignored, but which does not spoil [`Block::all_ok`]).
struct Basis {
    b: [Vec<f32>; 4],
    d: [Vec<f32>; 4],
    /// `at[i] = ([B_k(i / n)], [B_k'(i / n)])`, for setting up lines.
    at: Vec<([f32; 4], [f32; 4])>,
}

impl Basis {
    fn new(n: usize) -> Basis {
        let len = n + 1 + LANES;
        let mut basis = Basis {
            b: std::array::from_fn(|_| vec![0.0; len]),
            d: std::array::from_fn(|_| vec![0.0; len]),
            at: Vec::new(),
        };
        for i in 0..len {
            // The edge sampling's parameters: exactly 1 at the end.
            let (b, d) = bernstein3(EdgeSampling::Uniform { segments: n as u32 }.param(i.min(n) as u32));
            for k in 0..4 {
                basis.b[k][i] = b[k] as f32;
                basis.d[k][i] = d[k] as f32;
            }
        }
        basis.at =
            (0..=n).map(|i| (basis.b.each_ref().map(|b| b[i]), basis.d.each_ref().map(|d| d[i]))).collect();
        basis
    }
}

/// One patch in a local frame: `P = origin + scale · p`, with `p` within `[-1, 1]³`.
struct LocalPatch {
    origin: [f32; 3],
    scale: f32,
    /// `by_v[c][j][i]`: component `c` of `p_ij` (`i` along `u`, `j` along `v`), so that a
    /// row's curve, a sum over `j`, is a sum of 4-vectors over `i`.
    by_v: [[[f32; 4]; 4]; 3],
}

impl LocalPatch {
    fn new(patch: &RationalBicubic) -> LocalPatch {
        let (lo, hi) = patch
            .points
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &q| (lo.min(q), hi.max(q)));
        let origin = (lo + hi) * 0.5;
        let scale = power_of_two_above(((hi - lo) * 0.5).max_element());
        // Exact: a power of two.
        let inv = 1.0 / scale;
        let mut local =
            LocalPatch { origin: origin.as_vec3().to_array(), scale: scale as f32, by_v: Default::default() };
        for (k, &q) in patch.points.iter().enumerate() {
            let (i, j) = (k / 4, k % 4);
            let q = ((q - origin) * inv).as_vec3().to_array();
            for (c, &x) in q.iter().enumerate() {
                local.by_v[c][j][i] = x;
            }
        }
        local
    }

    /// The curve `v = j / n`: its control points `c_i = Σ_j p_ij B_j(v)` and the cross
    /// derivative's `d_i = Σ_j p_ij B_j'(v)`.
    #[inline(always)]
    fn row(&self, basis: &Basis, j: usize) -> Line {
        Line::new(&self.by_v, basis, j, false)
    }

    /// The curve `u = i / n`, likewise (along `v`, cross derivative `∂/∂u`).
    #[inline(always)]
    fn column(&self, basis: &Basis, i: usize) -> Line {
        // Columns are rare (two edges a patch): transpose here rather than store both forms.
        let by_u = self.by_v.map(|q| std::array::from_fn(|a| std::array::from_fn(|b| q[b][a])));
        Line::new(&by_u, basis, i, true)
    }
}

/// A power of two above `x` (and at most `2x`), kept well inside f32's range; 1 for 0.
fn power_of_two_above(x: f64) -> f64 {
    if x <= 0.0 || !x.is_finite() {
        return 1.0;
    }
    // 2^e ≤ x < 2^(e+1) for the unbiased exponent e of a normal x.
    let e = ((x.to_bits() >> 52) & 0x7ff) as i64 - 1023;
    f64::from_bits((((e + 1).clamp(-100, 100) + 1023) as u64) << 52)
}

/// A grid line of a patch as a cubic Bézier curve in the local frame, with the control points
/// of its cross derivative.
struct Line {
    /// `c[component][k]`.
    c: [[f32; 4]; 3],
    d: [[f32; 4]; 3],
    /// True for a line of constant `u`: the derivative along it is `∂/∂v`.
    column: bool,
}

/// [`LANES`] consecutive points of a line, in structure-of-arrays form.
struct Block {
    pos: [[f32; LANES]; 3],
    nrm: [[f32; LANES]; 3],
    /// Positive where the f32 normal is reliable; elsewhere (zero, negative or NaN) the point
    /// must be evaluated in f64.
    margin: [f32; LANES],
}

impl Block {
    #[inline(always)]
    fn ok(&self, l: usize) -> bool {
        self.margin[l] > 0.0
    }

    /// Every lane is reliable (branch-free, so that it vectorizes).
    #[inline(always)]
    fn all_ok(&self) -> bool {
        self.margin.iter().fold(true, |all, &m| all & (m > 0.0))
    }

    /// Writes lanes `0..pos.len()`, taking `exact(l)` where a lane is unreliable.
    #[inline(always)]
    fn write(&self, pos: &mut [[f32; 3]], nrm: &mut [[f32; 3]], exact: impl Fn(usize) -> SurfacePoint) {
        if self.all_ok() {
            for (l, (pos, nrm)) in pos.iter_mut().zip(nrm).enumerate() {
                *pos = [self.pos[0][l], self.pos[1][l], self.pos[2][l]];
                *nrm = [self.nrm[0][l], self.nrm[1][l], self.nrm[2][l]];
            }
        } else {
            for (l, (pos, nrm)) in pos.iter_mut().zip(nrm).enumerate() {
                store(self, l, pos, nrm, || exact(l));
            }
        }
    }
}

impl Line {
    /// The line at grid index `s` across `q`'s first axis (see [`LocalPatch`]).
    // Index loops mirror the sum `Σ_k q_kt B_k` (and vectorize over `t`).
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn new(q: &[[[f32; 4]; 4]; 3], basis: &Basis, s: usize, column: bool) -> Line {
        let mut line = Line { c: [[0.0; 4]; 3], d: [[0.0; 4]; 3], column };
        let (b, d) = &basis.at[s];
        for c in 0..3 {
            for k in 0..4 {
                let (b, d) = (b[k], d[k]);
                for t in 0..4 {
                    line.c[c][t] += q[c][k][t] * b;
                    line.d[c][t] += q[c][k][t] * d;
                }
            }
        }
        line
    }

    /// Points `t0 .. t0 + LANES` of the grid along the line (past `n`, copies of point `n`).
    #[inline(always)]
    fn block<const FMA: bool>(&self, basis: &Basis, t0: usize, patch: &LocalPatch) -> Block {
        let mut pos = [[0f32; LANES]; 3];
        let mut along = [[0f32; LANES]; 3];
        let mut across = [[0f32; LANES]; 3];
        for k in 0..4 {
            let b: &[f32; LANES] = basis.b[k][t0..t0 + LANES].try_into().unwrap();
            let d: &[f32; LANES] = basis.d[k][t0..t0 + LANES].try_into().unwrap();
            for c in 0..3 {
                let (ck, dk) = (self.c[c][k], self.d[c][k]);
                for l in 0..LANES {
                    pos[c][l] = madd::<FMA>(b[l], ck, pos[c][l]);
                    along[c][l] = madd::<FMA>(d[l], ck, along[c][l]);
                    across[c][l] = madd::<FMA>(b[l], dk, across[c][l]);
                }
            }
        }
        // ∂S/∂u × ∂S/∂v: along × across on a row, across × along on a column. Written as
        // whole-array lane loops, one quantity at a time, so that each becomes SIMD code.
        let sign = if self.column { -1.0 } else { 1.0 };
        let ([ax, ay, az], [cx, cy, cz]) = (along, across);
        let mut nrm = [[0f32; LANES]; 3];
        let [nx, ny, nz] = &mut nrm;
        let mut margin = [0f32; LANES];
        for l in 0..LANES {
            nx[l] = ay[l] * cz[l] - az[l] * cy[l];
            ny[l] = az[l] * cx[l] - ax[l] * cz[l];
            nz[l] = ax[l] * cy[l] - ay[l] * cx[l];
        }
        for l in 0..LANES {
            let n2 = nx[l] * nx[l] + ny[l] * ny[l] + nz[l] * nz[l];
            let a2 = ax[l] * ax[l] + ay[l] * ay[l] + az[l] * az[l];
            let c2 = cx[l] * cx[l] + cy[l] * cy[l] + cz[l] * cz[l];
            // |a × c|² = |a|²|c|² sin²: the angle between the derivatives, scale-free.
            margin[l] = n2 - MIN_SIN2 * (a2 * c2);
            let inv = sign / n2.sqrt();
            nx[l] *= inv;
            ny[l] *= inv;
            nz[l] *= inv;
        }
        for (row, &origin) in pos.iter_mut().zip(&patch.origin) {
            for x in row {
                *x = madd::<FMA>(patch.scale, *x, origin);
            }
        }
        Block { pos, nrm, margin }
    }
}

/// `a · b + c`, fused in the kernels compiled for FMA (elsewhere `mul_add` would be a slow
/// library call). Fusing changes only the rounding.
#[inline(always)]
fn madd<const FMA: bool>(a: f32, b: f32, c: f32) -> f32 {
    if FMA {
        a.mul_add(b, c)
    } else {
        a * b + c
    }
}

/// Writes lane `l` of `block`, or the f64 evaluation `exact()` where the lane is unreliable.
#[inline(always)]
fn store(
    block: &Block,
    l: usize,
    pos: &mut [f32; 3],
    nrm: &mut [f32; 3],
    exact: impl FnOnce() -> SurfacePoint,
) {
    if block.ok(l) {
        *pos = [block.pos[0][l], block.pos[1][l], block.pos[2][l]];
        *nrm = [block.nrm[0][l], block.nrm[1][l], block.nrm[2][l]];
    } else {
        let q = exact();
        *pos = q.position.as_vec3().to_array();
        *nrm = q.normal.as_vec3().to_array();
    }
}

/// The grid line that local edge `e` of a patch runs along, as (row or column, index).
fn edge_line(patch: &LocalPatch, basis: &Basis, n: usize, e: usize) -> Line {
    match e {
        0 => patch.row(basis, 0),
        1 => patch.column(basis, n),
        2 => patch.row(basis, n),
        _ => patch.column(basis, 0),
    }
}

/// A range of grid rows with the output slices they fill. Row `r` is row `r % n` of patch
/// `r / n`: its `2n` triangles and, for rows `j ≥ 1`, interior vertex row `j`.
struct RowTask<'a> {
    rows: std::ops::Range<usize>,
    verts: VertexSlices<'a>,
    indices: &'a mut [u32],
    triangle_patch: &'a mut [u32],
    /// Empty unless corner parameters were asked for.
    params: &'a mut [[f32; 2]],
}

/// Per-task buffers for one grid row's output indices and parameters.
struct Scratch {
    lo: Vec<u32>,
    hi: Vec<u32>,
    lo_uv: Vec<[f32; 2]>,
    hi_uv: Vec<[f32; 2]>,
}

impl Scratch {
    fn new(n: usize) -> Scratch {
        Scratch {
            lo: vec![0; n + 1],
            hi: vec![0; n + 1],
            lo_uv: vec![[0.0; 2]; n + 1],
            hi_uv: vec![[0.0; 2]; n + 1],
        }
    }
}

/// Where a patch's grid points are in the output.
struct PatchMap {
    corners: [u32; 4],
    /// Per local edge: output index of its canonical sample 1, and whether the patch runs
    /// along it reversed.
    edges: [(u32, bool); 4],
    interior: u32,
}

/// True when the CPU has AVX2 and FMA, so the kernels compiled for them may run.
fn has_avx2_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

impl PatchMap {
    /// Output index of the patch's own sample `kp` (`1 ≤ kp < n`) of local edge `e`; the edge
    /// stores its samples in canonical order.
    #[inline(always)]
    fn edge(&self, n: usize, e: usize, kp: usize) -> u32 {
        let (base, rev) = self.edges[e];
        base + (if rev { n - kp } else { kp }) as u32 - 1
    }
}

/// Everything the tasks share.
struct Context<'a> {
    set: &'a SurfaceSet,
    n: usize,
    basis: Basis,
    /// `(i / n)` as the uniform pattern computes interior parameters (`i · (1/n)`), in f64.
    grid: Vec<f64>,
    /// `grid` rounded to f32, the interior vertices' parameters.
    grid32: Vec<f32>,
    /// Per local edge and reversed flag, the f64 parameters of canonical sample `k` in the
    /// owner's domain, as the generic engine evaluates edge vertices.
    edge_uv: [[Vec<DVec2>; 2]; 4],
    /// Per local edge and reversed flag, the f32 parameters of the patch's own sample `k` (its
    /// corner parameters); empty unless asked for.
    edge_params: [[Vec<[f32; 2]>; 2]; 4],
    corner_count: usize,
    /// Every patch in its local frame; each is needed by several tasks (its corners, edges
    /// and rows), so it is made once.
    locals: Vec<LocalPatch>,
    /// Triangles of the inner cells `i = 1..n-1` of a row between interior rows, relative to
    /// the row's first interior vertex (see `triangle_row`).
    cells: Vec<u32>,
    /// Run the kernels compiled for AVX2 and FMA. Only ever true where the CPU has both:
    /// the `unsafe` calls below rely on it.
    avx2_fma: bool,
}

impl<'a> Context<'a> {
    /// Precondition: `avx2_fma` only where [`has_avx2_fma`].
    fn new(set: &'a SurfaceSet, n: u32, corner_params: bool, avx2_fma: bool) -> Context<'a> {
        let sampling = EdgeSampling::Uniform { segments: n };
        let step = 1.0 / n as f64;
        let nu = n as usize;
        let d = Domain::Quad;
        let edge_uv = std::array::from_fn(|e| {
            std::array::from_fn(|rev| {
                (0..=n)
                    .map(|k| {
                        let t = sampling.param(k);
                        d.edge_point(e, if rev == 1 { 1.0 - t } else { t })
                    })
                    .collect()
            })
        });
        let edge_params = std::array::from_fn(|e| {
            std::array::from_fn(|rev| {
                if !corner_params {
                    return Vec::new();
                }
                (0..=n)
                    .map(|k| d.edge_point(e, sampling.local_param(k, rev == 1)).as_vec2().to_array())
                    .collect()
            })
        });
        Context {
            set,
            n: nu,
            basis: Basis::new(nu),
            grid: (0..=nu).map(|i| i as f64 * step).collect(),
            grid32: (0..=nu).map(|i| (i as f64 * step) as f32).collect(),
            edge_uv,
            edge_params,
            corner_count: set.topology.corner_entries.len(),
            locals: set
                .patches
                .par_iter()
                .with_min_len(64)
                .map(|p| match p {
                    Patch::Bicubic(b) => LocalPatch::new(b),
                    _ => unreachable!("the fast path checked that every patch is bicubic"),
                })
                .collect(),
            cells: (1..nu.saturating_sub(1) as u32)
                .flat_map(|i| {
                    let m = n - 1;
                    [i - 1, i, m + i, i - 1, m + i, m + i - 1]
                })
                .collect(),
            avx2_fma: avx2_fma && has_avx2_fma(),
        }
    }

    fn local(&self, p: usize) -> &LocalPatch {
        &self.locals[p]
    }

    /// The generic f64 evaluation, for the rare points f32 cannot resolve.
    #[cold]
    #[inline(never)]
    fn exact(&self, p: usize, uv: DVec2) -> SurfacePoint {
        self.set.patches[p].eval(uv)
    }

    /// Evaluates every corner entry at its owner's corner.
    fn corners(&self, out: VertexSlices<'_>) {
        let topo = &self.set.topology;
        let n = self.n;
        out.pos
            .par_iter_mut()
            .zip(out.nrm.par_iter_mut())
            .zip(out.uv.par_iter_mut())
            .zip(out.patch.par_iter_mut())
            .enumerate()
            .with_min_len(256)
            .for_each(|(i, (((pos, nrm), uv), vp))| {
                let entry = &topo.corner_entries[i];
                let (p, c) = (entry.owner_patch as usize, entry.owner_corner as usize);
                let local = self.local(p);
                let (gi, gj) = [(0, 0), (n, 0), (n, n), (0, n)][c];
                let block = local.row(&self.basis, gj).block::<false>(&self.basis, gi, local);
                let corner = Domain::Quad.corner(c);
                store(&block, 0, pos, nrm, || self.exact(p, corner));
                *uv = corner.as_vec2().to_array();
                *vp = p as u32;
            });
        // Split-normal entries take the position bits of their vertex's first entry (for
        // bicubic patches every vertex has one entry; kept for the layout's contract).
        for (i, e) in topo.corner_entries.iter().enumerate() {
            if e.position_entry as usize != i {
                out.pos[i] = out.pos[e.position_entry as usize];
            }
        }
    }

    /// Evaluates every edge's inner samples with its owner patch, in canonical order.
    fn edges(&self, out: VertexSlices<'_>) {
        let m = self.n - 1;
        if m == 0 {
            return;
        }
        out.pos
            .par_chunks_mut(m)
            .zip(out.nrm.par_chunks_mut(m))
            .zip(out.uv.par_chunks_mut(m))
            .zip(out.patch.par_chunks_mut(m))
            .enumerate()
            .with_min_len(16)
            .for_each(|(e, (((pos, nrm), uv), vp))| self.edge(e, VertexSlices { pos, nrm, uv, patch: vp }));
    }

    fn edge(&self, e: usize, out: VertexSlices<'_>) {
        if self.avx2_fma {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `avx2_fma` is only set where the CPU has AVX2 and FMA (`Context::new`).
            return unsafe { self.edge_avx2_fma(e, out) };
        }
        self.edge_with::<false>(e, out)
    }

    /// [`Context::edge_with`] compiled for AVX2 and FMA (everything it calls is inlined).
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn edge_avx2_fma(&self, e: usize, out: VertexSlices<'_>) {
        self.edge_with::<true>(e, out)
    }

    /// The inner samples of edge `e`, evaluated by its owner.
    #[inline(always)]
    fn edge_with<const FMA: bool>(&self, e: usize, out: VertexSlices<'_>) {
        let owner = self.set.topology.edge_uses(e)[0];
        let (p, local_edge, rev) = (owner.patch as usize, owner.local as usize, owner.reversed);
        let local = self.local(p);
        let line = edge_line(local, &self.basis, self.n, local_edge);
        // The line runs with the patch's grid index; canonical sample k sits at line index k
        // or n − k (edges 2 and 3 run against the grid, reversed edges against the patch).
        let flip = rev ^ (local_edge >= 2);
        let uvs = &self.edge_uv[local_edge][rev as usize];
        for t0 in (1..self.n).step_by(LANES) {
            let block = line.block::<FMA>(&self.basis, t0, local);
            for l in 0..LANES.min(self.n - t0) {
                let t = t0 + l;
                let k = if flip { self.n - t } else { t };
                store(&block, l, &mut out.pos[k - 1], &mut out.nrm[k - 1], || self.exact(p, uvs[k]));
                out.uv[k - 1] = uvs[k].as_vec2().to_array();
            }
        }
        out.patch.fill(p as u32);
    }

    /// Splits the interior and triangle buffers into tasks of whole grid rows.
    fn row_tasks<'b>(
        &self,
        mut verts: VertexSlices<'b>,
        mut indices: &'b mut [u32],
        mut triangle_patch: &'b mut [u32],
        mut params: &'b mut [[f32; 2]],
    ) -> Vec<RowTask<'b>> {
        let (n, m) = (self.n, self.n - 1);
        let total = self.set.patches.len() * n;
        let per_task = TASK_TRIANGLES.div_ceil(2 * n).max(1);
        // Interior vertices before row r: whole patches, then rows 1..j of this one.
        let vertex_offset = |r: usize| (r / n) * m * m + (r % n).saturating_sub(1) * m;
        let mut tasks = Vec::with_capacity(total.div_ceil(per_task));
        let mut r0 = 0;
        while r0 < total {
            let r1 = (r0 + per_task).min(total);
            let triangles = (r1 - r0) * 2 * n;
            tasks.push(RowTask {
                rows: r0..r1,
                verts: verts.take_front(vertex_offset(r1) - vertex_offset(r0)),
                indices: take_front(&mut indices, 3 * triangles),
                triangle_patch: take_front(&mut triangle_patch, triangles),
                params: if params.is_empty() { &mut [] } else { take_front(&mut params, 3 * triangles) },
            });
            r0 = r1;
        }
        tasks
    }

    fn patch_map(&self, p: usize) -> PatchMap {
        let topo = &self.set.topology;
        let m = self.n - 1;
        PatchMap {
            corners: topo.patch_corner_entries[p],
            edges: std::array::from_fn(|e| {
                let pe = topo.patch_edges[p][e];
                ((self.corner_count + pe.edge as usize * m) as u32, pe.reversed)
            }),
            interior: (self.corner_count + topo.edges.len() * m + p * m * m) as u32,
        }
    }

    /// Output indices of grid row `j` (`i = 0..=n`) of a patch.
    fn index_row(&self, map: &PatchMap, j: usize, row: &mut [u32]) {
        let n = self.n;
        // Patch-direction sample kp of local edge e; the edge stores canonical order.
        let edge = |e: usize, kp: usize| map.edge(n, e, kp);
        let last = row.len() - 1;
        let inner = &mut row[1..last];
        if j == 0 {
            inner.iter_mut().enumerate().for_each(|(i, x)| *x = edge(0, i + 1));
            (row[0], row[last]) = (map.corners[0], map.corners[1]);
        } else if j == n {
            inner.iter_mut().enumerate().for_each(|(i, x)| *x = edge(2, n - 1 - i));
            (row[0], row[last]) = (map.corners[3], map.corners[2]);
        } else {
            let base = map.interior + ((j - 1) * (n - 1)) as u32;
            inner.iter_mut().enumerate().for_each(|(i, x)| *x = base + i as u32);
            (row[0], row[last]) = (edge(3, n - j), edge(1, j));
        }
    }

    /// Parameters of grid row `j` in the patch's own domain, as the generic path computes a
    /// triangle corner's parameters.
    fn param_row(&self, map: &PatchMap, j: usize, row: &mut [[f32; 2]]) {
        let n = self.n;
        let edge = |e: usize, kp: usize| self.edge_params[e][map.edges[e].1 as usize][kp];
        let last = row.len() - 1;
        let inner = &mut row[1..last];
        if j == 0 {
            inner.iter_mut().enumerate().for_each(|(i, x)| *x = edge(0, i + 1));
            (row[0], row[last]) = ([0.0, 0.0], [1.0, 0.0]);
        } else if j == n {
            inner.iter_mut().enumerate().for_each(|(i, x)| *x = edge(2, n - 1 - i));
            (row[0], row[last]) = ([0.0, 1.0], [1.0, 1.0]);
        } else {
            let v = self.grid32[j];
            inner.iter_mut().zip(&self.grid32[1..n]).for_each(|(x, &u)| *x = [u, v]);
            (row[0], row[last]) = (edge(3, n - j), edge(1, j));
        }
    }

    /// Fills one task: interior vertices and triangles of its rows.
    fn rows(&self, task: RowTask<'_>, s: &mut Scratch) {
        if self.avx2_fma {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `avx2_fma` is only set where the CPU has AVX2 and FMA (`Context::new`).
            return unsafe { self.rows_avx2_fma(task, s) };
        }
        self.rows_with::<false>(task, s)
    }

    /// [`Context::rows_with`] compiled for AVX2 and FMA (everything it calls is inlined).
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn rows_avx2_fma(&self, task: RowTask<'_>, s: &mut Scratch) {
        self.rows_with::<true>(task, s)
    }

    /// The body of [`Context::rows`]. Inlined into both builds; so are the kernels it calls,
    /// which is what compiles them for AVX2 in the fast build (a kernel left out of line
    /// would be baseline code, and its `mul_add` a library call).
    #[inline(always)]
    fn rows_with<const FMA: bool>(&self, task: RowTask<'_>, s: &mut Scratch) {
        let (n, m) = (self.n, self.n - 1);
        let RowTask { rows, mut verts, mut indices, mut triangle_patch, mut params } = task;
        let mut r = rows.start;
        while r < rows.end {
            let p = r / n;
            let j_range = r % n..(r % n + rows.end - r).min(n);
            r += j_range.len();
            let local = self.local(p);
            let map = self.patch_map(p);
            for j in j_range {
                if j >= 1 {
                    self.interior_row::<FMA>(p, local, j, verts.take_front(m));
                }
                self.triangle_row(&map, j, take_front(&mut indices, 6 * n), s);
                take_front(&mut triangle_patch, 2 * n).fill(p as u32);
                if !params.is_empty() {
                    self.param_row(&map, j, &mut s.lo_uv);
                    self.param_row(&map, j + 1, &mut s.hi_uv);
                    let out = take_front(&mut params, 6 * n);
                    for ((t, lo), hi) in
                        out.chunks_exact_mut(6).zip(s.lo_uv.windows(2)).zip(s.hi_uv.windows(2))
                    {
                        t.copy_from_slice(&[lo[0], lo[1], hi[1], lo[0], hi[1], hi[0]]);
                    }
                }
            }
        }
    }

    /// The `2n` triangles of grid row `j` (cells `(i, j)`, `i = 0..n`).
    #[inline(always)]
    fn triangle_row(&self, map: &PatchMap, j: usize, idx: &mut [u32], s: &mut Scratch) {
        let n = self.n;
        let cell = |t: &mut [u32], lo: [u32; 2], hi: [u32; 2]| {
            t.copy_from_slice(&[lo[0], lo[1], hi[1], lo[0], hi[1], hi[0]]);
        };
        if j == 0 || j + 1 == n {
            // Along an edge: the general form.
            self.index_row(map, j, &mut s.lo);
            self.index_row(map, j + 1, &mut s.hi);
            for ((t, lo), hi) in idx.chunks_exact_mut(6).zip(s.lo.windows(2)).zip(s.hi.windows(2)) {
                cell(t, [lo[0], lo[1]], [hi[0], hi[1]]);
            }
            return;
        }
        // Between two interior rows, cells 1..n-1 use only interior vertices: the row's first
        // interior index plus a fixed pattern (a vector add); the end cells touch edges 3 and 1.
        let m = (n - 1) as u32;
        let base = map.interior + (j as u32 - 1) * m;
        let (first, rest) = idx.split_at_mut(6);
        let (middle, last) = rest.split_at_mut(6 * (n - 2));
        for (x, &t) in middle.iter_mut().zip(&self.cells) {
            *x = base + t;
        }
        cell(first, [map.edge(n, 3, n - j), base], [map.edge(n, 3, n - j - 1), base + m]);
        cell(last, [base + m - 1, map.edge(n, 1, j)], [base + 2 * m - 1, map.edge(n, 1, j + 1)]);
    }

    /// Interior vertices `i = 1..n` of grid row `j` (`1 ≤ j < n`) of patch `p`.
    #[inline(always)]
    fn interior_row<const FMA: bool>(&self, p: usize, local: &LocalPatch, j: usize, out: VertexSlices<'_>) {
        let line = local.row(&self.basis, j);
        let v = self.grid[j];
        let chunks = out.pos.chunks_mut(LANES).zip(out.nrm.chunks_mut(LANES));
        for (b, (pos, nrm)) in chunks.enumerate() {
            let t0 = 1 + b * LANES;
            let block = line.block::<FMA>(&self.basis, t0, local);
            block.write(pos, nrm, |l| self.exact(p, DVec2::new(self.grid[t0 + l], v)));
        }
        let v = self.grid32[j];
        out.uv.iter_mut().zip(&self.grid32[1..self.n]).for_each(|(x, &u)| *x = [u, v]);
        out.patch.fill(p as u32);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pattern::uniform::Uniform;
    use crate::surface::{BuildOptions, Orientation};
    use crate::verify;

    fn load(name: &str) -> SurfaceSet {
        let path = std::path::PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/"))
            .join(name);
        let file = crate::io::patches::read_patches(&path).expect("test model");
        SurfaceSet::from_patch_file(&file, Default::default())
    }

    /// Both builds of the kernels where the CPU has AVX2 and FMA, else the baseline twice.
    const KERNELS: [bool; 2] = [false, true];

    fn fast(set: &SurfaceSet, plan: &Plan, options: TessellateOptions, out: &mut Mesh, avx2_fma: bool) {
        tessellate_with(set, plan, options, out, avx2_fma)
            .expect("the fast path applies")
            .expect("fast path");
    }

    fn generic(set: &SurfaceSet, plan: &Plan, options: TessellateOptions) -> Mesh {
        super::super::tessellate_generic(set, plan, &Uniform, options).expect("generic path")
    }

    /// Layout, topology and parameters equal; positions within 1e-5 of the model's size and
    /// normals within 1e-5.
    fn assert_same_mesh(fast: &Mesh, generic: &Mesh, what: &str) {
        assert_eq!(fast.indices, generic.indices, "{what}: indices");
        assert_eq!(fast.triangle_patch, generic.triangle_patch, "{what}: triangle_patch");
        assert_eq!(fast.vertex_patch, generic.vertex_patch, "{what}: vertex_patch");
        assert_eq!(fast.uvs, generic.uvs, "{what}: uvs");
        assert_eq!(fast.corner_params, generic.corner_params, "{what}: corner_params");
        assert_eq!(fast.positions.len(), generic.positions.len(), "{what}: vertex count");
        assert_eq!(fast.normals.len(), generic.normals.len(), "{what}: normal count");
        let dvec = |p: &[f32; 3]| glam::Vec3::from(*p).as_dvec3();
        let (lo, hi) = generic
            .positions
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(dvec(p)), hi.max(dvec(p))));
        let size = (hi - lo).length();
        let max_diff = |a: &[[f32; 3]], b: &[[f32; 3]]| {
            a.iter().zip(b).map(|(a, b)| (dvec(a) - dvec(b)).length()).fold(0.0, f64::max)
        };
        let dp = max_diff(&fast.positions, &generic.positions) / size;
        let dn = max_diff(&fast.normals, &generic.normals);
        assert!(dp <= 1e-5, "{what}: positions differ by {dp:e} of the model size");
        assert!(dn <= 1e-5, "{what}: normals differ by {dn:e}");
    }

    #[test]
    fn fast_path_matches_the_generic_engine() {
        for model in ["bench/torus_64x32.patches", "patches/teacup.patches"] {
            let set = load(model);
            for avx2_fma in KERNELS {
                // One mesh for every call: each call must overwrite the previous, larger or
                // smaller, result completely.
                let mut mesh = Mesh::default();
                for n in [1, 2, 3, 7, 16, 2] {
                    let plan = Plan::uniform(&set, n).unwrap();
                    for corner_params in [false, true] {
                        let options = TessellateOptions { corner_params, ..Default::default() };
                        fast(&set, &plan, options, &mut mesh, avx2_fma);
                        let what = format!("{model} n={n} corner_params={corner_params} avx2_fma={avx2_fma}");
                        assert_same_mesh(&mesh, &generic(&set, &plan, options), &what);
                    }
                }
            }
        }
    }

    /// Where the derivatives are parallel, f32 cannot give the normal: the point must take
    /// the f64 evaluation, and come out as the generic path's bits exactly.
    #[test]
    fn degenerate_points_take_the_exact_evaluation() {
        // A curved patch whose control points P00 and P10 coincide: ∂S/∂u vanishes at corner
        // (0, 0), though no boundary curve collapses and no corner repeats.
        let mut points = [DVec3::ZERO; 16];
        for i in 0..4 {
            for j in 0..4 {
                points[4 * i + j] = DVec3::new(i as f64, j as f64, 0.1 * (i * j) as f64);
            }
        }
        points[4] = points[0];
        let options = BuildOptions { orientation: Orientation::AsGiven, ..Default::default() };
        let set =
            SurfaceSet::from_patches(vec![Patch::Bicubic(RationalBicubic::polynomial(points))], options);
        for avx2_fma in KERNELS {
            for n in [1, 4, 9] {
                let plan = Plan::uniform(&set, n).unwrap();
                let mut mesh = Mesh::default();
                fast(&set, &plan, TessellateOptions::default(), &mut mesh, avx2_fma);
                let reference = generic(&set, &plan, TessellateOptions::default());
                assert_same_mesh(&mesh, &reference, &format!("pinched corner n={n} avx2_fma={avx2_fma}"));
                let corner = set.topology.patch_corner_entries[0][0] as usize;
                assert_eq!(mesh.normals[corner], reference.normals[corner], "n={n}: the limit normal");
                assert_eq!(mesh.positions[corner], reference.positions[corner], "n={n}");
            }
        }
    }

    #[test]
    fn fast_path_keeps_the_torus_closed() {
        let set = load("bench/torus_64x32.patches");
        for avx2_fma in KERNELS {
            for n in [1, 2, 5, 16] {
                let plan = Plan::uniform(&set, n).unwrap();
                let mut mesh = Mesh::default();
                fast(&set, &plan, TessellateOptions::default(), &mut mesh, avx2_fma);
                let w = verify::watertight(&mesh);
                assert!(w.is_closed(), "n={n}: {w:?}");
                assert_eq!(w.degenerate_triangles(), 0, "n={n}");
                assert_eq!(w.euler_characteristic, 0, "n={n}");
                assert_eq!(w.vertices, mesh.vertex_count(), "n={n}: every vertex is distinct and used");
            }
        }
    }

    #[test]
    fn fast_path_declines_what_it_does_not_cover() {
        let opts = TessellateOptions::default();
        let mut mesh = Mesh::default();

        // The teapot's lid apex is a collapsed curve: its triangles degenerate and are dropped.
        let teapot = load("patches/teapot.patches");
        assert!(teapot.topology.edges.iter().any(|e| e.collapsed));
        assert!(try_tessellate(&teapot, &Plan::uniform(&teapot, 4).unwrap(), opts, &mut mesh).is_none());

        let set = load("bench/torus_64x32.patches");
        let plan = Plan::uniform(&set, 4).unwrap();
        let mut one_edge = plan.clone();
        one_edge.edges[7] = EdgeSampling::uniform(5);
        assert!(try_tessellate(&set, &one_edge, opts, &mut mesh).is_none());
        let mut one_interior = plan.clone();
        one_interior.interior[3] = [4, 5];
        assert!(try_tessellate(&set, &one_interior, opts, &mut mesh).is_none());
        let mut culled = plan.clone();
        culled.visible[3] = false;
        assert!(try_tessellate(&set, &culled, opts, &mut mesh).is_none());
        let mut explicit = plan.clone();
        explicit.edges[0] = EdgeSampling::Params(vec![0.0, 0.25, 0.5, 0.75, 1.0].into());
        assert!(try_tessellate(&set, &explicit, opts, &mut mesh).is_none());
        let mut rational = set.clone();
        if let Patch::Bicubic(b) = &mut rational.patches[5] {
            b.weights[5] = 2.0;
        }
        assert!(try_tessellate(&rational, &plan, opts, &mut mesh).is_none());
        // An output the generic path refuses: it reports the error, so the fast path declines.
        let tiny = TessellateOptions { memory_limit: Some(1000), ..Default::default() };
        assert!(try_tessellate(&set, &plan, tiny, &mut mesh).is_none());
        assert_eq!(mesh, Mesh::default(), "declining leaves the output untouched");
    }

    #[test]
    fn power_of_two_above_brackets_its_argument() {
        for x in [1e-30, 0.3, 0.5, 1.0, 3.0, 1024.0, 1e30] {
            let p = power_of_two_above(x);
            assert!(x < p && p <= 2.0 * x, "{x} → {p}");
            assert_eq!(p.to_bits() & ((1 << 52) - 1), 0, "{p} is a power of two");
        }
        assert_eq!(power_of_two_above(0.0), 1.0);
    }
}
