//! `tessera render` against an independent coverage count, the CPU and GPU engines against
//! each other, and the CPU fallback rasteriser against the wgpu renderer. The wgpu runs need
//! a GPU adapter (lavapipe in CI): without one they fail with the packages to install.
//!
//! The coverage reference is a small rasteriser written here, not the renderer's: the test
//! tessellates the same plan with the library, projects every vertex with
//! `Camera::project` (the camera rule the criteria use) and marks the pixels whose centre
//! lies inside a triangle. Images are 256×256 with one sample per pixel (`--msaa 1`), so
//! both count the same thing: pixel centres covered.

mod common;

use common::{data, scratch, tessera, text};
use std::path::Path;
use tessera::camera::Camera;
use tessera::scheme::{Criterion, PlanOptions, Scheme};
use tessera::surface::BuildOptions;
use tessera::tessellator::{Tessellator, TessellatorOptions};

const SIZE: u32 = 256;

/// Pixels that are not pure white (the renderer's background; no surface pixel is white).
fn covered(png: &Path) -> (usize, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (SIZE, SIZE));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let rgb = buf[..info.buffer_size()].to_vec();
    (rgb.chunks_exact(3).filter(|p| *p != [255, 255, 255]).count(), rgb)
}

/// Covered pixel centres of the mesh the library makes for `criterion` on `input`, seen
/// from the default camera framing the model at SIZE × SIZE.
fn reference_coverage(input: &Path, scheme: Scheme, criterion: Criterion) -> usize {
    let set = tessera::io::load(input, BuildOptions::default()).unwrap();
    let (lo, hi) = set.bounds();
    let camera = Camera::framing_up(lo, hi, SIZE, SIZE, set.up);
    let options = TessellatorOptions {
        plan: PlanOptions { camera: Some(camera), ..Default::default() },
        engine: Default::default(),
    };
    let mut tess = Tessellator::new(&set, scheme, criterion, options).unwrap();
    let mesh = tess.frame(Some(&camera)).unwrap();
    let half = SIZE as f64 / 2.0;
    // Image coordinates: x right from the left edge, y down from the top.
    let screen: Vec<Option<(f64, f64)>> = mesh
        .positions
        .iter()
        .map(|p| {
            let p = glam::DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
            camera.project(p).map(|q| (q.x + half, half - q.y))
        })
        .collect();
    let mut hit = vec![false; (SIZE * SIZE) as usize];
    for t in mesh.indices.chunks_exact(3) {
        let [Some(a), Some(b), Some(c)] =
            [screen[t[0] as usize], screen[t[1] as usize], screen[t[2] as usize]]
        else {
            continue;
        };
        let cross =
            |o: (f64, f64), p: (f64, f64), x: f64, y: f64| (p.0 - o.0) * (y - o.1) - (p.1 - o.1) * (x - o.0);
        let area = cross(a, b, c.0, c.1);
        if area == 0.0 {
            continue;
        }
        let x0 = a.0.min(b.0).min(c.0).floor().max(0.0) as usize;
        let x1 = (a.0.max(b.0).max(c.0).ceil().max(0.0) as usize).min(SIZE as usize);
        let y0 = a.1.min(b.1).min(c.1).floor().max(0.0) as usize;
        let y1 = (a.1.max(b.1).max(c.1).ceil().max(0.0) as usize).min(SIZE as usize);
        for y in y0..y1 {
            for x in x0..x1 {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                let w = [cross(b, c, px, py), cross(c, a, px, py), cross(a, b, px, py)];
                if w.iter().all(|&w| w * area >= 0.0) {
                    hit[y * SIZE as usize + x] = true;
                }
            }
        }
    }
    hit.iter().filter(|&&h| h).count()
}

fn render(input: &Path, dir: &Path, name: &str, extra: &[&str]) -> (usize, Vec<u8>) {
    let size = format!("{SIZE}x{SIZE}");
    let mut args = vec!["render", input.to_str().unwrap(), "-o", name, "--size", &size];
    args.extend_from_slice(extra);
    let out = tessera(&args, dir);
    assert!(out.status.success(), "tessera {}: {}", args.join(" "), text(&out.stderr));
    covered(&dir.join(name))
}

fn within(a: usize, b: usize, share: f64) -> bool {
    (a as f64 - b as f64).abs() <= share * b as f64
}

#[test]
fn coverage_equals_an_independent_rasteriser_within_one_percent() {
    let dir = scratch("render-coverage");
    let cases: [(&str, &[&str], Scheme, Criterion); 3] = [
        ("patches/teapot.patches", &["--pixel-error", "1"], Scheme::Transition, Criterion::PixelError(1.0)),
        ("meshes/spool.obj", &["--factor", "3"], Scheme::Uniform, Criterion::Factor(3.0)),
        ("meshes/blob.obj", &["--factor", "4", "--wireframe"], Scheme::Uniform, Criterion::Factor(4.0)),
    ];
    for (model, flags, scheme, criterion) in cases {
        let input = data(model);
        let mut args = flags.to_vec();
        args.extend(["--msaa", "1", "--renderer", "wgpu"]);
        let (rendered, _) = render(&input, &dir, "c.png", &args);
        let reference = reference_coverage(&input, scheme, criterion);
        // A framed model covers a good part of the image: a tiny count would prove nothing.
        assert!(reference > 4000, "{model}: only {reference} pixels covered");
        eprintln!("{model}: rendered {rendered} covered pixels, reference {reference}");
        assert!(
            within(rendered, reference, 0.01),
            "{model}: rendered {rendered} pixels, reference {reference}"
        );
    }
}

#[test]
fn cpu_and_gpu_engines_draw_the_same_picture() {
    let dir = scratch("render-engines");
    let input = data("patches/teapot.patches");
    for flags in [&["--pixel-error", "1", "--wireframe"][..], &["--factor", "6", "--color", "patch"][..]] {
        let mut cpu_args = flags.to_vec();
        cpu_args.extend(["--engine", "cpu"]);
        let mut gpu_args = flags.to_vec();
        gpu_args.extend(["--engine", "gpu"]);
        let (cpu_covered, cpu) = render(&input, &dir, "cpu.png", &cpu_args);
        let (gpu_covered, gpu) = render(&input, &dir, "gpu.png", &gpu_args);
        assert!(cpu_covered > 4000, "{flags:?}: {cpu_covered}");
        assert!(within(gpu_covered, cpu_covered, 0.005), "{flags:?}: GPU {gpu_covered}, CPU {cpu_covered}");
        // A pixel differs when a channel is off by more than 2/255 (rounding of shading).
        let differ = cpu
            .chunks_exact(3)
            .zip(gpu.chunks_exact(3))
            .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > 2))
            .count();
        let share = differ as f64 / (SIZE * SIZE) as f64;
        eprintln!("{flags:?}: {differ} pixels differ ({:.3} %)", 100.0 * share);
        assert!(share <= 0.005, "{flags:?}: {differ} pixels differ ({:.3} %)", 100.0 * share);
    }
}

#[test]
fn cpu_fallback_rasteriser_covers_what_wgpu_covers() {
    let dir = scratch("render-fallback");
    for (model, flags) in [
        ("patches/teapot.patches", &["--pixel-error", "1", "--wireframe"][..]),
        ("meshes/spool.obj", &["--factor", "3", "--color", "level"][..]),
    ] {
        let input = data(model);
        let mut wgpu_args = flags.to_vec();
        wgpu_args.extend(["--msaa", "1", "--renderer", "wgpu"]);
        let mut cpu_args = flags.to_vec();
        cpu_args.extend(["--renderer", "cpu"]);
        let (w, wgpu_rgb) = render(&input, &dir, "wgpu.png", &wgpu_args);
        let (c, cpu_rgb) = render(&input, &dir, "cpu.png", &cpu_args);
        assert!(within(c, w, 0.01), "{model}: CPU rasteriser {c} pixels, wgpu {w}");
        // Same shading: most covered pixels agree closely (edges and wire anti-aliasing may
        // differ by a sample position).
        let close = cpu_rgb
            .chunks_exact(3)
            .zip(wgpu_rgb.chunks_exact(3))
            .filter(|(a, b)| a.iter().zip(b.iter()).all(|(x, y)| x.abs_diff(*y) <= 8))
            .count();
        let far = (SIZE * SIZE) as usize - close;
        eprintln!("{model}: {far} of {w} covered pixels differ by more than 8/255");
        assert!(
            far as f64 <= 0.05 * w as f64,
            "{model}: {far} of {w} covered pixels differ by more than 8/255"
        );
    }
}

#[test]
fn a_mesh_split_to_fit_a_low_binding_cap_draws_the_same_picture() {
    // Armadillo at --factor 16 (6.6 M vertices) passed lavapipe's 128 MiB storage binding
    // and panicked in wgpu; the hidden cap makes the teapot split the same way, fast.
    let dir = scratch("render-split");
    let input = data("patches/teapot.patches");
    for flags in [&["--factor", "8", "--wireframe", "--color", "patch"][..], &["--pixel-error", "1"][..]] {
        let (whole_covered, whole) = render(&input, &dir, "whole.png", flags);
        let mut split_flags = flags.to_vec();
        split_flags.extend(["--max-binding-bytes", "4096"]);
        let size = format!("{SIZE}x{SIZE}");
        let mut args = vec!["render", input.to_str().unwrap(), "-o", "split.png", "--size", &size];
        args.extend_from_slice(&split_flags);
        let out = tessera(&args, &dir);
        let stderr = text(&out.stderr);
        assert!(out.status.success(), "{flags:?}: {stderr}");
        assert!(stderr.contains(" parts within the adapter's binding limit"), "{flags:?}: {stderr}");
        let (split_covered, split) = covered(&dir.join("split.png"));
        assert!(whole_covered > 4000, "{flags:?}: {whole_covered}");
        assert_eq!(split_covered, whole_covered, "{flags:?}");
        assert!(split == whole, "{flags:?}: the split picture differs from the whole one");
    }
}

#[test]
fn sizes_the_adapter_or_the_memory_caps_cannot_take_are_refused_before_any_work() {
    let dir = scratch("render-sizes");
    let input = data("patches/teapot.patches");
    let input = input.to_str().unwrap();
    // Each of these passed the old check and then panicked in wgpu (out of memory, rc 101),
    // or would have taken the CPU rasteriser gigabytes.
    let cases: [(&[&str], &str); 6] = [
        (&["--size", "12000x12000"], "MAX_ALLOCATION_BYTES"),
        (&["--size", "16384x16384"], "MAX_ALLOCATION_BYTES"),
        (&["--size", "12000x12000", "--engine", "gpu"], "MAX_ALLOCATION_BYTES"),
        (&["--size", "20000x100"], "max_texture_dimension_2d"),
        (&["--size", "100000x100000", "--msaa", "1"], "max_texture_dimension_2d"),
        (&["--size", "9000x9000", "--renderer", "cpu"], "the CPU rasteriser's limit"),
    ];
    for (flags, limit) in cases {
        let mut args = vec!["render", input, "-o", "big.png"];
        args.extend_from_slice(flags);
        let out = tessera(&args, &dir);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flags:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{flags:?}: {stderr}");
        let size = flags[1];
        assert!(stderr.contains(&format!("error: image size {size}: ")), "{flags:?}: {stderr}");
        assert!(stderr.contains(limit), "{flags:?}: {stderr}");
        assert!(!dir.join("big.png").exists(), "{flags:?}: a picture was written");
    }
}
