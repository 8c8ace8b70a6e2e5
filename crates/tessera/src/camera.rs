//! A pinhole camera: where the eye is, where it looks, and how many pixels it has. Criteria
//! use it to turn a pixel tolerance into an object-space one, to cull, and to find silhouettes.

use crate::error::{Error, Result};
use glam::{DVec2, DVec3};

/// A perspective camera. Camera space: `x` right, `y` up, `z` the distance along the viewing
/// direction (positive in front of the eye).
/// Which axis points up in a model, for default cameras: a property of the file format's
/// convention (glTF says +Y, OBJ and PLY tools mostly write +Y, Newell's patches and STL's
/// 3D-printing world are +Z), chosen by [`crate::io::up_axis_of`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UpAxis {
    /// +Z up.
    #[default]
    Z,
    /// +Y up.
    Y,
}

impl UpAxis {
    /// The axis as a unit vector.
    pub fn vector(self) -> DVec3 {
        match self {
            UpAxis::Z => DVec3::Z,
            UpAxis::Y => DVec3::Y,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub eye: DVec3,
    pub target: DVec3,
    pub up: DVec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_degrees: f64,
    /// Viewport in pixels.
    pub width: u32,
    pub height: u32,
    /// Near and far plane distances along the viewing direction, `0 < near < far`.
    pub near: f64,
    pub far: f64,
}

impl Camera {
    /// Checks the camera is usable: finite, eye ≠ target, up not parallel to the view, field
    /// of view in (0°, 180°), a non-empty viewport, `0 < near < far`.
    pub fn validate(&self) -> Result<()> {
        let bad = |why: &str| Err(Error::InvalidParameter { name: "camera", reason: why.to_string() });
        if !(self.eye.is_finite() && self.target.is_finite() && self.up.is_finite()) {
            return bad("eye, target and up must be finite");
        }
        let forward = self.target - self.eye;
        if forward.length_squared() == 0.0 {
            return bad("eye and target coincide");
        }
        if forward.cross(self.up).length_squared()
            <= 1e-24 * forward.length_squared() * self.up.length_squared()
        {
            return bad("up is parallel to the viewing direction (give up=X,Y,Z)");
        }
        if !(self.fov_y_degrees > 0.0 && self.fov_y_degrees < 180.0) {
            return bad("fov must be between 0 and 180 degrees");
        }
        if self.width == 0 || self.height == 0 {
            return bad("size must be at least 1x1 pixels");
        }
        if !(self.near > 0.0 && self.far > self.near && self.far.is_finite()) {
            return bad("need 0 < near < far");
        }
        Ok(())
    }

    /// A camera that frames the box `[lo, hi]` of a Z-up model: looking at its centre from
    /// the +x, −y, +z octant (a three-quarter view), far enough that the bounding sphere fits
    /// the view. [`Camera::framing_up`] with [`UpAxis::Z`].
    pub fn framing(lo: DVec3, hi: DVec3, width: u32, height: u32) -> Camera {
        Camera::framing_up(lo, hi, width, height, UpAxis::Z)
    }

    /// A camera that frames the box `[lo, hi]` of a model whose up axis is `up`: the same
    /// three-quarter view from the front-right and above whichever axis is up (for Z-up,
    /// from the +x, −y, +z octant; for Y-up, from +x, +y, +z, glTF's front being +z), far
    /// enough that the bounding sphere fits the view. Cost: O(1).
    pub fn framing_up(lo: DVec3, hi: DVec3, width: u32, height: u32, up: UpAxis) -> Camera {
        let centre = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-9);
        let fov_y_degrees: f64 = 45.0;
        let aspect = width as f64 / height.max(1) as f64;
        let half =
            (fov_y_degrees.to_radians() / 2.0).tan().min((fov_y_degrees.to_radians() / 2.0).tan() * aspect);
        let distance = radius / half.atan().sin();
        let (direction, up) = match up {
            UpAxis::Z => (DVec3::new(1.0, -1.5, 0.8).normalize(), DVec3::Z),
            UpAxis::Y => (DVec3::new(1.0, 0.8, 1.5).normalize(), DVec3::Y),
        };
        Camera {
            eye: centre + direction * distance,
            target: centre,
            up,
            fov_y_degrees,
            width,
            height,
            near: (distance - radius).max(distance * 1e-3),
            far: distance + radius * 2.0,
        }
    }

    /// Orthonormal camera basis `(right, up, forward)`.
    pub fn basis(&self) -> (DVec3, DVec3, DVec3) {
        let f = (self.target - self.eye).normalize();
        let r = f.cross(self.up).normalize();
        let u = r.cross(f);
        (r, u, f)
    }

    /// A world point in camera space. Computes the basis each call; a loop over many points
    /// takes [`Camera::view`] once instead.
    pub fn to_camera(&self, p: DVec3) -> DVec3 {
        self.view().to_camera(p)
    }

    /// The camera's basis, planes and focal length computed once, for loops over many
    /// points (culling and pixel tolerances per patch). Cost: two normalisations.
    pub fn view(&self) -> View {
        let (right, up, forward) = self.basis();
        View {
            eye: self.eye,
            right,
            up,
            forward,
            near: self.near,
            far: self.far,
            half_tangents: self.half_tangents(),
            side_norms: self.half_tangents().map(|t| (1.0 + t * t).sqrt()),
            focal_pixels: self.focal_pixels(),
        }
    }

    /// Focal length in pixels: a unit offset at depth 1 spans this many pixels.
    pub fn focal_pixels(&self) -> f64 {
        self.height as f64 / 2.0 / (self.fov_y_degrees.to_radians() / 2.0).tan()
    }

    /// Tangents of the half field of view horizontally and vertically.
    pub fn half_tangents(&self) -> DVec2 {
        let ty = (self.fov_y_degrees.to_radians() / 2.0).tan();
        DVec2::new(ty * self.width as f64 / self.height as f64, ty)
    }

    /// Pixel coordinates of a point (origin at the viewport centre, y up), or None behind
    /// the near plane.
    pub fn project(&self, p: DVec3) -> Option<DVec2> {
        let c = self.to_camera(p);
        (c.z >= self.near).then(|| DVec2::new(c.x, c.y) / c.z * self.focal_pixels())
    }

    /// The view-projection matrix of a rasteriser drawing what [`Camera::project`] sees:
    /// world → clip space in the convention of wgpu, Vulkan, Metal and Direct3D (after the
    /// divide by w: x and y in [−1, 1] with y up, depth in [0, 1] from `near` to `far`).
    /// A point's normalised device coordinates times `(width / 2, height / 2)` are exactly
    /// its [`Camera::project`] pixel coordinates, so renderers and criteria share one
    /// camera rule. Cost: a basis (two normalisations).
    pub fn view_projection(&self) -> glam::DMat4 {
        let (r, u, f) = self.basis();
        let view = glam::DMat4::from_cols(
            glam::DVec4::new(r.x, u.x, f.x, 0.0),
            glam::DVec4::new(r.y, u.y, f.y, 0.0),
            glam::DVec4::new(r.z, u.z, f.z, 0.0),
            glam::DVec4::new(-r.dot(self.eye), -u.dot(self.eye), -f.dot(self.eye), 1.0),
        );
        let t = self.half_tangents();
        // Camera z is the positive distance in front of the eye; w = z, and depth maps
        // [near, far] onto [0, 1].
        let depth = self.far / (self.far - self.near);
        let projection = glam::DMat4::from_cols(
            glam::DVec4::new(1.0 / t.x, 0.0, 0.0, 0.0),
            glam::DVec4::new(0.0, 1.0 / t.y, 0.0, 0.0),
            glam::DVec4::new(0.0, 0.0, depth, 1.0),
            glam::DVec4::new(0.0, 0.0, -depth * self.near, 0.0),
        );
        projection * view
    }

    /// True when the point is inside the view frustum.
    pub fn sees(&self, p: DVec3) -> bool {
        let c = self.to_camera(p);
        let t = self.half_tangents();
        c.z >= self.near && c.z <= self.far && c.x.abs() <= t.x * c.z && c.y.abs() <= t.y * c.z
    }

    /// Parses `eye=X,Y,Z,target=X,Y,Z,fov=DEG,size=WxH` with optional `up=X,Y,Z`,
    /// `near=D`, `far=D`, in any order. Keys left out come from `default` (the framing
    /// camera), so `fov=30` alone only narrows the default view.
    pub fn parse(text: &str, default: &Camera) -> Result<Camera> {
        let bad = |why: String| {
            Error::InvalidParameter {
                name: "camera",
                reason: format!(
                    "{text}: {why} (expected eye=X,Y,Z,target=X,Y,Z,fov=DEG,size=WxH[,up=X,Y,Z][,near=D][,far=D])"
                ),
            }
        };
        let mut cam = *default;
        let mut explicit_near_far = false;
        let tokens: Vec<&str> = text.split(',').map(str::trim).collect();
        let mut i = 0;
        let number = |s: &str| s.parse::<f64>().ok().filter(|v| v.is_finite());
        while i < tokens.len() {
            let (key, first) =
                tokens[i].split_once('=').ok_or_else(|| bad(format!("`{}` is not key=value", tokens[i])))?;
            let vec3 = |i: usize| -> Result<DVec3> {
                let parts = [
                    first,
                    tokens.get(i + 1).copied().unwrap_or(""),
                    tokens.get(i + 2).copied().unwrap_or(""),
                ];
                let v: Option<Vec<f64>> = parts.iter().map(|s| number(s)).collect();
                v.map(|v| DVec3::new(v[0], v[1], v[2]))
                    .ok_or_else(|| bad(format!("{key} needs three numbers")))
            };
            match key {
                "eye" | "target" | "up" => {
                    let v = vec3(i)?;
                    match key {
                        "eye" => cam.eye = v,
                        "target" => cam.target = v,
                        _ => cam.up = v,
                    }
                    i += 3;
                    continue;
                }
                "fov" => cam.fov_y_degrees = number(first).ok_or_else(|| bad("fov needs a number".into()))?,
                "near" | "far" => {
                    let v = number(first).ok_or_else(|| bad(format!("{key} needs a number")))?;
                    explicit_near_far = true;
                    if key == "near" {
                        cam.near = v
                    } else {
                        cam.far = v
                    }
                }
                "size" => {
                    let (w, h) = first.split_once(['x', 'X']).ok_or_else(|| bad("size is WxH".into()))?;
                    cam.width = w.parse().map_err(|_| bad("size width is not an integer".into()))?;
                    cam.height = h.parse().map_err(|_| bad("size height is not an integer".into()))?;
                }
                _ => return Err(bad(format!("unknown key `{key}`"))),
            }
            i += 1;
        }
        if !explicit_near_far {
            // Keep the default's depth range around the new eye: wide enough for the model.
            let span =
                default.far + (cam.eye - default.eye).length() + (cam.target - default.target).length();
            cam.far = span.max(cam.near * 2.0);
            cam.near = (span * 1e-5).max(f64::MIN_POSITIVE);
        }
        cam.validate()?;
        Ok(cam)
    }
}

/// A [`Camera`] with its basis and derived constants computed ([`Camera::view`]): the
/// per-frame form the criteria loop over patches with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    pub eye: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    pub forward: DVec3,
    pub near: f64,
    pub far: f64,
    /// [`Camera::half_tangents`].
    pub half_tangents: DVec2,
    /// `√(1 + t²)` of each half tangent `t`: the norms of the side planes' normals
    /// `(±1, 0, −t)` (x) and `(0, ±1, −t)` (y), computed once per view rather than per patch.
    pub side_norms: DVec2,
    /// [`Camera::focal_pixels`].
    pub focal_pixels: f64,
}

impl View {
    /// A world point in camera space (x right, y up, z forward).
    #[inline]
    pub fn to_camera(&self, p: DVec3) -> DVec3 {
        let d = p - self.eye;
        DVec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward))
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn framing_looks_down_on_the_model_along_its_up_axis() {
        let (lo, hi) = (DVec3::new(-1.0, -2.0, -3.0), DVec3::new(1.0, 2.0, 3.0));
        for (up, axis) in [(UpAxis::Z, DVec3::Z), (UpAxis::Y, DVec3::Y)] {
            let c = Camera::framing_up(lo, hi, 640, 480, up);
            assert_eq!(c.up, axis);
            let centre = (lo + hi) * 0.5;
            // From above, and not along the up axis (a three-quarter view).
            let view = (c.eye - centre).normalize();
            assert!(view.dot(axis) > 0.2 && view.dot(axis) < 0.8, "{up:?}: {view}");
            let (_, u, _) = c.basis();
            assert!(u.dot(axis) > 0.5, "{up:?}: the image's up is not the model's");
        }
        assert_eq!(Camera::framing(lo, hi, 640, 480), Camera::framing_up(lo, hi, 640, 480, UpAxis::Z));
    }

    use super::*;

    #[test]
    fn parse_reads_every_key_and_rejects_nonsense() {
        let d = Camera::framing(DVec3::ZERO, DVec3::ONE, 800, 600);
        let c = Camera::parse("eye=10,0,0,target=0,0,0,fov=30,size=640x480", &d).unwrap();
        assert_eq!(c.eye, DVec3::new(10.0, 0.0, 0.0));
        assert_eq!((c.width, c.height, c.fov_y_degrees), (640, 480, 30.0));
        assert!(c.project(DVec3::ZERO).unwrap().length() < 1e-9);
        for bad in ["eye=1,2", "fov=200", "size=0x10", "eye=0,0,0,target=0,0,0", "what=1", "fov=nan"] {
            assert!(Camera::parse(bad, &d).is_err(), "{bad}");
        }
    }

    #[test]
    fn view_projection_agrees_with_project() {
        let c = Camera::parse(
            "eye=3,-4,2,target=0.2,0.1,0.3,fov=40,size=640x360,near=0.5,far=20",
            &Camera::framing(DVec3::ZERO, DVec3::ONE, 8, 8),
        )
        .unwrap();
        let m = c.view_projection();
        for p in [DVec3::new(0.2, 0.1, 0.3), DVec3::new(1.0, -0.5, 0.7), DVec3::new(-0.8, 0.9, -0.2)] {
            let clip = m * p.extend(1.0);
            let ndc = clip.truncate() / clip.w;
            let pixel = c.project(p).unwrap();
            assert!((ndc.x * 320.0 - pixel.x).abs() < 1e-9 && (ndc.y * 180.0 - pixel.y).abs() < 1e-9);
            assert!(ndc.z > 0.0 && ndc.z < 1.0);
        }
        let (_, _, f) = c.basis();
        let depth = |d: f64| {
            let clip = m * (c.eye + f * d).extend(1.0);
            clip.z / clip.w
        };
        assert!(depth(0.5).abs() < 1e-12 && (depth(20.0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn framing_sees_the_whole_box() {
        let (lo, hi) = (DVec3::new(-3.0, -2.0, 0.0), DVec3::new(3.5, 2.0, 3.15));
        let c = Camera::framing(lo, hi, 1280, 720);
        for i in 0..8 {
            let p = DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            assert!(c.sees(p), "corner {p} outside the framing view");
        }
    }
}
