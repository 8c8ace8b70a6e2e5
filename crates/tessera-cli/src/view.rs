//! `tessera view`: a window (winit, X11) with an orbit camera that re-tessellates the model
//! every frame from the camera — on the GPU engine where it draws the scheme, else on the CPU
//! engine, uploaded — and draws it with tessera-render's pipeline, with a statistics line.
//! The semi-uniform scheme is drawn on the GPU by the instanced path
//! (`tessera_render::instanced`: render queues on the GPU, one instanced draw per level); the
//! hardware schemes (fractional-odd, integer), which take no pixel error, at the factor the
//! uniform scheme needs for it.
//!
//! Keys: S scheme, + / - pixel error ×2 / ÷2, W wireframe, L level colours, P patch colours,
//! C culling, E engine (gpu / cpu), arrows orbit, Q or Esc quit. Mouse: drag to orbit, wheel to
//! zoom. `--frames N --screenshot OUT.png` draws N frames (the camera turning by itself),
//! saves the last one and exits, for headless tests (Xvfb).
//!
//! The statistics line reads a few bytes back per frame (the GPU engine's triangle count and,
//! with timestamp queries, its pass times): a viewer's convenience; an application's frame
//! loop reads nothing back (see tessera-render's `gpu_frames` example).

use crate::plan;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;
use tessera::camera::Camera;
use tessera::criterion::{Plan, PlanScratch};
use tessera::pattern::hardware::Partitioning;
use tessera::scheme::{validate, Criterion, Engine, PlanOptions, Prepared, Scheme, SchemePlan};
use tessera::surface::SurfaceSet;
use tessera::tessellator::{Tessellator, TessellatorOptions};
use tessera_gpu::tessellator::{PassTimer, PASSES};
use tessera_gpu::{GpuContext, GpuError, GpuTessellator};
use tessera_render::instanced::InstancedDraw;
use tessera_render::overlay::Overlay;
use tessera_render::{gpu, ColorMode, Drawing, RenderError, RenderOptions, Renderer};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

#[derive(Args)]
pub struct ViewArgs {
    /// Input, as for `tessera mesh`.
    input: PathBuf,
    /// Starting screen-space error in pixels (keys + and - change it).
    #[arg(long, value_name = "P", default_value_t = 1.0)]
    pixel_error: f64,
    /// Starting scheme, one of those key S cycles through: transition, uniform, semi-uniform
    /// (adaptive to the pixel error), fractional-odd, integer (the hardware tessellator at one
    /// factor: the uniform scheme's for the pixel error).
    #[arg(long, value_enum)]
    scheme: Option<plan::SchemeArg>,
    /// Window size.
    #[arg(long, value_name = "WxH", default_value = "1024x640")]
    size: String,
    /// Largest factor the criterion may use.
    #[arg(long, value_name = "N", default_value_t = 64)]
    max_factor: u32,
    /// Draw N frames (the camera turning by itself), then exit.
    #[arg(long, value_name = "N")]
    frames: Option<u32>,
    /// With --frames: save the last frame as PNG.
    #[arg(long, value_name = "OUT.png", requires = "frames")]
    screenshot: Option<PathBuf>,
    #[command(flatten)]
    input_args: crate::InputArgs,
}

/// The schemes key S cycles through and `--scheme` starts in: those taking a pixel error, the
/// hardware tessellator and SD-2 at the factor derived from it, and ESC with its own criterion
/// ([`criterion_for`]); SD-2 on triangle sets and ESC on bicubic ones only ([`shows`]).
const SCHEMES: [Scheme; 7] = [
    Scheme::Transition,
    Scheme::Uniform,
    Scheme::SemiUniform { max_level: Scheme::DEFAULT_SEMI_UNIFORM_LEVEL },
    Scheme::Hardware(Partitioning::FractionalOdd),
    Scheme::Hardware(Partitioning::Integer),
    Scheme::Sd2 { warp: false },
    Scheme::Esc { max_level: Scheme::DEFAULT_ESC_LEVEL },
];

/// ESC's criterion in the viewer: levels per object from the camera, the medium preset.
const ESC_CRITERION: Criterion =
    Criterion::Esc { threshold: tessera::criterion::esc::Threshold::Medium, level: None };

/// Whether the viewer can show `scheme` on `set` (`validate`'s surface rules: SD-2 takes
/// triangles, ESC bicubic patches); the reason when not.
fn shows(scheme: Scheme, set: &SurfaceSet) -> Result<(), tessera::Error> {
    let criterion = match scheme {
        Scheme::Esc { .. } => ESC_CRITERION,
        _ => Criterion::Factor(2.0),
    };
    validate(scheme, &criterion, &PlanOptions::default(), set, Engine::Cpu).map(|_| ())
}

/// What the keys change.
struct Settings {
    scheme: usize,
    pixel_error: f64,
    wireframe: bool,
    color: ColorMode,
    cull: bool,
    gpu_engine: bool,
}

/// The orbit camera: yaw and pitch about the model's centre, a distance in radii.
struct Orbit {
    yaw: f64,
    pitch: f64,
    zoom: f64,
}

struct State {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    ctx: GpuContext,
    renderer: Renderer,
    overlay: Overlay,
    msaa: (wgpu::Texture, wgpu::Texture),
    /// None where the GPU engine refused the set: every frame takes the CPU engine.
    engine: Option<GpuTessellator>,
    timer: Option<PassTimer>,
    prepared: Prepared,
    scratch: PlanScratch,
    planned: SchemePlan,
    /// Every frame's plan, and the CPU engine's frames: made on the first frame,
    /// reconfigured when the scheme, the criterion or culling change.
    tess: Option<Tessellator<'static>>,
    /// The scheme, the criterion's bits and culling `tess` was set for.
    tess_key: (usize, u64, bool),
    /// The instanced semi-uniform draw (paper 000), made on first use; Err once it cannot
    /// draw this set (mixed domains), then the CPU engine draws semi-uniform.
    instanced: Option<Result<InstancedDraw, String>>,
}

struct App {
    set: &'static SurfaceSet,
    instance: wgpu::Instance,
    args: ViewArgs,
    size: (u32, u32),
    settings: Settings,
    orbit: Orbit,
    drag: Option<(f64, f64)>,
    cursor: (f64, f64),
    state: Option<State>,
    frames: u32,
    error: Option<Box<dyn std::error::Error>>,
    status: String,
}

const SAMPLES: u32 = 4;

/// The window's multisampled colour and depth attachments. Errors: [`RenderError::Wgpu`]
/// when the device cannot make them (the size was checked by [`check_size`]).
fn attachments(
    ctx: &GpuContext,
    format: wgpu::TextureFormat,
    w: u32,
    h: u32,
) -> Result<(wgpu::Texture, wgpu::Texture), RenderError> {
    let make = |format| {
        ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("view attachment"),
            size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: SAMPLES,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
    };
    tessera_render::scoped(&ctx.device, "making the window's attachments", || {
        (make(format), make(gpu::DEPTH_FORMAT))
    })
}

/// Refuses a window size the renderer cannot draw on this device: the one check `tessera
/// render` makes too (`tessera_render::check_image_size`), before anything of that size
/// (the window included) is made.
fn check_size(limits: &wgpu::Limits, width: u32, height: u32, screenshot: bool) -> Result<(), RenderError> {
    let drawing = Drawing::Window { limits, samples: SAMPLES, screenshot };
    tessera_render::check_image_size(width, height, drawing).map(|_| ())
}

/// The error for a machine where wgpu finds no adapter or cannot make a surface on any
/// backend: it names the packages of the software driver, as `render` and `mesh` do.
fn no_adapter(e: &dyn std::fmt::Display) -> GpuError {
    GpuError::NoAdapter { reason: e.to_string() }
}

impl App {
    /// The window, a device that can present to it (the adapter's own limits, timestamp
    /// queries when there are any, as `GpuContext::new` asks), the pipelines, the engine.
    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<State, Box<dyn std::error::Error>> {
        let attributes = Window::default_attributes()
            .with_title(format!("tessera view {}", self.args.input.display()))
            .with_inner_size(PhysicalSize::new(self.size.0, self.size.1));
        let window = Arc::new(event_loop.create_window(attributes)?);
        // No surface on any backend means no Vulkan driver (the only backend built in).
        let surface = self.instance.create_surface(window.clone()).map_err(|e| no_adapter(&e))?;
        let adapter = pollster::block_on(self.instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .map_err(|e| no_adapter(&e))?;
        let ctx = pollster::block_on(GpuContext::for_adapter(&adapter, "tessera view"))?;
        let size = window.inner_size();
        check_size(&ctx.limits, size.width, size.height, self.args.screenshot.is_some())?;
        let mut config = surface
            .get_default_config(&adapter, size.width.max(1), size.height.max(1))
            .ok_or("the window's surface does not work with this adapter")?;
        let caps = surface.get_capabilities(&adapter);
        // Display-space shading (tessera_render::shading) wants a non-sRGB format.
        if let Some(&f) = caps.formats.iter().find(|f| !f.is_srgb()) {
            config.format = f;
        }
        if self.args.screenshot.is_some() {
            if !caps.usages.contains(wgpu::TextureUsages::COPY_SRC) {
                return Err("--screenshot: this surface cannot be copied from".into());
            }
            config.usage |= wgpu::TextureUsages::COPY_SRC;
        }
        tessera_render::scoped(&ctx.device, "configuring the window's surface", || {
            surface.configure(&ctx.device, &config)
        })?;
        let renderer = Renderer::new(&ctx, config.format, SAMPLES)?;
        let overlay =
            tessera_render::scoped(&ctx.device, "making the overlay", || Overlay::new(&ctx, config.format))?;
        let msaa = attachments(&ctx, config.format, config.width, config.height)?;
        // A set the GPU engine cannot take is drawn by the CPU engine.
        let engine = match tessera_render::scoped(&ctx.device, "making the GPU engine", || {
            GpuTessellator::new(&ctx, self.set)
        })? {
            Ok(engine) => Some(engine),
            Err(e) => {
                eprintln!("note: {e}; the CPU engine draws it (E does not switch)");
                None
            }
        };
        let timer = PassTimer::new(&ctx);
        let criterion = Criterion::PixelError(self.settings.pixel_error);
        Ok(State {
            window,
            surface,
            config,
            renderer,
            overlay,
            msaa,
            engine,
            timer,
            prepared: Prepared::for_criterion(self.set, &criterion),
            scratch: PlanScratch::default(),
            planned: SchemePlan::default(),
            tess: None,
            tess_key: (usize::MAX, 0, false),
            instanced: None,
            ctx,
        })
    }

    fn camera(&self, width: u32, height: u32) -> Camera {
        let (lo, hi) = self.set.bounds();
        let framing = Camera::framing_up(lo, hi, width, height, self.set.up);
        let radius = (lo.distance(hi) * 0.5).max(1e-9);
        let base = framing.eye - framing.target;
        let distance = base.length() * self.orbit.zoom;
        let up = framing.up.normalize();
        let side = base.cross(up).normalize();
        let dir = glam::DQuat::from_axis_angle(up, self.orbit.yaw)
            * (glam::DQuat::from_axis_angle(side, self.orbit.pitch) * base.normalize());
        let eye = framing.target + dir * distance;
        Camera {
            eye,
            width,
            height,
            near: (distance - radius).max(distance * 1e-3),
            far: distance + 2.0 * radius,
            ..framing
        }
    }

    /// One frame: plan, tessellate, draw, statistics; the screenshot on the last one.
    fn frame(&mut self) -> Result<(), Box<dyn std::error::Error>> {
        let Some((w, h)) = self.state.as_ref().map(|s| (s.config.width, s.config.height)) else {
            return Ok(());
        };
        let camera = self.camera(w, h);
        let state = self.state.as_mut().expect("checked");
        let (set, settings) = (self.set, &self.settings);
        let scheme = SCHEMES[settings.scheme];
        let options = PlanOptions {
            camera: Some(camera),
            // ESC culls nothing (one level per object).
            cull: settings.cull && !matches!(scheme, Scheme::Esc { .. }),
            max_factor: self.args.max_factor,
            ..Default::default()
        };
        let start = Instant::now();
        let criterion = criterion_for(scheme, settings.pixel_error, set, state, &options)?;
        let mut encoder = state.ctx.device.create_command_encoder(&Default::default());
        let mut drawn = tessellate(state, set, settings, scheme, criterion, &options, &mut encoder)?;
        let frame = match state.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                state.surface.configure(&state.ctx.device, &state.config);
                return Ok(());
            }
            _ => return Ok(()),
        };
        let target = frame.texture.create_view(&Default::default());
        let render = RenderOptions { wireframe: settings.wireframe, color: settings.color };
        if !record_draw(state, &drawn, &camera, &render, &target, &mut encoder)? {
            return Ok(());
        }
        let line1 = self.status.clone();
        // Twice the font size when the longer line fits the window.
        let scale = if (line1.len().max(HELP.len()) as u32 * 12 + 24) < w { 2 } else { 1 };
        state.overlay.record(&state.ctx, &mut encoder, &target, &[&line1, HELP], 8, 8, scale);
        state.ctx.queue.submit([encoder.finish()]);
        let last = self.args.frames.is_some_and(|n| self.frames + 1 >= n);
        if last {
            if let Some(path) = &self.args.screenshot {
                let image = gpu::read_texture(&state.ctx, &frame.texture)?;
                image.write_png(path)?;
            }
        }
        state.window.pre_present_notify();
        state.ctx.queue.present(frame);
        // Statistics for the next frame's line (read back: see the module doc).
        state.ctx.wait()?;
        state.ctx.check_errors()?;
        let frame_ms = start.elapsed().as_secs_f64() * 1e3;
        let triangles = triangles_drawn(state, &mut drawn, settings.cull)?;
        let tess = state.tess.as_ref().expect("made by tessellate");
        let culled = tess.plan().map_or(0, Plan::culled_count);
        self.status = format!(
            "{} {}PX{} / {} TRIS / {} PATCHES{} / {} ENGINE: {} / FRAME {frame_ms:.1} MS",
            scheme.name(),
            settings.pixel_error,
            match criterion {
                Criterion::Factor(f) => format!(" (FACTOR {f})"),
                Criterion::View { fmax, .. } => format!(" (FACTORS UP TO {fmax})"),
                // ESC's own criterion: the pixel error does not drive it.
                Criterion::Esc { .. } => " (ESC LEVELS, MEDIUM THRESHOLD)".into(),
                _ => String::new(),
            },
            triangles,
            set.patches.len(),
            if settings.cull { format!(" ({culled} CULLED)") } else { String::new() },
            if drawn.path == Path::Cpu { "CPU" } else { "GPU" },
            drawn.stages,
        );
        self.frames += 1;
        Ok(())
    }
}

/// Which engine drew a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Path {
    /// The CPU engine, the mesh uploaded.
    Cpu,
    /// The GPU engine, from the CPU's plan.
    Gpu,
    /// Semi-uniform's instanced draw (render queues on the GPU).
    Instanced,
}

/// A frame tessellated, not drawn yet.
struct Tessellated {
    path: Path,
    /// The statistics line's stages.
    stages: String,
    /// Per-patch levels for the level colours (empty for the instanced path).
    levels: Vec<f32>,
    /// The CPU engine's mesh, uploaded, and its triangle count.
    upload: Option<(gpu::MeshBuffers, usize)>,
}

/// Plans the frame through the tessellator (made, or reconfigured, when the scheme, the
/// criterion or culling changed) and tessellates it: on the GPU where the GPU draws the
/// scheme (`validate` for [`Engine::Gpu`]; the instanced path for semi-uniform), else on
/// the CPU. The GPU's passes go into `encoder`.
fn tessellate(
    state: &mut State,
    set: &'static SurfaceSet,
    settings: &Settings,
    scheme: Scheme,
    criterion: Criterion,
    plan: &PlanOptions,
    encoder: &mut wgpu::CommandEncoder,
) -> Result<Tessellated, Box<dyn std::error::Error>> {
    let start = Instant::now();
    let camera = plan.camera.as_ref();
    let options = TessellatorOptions { plan: *plan, engine: crate::limits(None, false) };
    let key = (settings.scheme, criterion_bits(criterion, settings.pixel_error), settings.cull);
    match &mut state.tess {
        Some(tess) if state.tess_key == key => {}
        Some(tess) => tess.reconfigure(scheme, criterion, options.plan)?,
        None => state.tess = Some(Tessellator::new(set, scheme, criterion, options)?),
    }
    state.tess_key = key;
    let tess = state.tess.as_mut().expect("made above");
    let max_factor = options.plan.max_factor;
    let mut path = Path::Cpu;
    if settings.gpu_engine && state.engine.is_some() {
        if let Scheme::SemiUniform { max_level } = scheme {
            if state.instanced.is_none() {
                let made = InstancedDraw::new(&state.ctx, set, max_level, state.config.format, SAMPLES);
                state.instanced = Some(made.map_err(|e| e.to_string()));
            }
            if let Some(Ok(_)) = &state.instanced {
                path = Path::Instanced;
            }
        } else if validate(scheme, &criterion, &options.plan, set, Engine::Gpu).is_ok() {
            path = Path::Gpu;
        }
    }
    if path != Path::Cpu {
        tess.plan_frame(camera)?;
        let plan_ms = start.elapsed().as_secs_f64() * 1e3;
        let (plan, pattern) = (tess.plan().expect("planned"), tess.pattern().expect("planned"));
        if path == Path::Instanced {
            return Ok(Tessellated {
                path,
                stages: format!("PLAN {plan_ms:.1} (INSTANCED)"),
                levels: Vec::new(),
                upload: None,
            });
        }
        let engine = state.engine.as_mut().expect("the GPU path is taken with an engine");
        engine.prepare(&state.ctx, set, plan, pattern)?;
        engine.record_timed(encoder, state.timer.as_ref());
        let levels = tessera_render::patch_levels(plan, max_factor);
        return Ok(Tessellated { path, stages: format!("PLAN {plan_ms:.1}"), levels, upload: None });
    }
    let mesh = tess.frame(camera)?;
    let count = mesh.triangle_count();
    let t = tess.timings();
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    let stages = format!(
        "CRITERION {:.1} RESOLVE {:.1} LAYOUT {:.1} WRITE {:.1}",
        ms(t.criterion),
        ms(t.resolve),
        ms(t.layout),
        ms(t.write)
    );
    let levels = tessera_render::patch_levels(tess.plan().expect("a frame"), max_factor);
    let upload = gpu::MeshBuffers::upload(&state.ctx, tess.mesh(), &levels)?;
    Ok(Tessellated { path, stages, levels, upload: Some((upload, count)) })
}

/// The bits that tell criteria apart for [`tessellate`]'s key.
fn criterion_bits(criterion: Criterion, pixel_error: f64) -> u64 {
    match criterion {
        Criterion::Factor(f) => f.to_bits(),
        _ => pixel_error.to_bits(),
    }
}

/// Records the draw of `drawn` into `encoder`; false when there is nothing to draw yet (the
/// GPU engine has no buffers before its first plan).
fn record_draw(
    state: &State,
    drawn: &Tessellated,
    camera: &Camera,
    options: &RenderOptions,
    target: &wgpu::TextureView,
    encoder: &mut wgpu::CommandEncoder,
) -> Result<bool, Box<dyn std::error::Error>> {
    let colour = state.msaa.0.create_view(&Default::default());
    let depth = state.msaa.1.create_view(&Default::default());
    if let (Path::Instanced, Some(Ok(draw))) = (drawn.path, &state.instanced) {
        let plan = state.tess.as_ref().and_then(|t| t.plan()).expect("planned");
        draw.record(&state.ctx, encoder, plan, camera, options, &colour, Some(target), &depth)?;
        return Ok(true);
    }
    let level_buffer = {
        use wgpu::util::DeviceExt;
        state.ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("levels"),
            contents: bytemuck::cast_slice(if drawn.levels.is_empty() { &[0f32] } else { &drawn.levels[..] }),
            usage: wgpu::BufferUsages::STORAGE,
        })
    };
    let parts = match &drawn.upload {
        Some((buffers, _)) => buffers.geometries(),
        None => {
            let Some(engine) = &state.engine else { return Ok(false) };
            let (Some(vertices), Some(indices)) = (engine.vertex_buffer(), engine.index_buffer()) else {
                return Ok(false);
            };
            vec![gpu::Geometry {
                vertices,
                indices,
                indexed_args: engine.indirect_buffer(),
                // Patch colours of GPU output would need the engine's triangle offsets every
                // frame (a read-back): they are drawn from the CPU engine instead.
                triangle_patch: None,
                patch_level: Some(&level_buffer),
            }]
        }
    };
    state.renderer.record(&state.ctx, encoder, &colour, Some(target), &depth, &parts, camera, options)?;
    Ok(true)
}

/// The frame's triangle count for the statistics line; for the GPU engine also its pass
/// times, appended to `drawn.stages` (a read-back).
fn triangles_drawn(
    state: &State,
    drawn: &mut Tessellated,
    cull: bool,
) -> Result<u64, Box<dyn std::error::Error>> {
    match (drawn.path, &drawn.upload, &state.instanced) {
        (Path::Cpu, Some((_, count)), _) => Ok(*count as u64),
        // Drawn by the instanced path: the queues' patches times their patterns' triangles,
        // degenerate ones included (the rasteriser drops those).
        (Path::Instanced, _, Some(Ok(draw))) => {
            let queues = draw.queues().read(&state.ctx)?;
            Ok((0..=queues.max_level())
                .map(|m| (queues.level(m).len() * draw.patterns()[m as usize].triangles.len()) as u64)
                .sum())
        }
        _ => {
            if let Some(timer) = &state.timer {
                for (name, ms) in timer.read(&state.ctx)? {
                    if name != PASSES[0] || cull {
                        drawn.stages += &format!(" {} {ms:.2}", name.to_uppercase());
                    }
                }
            }
            let engine = state.engine.as_ref().ok_or("no GPU engine")?;
            Ok(engine.read_status(&state.ctx)?.2 as u64)
        }
    }
}

/// The criterion `scheme` is drawn with at `pixel_error`: the pixel error itself for the
/// schemes that take one; for the hardware tessellator, which takes a factor and no error
/// bound, the factor the uniform scheme needs for that pixel error from this camera (within
/// the hardware's range and --max-factor), so + and - still refine and coarsen it.
fn criterion_for(
    scheme: Scheme,
    pixel_error: f64,
    set: &SurfaceSet,
    state: &mut State,
    options: &PlanOptions,
) -> Result<Criterion, tessera::Error> {
    let criterion = Criterion::PixelError(pixel_error);
    match scheme {
        Scheme::Esc { .. } => return Ok(ESC_CRITERION),
        Scheme::Hardware(_) | Scheme::Sd2 { .. } => {}
        _ => return Ok(criterion),
    }
    Scheme::Uniform.plan_into(
        set,
        &state.prepared,
        &criterion,
        options,
        &mut state.scratch,
        &mut state.planned,
    )?;
    let factor = state.planned.plan.segments.iter().copied().max().unwrap_or(1) as f64;
    let factor = factor.clamp(1.0, scheme.cap(options));
    if let Scheme::Sd2 { .. } = scheme {
        // Paper 001's distance level function up to that factor: near edges get it.
        let distance =
            tessera::criterion::view::ViewCriterion::Distance(tessera::criterion::view::Mapping::Linear);
        return Ok(Criterion::View { criterion: distance, fmin: 1.0, fmax: factor.max(1.0) });
    }
    Ok(Criterion::Factor(factor))
}

/// The keys, for `tessera view --help`.
pub const KEYS: &str = "Keys: S scheme (transition, uniform, semi-uniform; fractional-odd, integer at the factor \
the pixel error needs; sd2 on triangles, its distance levels up to that factor; esc on bicubic patches, its own \
levels and medium threshold), + / - pixel error /2 or x2, W wireframe, L level colours, P patch colours (CPU engine), C culling, E engine (GPU or CPU), \
arrows or mouse drag orbit, wheel zoom, Q or Esc quit. The window needs an X11 display (no Wayland backend; \
XWayland works); headless: xvfb-run -a tessera view IN --frames N --screenshot OUT.png";

const HELP: &str = "S SCHEME  +/- PIXEL ERROR  W WIRE  L LEVELS  P PATCHES  C CULL  E ENGINE  DRAG/ARROWS ORBIT  WHEEL ZOOM  Q QUIT";

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        match self.start(event_loop) {
            Ok(s) => {
                s.window.request_redraw();
                self.state = Some(s);
            }
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(state) = self.state.as_mut() {
                    if size.width > 0 && size.height > 0 {
                        let screenshot = self.args.screenshot.is_some();
                        let resized = check_size(&state.ctx.limits, size.width, size.height, screenshot)
                            .and_then(|()| {
                                state.config.width = size.width;
                                state.config.height = size.height;
                                tessera_render::scoped(
                                    &state.ctx.device,
                                    "resizing the window's surface",
                                    || state.surface.configure(&state.ctx.device, &state.config),
                                )?;
                                attachments(&state.ctx, state.config.format, size.width, size.height)
                            });
                        match resized {
                            Ok(msaa) => state.msaa = msaa,
                            Err(e) => {
                                self.error = Some(e.into());
                                event_loop.exit();
                            }
                        }
                    }
                }
            }
            WindowEvent::RedrawRequested => {
                if self.args.frames.is_some() {
                    // Headless runs turn the camera by themselves, so frames differ.
                    self.orbit.yaw += 0.05;
                }
                if let Err(e) = self.frame() {
                    self.error = Some(e);
                    event_loop.exit();
                    return;
                }
                if self.args.frames.is_some_and(|n| self.frames >= n) {
                    event_loop.exit();
                }
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                let s = &mut self.settings;
                match event.logical_key {
                    Key::Named(NamedKey::Escape) => event_loop.exit(),
                    Key::Named(NamedKey::ArrowLeft) => self.orbit.yaw -= 0.1,
                    Key::Named(NamedKey::ArrowRight) => self.orbit.yaw += 0.1,
                    Key::Named(NamedKey::ArrowUp) => self.orbit.pitch = (self.orbit.pitch + 0.1).min(1.5),
                    Key::Named(NamedKey::ArrowDown) => self.orbit.pitch = (self.orbit.pitch - 0.1).max(-1.5),
                    Key::Character(c) => match c.to_lowercase().as_str() {
                        "q" => event_loop.exit(),
                        "s" => {
                            // The next scheme this set can be shown in (the first always can).
                            let next = (1..=SCHEMES.len()).map(|k| (s.scheme + k) % SCHEMES.len());
                            s.scheme =
                                next.into_iter().find(|&i| shows(SCHEMES[i], self.set).is_ok()).unwrap_or(0);
                        }
                        "+" | "=" => s.pixel_error = (s.pixel_error / 2.0).max(1.0 / 64.0),
                        "-" => s.pixel_error = (s.pixel_error * 2.0).min(256.0),
                        "w" => s.wireframe = !s.wireframe,
                        "l" => {
                            s.color =
                                if s.color == ColorMode::Level { ColorMode::Shaded } else { ColorMode::Level }
                        }
                        "p" => {
                            s.color = if s.color == ColorMode::Patch {
                                ColorMode::Shaded
                            } else {
                                ColorMode::Patch
                            };
                            // Patch colours need the triangles' patches: the CPU engine has them.
                            if s.color == ColorMode::Patch {
                                s.gpu_engine = false;
                            }
                        }
                        "c" => s.cull = !s.cull,
                        "e" => s.gpu_engine = !s.gpu_engine,
                        _ => {}
                    },
                    _ => {}
                }
            }
            WindowEvent::MouseInput { state, button: MouseButton::Left, .. } => {
                self.drag = (state == ElementState::Pressed).then_some(self.cursor);
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = (position.x, position.y);
                if let Some((x, y)) = self.drag {
                    self.orbit.yaw -= (position.x - x) * 0.01;
                    self.orbit.pitch = (self.orbit.pitch + (position.y - y) * 0.01).clamp(-1.5, 1.5);
                    self.drag = Some(self.cursor);
                }
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                self.orbit.zoom = (self.orbit.zoom * 0.9f64.powf(lines)).clamp(0.05, 10.0);
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        // Live re-tessellation: a new frame as soon as the last one is done.
        if let Some(state) = &self.state {
            state.window.request_redraw();
        }
    }
}

pub fn run(a: ViewArgs) -> crate::CliResult {
    if a.frames == Some(0) {
        return Err("--frames 0: use 1 or more".into());
    }
    if let Some(path) = &a.screenshot {
        if path.extension().is_none_or(|e| !e.eq_ignore_ascii_case("png")) {
            return Err(format!("--screenshot {}: give a .png name", path.display()).into());
        }
    }
    if !(a.pixel_error.is_finite() && a.pixel_error > 0.0) {
        return Err(format!("--pixel-error {}: must be a positive number", a.pixel_error).into());
    }
    let size = {
        let (w, h) =
            a.size.split_once(['x', 'X']).ok_or_else(|| format!("--size {}: expected WxH", a.size))?;
        let parse = |s: &str| s.trim().parse::<u32>().ok().filter(|&v| v > 0);
        (
            parse(w).ok_or_else(|| format!("--size {}: expected WxH", a.size))?,
            parse(h).ok_or_else(|| format!("--size {}: expected WxH", a.size))?,
        )
    };
    let options = crate::load_options(&a.input_args)?;
    // The tessellator borrows the set for the whole run (the event loop owns the app): leaked
    // once, freed at exit.
    let set: &'static SurfaceSet = Box::leak(Box::new(crate::load_surfaces(&a.input, options)?));
    let scheme = a.scheme.map(|s| s.scheme(None, false)).unwrap_or(Scheme::Transition);
    let first = SCHEMES.iter().position(|s| s.name() == scheme.name()).ok_or_else(|| {
        let names: Vec<&str> = SCHEMES.iter().map(|s| s.name()).collect();
        format!("--scheme {}: the viewer shows {}", scheme.name(), names.join(", "))
    })?;
    shows(SCHEMES[first], set).map_err(|e| format!("--scheme {}: {e}", scheme.name()))?;
    // The adapter's limits before any window exists: a refused size never reaches winit or
    // wgpu (the surface's adapter is asked for again once there is a window to present to).
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let probe = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        ..Default::default()
    }))
    .map_err(|e| no_adapter(&e))?;
    check_size(&probe.limits(), size.0, size.1, a.screenshot.is_some())?;
    let event_loop = EventLoop::new().map_err(|e| {
        format!("cannot open a window ({e}): the viewer needs an X11 display (DISPLAY); headless, run it under xvfb-run")
    })?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        set,
        instance,
        settings: Settings {
            scheme: first,
            pixel_error: a.pixel_error,
            wireframe: true,
            color: ColorMode::Shaded,
            cull: false,
            gpu_engine: true,
        },
        args: a,
        size,
        orbit: Orbit { yaw: 0.0, pitch: 0.0, zoom: 1.0 },
        drag: None,
        cursor: (0.0, 0.0),
        state: None,
        frames: 0,
        error: None,
        status: "FIRST FRAME".into(),
    };
    event_loop.run_app(&mut app)?;
    if let Some(e) = app.error {
        return Err(e);
    }
    if let Some(path) = &app.args.screenshot {
        eprintln!("wrote {} after {} frames: {}", path.display(), app.frames, app.status);
    }
    Ok(ExitCode::SUCCESS)
}
