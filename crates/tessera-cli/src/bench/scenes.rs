//! The bench's inputs: models of the shared folder, the scenes built from them in code
//! (`tessera::scene` grids, paper 002's teacups), seeded cameras and camera walks.

#[path = "../../../tessera/examples/common/teacups.rs"]
pub mod teacups;

use super::{BenchResult, Ctx};
use glam::DVec3;
use tessera::camera::Camera;
use tessera::surface::SurfaceSet;

/// A model of the shared folder, by extension (`tessera::io::load`, default build options:
/// exact welding, outward orientation — what `tessera mesh` does).
pub fn load(ctx: &Ctx, rel: &str) -> BenchResult<SurfaceSet> {
    Ok(tessera::io::load(&ctx.model(rel)?, tessera::io::LoadOptions::default())?)
}

/// `copies` copies of `bench/torus_64x32.patches` in a grid (45: the 92,160-patch real-time
/// scene).
pub fn torus_grid(ctx: &Ctx, copies: usize) -> BenchResult<SurfaceSet> {
    let file = tessera::io::patches::read_patches(&ctx.model("bench/torus_64x32.patches")?)?;
    Ok(SurfaceSet::from_patch_file(&tessera::scene::patch_grid(&file, copies), Default::default()))
}

/// A herd of `copies` copies of `meshes/killeroo_cage.obj` as PN triangles (11: ≈ 91k
/// patches).
pub fn killeroo_herd(ctx: &Ctx, copies: usize) -> BenchResult<SurfaceSet> {
    let path = ctx.model("meshes/killeroo_cage.obj")?;
    let mesh = tessera::io::obj::read_obj(&path)?;
    Ok(SurfaceSet::pn_from_mesh(&tessera::scene::mesh_grid(&mesh, copies), &path, Default::default())?)
}

/// Paper 002's Teacups scene (100 teacups, 2,600 patches) and its 60-camera walk.
pub fn teacups(ctx: &Ctx) -> BenchResult<(SurfaceSet, Vec<Camera>)> {
    let cup = load(ctx, "patches/teacup.patches")?;
    Ok(teacups::teacups_scene(&cup)?)
}

pub use tessera::scene::walk;

/// A small seeded generator (xorshift64*), so the cameras are the same on every run.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `count` seeded cameras on a sphere of 1.5 bounding-box diagonals around the set, looking
/// at its centre, 1280×720 (paper 000's "randomly varied viewpoint").
pub fn random_cameras(set: &SurfaceSet, count: usize) -> Vec<Camera> {
    let (lo, hi) = set.bounds();
    let (centre, diag) = ((lo + hi) * 0.5, lo.distance(hi));
    let mut rng = Rng(0x5eed_0000_0000_0001);
    let mut out = Vec::new();
    while out.len() < count {
        let d = DVec3::new(rng.unit(), rng.unit(), rng.unit()) * 2.0 - 1.0;
        let Some(dir) = d.try_normalize() else { continue };
        let up = if dir.cross(DVec3::Z).length() > 0.1 { DVec3::Z } else { DVec3::Y };
        let camera = Camera {
            eye: centre + dir * 1.5 * diag,
            target: centre,
            up,
            fov_y_degrees: 45.0,
            width: 1280,
            height: 720,
            near: diag * 1e-3,
            far: diag * 10.0,
        };
        if camera.validate().is_ok() {
            out.push(camera);
        }
    }
    out
}
