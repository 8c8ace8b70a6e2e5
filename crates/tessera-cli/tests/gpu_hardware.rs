//! `tessera mesh --engine gpu` with the Direct3D 11 partitionings: the GPU engine's mesh has
//! the CPU engine's counts and closedness for the same command.

mod common;

use common::{data, scratch, tessera, text};
use std::process::Output;

fn stats_of(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "{}", text(&out.stderr));
    serde_json::from_str(text(&out.stdout).trim()).unwrap()
}

#[test]
fn fractional_schemes_on_the_gpu_give_the_cpu_mesh() {
    let dir = scratch("gpu-hardware");
    let teapot = data("patches/teapot.patches");
    let blob = data("meshes/blob.obj");
    for (input, args, closed) in [
        // A real factor on the bicubic teapot (open along its 16 free curves).
        (&teapot, &["--scheme", "fractional-odd", "--factor", "5.3"][..], false),
        // Real per-edge factors from the silhouettes of a closed PN-triangle mesh.
        (&blob, &["--scheme", "fractional-even", "--silhouette", "2:9.5"][..], true),
    ] {
        let mut command = vec!["mesh", input.to_str().unwrap(), "--stats"];
        command.extend_from_slice(args);
        let cpu = stats_of(&tessera(&[&command[..], &["-o", "cpu.obj"]].concat(), &dir));
        let gpu = stats_of(&tessera(&[&command[..], &["--engine", "gpu", "-o", "gpu.obj"]].concat(), &dir));
        assert_eq!(gpu["engine"], "gpu", "{args:?}");
        assert!(gpu["gpu_pass_ms"].is_object(), "{gpu}");
        for key in ["triangles", "vertices", "boundary_edges", "nonmanifold_edges", "euler_characteristic"] {
            assert_eq!(gpu[key], cpu[key], "{args:?}: {key}");
        }
        assert_eq!(gpu["repairs"]["collapsed_triangles"], cpu["repairs"]["collapsed_triangles"], "{args:?}");
        assert!(gpu["triangles"].as_u64().unwrap() > 1000, "{args:?}: {gpu}");
        if closed {
            assert_eq!(gpu["boundary_edges"], 0, "{args:?}: the GPU mesh is not watertight");
        }
        // The file written is the GPU's mesh, and it checks as the CPU's does (its welded
        // topology: boundary, non-manifold and misoriented edges, Euler characteristic).
        let check = |file: &str| {
            let out = tessera(&["check", file, "--against", input.to_str().unwrap()], &dir);
            assert!(out.status.success(), "{file}: {}", text(&out.stderr));
            let report = text(&out.stdout);
            let keys =
                ["triangles", "boundary edges", "non-manifold edges", "misoriented edges", "Euler", "closed"];
            let lines: Vec<String> =
                report.lines().filter(|l| keys.iter().any(|k| l.starts_with(k))).map(String::from).collect();
            assert_eq!(lines.len(), keys.len(), "{report}");
            lines
        };
        let (gpu_check, cpu_check) = (check("gpu.obj"), check("cpu.obj"));
        assert_eq!(gpu_check, cpu_check, "{args:?}");
        if closed {
            assert!(gpu_check.iter().any(|l| l.starts_with("closed") && l.contains("yes")), "{gpu_check:?}");
        }
    }
}
