//! The one shading rule of both renderers: base colours per patch or per level, Lambert +
//! Blinn-Phong from the interpolated normal, the anti-aliased wireframe. `shaders/draw.wgsl`
//! mirrors each function here under the same name; the CPU fallback ([`crate::cpu`]) calls
//! them directly, so the two renderers draw the same picture.
//!
//! Colours are display values (0..1, written to an 8-bit non-sRGB target as they are): a
//! simple "gamma-space" shading, enough to show the shape and the tessellation.

use glam::Vec3;

/// How triangles are coloured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ColorMode {
    /// One porcelain colour, shaded.
    #[default]
    Shaded,
    /// A distinct colour per patch (a hash of its index), shaded.
    Patch,
    /// A colour ramp (blue → green → red) over each patch's tessellation level, shaded: the
    /// adaptive detail made visible.
    Level,
}

impl ColorMode {
    /// The code `draw.wgsl` reads in `Frame::flags.x`.
    pub fn code(self) -> u32 {
        match self {
            ColorMode::Shaded => 0,
            ColorMode::Patch => 1,
            ColorMode::Level => 2,
        }
    }
}

/// The background: pure white. No surface pixel is pure white ([`MAX_SURFACE`] clamps every
/// channel below it, MSAA blends included), so a pixel is covered exactly when it differs
/// from the background — what the coverage tests count.
pub const BACKGROUND: [f32; 3] = [1.0, 1.0, 1.0];

/// The largest channel value a surface pixel gets.
pub const MAX_SURFACE: f32 = 0.96;

/// Wireframe colour.
pub const WIRE_COLOR: [f32; 3] = [0.20, 0.18, 0.18];

/// Wireframe line width in pixels.
pub const WIRE_WIDTH: f32 = 1.0;

/// The direction towards the light for a camera basis: a head light from above left, so
/// that what the camera sees is lit.
pub fn light_direction(right: Vec3, up: Vec3, forward: Vec3) -> Vec3 {
    (-forward + 0.45 * up - 0.35 * right).normalize()
}

/// Base colour of a triangle: `patch` its patch, `level` that patch's level in [0, 1]
/// (see [`crate::patch_levels`]). Mirrored by `base_colour` in `draw.wgsl`.
pub fn base_colour(mode: ColorMode, patch: u32, level: f32) -> Vec3 {
    match mode {
        ColorMode::Shaded => Vec3::new(0.80, 0.63, 0.47),
        ColorMode::Patch => {
            // The golden-ratio sequence spreads consecutive patches round the hue circle.
            let h = (patch as f32 * 0.618_034).fract();
            hsv(h, 0.45, 0.85)
        }
        ColorMode::Level => {
            let t = level.clamp(0.0, 1.0);
            let (a, b, c) =
                (Vec3::new(0.25, 0.45, 0.85), Vec3::new(0.35, 0.75, 0.35), Vec3::new(0.85, 0.30, 0.25));
            if t < 0.5 {
                a.lerp(b, 2.0 * t)
            } else {
                b.lerp(c, 2.0 * t - 1.0)
            }
        }
    }
}

/// HSV to RGB. Mirrored by `hsv` in `draw.wgsl`.
pub fn hsv(h: f32, s: f32, v: f32) -> Vec3 {
    let k = Vec3::new(5.0, 3.0, 1.0);
    let p = (Vec3::splat(h * 6.0) + k).map(|x| x % 6.0);
    let q = (p.min(Vec3::splat(4.0) - p)).clamp(Vec3::ZERO, Vec3::ONE);
    Vec3::splat(v) - v * s * q
}

/// Lambert + Blinn-Phong: `n` the unit normal facing the viewer (a back face's normal
/// flipped, so that insides seen through openings are lit too, `back` darkens them), `v`
/// towards the eye, `l` towards the light. Mirrored by `shade` in `draw.wgsl`.
pub fn shade(base: Vec3, n: Vec3, v: Vec3, l: Vec3, back: bool) -> Vec3 {
    let diffuse = n.dot(l).max(0.0);
    let h = (l + v).normalize_or_zero();
    let specular = 0.30 * n.dot(h).max(0.0).powf(40.0);
    let tint = if back { 0.6 } else { 1.0 };
    let c = base * tint * (0.18 + 0.82 * diffuse) + Vec3::splat(specular * tint);
    c.min(Vec3::splat(MAX_SURFACE))
}

/// How much of the wireframe line covers a pixel whose distance to the triangle's nearest
/// edge is `distance_px` pixels: 1 on the line, a one-pixel linear ramp at its border.
/// Mirrored by `wire_coverage` in `draw.wgsl`.
pub fn wire_coverage(distance_px: f32) -> f32 {
    (WIRE_WIDTH * 0.5 + 0.5 - distance_px).clamp(0.0, 1.0)
}

/// The final colour: the shaded colour under the wire.
pub fn with_wire(colour: Vec3, coverage: f32) -> Vec3 {
    colour.lerp(Vec3::from(WIRE_COLOR), coverage)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_surface_colour_is_the_background() {
        let (n, v, l) = (Vec3::Z, Vec3::Z, Vec3::Z);
        for mode in [ColorMode::Shaded, ColorMode::Patch, ColorMode::Level] {
            for p in 0..64 {
                let c = shade(base_colour(mode, p, p as f32 / 63.0), n, v, l, false);
                assert!(c.max_element() <= MAX_SURFACE && MAX_SURFACE < BACKGROUND[0]);
            }
        }
        assert!(hsv(0.0, 1.0, 1.0).abs_diff_eq(Vec3::X, 1e-6));
        assert!(hsv(1.0 / 3.0, 1.0, 1.0).abs_diff_eq(Vec3::Y, 1e-5));
    }
}
