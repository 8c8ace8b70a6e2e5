//! `tessera render`: one picture of a tessellation (tessera-render), drawn by the wgpu
//! renderer from the CPU engine's mesh or straight from the GPU engine's buffers, or by the
//! CPU fallback rasteriser where there is no GPU adapter. Also what `tessera demo` draws
//! with, and its watertightness verdict.

use crate::plan;
use clap::{Args, ValueEnum};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use tessera::camera::Camera;
use tessera::criterion::Plan;
use tessera::engine::layout::Layout;
use tessera::mesh::Mesh;
use tessera::scheme::{validate, Engine};
use tessera::surface::SurfaceSet;
use tessera::tessellator::{Tessellator, TessellatorOptions};
use tessera_gpu::{GpuContext, GpuError, GpuTessellator};
use tessera_render::{gpu, ColorMode, Drawing, Image, RenderError, RenderOptions};

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ColorArg {
    /// One porcelain colour.
    Shaded,
    /// A colour per patch.
    Patch,
    /// A colour per tessellation level (blue: coarse, red: at --max-factor): the adaptive
    /// detail made visible.
    Level,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RendererArg {
    /// wgpu when an adapter exists, else the CPU rasteriser.
    Auto,
    /// The wgpu renderer only (fails without an adapter).
    Wgpu,
    /// The CPU fallback rasteriser (one sample per pixel; --msaa is ignored).
    Cpu,
}

#[derive(Args)]
pub struct RenderArgs {
    /// Input, as for `tessera mesh`: .patches, .bezt, or a triangle mesh (.obj, .ply, .stl,
    /// .glb, .gltf) as PN triangles.
    input: PathBuf,
    /// The PNG picture to write.
    #[arg(short, long, value_name = "OUT.png")]
    output: PathBuf,
    #[command(flatten)]
    criterion: plan::CriterionArgs,
    /// Overlay the triangle edges (anti-aliased).
    #[arg(long)]
    wireframe: bool,
    /// Image size; it is the camera's viewport, so --pixel-error is measured in these
    /// pixels (default: the camera's, 1280x720 unless --camera gives size=).
    #[arg(long, value_name = "WxH")]
    size: Option<String>,
    /// Samples per pixel of the wgpu renderer: 1 or 4.
    #[arg(long, value_name = "N", default_value_t = 4)]
    msaa: u32,
    /// Colours.
    #[arg(long, value_enum, default_value = "shaded")]
    color: ColorArg,
    /// Engine: `cpu` (the CPU mesh, uploaded) or `gpu` (tessellated by tessera-gpu and drawn
    /// from its buffers, no read-back between the two).
    #[arg(long, value_enum, default_value = "cpu")]
    engine: plan::EngineArg,
    /// Renderer.
    #[arg(long, value_enum, default_value = "auto")]
    renderer: RendererArg,
    /// Caps each storage binding of the uploaded mesh at N bytes (below the adapter's own
    /// limit), so the split into parts can be tested on a small mesh.
    #[arg(long, value_name = "N", hide = true)]
    max_binding_bytes: Option<u64>,
    #[command(flatten)]
    input_args: crate::InputArgs,
}

/// Parses `WxH`.
fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let bad = || format!("--size {text}: expected WxH, two positive integers (e.g. 1280x720)");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.trim().parse().map_err(|_| bad())?, h.trim().parse().map_err(|_| bad())?);
    if w == 0 || h == 0 {
        return Err(bad());
    }
    Ok((w, h))
}

/// The camera of a render: `--camera` on the default framing camera, whose viewport is
/// `--size` when given (so the model is framed for that aspect).
fn camera(args: &RenderArgs, set: &SurfaceSet) -> Result<Camera, Box<dyn std::error::Error>> {
    let Some(size) = &args.size else { return Ok(plan::camera(&args.criterion, set)?) };
    let (w, h) = parse_size(size)?;
    let (lo, hi) = set.bounds();
    let default = Camera::framing_up(lo, hi, w, h, set.up);
    let camera = match &args.criterion.camera {
        Some(spec) => Camera::parse(spec, &default)?,
        None => default,
    };
    if (camera.width, camera.height) != (w, h) {
        return Err(format!(
            "--size {size} and --camera size={}x{} disagree: give the size once",
            camera.width, camera.height
        )
        .into());
    }
    Ok(camera)
}

/// Which renderer drew a picture, for the user.
pub struct Drawn {
    pub image: Image,
    /// "wgpu on llvmpipe (Vulkan)" or "the CPU rasteriser (…why)".
    pub renderer: String,
    /// The draw alone: submission to image on the CPU (wgpu), or the rasterisation.
    pub draw_seconds: f64,
}

/// A device for the wgpu renderer. Its context records the errors wgpu reports outside the
/// renderer's error scopes instead of panicking; they are checked after each picture.
pub struct Device {
    pub ctx: GpuContext,
}

impl Device {
    fn new() -> Result<Device, GpuError> {
        Ok(Device { ctx: GpuContext::new()? })
    }
}

/// Opens a GPU adapter for `choice`: Err for the CPU rasteriser, with the reason.
fn context(choice: RendererArg) -> Result<Result<Device, String>, GpuError> {
    match choice {
        RendererArg::Cpu => Ok(Err("--renderer cpu".into())),
        RendererArg::Wgpu => Device::new().map(Ok),
        RendererArg::Auto => Ok(Device::new().map_err(|e| match e {
            GpuError::NoAdapter { .. } => format!(
                "no GPU adapter on this machine; `{}` installs a software one",
                tessera_gpu::SOFTWARE_DRIVER_PACKAGES
            ),
            e => format!("the GPU failed: {e}"),
        })),
    }
}

/// Refuses an image size the renderer that will draw it cannot take (the adapter's texture
/// limit, the memory caps: `tessera_render::check_image_size`, which `tessera view` calls
/// too), before the tessellation and before anything of that size is allocated.
fn check_size(camera: &Camera, device: &Result<Device, String>, samples: u32) -> Result<(), RenderError> {
    let drawing = match device {
        Ok(d) => Drawing::Gpu { limits: &d.ctx.limits, samples },
        Err(_) => Drawing::Cpu,
    };
    tessera_render::check_image_size(camera.width, camera.height, drawing).map(|_| ())
}

fn wgpu_name(ctx: &GpuContext) -> String {
    format!("the wgpu renderer on {} ({:?})", ctx.info.name, ctx.info.backend)
}

/// Uploads `mesh` (in parts where it exceeds a binding) and draws it with the wgpu renderer.
fn draw_uploaded(
    device: &Device,
    mesh: &Mesh,
    levels: &[f32],
    camera: &Camera,
    options: &RenderOptions,
    samples: u32,
    max_binding: u64,
) -> Result<Drawn, RenderError> {
    let ctx = &device.ctx;
    let buffers = gpu::MeshBuffers::upload_within(ctx, mesh, levels, max_binding)?;
    ctx.wait()?;
    let start = Instant::now();
    let image = gpu::render(ctx, &buffers.geometries(), camera, options, samples)?;
    device.ctx.check_errors()?;
    let parts = match buffers.part_count() {
        1 => String::new(),
        n => format!(", the mesh in {n} parts within the adapter's binding limit"),
    };
    Ok(Drawn {
        image,
        renderer: format!("{}{parts}", wgpu_name(ctx)),
        draw_seconds: start.elapsed().as_secs_f64(),
    })
}

/// Draws a CPU mesh: uploaded to the wgpu renderer on `device`, or rasterised on the CPU
/// (no device, for the reason given; or under `--renderer auto` when the wgpu renderer fails,
/// saying so). `max_binding` caps each storage binding of the upload (u64::MAX: the
/// adapter's limits).
#[allow(clippy::too_many_arguments)]
fn draw_mesh(
    device: &Result<Device, String>,
    mesh: &Mesh,
    levels: &[f32],
    camera: &Camera,
    options: &RenderOptions,
    samples: u32,
    choice: RendererArg,
    max_binding: u64,
) -> Result<Drawn, Box<dyn std::error::Error>> {
    let why = match device {
        Ok(device) => match draw_uploaded(device, mesh, levels, camera, options, samples, max_binding) {
            Ok(drawn) => return Ok(drawn),
            Err(e @ RenderError::Wgpu { .. }) if choice == RendererArg::Auto => {
                eprintln!("warning: {e}; drawing with the CPU rasteriser instead (--renderer auto)");
                format!("the wgpu renderer failed: {e}")
            }
            Err(e) => return Err(e.into()),
        },
        Err(why) => why.clone(),
    };
    let start = Instant::now();
    let image = tessera_render::cpu::render(mesh, camera, options, levels)?;
    Ok(Drawn {
        image,
        renderer: format!("tessera's CPU rasteriser ({why})"),
        draw_seconds: start.elapsed().as_secs_f64(),
    })
}

/// Tessellates `plan` on the GPU and draws the engine's buffers directly (`--engine gpu`).
/// Patch and level colours read the triangles' patches back once (the engine keeps no
/// per-triangle patch buffer); the shaded picture reads nothing back before the image.
#[allow(clippy::too_many_arguments)]
fn draw_gpu_engine(
    device: &Device,
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn tessera::pattern::Pattern,
    levels: &[f32],
    camera: &Camera,
    options: &RenderOptions,
    samples: u32,
) -> Result<(Drawn, usize), Box<dyn std::error::Error>> {
    let ctx = &device.ctx;
    let scoped =
        |what, f: &mut dyn FnMut() -> Result<(), GpuError>| -> Result<(), Box<dyn std::error::Error>> {
            tessera_render::scoped(&ctx.device, what, f)??;
            Ok(())
        };
    let mut engine =
        tessera_render::scoped(&ctx.device, "making the GPU engine", || GpuTessellator::new(ctx, set))??;
    scoped("preparing the GPU engine", &mut || engine.prepare(ctx, set, plan, pattern))?;
    scoped("tessellating on the GPU", &mut || {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        engine.record(&mut encoder);
        ctx.queue.submit([encoder.finish()]);
        Ok(())
    })?;
    let (overflow, _, triangles) = engine.read_status(ctx)?;
    if overflow {
        return Err("the GPU engine's output overflowed its buffers".into());
    }
    let use_upload = |data: &[u8], label: &str| {
        use wgpu::util::DeviceExt;
        let mut data = data.to_vec();
        data.resize(data.len().max(16), 0);
        tessera_render::scoped(&ctx.device, "uploading the patches", || {
            ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &data,
                usage: wgpu::BufferUsages::STORAGE,
            })
        })
    };
    let patches = match options.color {
        ColorMode::Shaded => None,
        _ => {
            let (_, _, offsets) = engine.read_layout(ctx)?;
            Some(use_upload(
                bytemuck::cast_slice(&tessera_render::triangle_patches(&offsets)),
                "triangle patches",
            )?)
        }
    };
    let level_buffer = use_upload(bytemuck::cast_slice(levels), "patch levels")?;
    let (Some(vertices), Some(indices)) = (engine.vertex_buffer(), engine.index_buffer()) else {
        return Err("the GPU engine has no output buffers".into());
    };
    let geometry = gpu::Geometry {
        vertices,
        indices,
        indexed_args: engine.indirect_buffer(),
        triangle_patch: patches.as_ref(),
        patch_level: Some(&level_buffer),
    };
    let start = Instant::now();
    let image = gpu::render(ctx, &[geometry], camera, options, samples)?;
    device.ctx.check_errors()?;
    let drawn = Drawn { image, renderer: wgpu_name(ctx), draw_seconds: start.elapsed().as_secs_f64() };
    Ok((drawn, triangles as usize))
}

pub fn run(a: RenderArgs) -> crate::CliResult {
    let options = crate::load_options(&a.input_args)?;
    if a.output.extension().is_none_or(|e| !e.eq_ignore_ascii_case("png")) {
        return Err(
            format!("-o {}: the picture is written as PNG: give a .png name", a.output.display()).into()
        );
    }
    if a.msaa != 1 && a.msaa != 4 {
        return Err(format!("--msaa {}: use 1 or 4", a.msaa).into());
    }
    let set = crate::load_surfaces(&a.input, options)?;
    let engine_options = crate::limits(None, false);
    plan::note_up_axis(a.criterion.camera.as_deref(), &a.input);
    let mut chosen = plan::choose(&a.criterion, &set, engine_options.max_triangles.unwrap_or(u64::MAX))?;
    let camera = camera(&a, &set)?;
    chosen.options.camera = Some(camera);
    if a.engine == plan::EngineArg::Gpu && a.renderer == RendererArg::Cpu {
        return Err("--engine gpu draws the GPU engine's buffers: it needs --renderer wgpu or auto".into());
    }
    let device = if a.engine == plan::EngineArg::Gpu { Ok(Device::new()?) } else { context(a.renderer)? };
    check_size(&camera, &device, a.msaa)?;
    let start = Instant::now();
    let on_gpu = a.engine == plan::EngineArg::Gpu;
    if on_gpu {
        validate(chosen.scheme, &chosen.criterion, &chosen.options, &set, Engine::Gpu)?;
    }
    let mut tess = Tessellator::new(
        &set,
        chosen.scheme,
        chosen.criterion,
        TessellatorOptions { plan: chosen.options, engine: engine_options },
    )?;
    // The GPU engine draws the CPU's plan: no CPU write for it.
    if on_gpu {
        tess.plan_frame(Some(&camera))?;
    } else {
        tess.frame(Some(&camera))?;
    }
    let tessellate = start.elapsed().as_secs_f64();
    let plan = tess.plan().expect("a frame was planned");
    let levels = tessera_render::patch_levels(plan, a.criterion.max_factor);
    let render_options = RenderOptions {
        wireframe: a.wireframe,
        color: match a.color {
            ColorArg::Shaded => ColorMode::Shaded,
            ColorArg::Patch => ColorMode::Patch,
            ColorArg::Level => ColorMode::Level,
        },
    };
    let (drawn, triangles) = match &device {
        Ok(device) if on_gpu => {
            let pattern = tess.pattern().expect("a frame was planned");
            draw_gpu_engine(device, &set, plan, pattern, &levels, &camera, &render_options, a.msaa)?
        }
        _ => {
            let mesh = tess.mesh();
            let max_binding = a.max_binding_bytes.unwrap_or(u64::MAX);
            let drawn =
                draw_mesh(&device, mesh, &levels, &camera, &render_options, a.msaa, a.renderer, max_binding)?;
            (drawn, mesh.triangle_count())
        }
    };
    drawn.image.write_png(&a.output)?;
    eprintln!(
        "wrote {} ({}x{}): {} patches, {triangles} triangles ({}, {} engine, {:.1} ms); drawn by {} in {:.1} ms",
        a.output.display(),
        camera.width,
        camera.height,
        set.patches.len(),
        chosen.description,
        a.engine,
        tessellate * 1e3,
        drawn.renderer,
        drawn.draw_seconds * 1e3
    );
    Ok(ExitCode::SUCCESS)
}

/// Where an open output edge lies, judged from the mesh's own indices and the layout that
/// placed its vertices: on a free input curve (a boundary curve of one patch only) or not.
pub struct BoundaryVerdict {
    /// Output edges used by one triangle.
    pub open_edges: usize,
    /// Of them, those lying on a free input curve (both ends on the curve's samples or its
    /// end corners).
    pub on_free_curves: usize,
    /// Output edges used by three or more triangles.
    pub nonmanifold_edges: usize,
    /// The input's free curves.
    pub free_curves: usize,
    /// Free curves with at least one open output edge on them.
    pub curves_reached: usize,
}

impl BoundaryVerdict {
    /// True when every open edge is on a free curve and none is non-manifold.
    pub fn watertight(&self) -> bool {
        self.open_edges == self.on_free_curves && self.nonmanifold_edges == 0
    }

    /// The verdict in words a newcomer understands.
    pub fn sentence(&self, what: &str) -> String {
        if self.watertight() {
            format!(
                "watertight: every open edge lies on one of {what}'s {} free curves (the input's own boundary: {} of {} output edges, on {} of the curves)",
                self.free_curves, self.on_free_curves, self.open_edges, self.curves_reached
            )
        } else {
            format!(
                "NOT watertight: {} of {} open edges lie inside the surface (cracks), {} edges are non-manifold",
                self.open_edges - self.on_free_curves,
                self.open_edges,
                self.nonmanifold_edges
            )
        }
    }
}

/// Finds every open output edge of `mesh` (made by the CPU engine from `plan` on `set`) and
/// checks it lies on a free curve of the input. Cost: O(T) with a hash map of edges.
pub fn boundary_verdict(
    set: &SurfaceSet,
    plan: &Plan,
    pattern: &dyn tessera::pattern::Pattern,
    mesh: &Mesh,
) -> Result<BoundaryVerdict, tessera::Error> {
    let topo = &set.topology;
    let mut layout = Layout::default();
    layout.build(set, plan, pattern, &Default::default())?;
    let mut uses: HashMap<(u32, u32), u32> = HashMap::with_capacity(mesh.indices.len());
    for t in mesh.indices.chunks_exact(3) {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let free: Vec<bool> = topo.edges.iter().map(|e| e.uses.len() == 1 && !e.collapsed).collect();
    // Where an output vertex lies: a corner (its input vertex) or inside an edge's samples.
    enum On {
        Corner(u32),
        Edge(usize),
        Inside,
    }
    let on = |v: u32| -> On {
        if v < layout.corners {
            return On::Corner(topo.corner_entries[v as usize].vertex);
        }
        let e = layout.edge_offsets.partition_point(|&o| o <= v);
        if e > 0 && e < layout.edge_offsets.len() {
            On::Edge(e - 1)
        } else {
            On::Inside
        }
    };
    // Free curves at each input vertex, for corner-to-sample and corner-to-corner edges.
    let mut at_vertex: HashMap<u32, Vec<usize>> = HashMap::new();
    for (e, edge) in topo.edges.iter().enumerate() {
        if free[e] {
            for v in edge.ends {
                at_vertex.entry(v).or_default().push(e);
            }
        }
    }
    let curve_of = |a: u32, b: u32| -> Option<usize> {
        match (on(a), on(b)) {
            (On::Edge(e), On::Edge(f)) => (e == f && free[e]).then_some(e),
            (On::Edge(e), On::Corner(c)) | (On::Corner(c), On::Edge(e)) => {
                (free[e] && topo.edges[e].ends.contains(&c)).then_some(e)
            }
            (On::Corner(c), On::Corner(d)) => at_vertex.get(&c)?.iter().copied().find(|&e| {
                let ends = topo.edges[e].ends;
                plan.segments[e] == 1 && (ends == [c, d] || ends == [d, c])
            }),
            _ => None,
        }
    };
    let mut reached = vec![false; topo.edges.len()];
    let mut verdict = BoundaryVerdict {
        open_edges: 0,
        on_free_curves: 0,
        nonmanifold_edges: 0,
        free_curves: free.iter().filter(|&&f| f).count(),
        curves_reached: 0,
    };
    for (&(a, b), &n) in &uses {
        if n > 2 {
            verdict.nonmanifold_edges += 1;
        }
        if n != 1 {
            continue;
        }
        verdict.open_edges += 1;
        if let Some(e) = curve_of(a, b) {
            verdict.on_free_curves += 1;
            reached[e] = true;
        }
    }
    verdict.curves_reached = reached.iter().filter(|&&r| r).count();
    Ok(verdict)
}

/// The demo's picture: the teapot adaptive at 0.5 px from the default camera, shaded with
/// the wireframe, written to `path`. Returns the sentence for the report.
pub fn demo_picture(set: &SurfaceSet, path: &Path) -> Result<String, Box<dyn std::error::Error>> {
    let (lo, hi) = set.bounds();
    let camera = Camera::framing(lo, hi, 1280, 720);
    let scheme = tessera::scheme::Scheme::default_for(&tessera::scheme::Criterion::PixelError(0.5));
    let options = TessellatorOptions {
        plan: tessera::scheme::PlanOptions { camera: Some(camera), ..Default::default() },
        engine: crate::limits(None, false),
    };
    let mut tess = Tessellator::new(set, scheme, tessera::scheme::Criterion::PixelError(0.5), options)?;
    tess.frame(Some(&camera))?;
    let mesh = tess.mesh();
    let render_options = RenderOptions { wireframe: true, color: ColorMode::Shaded };
    let device = context(RendererArg::Auto)?;
    let drawn = draw_mesh(&device, mesh, &[], &camera, &render_options, 4, RendererArg::Auto, u64::MAX)?;
    drawn.image.write_png(path)?;
    Ok(format!(
        "{} ({}x{}, {} triangles, {}, adaptive at 0.5 px from the default camera), drawn by {} in {:.0} ms",
        path.display(),
        camera.width,
        camera.height,
        mesh.triangle_count(),
        scheme.name(),
        drawn.renderer,
        drawn.draw_seconds * 1e3
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use tessera::pattern::uniform::Uniform;

    #[test]
    fn the_verdict_sees_a_hole_inside_the_surface() {
        let file = tessera::io::patches::parse_patches(crate::TEAPOT, Path::new("teapot")).unwrap();
        let set = SurfaceSet::from_patch_file(&file, Default::default());
        let plan = Plan::uniform(&set, 4).unwrap();
        let mut mesh = tessera::engine::tessellate(&set, &plan, &Uniform, Default::default()).unwrap();
        let v = boundary_verdict(&set, &plan, &Uniform, &mesh).unwrap();
        assert!(v.watertight(), "{}", v.sentence("the teapot"));
        assert_eq!((v.open_edges, v.free_curves, v.curves_reached), (16 * 4, 16, 16));
        // Drop a triangle: at least two of its edges are inside the surface.
        let t = mesh.triangle_count() / 2;
        mesh.indices.drain(3 * t..3 * t + 3);
        let v = boundary_verdict(&set, &plan, &Uniform, &mesh).unwrap();
        assert!(!v.watertight());
        assert!(v.sentence("the teapot").starts_with("NOT watertight"));
        assert!(v.open_edges > v.on_free_curves);
    }
}
