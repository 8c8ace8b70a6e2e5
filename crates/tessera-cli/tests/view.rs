//! `tessera view --frames N --screenshot`: the viewer opens a window under Xvfb (a virtual X
//! server), re-tessellates and draws N frames and saves the last one. Needs `xvfb-run`
//! (Debian: `apt-get install -y xvfb xauth`, as `.ci/run` does) and a GPU adapter
//! (`mesa-vulkan-drivers libvulkan1`); without them the test fails, saying so.

mod common;

use common::{data, scratch, text};
use std::process::Command;

#[test]
fn viewer_draws_frames_under_xvfb_and_saves_a_screenshot() {
    let found =
        Command::new("sh").args(["-c", "command -v xvfb-run"]).output().is_ok_and(|o| o.status.success());
    assert!(found, "xvfb-run is missing: install it (Debian/Ubuntu: apt-get install -y xvfb xauth) to run the viewer test");
    let dir = scratch("viewer-shot");
    let input = data("patches/teapot.patches");
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1024x768x24", env!("CARGO_BIN_EXE_tessera"), "view"])
        .arg(&input)
        .args(["--frames", "4", "--screenshot", "shot.png", "--size", "480x320"])
        .current_dir(&dir)
        .output()
        .expect("run xvfb-run");
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "tessera view failed: {stderr}");
    assert!(stderr.contains("after 4 frames"), "{stderr}");
    assert!(stderr.contains("TRIS"), "{stderr}");
    let decoder =
        png::Decoder::new(std::io::BufReader::new(std::fs::File::open(dir.join("shot.png")).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (480, 320));
    let rgb = &buf[..info.buffer_size()];
    let pixel = |x: usize, y: usize| &rgb[3 * (y * 480 + x)..][..3];
    // The model in the middle (not the white background) ...
    let covered = (0..320)
        .flat_map(|y| (0..480).map(move |x| (x, y)))
        .filter(|&(x, y)| pixel(x, y) != [255, 255, 255])
        .count();
    assert!(covered > 480 * 320 / 20, "only {covered} pixels are not background");
    assert_ne!(pixel(240, 170), [255, 255, 255], "nothing drawn at the centre");
    // ... and the statistics panel at the top left: dark pixels and light glyph pixels.
    let panel: Vec<&[u8]> =
        (10..30).flat_map(|y| (10..200).map(move |x| (x, y))).map(|(x, y)| pixel(x, y)).collect();
    assert!(panel.iter().any(|p| p.iter().all(|&c| c < 110)), "no statistics panel");
    assert!(panel.iter().any(|p| p.iter().all(|&c| c > 200)), "no text on the panel");
}

#[test]
fn viewer_draws_semi_uniform_with_the_instanced_path() {
    let found =
        Command::new("sh").args(["-c", "command -v xvfb-run"]).output().is_ok_and(|o| o.status.success());
    assert!(found, "xvfb-run is missing: install it (Debian/Ubuntu: apt-get install -y xvfb xauth) to run the viewer test");
    let dir = scratch("viewer-instanced");
    let input = data("meshes/blob.obj");
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1024x768x24", env!("CARGO_BIN_EXE_tessera"), "view"])
        .arg(&input)
        .args(["--scheme", "semi-uniform", "--frames", "3", "--screenshot", "su.png", "--size", "320x240"])
        .current_dir(&dir)
        .output()
        .expect("run xvfb-run");
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "tessera view failed: {stderr}");
    assert!(stderr.contains("semi-uniform") && stderr.contains("(INSTANCED)"), "{stderr}");
    let decoder =
        png::Decoder::new(std::io::BufReader::new(std::fs::File::open(dir.join("su.png")).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let rgb = &buf[..info.buffer_size()];
    let covered = rgb.chunks_exact(3).filter(|p| *p != [255, 255, 255]).count();
    assert!(covered > 320 * 240 / 10, "only {covered} pixels are not background");
}

/// Runs `tessera view IN ARGS` under `xvfb-run` with extra environment, returning the output.
fn view(input: &str, args: &[&str], env: &[(&str, &str)], dir: &std::path::Path) -> std::process::Output {
    let found =
        Command::new("sh").args(["-c", "command -v xvfb-run"]).output().is_ok_and(|o| o.status.success());
    assert!(found, "xvfb-run is missing: install it (Debian/Ubuntu: apt-get install -y xvfb xauth) to run the viewer test");
    let mut command = Command::new("xvfb-run");
    command
        .args(["-a", "-s", "-screen 0 1024x768x24", env!("CARGO_BIN_EXE_tessera"), "view"])
        .arg(data(input))
        .args(args)
        .current_dir(dir);
    for (k, v) in env {
        command.env(k, v);
    }
    command.output().expect("run xvfb-run")
}

#[test]
fn viewer_refuses_sizes_it_cannot_draw_before_opening_a_window() {
    // Each panicked in wgpu or winit; now the check `tessera render` makes refuses them.
    let dir = scratch("viewer-sizes");
    for (size, limit) in [
        ("16384x16384", "MAX_ALLOCATION_BYTES"),
        ("20000x100", "max_texture_dimension_2d"),
        ("100000x100000", "max_texture_dimension_2d"),
    ] {
        let out = view("patches/teapot.patches", &["--size", size, "--frames", "1"], &[], &dir);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{size}: {stderr}");
        assert!(!stderr.contains("panicked"), "{size}: {stderr}");
        assert!(stderr.contains(&format!("error: image size {size}: ")), "{size}: {stderr}");
        assert!(stderr.contains(limit), "{size}: {stderr}");
    }
}

#[test]
fn viewer_starts_in_every_scheme_its_help_and_errors_list() {
    let dir = scratch("viewer-schemes");
    let schemes = ["transition", "uniform", "semi-uniform", "fractional-odd", "integer", "sd2", "esc"];
    let help = common::tessera(&["view", "--help"], &dir);
    let help = text(&help.stdout);
    // A scheme the viewer does not show: its error names exactly the ones it does.
    let out = view("meshes/blob.obj", &["--scheme", "pow2", "--frames", "1"], &[], &dir);
    let refusal = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{refusal}");
    assert!(refusal.contains(&format!("the viewer shows {}", schemes.join(", "))), "{refusal}");
    // One it shows, on a set it cannot draw: the library's reason.
    let out = view("patches/teapot.patches", &["--scheme", "sd2", "--frames", "1"], &[], &dir);
    let refusal = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{refusal}");
    assert!(refusal.contains("does not tessellate quad patches"), "{refusal}");
    for scheme in schemes {
        assert!(help.contains(scheme), "--help does not name {scheme}: {help}");
        // ESC takes bicubic patches, the others the triangle mesh.
        let model = if scheme == "esc" { "patches/teapot.patches" } else { "meshes/blob.obj" };
        let out = view(
            model,
            &["--scheme", scheme, "--frames", "2", "--screenshot", "s.png", "--size", "160x120"],
            &[],
            &dir,
        );
        let stderr = text(&out.stderr);
        assert!(out.status.success(), "--scheme {scheme}: {stderr}");
        assert!(stderr.contains(&format!("after 2 frames: {scheme} ")), "{scheme}: {stderr}");
        // The GPU engine draws every scheme of the viewer (semi-uniform by the instanced path).
        assert!(stderr.contains("GPU ENGINE") || stderr.contains("INSTANCED"), "{scheme}: {stderr}");
        if scheme == "fractional-odd" || scheme == "integer" {
            // The hardware tessellator takes a factor: the one derived from the pixel error.
            assert!(stderr.contains("(FACTOR "), "{scheme}: {stderr}");
        }
    }
}

#[test]
fn viewer_without_an_adapter_names_the_driver_packages() {
    // No Vulkan driver to load: what a machine without mesa-vulkan-drivers sees.
    let dir = scratch("viewer-no-adapter");
    let hide = [("VK_ICD_FILENAMES", "/nonexistent/icd.json"), ("VK_DRIVER_FILES", "/nonexistent/icd.json")];
    let out = view("patches/teapot.patches", &["--frames", "1"], &hide, &dir);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("mesa-vulkan-drivers libvulkan1"), "{stderr}");
}

/// A Loop cage is drawn by the GPU engine (its trees of quartic and Gregory triangles,
/// `tree.wgsl`), not by the CPU fallback the viewer keeps for sets the GPU refuses.
#[test]
fn viewer_draws_a_loop_cage_with_the_gpu_engine() {
    let dir = scratch("viewer-loop");
    let args = ["--surface", "loop", "--frames", "2", "--screenshot", "l.png", "--size", "160x120"];
    let out = view("subdivision/loop_cube_creases0.obj", &args, &[], &dir);
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("the CPU engine draws it"), "{stderr}");
    assert!(stderr.contains("GPU ENGINE") && !stderr.contains("CPU ENGINE"), "{stderr}");
    assert!(dir.join("l.png").exists());
}
