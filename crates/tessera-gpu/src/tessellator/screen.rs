//! Planning on the GPU from the camera alone ([`GpuTessellator::prepare_screen`]): the
//! request ([`ScreenCriterion`]) checked and turned into `view.wgsl`'s uniform
//! ([`ViewUniform`]), the view passes' buffers ([`ViewBuffers`]) and their view-independent
//! rows ([`patch_view_rows`]), and the culling camera ([`GpuTessellator::set_cull_camera`]).

use std::mem::size_of;

use super::capacity::screen_worst_case;
use super::report::{CheckRow, FrameState};
use super::{buffer, Capacity, GpuPattern, GpuTessellator};
use crate::context::GpuContext;
use crate::error::{GpuError, Result};
use crate::shader;
use crate::upload;
use tessera::camera::Camera;
use tessera::criterion::resolve::{EdgeRule, InteriorRule};
use tessera::criterion::view::{Mapping, ViewCriterion};
use tessera::sampling::Spacing;
use tessera::scheme::{validate, Criterion, Engine, ErrorBound, PlanOptions, Prepared, Scheme};
use tessera::surface::SurfaceSet;

/// `view.wgsl`'s binding of the frame state, and `check.wgsl`'s of the rounds' arguments.
pub(super) const STATE_BINDING: u32 = 3;
pub(super) const ROUND_ARGS_BINDING: u32 = 5;

/// The largest factor cap of a frame whose a-posteriori check runs on the GPU: the library's
/// [`tessera::scheme::GPU_CHECK_MAX_FACTOR`] (whose documentation says why the shaders rely
/// on it), which `validate` enforces.
pub const CHECK_MAX_FACTOR: u32 = tessera::scheme::GPU_CHECK_MAX_FACTOR;

/// `vec4<f32>` per patch in the view passes' patch rows ([`patch_view_rows`]).
pub(crate) const PATCH_VIEW_ROW: u32 = 10;

/// What [`GpuTessellator::prepare_screen`] plans on the GPU: `scheme` under `criterion`
/// with `PlanOptions::max_factor = max_factor`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenCriterion {
    /// The scheme: [`Scheme::Uniform`], [`Scheme::Transition`], [`Scheme::SemiUniform`],
    /// [`Scheme::Hardware`], [`Scheme::Sd2`] or [`Scheme::Esc`].
    pub scheme: Scheme,
    /// [`Criterion::PixelError`] (uniform, transition and semi-uniform schemes), [`Criterion::View`] with
    /// [`ViewCriterion::Silhouetteness`], or [`Criterion::Factor`] (hardware schemes).
    pub criterion: Criterion,
    /// The factor cap, `1..=MAX_FACTOR`.
    pub max_factor: u32,
    /// The output room to start with: None for the worst case (every patch at the cap),
    /// clamped to the device's buffer limits; a smaller one saves memory, and a frame that
    /// needs more overflows (drawing nothing) until [`GpuTessellator::grow_if_overflowed`]
    /// grows it.
    pub capacity: Option<Capacity>,
    /// The guaranteed bound a pixel error plans with (`PlanOptions::bound`):
    /// [`ErrorBound::Hessian`] or [`ErrorBound::Expansion`] (the a-posteriori check and the
    /// proposals then also compute the Taylor expansion, `expansion.wgsl`); the GPU refuses
    /// [`ErrorBound::Taylor`], whose sampled refinements it does not compute.
    pub bound: ErrorBound,
}

impl ScreenCriterion {
    /// `scheme` under `criterion` with the factor cap `max_factor`: output room for the
    /// worst case, planned with the second-derivative bound (set `capacity` and `bound` on
    /// the result for others).
    pub fn new(scheme: Scheme, criterion: Criterion, max_factor: u32) -> ScreenCriterion {
        ScreenCriterion { scheme, criterion, max_factor, capacity: None, bound: ErrorBound::Hessian }
    }
}

/// `view.wgsl`'s `View` uniform (member for member: the contract test, `contract.rs`, checks
/// the offsets): the camera's basis and frustum, and the screen criterion of the frame.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct ViewUniform {
    pub(crate) eye: [f32; 4],
    pub(crate) right: [f32; 4],
    pub(crate) up: [f32; 4],
    pub(crate) forward: [f32; 4],
    pub(crate) near: f32,
    pub(crate) far: f32,
    pub(crate) tan_x: f32,
    pub(crate) tan_y: f32,
    pub(crate) focal: f32,
    pub(crate) pixels: f32,
    pub(crate) cap: f32,
    pub(crate) interior_rule: u32,
    pub(crate) criterion: u32,
    pub(crate) lo: f32,
    pub(crate) hi: f32,
    pub(crate) edge_rule: u32,
    pub(crate) bound: u32,
    /// Where the expansion nets start in the patch view rows ([`expansion_rows`]).
    pub(crate) expansion_rows: u32,
    pub(crate) _pad: [u32; 2],
}

/// `view.wgsl`'s interior rules, criteria and edge rules (substituted into it by
/// [`constants`], so they are typed here only).
pub(super) const INTERIOR_GLOBAL: u32 = 0;
pub(super) const INTERIOR_CORE: u32 = 1;
pub(super) const INTERIOR_MAX_EDGE: u32 = 2;
pub(super) const INTERIOR_LEVEL: u32 = 3;
pub(super) const CRITERION_PIXEL_ERROR: u32 = 0;
pub(super) const CRITERION_SILHOUETTENESS: u32 = 1;
pub(super) const CRITERION_FIXED: u32 = 2;
pub(super) const CRITERION_DISTANCE_LINEAR: u32 = 3;
pub(super) const CRITERION_DISTANCE_QUADRATIC: u32 = 4;
pub(super) const CRITERION_VERTEX_SILHOUETTE: u32 = 5;
/// ESC's own criterion (`esc_plan.wgsl`): levels per object and the distance test.
pub(super) const CRITERION_ESC: u32 = 6;
/// ESC's threshold in the view uniform's `edge_rule`: a distance (else a fraction of each
/// object's diagonal).
pub(super) const ESC_THRESHOLD_ABSOLUTE: u32 = 1;
pub(super) const EDGE_RULE_INTEGER: u32 = 0;
pub(super) const EDGE_RULE_HARDWARE: u32 = 1;
pub(super) const EDGE_RULE_POWER_OF_TWO: u32 = 2;
pub(super) const EDGE_RULE_SYMMETRIC: u32 = 3;
/// `view.wgsl`'s error bounds of a pixel error: [`ErrorBound::Hessian`] and
/// [`ErrorBound::Expansion`] (`expansion.wgsl`).
pub(super) const BOUND_HESSIAN: u32 = 0;
pub(super) const BOUND_EXPANSION: u32 = 1;
/// `expansion.wgsl`'s kinds of expansion net ([`expansion_rows`]; 0 is none).
pub(super) const EXPANSION_BICUBIC: u32 = 1;
pub(super) const EXPANSION_TRIANGLE: u32 = 2;
/// `vec4<f32>` per edge after the patch rows ([`patch_view_rows`]).
pub(super) const EDGE_VIEW_ROW: usize = 3;
/// `vec4<f32>` per topology vertex after the edge rows ([`patch_view_rows`]).
pub(super) const VERTEX_VIEW_ROW: usize = 2;

/// The criterion of [`GpuTessellator::prepare_screen`], as `view.wgsl` reads it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Screen {
    pub(super) criterion: u32,
    pub(super) pixels: f64,
    pub(super) lo: f64,
    pub(super) hi: f64,
    /// The factor cap (`Scheme`'s own and `max_factor`).
    pub(super) cap: f64,
    pub(super) interior: u32,
    pub(super) edge_rule: u32,
    /// [`BOUND_HESSIAN`] or [`BOUND_EXPANSION`].
    pub(super) bound: u32,
}

impl Screen {
    /// Whether the frame's factors read the range of its vertex depths (SD-2's distance level
    /// function: the `vertex_depths` pass first).
    pub(super) fn reads_depths(&self) -> bool {
        self.criterion == CRITERION_DISTANCE_LINEAR || self.criterion == CRITERION_DISTANCE_QUADRATIC
    }

    /// Whether the frame is ESC's (its own planning passes, `esc_plan.wgsl`).
    pub(super) fn is_esc(&self) -> bool {
        self.criterion == CRITERION_ESC
    }

    /// Whether the frame's interiors come from the a-posteriori check (a pixel error with
    /// the transition scheme's core rule or the semi-uniform scheme's level).
    pub(super) fn checked(&self) -> bool {
        self.criterion == CRITERION_PIXEL_ERROR
            && (self.interior == INTERIOR_CORE || self.interior == INTERIOR_LEVEL)
    }
}

/// The view passes' buffers (`view.wgsl`'s group 1) and their bind group.
#[derive(Debug)]
pub(super) struct ViewBuffers {
    pub(super) uniform: wgpu::Buffer,
    pub(super) patch_views: wgpu::Buffer,
    /// Each patch's proposed factors (`view.wgsl`'s `proposals`).
    pub(super) proposals: wgpu::Buffer,
    /// `view.wgsl`'s `FrameState`.
    pub(super) state: wgpu::Buffer,
    /// The check rows (`view.wgsl`'s `CheckRow`, per patch).
    pub(super) checks: wgpu::Buffer,
    pub(super) bind: wgpu::BindGroup,
    /// The check rounds' dispatch arguments (`check.wgsl`'s `round_args`) and their bind
    /// group (group 2 of the rounds' decisions).
    pub(super) round_args: wgpu::Buffer,
    pub(super) rounds: wgpu::BindGroup,
    /// Whether the bounds and edge rows of [`GpuTessellator::prepare_screen`] are on the
    /// device.
    pub(super) bounds_uploaded: bool,
    /// Whether a [`crate::GpuStencils`] moves the patches' bounds each frame
    /// ([`GpuTessellator::moving_view_rows`]): the edge, vertex and ESC rows then stay the
    /// rest cage's, so the criteria that read them are refused.
    pub(super) moving: bool,
    /// The set's topology vertices (their rows follow the edges').
    pub(super) vertices: u32,
    /// Where the expansion nets ([`expansion_rows`]) start in `patch_views`, once a frame
    /// planned with the expansion bound appended them (None before: most frames never
    /// need them).
    pub(super) expansion_rows: Option<u32>,
}

impl ViewBuffers {
    /// The buffers for `set`, the culling rows filled (the bounds come with
    /// [`GpuTessellator::prepare_screen`]). Cost: O(P) cone computations, one upload.
    pub(super) fn new(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        rounds_layout: &wgpu::BindGroupLayout,
        set: &SurfaceSet,
    ) -> ViewBuffers {
        use wgpu::BufferUsages as U;
        let patches = set.patches.len() as u64;
        let uniform =
            buffer(device, "view", std::mem::size_of::<ViewUniform>() as u64, U::UNIFORM | U::COPY_DST);
        let patch_views = upload::storage_buffer(device, "patch views", &patch_view_rows(set, None));
        let proposals = buffer(device, "proposals", 16 * patches, U::STORAGE);
        let state = buffer(
            device,
            "frame state",
            size_of::<FrameState>() as u64,
            U::STORAGE | U::COPY_DST | U::COPY_SRC,
        );
        let checks =
            buffer(device, "check rows", size_of::<CheckRow>() as u64 * patches, U::STORAGE | U::COPY_SRC);
        let bind = shader::bind(device, layout, &[&uniform, &patch_views, &proposals, &state, &checks]);
        let round_args = buffer(device, "check round dispatches", 24, U::STORAGE | U::INDIRECT);
        let rounds = shader::bind_at(
            device,
            rounds_layout,
            &[(STATE_BINDING, &state), (ROUND_ARGS_BINDING, &round_args)],
        );
        let vertices = set.topology.vertex_count;
        ViewBuffers {
            uniform,
            patch_views,
            proposals,
            state,
            checks,
            bind,
            round_args,
            rounds,
            bounds_uploaded: false,
            moving: false,
            vertices,
            expansion_rows: None,
        }
    }

    /// Appends the expansion nets of `set` to `patch_views` ([`expansion_rows`]), once: a
    /// larger buffer with the nets after the view rows (which `prepare_screen` then uploads
    /// again), the bind group remade. Cost: the first call O(P) and 256 bytes a patch more;
    /// later calls nothing.
    pub(super) fn add_expansion_rows(
        &mut self,
        ctx: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        set: &SurfaceSet,
    ) {
        if self.expansion_rows.is_some() {
            return;
        }
        use wgpu::BufferUsages as U;
        let at = view_row_count(set);
        let nets = expansion_rows(set);
        let size = (16 * (at + nets.len())) as u64;
        self.patch_views = buffer(&ctx.device, "patch views", size, U::STORAGE | U::COPY_DST | U::COPY_SRC);
        ctx.queue.write_buffer(&self.patch_views, 16 * at as u64, bytemuck::cast_slice(&nets));
        self.bind = shader::bind(
            &ctx.device,
            layout,
            &[&self.uniform, &self.patch_views, &self.proposals, &self.state, &self.checks],
        );
        self.bounds_uploaded = false;
        self.expansion_rows = Some(at as u32);
    }
}

/// Whether a frame of `criterion` asked for `bound` plans with the expansion bound (only a
/// pixel error plans with a bound).
fn plans_with_expansion(criterion: &Criterion, bound: ErrorBound) -> bool {
    bound == ErrorBound::Expansion && matches!(criterion, Criterion::PixelError(_))
}

/// How many rows [`patch_view_rows`] makes for `set`: the patches', the edges' and the
/// vertices'.
fn view_row_count(set: &SurfaceSet) -> usize {
    PATCH_VIEW_ROW as usize * set.patches.len()
        + EDGE_VIEW_ROW * set.topology.edges.len()
        + VERTEX_VIEW_ROW * set.topology.vertex_count as usize
}

/// Per patch, [`upload::CONTROL_POINTS`] `vec4<f32>` for `expansion.wgsl`: the control net
/// of its expansion bound (`taylor::ExpansionNet`: a polynomial bicubic's 16 points, a cubic
/// or PN triangle's 10 at `BezierTriangle::index`) less the net's first point, differenced in
/// f64 and then rounded, so the bound's second and third differences keep f32's precision
/// relative to the patch's size, not to its distance from the origin (from the f32 control
/// points, a small PN triangle's bound was 1 % off the CPU's); the first row's w holds the
/// kind (`expansion.wgsl`'s EXPANSION_NONE, _BICUBIC, _TRIANGLE). Cost: O(P).
fn expansion_rows(set: &SurfaceSet) -> Vec<[f32; 4]> {
    use tessera::criterion::taylor::ExpansionNet;
    let per_patch = upload::CONTROL_POINTS as usize;
    let mut out = vec![[0.0f32; 4]; per_patch * set.patches.len()];
    for (p, patch) in set.patches.iter().enumerate() {
        let Some(net) = ExpansionNet::of(patch) else { continue };
        let rows = &mut out[per_patch * p..per_patch * (p + 1)];
        let points = net.points();
        for (row, point) in rows.iter_mut().zip(points) {
            let d = *point - points[0];
            *row = [d.x as f32, d.y as f32, d.z as f32, 0.0];
        }
        rows[0][3] = match net {
            ExpansionNet::Bicubic(_) => EXPANSION_BICUBIC,
            ExpansionNet::Triangle(_) => EXPANSION_TRIANGLE,
        } as f32;
    }
    out
}

/// Per patch, [`PATCH_VIEW_ROW`] `vec4<f32>` (`view.wgsl`): from
/// [`tessera::criterion::screen::PatchView`] the normal cone (axis, half-angle α), the
/// bounding sphere of the control points about their mean (`screen::back_facing`'s),
/// `(sin α, cos α, has cone, 0)`, the control-point box's lo and hi; then from `prepared`
/// (zero without it) the second-derivative bound `(uu, uv, vv, 0)`, the four boundary
/// curves' bounds and the minimum interior factors; after the patches, [`EDGE_VIEW_ROW`]
/// per edge from `Prepared::edge_midpoints` (the midpoint as its first patch sees it, with
/// the edge's `Prepared::minimum_segments` in w; the normals of its first and last patch,
/// with the edge's two end vertices in w as u32 bits); after the edges, [`VERTEX_VIEW_ROW`]
/// per topology vertex from `view::vertex_data` (its position and its normal: SD-2's level
/// functions read them). Rows 8 and 9 of a patch are its ESC object's box
/// (`criterion::esc::Objects`): lo with the box's diagonal in w, hi.
/// View-independent: computed once. Cost: O(P) cone
/// computations, the midpoints' evaluations when `prepared` has none yet.
fn patch_view_rows(set: &SurfaceSet, prepared: Option<&Prepared>) -> Vec<[f32; 4]> {
    let v4 = |v: glam::DVec3, w: f64| [v.x as f32, v.y as f32, v.z as f32, w as f32];
    let mut out = Vec::with_capacity(view_row_count(set));
    let objects = prepared.map(|_| tessera::criterion::esc::Objects::of(set));
    for (p, patch) in set.patches.iter().enumerate() {
        let view = tessera::criterion::screen::PatchView::new(patch);
        let (axis, alpha) = view.cone.unwrap_or((glam::DVec3::Z, 0.0));
        out.push(v4(axis, alpha));
        out.push(v4(view.centre, view.radius));
        out.push([alpha.sin() as f32, alpha.cos() as f32, view.cone.is_some() as u32 as f32, 0.0]);
        out.push(v4(view.lo, 0.0));
        out.push(v4(view.hi, 0.0));
        match prepared {
            Some(prepared) => {
                let m = &prepared.hessians[p];
                out.push([m.uu as f32, m.uv as f32, m.vv as f32, 0.0]);
                out.push(prepared.curves[p].map(|c| c as f32));
                let [u, v] = prepared.minimum_interior[p];
                out.push([u as f32, v as f32, 0.0, 0.0]);
                let (lo, hi) =
                    objects.as_ref().map_or(Default::default(), |o| o.boxes[o.component[p] as usize]);
                out.extend([v4(lo, lo.distance(hi)), v4(hi, 0.0)]);
            }
            None => out.extend([[0.0; 4]; 5]),
        }
    }
    let edges = &set.topology.edges;
    let with_end = |v: glam::DVec3, end: u32| {
        let mut row = v4(v, 0.0);
        row[3] = f32::from_bits(end);
        row
    };
    match prepared {
        Some(prepared) => {
            let minimum = &prepared.minimum_segments;
            for (e, [(mid, nl), (_, nr)]) in prepared.edge_midpoints(set).iter().enumerate() {
                let [a, b] = edges[e].ends;
                out.extend([v4(*mid, minimum[e] as f64), with_end(*nl, a), with_end(*nr, b)]);
            }
            for (position, normal) in tessera::criterion::view::vertex_data(set) {
                out.extend([v4(position, 0.0), v4(normal, 0.0)]);
            }
        }
        None => out.resize(view_row_count(set), [0.0; 4]),
    }
    debug_assert_eq!(out.len(), view_row_count(set));
    out
}

impl GpuTessellator {
    /// Makes every following frame plan itself on the GPU from the camera alone: culling
    /// for `camera` (`cull.wgsl`), then the factors of `criterion` (`factors.wgsl`: per
    /// patch its proposals — for a pixel error the object-space tolerance of
    /// `screen::PatchView::tolerance` and the proposals from `prepared`'s bounds, for
    /// silhouetteness its edges' factors from `prepared`'s edge midpoints — per edge the
    /// maximum over its patches through the topology's edge uses, the cap and the minimum
    /// segments, then the scheme's interior rule), as `scheme.plan_prepared(set, prepared,
    /// &criterion, &PlanOptions { camera, cull: true, max_factor, .. })` plans on the CPU.
    /// Later cameras go to [`GpuTessellator::set_cull_camera`] (a 112-byte upload a frame);
    /// the plan never comes back to the CPU ([`GpuTessellator::read_plan`] reads it for
    /// tests).
    ///
    /// On the GPU: [`Criterion::PixelError`] with [`Scheme::Uniform`] (the global factor:
    /// the largest over the visible patches) or [`Scheme::Transition`] (CudaTess: per-edge
    /// factors and the a-posteriori check of `check.wgsl`, which raises interiors and, round
    /// by round, edges until every visible patch's bound holds; see
    /// [`GpuTessellator::read_screen_report`]) or [`Scheme::SemiUniform`] (each edge at the
    /// next power of two of its wish, each patch's level checked the same way,
    /// `InteriorRule::Level`); [`Criterion::View`] with
    /// [`ViewCriterion::Silhouetteness`] with [`Scheme::Uniform`], [`Scheme::Transition`]
    /// (per-edge factors, CudaTess's core rule), [`Scheme::SemiUniform`] (the factors taken
    /// between the levels, as paper 000) or a [`Scheme::Hardware`] partitioning (real
    /// per-edge factors by `EdgeRule::Fractional`: the cap, the minimum segments, the hull
    /// shader's pow2 rounding and `settled_factor`; Direct3D's `max` inside reduction in the
    /// pattern); and [`Criterion::Factor`] with a [`Scheme::Hardware`] partitioning (one real
    /// factor, resolved the same way, with the GPU's culling); and [`Scheme::Sd2`] (with
    /// or without the warp, whose edge depths the GPU writes too) with paper 001's level functions ([`ViewCriterion::Distance`], the vertex
    /// depths' range reduced on the GPU, [`ViewCriterion::SilhouetteVertices`]) or a fixed
    /// factor (real per-edge factors by `EdgeRule::Fractional(Spacing::Symmetric)`; f32
    /// depths, so a factor may differ from the CPU's in its last bits); and [`Scheme::Esc`]
    /// with [`Criterion::Esc`] (`esc_plan.wgsl`: each object's level, the distance test on
    /// every candidate, the insertion grids; no culling, every patch drawn; f32 distances, so
    /// a candidate at the threshold may be decided unlike the CPU). A silhouetteness strictly
    /// between 0 and 1 is computed in f32 from f32 copies of the CPU's data, so such an edge's
    /// real factor may differ from the CPU's in its last bits (`factors.wgsl`). The distance
    /// and vertex-silhouette criteria of the other schemes are planned on the CPU (their
    /// plans draw on the GPU through [`GpuTessellator::prepare`]). The output is sized for the worst case, every
    /// patch at the cap (or at the largest minimum when that is higher), within the device's
    /// buffer limits, or as `criterion.capacity` says; a frame that needs more draws nothing
    /// and is reported ([`GpuTessellator::grow_if_overflowed`]).
    ///
    /// Preconditions: `prepared` was made for `set` with bounds (`Prepared::new(set, true)`).
    /// Errors: whatever `tessera::scheme::validate` refuses for [`Engine::GpuFromCamera`]
    /// ([`tessera::Error::EngineNotSupported`] for another scheme or criterion, or the
    /// transition scheme's pixel error with a `max_factor` above [`CHECK_MAX_FACTOR`];
    /// [`tessera::Error::InvalidParameter`] and [`tessera::Error::FactorOutOfRange`] for the
    /// ranges, as [`Scheme::plan`] refuses them); [`GpuError::Unsupported`] for a `prepared`
    /// without bounds or transition factors past this adapter's loop budget; as
    /// [`GpuTessellator::reserve`] for the output (a worst case past the u32 range is not
    /// refused: the frames that need that much overflow and are reported). Cost: the first
    /// call O(E + P) cone computations,
    /// the edge midpoints' evaluations when `prepared` has none yet, and an upload of 128
    /// bytes a patch and 52 an edge; later calls (another camera, criterion or cap) O(P)
    /// pattern counts for the capacity and a 112-byte upload.
    pub fn prepare_screen(
        &mut self,
        ctx: &GpuContext,
        set: &SurfaceSet,
        prepared: &Prepared,
        camera: &Camera,
        criterion: ScreenCriterion,
    ) -> Result<()> {
        let ScreenCriterion { scheme, criterion, max_factor, capacity, bound } = criterion;
        // The edge, vertex and ESC rows and the expansion nets stay the rest cage's.
        let reads_rest_rows = matches!(criterion, Criterion::View { .. } | Criterion::Esc { .. })
            || matches!(scheme, Scheme::Sd2 { .. } | Scheme::Esc { .. })
            || plans_with_expansion(&criterion, bound);
        if self.view.moving && reads_rest_rows {
            return Err(GpuError::Unsupported {
                what: format!(
                    "{scheme:?} with {criterion:?} and the {bound:?} bound on a moving cage (its moving \
                     bounds refresh the patches' boxes and second-derivative bounds only; use a pixel \
                     error with the second-derivative bound and the uniform, transition or \
                     semi-uniform scheme)"
                ),
            });
        }
        let screen = screen_of(set, camera, scheme, criterion, max_factor, bound)?;
        self.check_screen_support(set, prepared, scheme, max_factor)?;
        let pattern = match scheme {
            Scheme::Esc { .. } => GpuPattern::Esc,
            Scheme::Uniform => GpuPattern::Uniform,
            Scheme::Hardware(p) => GpuPattern::Hardware(p),
            // Every edge and level within the cap, a power of two (`validate`).
            Scheme::SemiUniform { .. } => GpuPattern::SemiUniform,
            Scheme::Sd2 { .. } => GpuPattern::Sd2,
            _ => GpuPattern::Transition,
        };
        let worst = screen_worst_case(set, prepared, &screen, pattern, max_factor)?;
        self.reserve_screen(ctx, worst, capacity)?;
        if screen.bound == BOUND_EXPANSION {
            self.view.add_expansion_rows(ctx, &self.pipelines.view_layout, set);
        }
        if !self.view.bounds_uploaded {
            // View-independent and the same for every `Prepared` of the set: uploaded once.
            let rows = patch_view_rows(set, Some(prepared));
            ctx.queue.write_buffer(&self.view.patch_views, 0, bytemuck::cast_slice(&rows));
            self.view.bounds_uploaded = true;
        }
        if pattern == GpuPattern::Esc {
            self.pipelines.esc_plan(&ctx.device);
            self.reserve_esc_grids(ctx);
        }
        self.esc_triangles = None;
        self.screen = Some(screen);
        self.pattern = pattern;
        self.warped = scheme == (Scheme::Sd2 { warp: true });
        self.pipelines.compile(&ctx.device, self.pattern);
        if screen.bound == BOUND_EXPANSION {
            self.pipelines.expansion(&ctx.device);
        }
        if self.strips.is_some() {
            self.pipelines.strips(&ctx.device, self.pattern);
        }
        self.rows = screen.cap as u32;
        if self.set.has_trees {
            self.pipelines.with_trees(&ctx.device, self.pattern);
        }
        self.write_params(ctx);
        self.set_cull_camera(ctx, Some(camera));
        Ok(())
    }

    /// What [`GpuTessellator::prepare_screen`] refuses beyond the request itself ([`screen_of`]):
    /// on this adapter and this tessellator, with `prepared`. Cost: O(1).
    fn check_screen_support(
        &self,
        set: &SurfaceSet,
        prepared: &Prepared,
        scheme: Scheme,
        max_factor: u32,
    ) -> Result<()> {
        if scheme == Scheme::Transition {
            self.check_loop_budget(max_factor)?;
        }
        let patches = set.patches.len();
        if patches as u32 != self.set.patches || set.topology.edges.len() as u32 != self.set.edges {
            return Err(
                tessera::Error::PlanMismatch { what: "a set other than the tessellator's".into() }.into()
            );
        }
        if prepared.hessians.len() != patches
            || prepared.curves.len() != patches
            || prepared.minimum_segments.len() != set.topology.edges.len()
            || prepared.minimum_interior.len() != patches
        {
            return Err(GpuError::Unsupported {
                what: "a Prepared without the error bounds (make it with Prepared::new(set, true))".into(),
            });
        }
        Ok(())
    }

    /// The view rows of `set` with `prepared`'s bounds ([`patch_view_rows`]), uploaded now
    /// and marked as moved each frame by a [`crate::GpuStencils`] made with moving bounds
    /// (which keeps rows 0–6 of each patch, its bounds' rest). Errors: as
    /// [`GpuTessellator::prepare_screen`] for another set or a `prepared` without bounds.
    /// Cost: O(E + P) cone computations and one upload.
    pub(crate) fn moving_view_rows(
        &mut self,
        ctx: &GpuContext,
        set: &SurfaceSet,
        prepared: &Prepared,
    ) -> Result<Vec<[f32; 4]>> {
        // The set and bounds checks only (a uniform scheme has no check loop to budget).
        self.check_screen_support(set, prepared, Scheme::Uniform, 1)?;
        let rows = patch_view_rows(set, Some(prepared));
        ctx.queue.write_buffer(&self.view.patch_views, 0, bytemuck::cast_slice(&rows));
        self.view.bounds_uploaded = true;
        self.view.moving = true;
        Ok(rows)
    }

    /// The patch view rows, for [`crate::GpuStencils`]'s moving-bounds pass.
    pub(crate) fn patch_views(&self) -> &wgpu::Buffer {
        &self.view.patch_views
    }

    /// Makes the GPU cull (frustum and normal cone, `cull.wgsl`) for `camera` in every
    /// following frame, writing the plan's visibility row on the device (the plan's own row
    /// is then ignored), and, after [`GpuTessellator::prepare_screen`], plan the factors for
    /// it; None goes back to the plan's row (and ends the GPU's own planning). The output
    /// capacity then covers every patch. Cost: a 112-byte upload.
    pub fn set_cull_camera(&mut self, ctx: &GpuContext, camera: Option<&Camera>) {
        let Some(camera) = camera else {
            self.camera = None;
            self.screen = None;
            return;
        };
        self.camera = Some(*camera);
        let view = camera.view();
        let v4 = |v: glam::DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
        let s = self.screen.unwrap_or(Screen {
            criterion: CRITERION_PIXEL_ERROR,
            pixels: 1.0,
            lo: 1.0,
            hi: 1.0,
            cap: 1.0,
            interior: INTERIOR_GLOBAL,
            edge_rule: EDGE_RULE_INTEGER,
            bound: BOUND_HESSIAN,
        });
        let t = view.half_tangents;
        let uniform = ViewUniform {
            eye: v4(view.eye),
            right: v4(view.right),
            up: v4(view.up),
            forward: v4(view.forward),
            near: view.near as f32,
            far: view.far as f32,
            tan_x: t.x as f32,
            tan_y: t.y as f32,
            focal: view.focal_pixels as f32,
            pixels: s.pixels as f32,
            cap: s.cap as f32,
            interior_rule: s.interior,
            criterion: s.criterion,
            lo: s.lo as f32,
            hi: s.hi as f32,
            edge_rule: s.edge_rule,
            bound: s.bound,
            expansion_rows: self.view.expansion_rows.unwrap_or(0),
            _pad: [0; 2],
        };
        ctx.queue.write_buffer(&self.view.uniform, 0, bytemuck::bytes_of(&uniform));
    }
}

/// The screen criterion `criterion` asks of `scheme` with the factor cap `max_factor`, as
/// `view.wgsl` reads it: the request is the library's to accept (`tessera::scheme::validate`
/// for [`Engine::GpuFromCamera`], so the GPU refuses exactly what the CPU's planner and the
/// command line refuse, with the same typed [`tessera::Error`]), then written in the
/// shader's codes, the factor range bounded as `Scheme::plan_into` and
/// `view::edge_factors_into` bound it. Cost: O(1).
fn screen_of(
    set: &SurfaceSet,
    camera: &Camera,
    scheme: Scheme,
    criterion: Criterion,
    max_factor: u32,
    bound: ErrorBound,
) -> Result<Screen> {
    // ESC culls nothing (its levels are per object); every other frame culls on the GPU.
    let cull = !matches!(scheme, Scheme::Esc { .. });
    let options = PlanOptions { camera: Some(*camera), cull, max_factor, bound, ..PlanOptions::default() };
    let bound = if plans_with_expansion(&criterion, bound) { BOUND_EXPANSION } else { BOUND_HESSIAN };
    let accepted = validate(scheme, &criterion, &options, set, Engine::GpuFromCamera)?;
    let cap = accepted.cap;
    let (kind, pixels, lo, hi) = match (scheme, criterion) {
        (_, Criterion::PixelError(px)) => (CRITERION_PIXEL_ERROR, px, 1.0, 1.0),
        // SD-2's level functions (`criterion::sd2::plan`, the range as `Scheme::plan_sd2`
        // bounds it); a fixed factor is the linear distance function with fmin = fmax.
        (Scheme::Sd2 { .. }, Criterion::View { criterion, fmin, fmax }) => {
            let fmax = fmax.min(cap);
            let kind = match criterion {
                ViewCriterion::Distance(Mapping::Linear) => CRITERION_DISTANCE_LINEAR,
                ViewCriterion::Distance(Mapping::Quadratic) => CRITERION_DISTANCE_QUADRATIC,
                _ => CRITERION_VERTEX_SILHOUETTE,
            };
            (kind, 1.0, fmin.min(fmax), fmax)
        }
        (Scheme::Sd2 { .. }, Criterion::Factor(f)) => (CRITERION_DISTANCE_LINEAR, 1.0, f, f),
        (_, Criterion::View { fmin, fmax, .. }) => {
            let fmax = fmax.min(cap);
            let lo = fmin.min(fmax).max(1.0);
            (CRITERION_SILHOUETTENESS, 1.0, lo, fmax.max(lo))
        }
        (_, Criterion::Factor(f)) => (CRITERION_FIXED, 1.0, f, f),
        // ESC: the threshold in `pixels` (its kind in the edge rule), the fixed level or −1
        // in `lo`, Lmax in `hi`, the near distance in diagonals as the cap (`esc_plan.wgsl`).
        (Scheme::Esc { max_level }, Criterion::Esc { threshold, level }) => {
            use tessera::criterion::esc::{EscOptions, Threshold};
            let (rho, rule) = match threshold {
                Threshold::High => (Threshold::HIGH_FRACTION, 0),
                Threshold::Medium => (Threshold::MEDIUM_FRACTION, 0),
                Threshold::Absolute(r) => (r, ESC_THRESHOLD_ABSOLUTE),
            };
            let level = level.map_or(-1.0, f64::from);
            let near = EscOptions::default().near_diagonals;
            let interior = INTERIOR_GLOBAL;
            return Ok(Screen {
                criterion: CRITERION_ESC,
                pixels: rho,
                lo: level,
                hi: max_level as f64,
                cap: near,
                interior,
                edge_rule: rule,
                bound,
            });
        }
        (_, Criterion::Tolerance(_) | Criterion::Esc { .. }) => {
            unreachable!("validate refuses them on the GPU")
        }
    };
    let interior = match accepted.interior_rule {
        InteriorRule::Global => INTERIOR_GLOBAL,
        InteriorRule::Core => INTERIOR_CORE,
        InteriorRule::MaxEdge => INTERIOR_MAX_EDGE,
        InteriorRule::Level => INTERIOR_LEVEL,
    };
    let edge_rule = match accepted.edge_rule {
        Some(EdgeRule::Fractional(Spacing::Hardware(_))) => EDGE_RULE_HARDWARE,
        Some(EdgeRule::PowerOfTwo) => EDGE_RULE_POWER_OF_TWO,
        Some(EdgeRule::Fractional(Spacing::Symmetric)) => EDGE_RULE_SYMMETRIC,
        _ => EDGE_RULE_INTEGER,
    };
    Ok(Screen { criterion: kind, pixels, lo, hi, cap, interior, edge_rule, bound })
}
