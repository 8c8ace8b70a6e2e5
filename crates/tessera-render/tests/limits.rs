//! What the renderer does at the device's limits: a mesh past one storage binding is drawn in
//! parts, pixel for pixel as the whole mesh (the binding capped low so a small mesh splits);
//! sizes past the adapter's texture limit or the memory caps are refused before anything is
//! made; wgpu's errors come back as `RenderError::Wgpu` instead of its panic. Needs a GPU
//! adapter (lavapipe in CI).

#[allow(dead_code)]
mod common;

use common::data;
use tessera::camera::Camera;
use tessera::mesh::Mesh;
use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera::tessellator::{Tessellator, TessellatorOptions};
use tessera_gpu::GpuContext;
use tessera_render::{gpu, ColorMode, Drawing, RenderError, RenderOptions, WgpuErrorKind};

/// The teapot at factor 8 (4032 triangles) and the camera framing it at 256 × 256.
fn teapot() -> (Mesh, Camera) {
    let set =
        tessera::io::load(&data("patches/teapot.patches"), tessera::io::LoadOptions::default()).unwrap();
    let (lo, hi) = set.bounds();
    let camera = Camera::framing(lo, hi, 256, 256);
    let options = TessellatorOptions {
        plan: PlanOptions { camera: Some(camera), ..Default::default() },
        engine: Default::default(),
    };
    let mut tess = Tessellator::new(&set, Scheme::Uniform, Criterion::Factor(8.0), options).unwrap();
    (tess.frame(Some(&camera)).unwrap().clone(), camera)
}

/// The same mesh with its vertices renumbered by a fixed shuffle: every run of triangles
/// then uses vertices from all over the vertex array.
fn shuffled(mesh: &Mesh) -> Mesh {
    let n = mesh.vertex_count();
    let mut order: Vec<usize> = (0..n).collect();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for i in (1..n).rev() {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        order.swap(i, (state % (i as u64 + 1)) as usize);
    }
    // order[new] = old.
    let mut new_of = vec![0u32; n];
    for (new, &old) in order.iter().enumerate() {
        new_of[old] = new as u32;
    }
    let mut out = mesh.clone();
    out.positions = order.iter().map(|&o| mesh.positions[o]).collect();
    out.normals = order.iter().map(|&o| mesh.normals[o]).collect();
    if mesh.uvs.len() == n {
        out.uvs = order.iter().map(|&o| mesh.uvs[o]).collect();
    }
    out.indices = mesh.indices.iter().map(|&i| new_of[i as usize]).collect();
    out
}

#[test]
fn a_mesh_split_to_fit_the_binding_draws_the_whole_meshs_picture_pixel_for_pixel() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    let (mesh, camera) = teapot();
    let levels: Vec<f32> = (0..32).map(|p| p as f32 / 31.0).collect();
    for (mesh, what) in [(mesh.clone(), "in order"), (shuffled(&mesh), "shuffled")] {
        let whole = gpu::MeshBuffers::upload(&ctx, &mesh, &levels).unwrap();
        assert_eq!(whole.part_count(), 1);
        // 4 KiB bindings: 128 vertices or 341 triangles a part.
        let split = gpu::MeshBuffers::upload_within(&ctx, &mesh, &levels, 4096).unwrap();
        assert!(split.part_count() >= 12, "{what}: {} parts", split.part_count());
        for (color, samples) in [(ColorMode::Patch, 1), (ColorMode::Level, 4), (ColorMode::Shaded, 4)] {
            let options = RenderOptions { wireframe: true, color };
            let a = gpu::render(&ctx, &whole.geometries(), &camera, &options, samples).unwrap();
            let b = gpu::render(&ctx, &split.geometries(), &camera, &options, samples).unwrap();
            assert!(a.covered_pixels() > 5000, "{what}: {} covered", a.covered_pixels());
            assert_eq!(a.differing_pixels(&b, 0), 0, "{what}, {color:?}, {samples} samples");
        }
    }
}

#[test]
fn a_binding_below_one_triangle_is_refused() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    let (mesh, _) = teapot();
    let e = gpu::MeshBuffers::upload_within(&ctx, &mesh, &[], 64).unwrap_err();
    assert!(matches!(e, RenderError::Invalid(_)), "{e}");
}

/// Limits of an adapter like lavapipe: 16384-pixel textures, 2 GiB buffers.
fn limits() -> wgpu::Limits {
    wgpu::Limits { max_texture_dimension_2d: 16384, max_buffer_size: 1 << 31, ..Default::default() }
}

#[test]
fn sizes_past_the_texture_limit_or_the_memory_caps_are_refused_naming_the_limit() {
    let limits = limits();
    let gpu = |samples| Drawing::Gpu { limits: &limits, samples };
    let window = |screenshot| Drawing::Window { limits: &limits, samples: 4, screenshot };
    let refused = |w, h, d| match tessera_render::check_image_size(w, h, d) {
        Err(RenderError::ImageTooLarge { reason, .. }) => reason,
        other => panic!("{w}x{h}: {other:?}"),
    };
    // What panicked in wgpu: a 2.3 GB multisampled target, 4.3 GB ones, sides past 16384.
    assert!(refused(12000, 12000, gpu(4)).contains("MAX_ALLOCATION_BYTES"));
    assert!(refused(16384, 16384, gpu(4)).contains("MAX_ALLOCATION_BYTES"));
    assert!(refused(16384, 16384, window(false)).contains("MAX_ALLOCATION_BYTES"));
    assert!(refused(20000, 100, window(false)).contains("max_texture_dimension_2d"));
    assert!(refused(100000, 100000, window(true)).contains("max_texture_dimension_2d"));
    assert!(refused(0, 100, gpu(1)).contains("1 to 16384"));
    // One sample: every target within 2 GiB, but five of 1 GiB (depth, three surface images,
    // the screenshot's read-back).
    assert!(refused(16384, 16384, Drawing::Window { limits: &limits, samples: 1, screenshot: true })
        .contains("MAX_TARGET_BYTES"));
    assert!(refused(9000, 9000, Drawing::Cpu).contains("8192"));
    // What lavapipe draws: 12000² at one sample (1.7 GB), 8192² at four (2.7 GB).
    for (w, h, d) in [(12000, 12000, gpu(1)), (8192, 8192, gpu(4)), (1024, 640, window(true))] {
        let bytes = tessera_render::check_image_size(w, h, d).unwrap();
        assert!(bytes.total <= tessera_render::MAX_TARGET_BYTES);
        assert!(bytes.largest <= tessera_render::MAX_ALLOCATION_BYTES);
    }
    let bytes = tessera_render::check_image_size(1000, 1000, gpu(4)).unwrap();
    // Colour and depth at 4 samples, the resolved image, the read-back (rows of 4096 bytes).
    assert_eq!(bytes.total, 16_000_000 + 16_000_000 + 4_000_000 + 4096 * 1000);
    assert_eq!(bytes.largest, 16_000_000);
}

#[test]
fn the_renderers_refuse_a_size_before_allocating_it() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    let (mesh, mut camera) = teapot();
    let buffers = gpu::MeshBuffers::upload(&ctx, &mesh, &[]).unwrap();
    camera.width = 12000;
    camera.height = 12000;
    let e = gpu::render(&ctx, &buffers.geometries(), &camera, &RenderOptions::default(), 4).unwrap_err();
    assert!(matches!(e, RenderError::ImageTooLarge { width: 12000, .. }), "{e}");
    camera.width = 9000;
    camera.height = 9000;
    let e = tessera_render::cpu::render(&mesh, &camera, &RenderOptions::default(), &[]).unwrap_err();
    assert!(matches!(e, RenderError::ImageTooLarge { width: 9000, .. }), "{e}");
}

#[test]
fn wgpu_errors_become_typed_errors_not_panics() {
    let ctx = GpuContext::new().unwrap_or_else(|e| panic!("{e}"));
    let too_wide = wgpu::TextureDescriptor {
        label: Some("too wide"),
        size: wgpu::Extent3d {
            width: ctx.limits.max_texture_dimension_2d + 1,
            height: 1,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: gpu::IMAGE_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    };
    let e = tessera_render::scoped(&ctx.device, "making a texture", || {
        drop(ctx.device.create_texture(&too_wide));
    })
    .unwrap_err();
    assert!(
        matches!(&e, RenderError::Wgpu { kind: WgpuErrorKind::Validation, what, .. } if what == "making a texture"),
        "{e}"
    );
    // Outside any scope: recorded by the context instead of wgpu's default handler, which
    // panics, and returned by its check.
    let _texture = ctx.device.create_texture(&too_wide);
    assert!(ctx.check_errors().is_err());
    ctx.check_errors().unwrap();
    // And a good call in a scope is Ok.
    tessera_render::scoped(&ctx.device, "nothing", || ()).unwrap();
}
