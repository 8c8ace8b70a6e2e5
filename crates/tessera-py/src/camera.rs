//! `Camera`: the library's pinhole camera, for the view-dependent criteria and culling.

use crate::errors::to_py_err;
use crate::surfaces::SurfaceSet;
use glam::DVec3;
use pyo3::prelude::*;

/// A perspective camera: where the eye is, where it looks, which way is up, the vertical
/// field of view in degrees and the viewport in pixels (`--pixel-error` is in its pixels).
///
/// `near` and `far` default to 1/1000 and 1000 times the eye's distance to the target.
/// `Camera.framing(set)` is the command line's default camera; `Camera.parse(spec, set)`
/// reads its `--camera` text.
#[pyclass(module = "tessera._tessera", from_py_object)]
#[derive(Clone, Copy)]
pub struct Camera {
    pub camera: tessera::camera::Camera,
}

#[pymethods]
impl Camera {
    #[new]
    #[pyo3(signature = (eye, target, up = (0.0, 0.0, 1.0), fov = 45.0, size = (1280, 720), near = None, far = None))]
    #[allow(clippy::too_many_arguments)] // Python's keyword arguments
    fn new(
        py: Python<'_>,
        eye: (f64, f64, f64),
        target: (f64, f64, f64),
        up: (f64, f64, f64),
        fov: f64,
        size: (u32, u32),
        near: Option<f64>,
        far: Option<f64>,
    ) -> PyResult<Camera> {
        let (eye, target) = (DVec3::from(eye), DVec3::from(target));
        let distance = eye.distance(target);
        let camera = tessera::camera::Camera {
            eye,
            target,
            up: DVec3::from(up),
            fov_y_degrees: fov,
            width: size.0,
            height: size.1,
            near: near.unwrap_or(distance * 1e-3),
            far: far.unwrap_or(distance * 1e3),
        };
        camera.validate().map_err(|e| to_py_err(py, e, None))?;
        Ok(Camera { camera })
    }

    /// The command line's default camera for `set`: a three-quarter view from above that
    /// frames its bounding box, 45° vertical field of view, the model's up axis.
    #[staticmethod]
    #[pyo3(signature = (set, size = (1280, 720)))]
    fn framing(py: Python<'_>, set: &Bound<'_, SurfaceSet>, size: (u32, u32)) -> PyResult<Camera> {
        let camera = default_camera(&set.get().set, size);
        camera.validate().map_err(|e| to_py_err(py, e, None))?;
        Ok(Camera { camera })
    }

    /// The camera of a `--camera` text (`eye=X,Y,Z,target=X,Y,Z,fov=DEG,size=WxH`, optional
    /// `up=`, `near=`, `far=`), keys left out taken from `Camera.framing(set)`.
    #[staticmethod]
    fn parse(py: Python<'_>, spec: &str, set: &Bound<'_, SurfaceSet>) -> PyResult<Camera> {
        let default = default_camera(&set.get().set, (1280, 720));
        let camera = tessera::camera::Camera::parse(spec, &default).map_err(|e| to_py_err(py, e, None))?;
        Ok(Camera { camera })
    }

    #[getter]
    fn eye(&self) -> [f64; 3] {
        self.camera.eye.to_array()
    }
    #[getter]
    fn target(&self) -> [f64; 3] {
        self.camera.target.to_array()
    }
    #[getter]
    fn up(&self) -> [f64; 3] {
        self.camera.up.to_array()
    }
    /// Vertical field of view in degrees.
    #[getter]
    fn fov(&self) -> f64 {
        self.camera.fov_y_degrees
    }
    /// Viewport `(width, height)` in pixels.
    #[getter]
    fn size(&self) -> (u32, u32) {
        (self.camera.width, self.camera.height)
    }
    #[getter]
    fn near(&self) -> f64 {
        self.camera.near
    }
    #[getter]
    fn far(&self) -> f64 {
        self.camera.far
    }

    /// The same camera with the eye moved to `eye` (for camera walks).
    fn moved_to(&self, py: Python<'_>, eye: (f64, f64, f64)) -> PyResult<Camera> {
        let camera = tessera::camera::Camera { eye: DVec3::from(eye), ..self.camera };
        camera.validate().map_err(|e| to_py_err(py, e, None))?;
        Ok(Camera { camera })
    }

    fn __repr__(&self) -> String {
        let c = &self.camera;
        format!(
            "Camera(eye={:?}, target={:?}, up={:?}, fov={}, size=({}, {}), near={}, far={})",
            c.eye.to_array(),
            c.target.to_array(),
            c.up.to_array(),
            c.fov_y_degrees,
            c.width,
            c.height,
            c.near,
            c.far
        )
    }
}

/// The command line's default camera (`plan::camera` with no `--camera`).
pub fn default_camera(set: &tessera::surface::SurfaceSet, size: (u32, u32)) -> tessera::camera::Camera {
    let (lo, hi) = set.bounds();
    tessera::camera::Camera::framing_up(lo, hi, size.0, size.1, set.up)
}
