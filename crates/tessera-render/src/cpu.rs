//! The CPU fallback rasteriser: a z-buffer scan converter with the same camera
//! ([`Camera::view_projection`]) and the same shading ([`crate::shading`]) as the wgpu
//! renderer, one sample per pixel centre.
//!
//! Why it exists: `tessera demo` must draw the teapot on a machine with no GPU adapter at
//! all (no Vulkan driver installed), where wgpu has nothing to render with. It is written
//! by hand (a few dozen lines) rather than taken from a crate to keep the clean build short
//! and to share the shading functions with the GPU path exactly. It is not fast (one
//! thread, O(covered pixels) per triangle) and is not the renderer of choice: the wgpu one
//! is, whenever an adapter exists.

use crate::shading;
use crate::{Image, RenderError, RenderOptions};
use glam::{Vec3, Vec4};
use tessera::camera::Camera;
use tessera::mesh::Mesh;

/// The longest side the rasteriser draws: WebGPU's default texture limit. It is one thread,
/// and its buffers take 20 bytes a pixel, so larger pictures would take minutes and
/// gigabytes.
pub const MAX_SIDE: u32 = 8192;

/// Draws `mesh` seen from `camera` (its viewport is the image size) with `options`;
/// `patch_level` gives each patch's level for [`crate::ColorMode::Level`] (may be empty).
/// A pixel is covered when its centre lies inside a triangle (top-left rule not needed for
/// a picture; shared edges may be drawn twice, with the nearer depth winning). Errors:
/// [`RenderError::ImageTooLarge`] from [`crate::check_image_size`], before any buffer is
/// made. Cost: O(V + Σ bounding-box pixels of the triangles), single-threaded.
pub fn render(
    mesh: &Mesh,
    camera: &Camera,
    options: &RenderOptions,
    patch_level: &[f32],
) -> Result<Image, RenderError> {
    crate::check_image_size(camera.width, camera.height, crate::Drawing::Cpu)?;
    let (w, h) = (camera.width as usize, camera.height as usize);
    let m = camera.view_projection().as_mat4();
    let (r, u, f) = camera.basis();
    let light = shading::light_direction(r.as_vec3(), u.as_vec3(), f.as_vec3());
    let eye = camera.eye.as_vec3();
    // Clip-space positions, then screen positions (pixel units, y down like the image).
    let clip: Vec<Vec4> = mesh.positions.iter().map(|p| m * Vec3::from(*p).extend(1.0)).collect();
    let mut depth = vec![f32::INFINITY; w * h];
    let background = Vec3::from(shading::BACKGROUND);
    let mut colour = vec![background; w * h];
    for t in 0..mesh.triangle_count() {
        let idx = mesh.triangle(t).map(|i| i as usize);
        let c = idx.map(|i| clip[i]);
        // Triangles reaching behind the eye would need clipping; a picture of a framed model
        // has none, and the near plane drops them whole (as depth clipping would drop
        // their hidden part).
        if c.iter().any(|c| c.w <= 0.0 || c.z < 0.0 || c.z > c.w) {
            continue;
        }
        let s = c.map(|c| {
            let ndc = c.truncate() / c.w;
            Vec3::new((ndc.x + 1.0) * 0.5 * w as f32, (1.0 - ndc.y) * 0.5 * h as f32, ndc.z)
        });
        let area = (s[1].x - s[0].x) * (s[2].y - s[0].y) - (s[2].x - s[0].x) * (s[1].y - s[0].y);
        if area == 0.0 || !area.is_finite() {
            continue;
        }
        let patch = mesh.triangle_patch.get(t).copied().unwrap_or(0);
        let level = patch_level.get(patch as usize).copied().unwrap_or(0.0);
        let base = shading::base_colour(options.color, patch, level);
        let lo_x = s.iter().map(|p| p.x).fold(f32::INFINITY, f32::min).floor().max(0.0) as usize;
        let hi_x = (s.iter().map(|p| p.x).fold(f32::NEG_INFINITY, f32::max).ceil() as usize).min(w);
        let lo_y = s.iter().map(|p| p.y).fold(f32::INFINITY, f32::min).floor().max(0.0) as usize;
        let hi_y = (s.iter().map(|p| p.y).fold(f32::NEG_INFINITY, f32::max).ceil() as usize).min(h);
        // Screen-space barycentric derivatives, summed as the shader's `fwidth` sums them.
        let edge = |a: Vec3, b: Vec3, x: f32, y: f32| (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x);
        let grad = [(1usize, 2usize), (2, 0), (0, 1)].map(|(i, j)| {
            let (a, b) = (s[i], s[j]);
            ((b.y - a.y).abs() + (b.x - a.x).abs()) / area.abs()
        });
        let normals = idx.map(|i| Vec3::from(mesh.normals.get(i).copied().unwrap_or([0.0; 3])));
        let world = idx.map(|i| Vec3::from(mesh.positions[i]));
        let face = (world[1] - world[0]).cross(world[2] - world[0]);
        for y in lo_y..hi_y {
            for x in lo_x..hi_x {
                let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                let b =
                    Vec3::new(edge(s[1], s[2], px, py), edge(s[2], s[0], px, py), edge(s[0], s[1], px, py))
                        / area;
                if b.min_element() < 0.0 {
                    continue;
                }
                let z = b.dot(Vec3::new(s[0].z, s[1].z, s[2].z));
                let k = y * w + x;
                if z >= depth[k] {
                    continue;
                }
                depth[k] = z;
                // Perspective-correct attributes: weights by 1/w.
                let pw = Vec3::new(b.x / c[0].w, b.y / c[1].w, b.z / c[2].w);
                let pw = pw / (pw.x + pw.y + pw.z);
                let p = world[0] * pw.x + world[1] * pw.y + world[2] * pw.z;
                let mut n = normals[0] * pw.x + normals[1] * pw.y + normals[2] * pw.z;
                if n.length_squared() < 1e-20 {
                    n = face;
                }
                let mut n = n.normalize_or_zero();
                let v = (eye - p).normalize_or_zero();
                let back = n.dot(v) < 0.0;
                if back {
                    n = -n;
                }
                let mut out = shading::shade(base, n, v, light, back);
                if options.wireframe {
                    let d = Vec3::new(b.x / grad[0], b.y / grad[1], b.z / grad[2]).min_element();
                    out = shading::with_wire(out, shading::wire_coverage(d));
                }
                colour[k] = out;
            }
        }
    }
    let rgba = colour
        .iter()
        .flat_map(|c| {
            let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            [q(c.x), q(c.y), q(c.z), 255]
        })
        .collect();
    Ok(Image { width: camera.width, height: camera.height, rgba })
}
