//! Input and output formats, one per file, each reading and writing its format, with errors
//! that name the file, the line (or byte offset) and the reason.
//!
//! | module | extension | read as | written from |
//! |---|---|---|---|
//! | [`patches`] | `.patches` | bicubic (rational) Bézier patches, Newell's text format | its text ([`patches::to_patches_text`]) |
//! | [`bezt`] | `.bezt` | cubic Bézier triangles, tessera's text format | its text ([`bezt::to_bezt_text`]) |
//! | [`obj`] | `.obj` | a polygon mesh: PN triangles, or a mesh to check | a [`Mesh`] |
//! | [`ply`] | `.ply` | a mesh (ASCII or binary): PN triangles, or a mesh to check | a [`Mesh`] (binary) |
//! | [`stl`] | `.stl` | a mesh (ASCII or binary), corners welded: PN triangles, or a mesh to check | a [`Mesh`] (binary) |
//! | [`glb`] | `.glb`, `.gltf` | any glTF triangle meshes as PN triangles; tessera's own `.glb` as a mesh to check | a [`Mesh`] (`.glb`) |
//!
//! [`load`] turns any input into a [`SurfaceSet`] by extension, [`read_mesh`] reads a mesh to
//! check, and [`write_mesh`] writes one by extension.
//!
//! What each output format keeps of a [`Mesh`]:
//!
//! | format | positions | normals | uvs | vertex patch | triangle patch | corner params | strips |
//! |--------|-----------|---------|-----|--------------|----------------|---------------|--------|
//! | OBJ    | yes       | yes     | `vt` | no          | `g patch_<id>` | no            | no     |
//! | PLY    | yes       | yes     | `u v` | `patch`    | `patch`        | `patch_uv`    | `tristrips` |
//! | STL    | yes       | facet   | no  | no           | no             | no            | no     |
//! | GLB    | yes       | yes     | `_PATCH_UV` | `_PATCH` | extras     | extras        | no     |
//!
//! Every writer first checks that the mesh is consistent (attribute lengths, indices in range,
//! finite numbers) and fits the format's limits, so a bad mesh fails with a typed error before
//! the first byte is written instead of producing a file that other tools reject later. Each
//! writer buffers internally, so callers may pass an unbuffered `File` without paying one
//! system call per number. A format that cannot store strips keeps the decoded triangle list
//! that [`Mesh::indices`] always holds.

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::surface::{BuildOptions, PolygonMesh, SurfaceSet};
use crate::topology::weld::Weld;
use binary::{check_mesh, BUF_CAPACITY, WRITER_LABEL};

pub mod bezt;
pub(crate) mod binary;
pub mod glb;
pub mod obj;
pub mod patches;
pub mod ply;
pub mod stl;

/// The extensions [`write_mesh`] understands, for error messages.
const SUPPORTED: &str = ".obj, .ply, .stl, .glb";

/// The extensions [`load`] understands, for error messages.
pub const INPUT_EXTENSIONS: &str = ".patches, .bezt, .obj, .ply, .stl, .glb, .gltf";

/// Which surface a polygon mesh input (`.obj`, `.ply`, `.stl`, `.glb`, `.gltf`) stands for
/// (`--surface`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SurfaceKind {
    /// Catmull-Clark for an OBJ with any face that is not a triangle (a subdivision cage),
    /// PN triangles for everything else.
    #[default]
    Auto,
    /// PN triangles: an interpolating surface through the mesh's vertices (polygons are
    /// split into triangle fans).
    Pn,
    /// The Catmull-Clark limit surface of the mesh as a cage, as OpenSubdiv's Bfr evaluates
    /// it ([`SurfaceSet::from_subdivision_cage`]); triangles too (OpenSubdiv's rule).
    CatmullClark,
    /// The Loop limit surface of the mesh as a triangle cage, as OpenSubdiv's Bfr evaluates
    /// it ([`SurfaceSet::from_loop_cage`]); any other face is refused.
    Loop,
}

/// How [`load`] reads an input: how the set is built, which surface a mesh stands for, and
/// where a `.gltf` input's buffer files may be. A [`BuildOptions`] converts into it with the
/// defaults.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LoadOptions {
    pub build: BuildOptions,
    /// Where a `.gltf` input's buffer files may be (`--allow-outside-uris`).
    pub uri_scope: glb::UriScope,
    /// The surface of a polygon mesh input (`--surface`).
    pub surface: SurfaceKind,
    /// How deep a subdivision cage's irregular faces are isolated (`--isolation-smooth`,
    /// `--isolation-sharp`).
    pub isolation: crate::subdivision::isolation::IsolationLevels,
}

impl From<BuildOptions> for LoadOptions {
    fn from(build: BuildOptions) -> LoadOptions {
        LoadOptions { build, ..Default::default() }
    }
}

/// The surface set of a polygon mesh `mesh` read from `path`, of the kind `options` say
/// (`split` polygons were already fanned by the reader; `keeps_polygons` says whether it
/// keeps them, as the OBJ reader does).
fn mesh_surfaces(
    mesh: PolygonMesh,
    path: &Path,
    options: &LoadOptions,
    split: usize,
    keeps_polygons: bool,
) -> Result<SurfaceSet> {
    let polygons = mesh.faces.iter().any(|f| f.positions.len() != 3);
    let kind = match options.surface {
        SurfaceKind::Auto if keeps_polygons && polygons => SurfaceKind::CatmullClark,
        SurfaceKind::Auto => SurfaceKind::Pn,
        k => k,
    };
    match kind {
        SurfaceKind::CatmullClark | SurfaceKind::Loop => {
            if split > 0 {
                return Err(Error::unsupported(
                    path,
                    0,
                    format!("{split} polygons of this format are read as triangle fans; give the cage as .obj for its subdivision surface"),
                ));
            }
            let cage = crate::subdivision::CageOptions {
                orientation: options.build.orientation,
                flip: options.build.flip,
                isolation: options.isolation,
            };
            let mut set = if kind == SurfaceKind::Loop {
                SurfaceSet::from_loop_cage(&mesh, path, cage)?
            } else {
                SurfaceSet::from_subdivision_cage(&mesh, path, cage)?
            };
            set.repairs.unknown_tag_lines = mesh.tags.unknown.len();
            Ok(set)
        }
        SurfaceKind::Pn | SurfaceKind::Auto => {
            let mut mesh = mesh;
            let split = split + mesh.split_polygons();
            let mut set = with_split(SurfaceSet::pn_from_mesh(&mesh, path, options.build)?, split);
            set.repairs.ignored_tag_lines = mesh.tags.lines.iter().map(|&(_, n)| n).sum();
            set.repairs.skipped_primitives = mesh.skipped_primitives;
            Ok(set)
        }
    }
}

/// Loads the surfaces of the input at `path`, choosing the format by the extension
/// (case-insensitive):
///
/// - `.patches`: bicubic Bézier patches ([`patches::read_patches`],
///   [`SurfaceSet::from_patch_file`]);
/// - `.bezt`: cubic Bézier triangles ([`bezt::read_bezt`],
///   [`SurfaceSet::from_bezier_triangle_file`]);
/// - `.obj`, `.ply`, `.stl`, `.glb`, `.gltf`: a polygon mesh, made into PN triangles
///   ([`SurfaceSet::pn_from_mesh`]) with the file's normals where every corner of a face has a
///   non-zero one. Faces of more than three corners, in OBJ and PLY alike, are split into
///   triangle fans from their first corner ([`PolygonMesh::split_polygons`]) and counted in
///   [`Repairs::split_polygons`](crate::surface::Repairs::split_polygons). `.obj` is read by [`obj::read_obj`], `.ply` and `.stl` by [`read_mesh`], and
///   glTF by [`glb::read_gltf_triangles`] (every triangle primitive of the default scene, in
///   world coordinates), so a `.glb` from any tool works, tessera's own included.
///
/// `options` say how control points or vertices are welded and how the set is oriented
/// ([`BuildOptions`], which converts into [`LoadOptions`]), and where a `.gltf` input's
/// buffer files may be.
///
/// Errors: an unknown or missing extension is [`Error::UnknownFormat`] naming the supported
/// list; otherwise the reader's errors, which name `path`, the line where there is one, and
/// the reason; and [`Error::Unsupported`] naming `path` when no patch is left after the
/// repairs (every patch collapsed to a single point, for example by too wide a weld).
///
/// Cost: one read of the file, the parse (O(file size)), and building the set (O(patches)
/// hashing).
pub fn load(path: &Path, options: impl Into<LoadOptions>) -> Result<SurfaceSet> {
    let load = options.into();
    let options = load.build;
    refuse_folder(path)?;
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    let set = match ext.as_deref() {
        Some("patches") => SurfaceSet::from_patch_file(&patches::read_patches(path)?, options),
        Some("bezt") => SurfaceSet::from_bezier_triangle_file(&bezt::read_bezt(path)?, options),
        Some("obj") => mesh_surfaces(obj::read_obj(path)?, path, &load, 0, true)?,
        Some("ply") => {
            let (mesh, split) = ply::parse_ply_counting_polygons(&read_input(path)?, path)?;
            mesh_surfaces(PolygonMesh::from_mesh(&mesh), path, &load, split, false)?
        }
        Some("stl") => mesh_surfaces(PolygonMesh::from_mesh(&read_mesh(path)?), path, &load, 0, false)?,
        Some("glb" | "gltf") => {
            mesh_surfaces(glb::read_gltf_triangles(path, load.uri_scope)?, path, &load, 0, false)?
        }
        other => return Err(unknown(path, "input", other, INPUT_EXTENSIONS)),
    };
    let mut set = set;
    set.up = up_axis_of(path).0;
    if set.patches.is_empty() {
        let weld = match options.weld {
            Weld::Within(eps) => format!(" (welding within {eps} merged them: use a smaller distance)"),
            _ => String::new(),
        };
        return Err(Error::unsupported(
            path,
            0,
            format!(
                "no usable patch: all {} collapsed to a single point{weld}",
                set.repairs.dropped_collapsed_patches
            ),
        ));
    }
    Ok(set)
}

/// The up axis of the model in `path` by its format's convention, and that convention in
/// words (for the note a default camera prints): +Y for glTF (its specification), OBJ and
/// PLY (what most modelling and scanning tools write: the Stanford bunny, spot); +Z for
/// Newell's `.patches` (the teapot), `.bezt` and STL (3D printing's build axis). Cost: O(1).
pub fn up_axis_of(path: &Path) -> (crate::camera::UpAxis, &'static str) {
    use crate::camera::UpAxis;
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("glb" | "gltf") => (UpAxis::Y, "glTF's convention"),
        Some("obj") => (UpAxis::Y, "the usual OBJ convention"),
        Some("ply") => (UpAxis::Y, "the usual PLY convention"),
        Some("stl") => (UpAxis::Z, "the usual STL convention"),
        _ => (UpAxis::Z, "the convention of Newell's patch data"),
    }
}

/// `set` with `split` polygons of its input recorded among its repairs.
fn with_split(mut set: SurfaceSet, split: usize) -> SurfaceSet {
    set.repairs.split_polygons = split;
    set
}

/// The extensions [`read_mesh`] understands, for error messages.
const SUPPORTED_MESHES: &str = ".obj, .ply, .stl, .glb";

/// Reads the triangle mesh in `path` (a mesh to check, not an input to tessellate), choosing
/// the format by the extension (case-insensitive): `.obj` ([`obj::read_obj`], polygons must be
/// triangles), `.ply` ([`ply::parse_ply`]), `.stl` ([`stl::parse_stl`]) or `.glb`
/// ([`glb::parse_glb`], tessera's layout). See each module for what is read.
///
/// Whatever the file lacks is filled in: zero normals and uvs, patch 0 for vertices and
/// triangles, no corner params.
///
/// Errors: an unknown extension is [`Error::UnknownFormat`]; an unreadable file is
/// [`Error::Io`]; malformed, truncated or out-of-range content is [`Error::Parse`], and valid
/// content beyond what the reader handles (sparse accessors, several primitives, polygons in
/// an OBJ, ...) is [`Error::Unsupported`]; all name `path`.
///
/// Cost: reads the whole file into memory, then O(file size) time; STL welding adds a hash map
/// of the distinct positions.
pub fn read_mesh(path: &Path) -> Result<Mesh> {
    refuse_folder(path)?;
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    let parse: fn(&[u8], &Path) -> Result<Mesh> = match ext.as_deref() {
        Some("obj") => {
            let obj = obj::read_obj(path)?;
            return obj.to_mesh(path);
        }
        Some("ply") => ply::parse_ply,
        Some("stl") => stl::parse_stl,
        Some("glb") => glb::parse_glb,
        other => return Err(unknown(path, "mesh", other, SUPPORTED_MESHES)),
    };
    let data = read_input(path)?;
    parse(&data, path)
}

/// The bytes of the input file at `path`, which must be a regular file: a folder or a device
/// (`/dev/zero` never ends) is refused before it is read.
///
/// # Errors
///
/// [`Error::Io`] when `path` cannot be read; [`Error::Unsupported`] naming `path` when it is
/// a folder or not a regular file.
///
/// Cost: one `stat` and one read of the file.
pub(crate) fn read_input(path: &Path) -> Result<Vec<u8>> {
    check_input_file(path)?;
    std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })
}

/// Refuses an input `path` that is a folder; called before the extension is looked at, so a
/// folder is not reported as a file without an extension. A path that does not exist passes
/// here (its extension is judged first, then reading it fails).
fn refuse_folder(path: &Path) -> Result<()> {
    match std::fs::metadata(path) {
        Ok(metadata) if metadata.is_dir() => {
            Err(Error::unsupported(path, 0, "is a folder, not an input file"))
        }
        _ => Ok(()),
    }
}

/// Refuses an input `path` that is not a regular file (see [`read_input`]).
fn check_input_file(path: &Path) -> Result<()> {
    refuse_folder(path)?;
    let metadata =
        std::fs::metadata(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    if !metadata.is_file() {
        return Err(Error::unsupported(path, 0, "is not a regular file (a device, pipe or socket)"));
    }
    Ok(())
}

/// The error for a file name whose extension `role` files cannot have.
fn unknown(path: &Path, role: &'static str, extension: Option<&str>, supported: &'static str) -> Error {
    Error::UnknownFormat {
        path: path.to_path_buf(),
        role,
        extension: extension.map(str::to_string),
        supported,
    }
}

/// Output formats, chosen by file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Format {
    Obj,
    Ply,
    Stl,
    Glb,
}

impl Format {
    fn from_path(path: &Path) -> Result<Format> {
        let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("obj") => Ok(Format::Obj),
            Some("ply") => Ok(Format::Ply),
            Some("stl") => Ok(Format::Stl),
            Some("glb") => Ok(Format::Glb),
            other => Err(unknown(path, "output", other, SUPPORTED)),
        }
    }
}

/// Checks that `path` names a supported output format, so a caller can refuse a bad output
/// name before doing the work. Cost: O(1).
pub fn check_output_path(path: &Path) -> Result<()> {
    Format::from_path(path).map(|_| ())
}

/// Writes `mesh` to `path`, choosing the format by the extension (case-insensitive): `.obj`
/// ([`obj::write_obj`]), `.ply` (binary little-endian, [`ply::write_ply`]), `.stl` (binary,
/// [`stl::write_stl`]) or `.glb` ([`glb::write_glb`]). See the module documentation for what
/// each format keeps.
///
/// Preconditions: the mesh is consistent (one normal, uv and vertex patch per position, one
/// triangle patch per triangle, `corner_params` parallel to `indices`, indices in range, finite
/// numbers); otherwise [`Error::InvalidMesh`], checked before the file is created. An
/// unknown or missing extension is [`Error::UnknownFormat`] naming it and the supported list.
/// I/O failures are [`Error::Write`] naming `path`.
///
/// The file appears whole or not at all: the bytes go to a hidden temporary file beside
/// `path` (`.NAME.tessera-partial-PID`), renamed over `path` once complete, so a failure
/// part-way (a full disk, an error) leaves `path` as it was and removes the temporary file.
/// A run killed part-way leaves its temporary file, never a truncated `path`; the next write
/// of the same `path` removes the temporary files of processes that no longer exist. A `path` that
/// exists and is a device or a pipe (`/dev/null`) is written directly.
///
/// Cost: O(vertices + triangles) time, formatted in parallel on the rayon threads (the bytes
/// do not depend on the thread count); memory: a 64 KiB buffer and a few MiB of chunk buffers,
/// plus the GLB JSON (a few KiB, independent of the mesh size).
pub fn write_mesh(mesh: &Mesh, path: &Path) -> Result<()> {
    write_mesh_with_progress(mesh, path, &mut |_| {})
}

/// [`write_mesh`], calling `progress` with the bytes written so far after every buffered
/// write (every 64 KiB or so), for a progress bar; [`estimated_file_bytes`] is the total to
/// expect. Cost: as [`write_mesh`].
pub fn write_mesh_with_progress(mesh: &Mesh, path: &Path, progress: &mut dyn FnMut(u64)) -> Result<()> {
    let format = Format::from_path(path)?;
    let prepared = prepare(mesh, format)?;
    let write_error = |source| Error::Write { path: path.to_path_buf(), source };
    // A device or pipe cannot be renamed over; a folder is left to the rename to refuse.
    let direct = std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir());
    let target = if direct { path.to_path_buf() } else { partial_path(path) };
    if !direct {
        remove_stale_partials(path);
    }
    let written = (|| {
        let file = std::fs::OpenOptions::new().write(true).create(true).truncate(!direct).open(&target)?;
        let mut counted = Counted { inner: &file, bytes: 0, progress };
        emit(mesh, &prepared, &mut counted)
    })();
    let finished = written.and_then(|()| if direct { Ok(()) } else { std::fs::rename(&target, path) });
    if finished.is_err() && !direct {
        let _ = std::fs::remove_file(&target);
    }
    finished.map_err(write_error)
}

/// The hidden temporary file [`write_mesh`] writes before renaming it to `path`: in the same
/// folder, so the rename never crosses a file system.
fn partial_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.tessera-partial-{}", std::process::id()))
}

/// Removes the temporary files that killed runs writing `path` left beside it (see
/// [`write_mesh`]): those whose process no longer exists. A large output killed part-way
/// would otherwise keep its gigabytes on disk until someone looks for hidden files; the next
/// write of the same output cleans up after it. Only where a process's existence can be
/// told (`/proc` on Linux); elsewhere nothing is removed. Errors are ignored: this is
/// tidying, not the write. Cost: one read of the folder.
fn remove_stale_partials(path: &Path) {
    let (Some(name), Some(folder)) = (path.file_name(), path.parent()) else { return };
    let folder = if folder.as_os_str().is_empty() { Path::new(".") } else { folder };
    if !Path::new("/proc/self").exists() {
        return;
    }
    let prefix = format!(".{}.tessera-partial-", name.to_string_lossy());
    let Ok(entries) = std::fs::read_dir(folder) else { return };
    for entry in entries.flatten() {
        let file = entry.file_name();
        let Some(pid) = file.to_str().and_then(|f| f.strip_prefix(&prefix)) else { continue };
        let alive = pid.parse::<u32>().map_or(true, |pid| Path::new(&format!("/proc/{pid}")).exists());
        if !alive {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// About how many bytes [`write_mesh`] writes for a mesh of `vertices` and `triangles` (with
/// corner parameters when `corner_params`) to `path`, by the extension: exact up to the
/// headers for the binary formats, a typical line length for OBJ text. For messages and
/// progress bars, not for allocation. Unknown extensions give `None`. Cost: O(1).
pub fn estimated_file_bytes(path: &Path, vertices: u64, triangles: u64, corner_params: bool) -> Option<u64> {
    let params = if corner_params { 1 } else { 0 };
    let (per_vertex, per_triangle) = match Format::from_path(path).ok()? {
        // "v x y z", "vn x y z", "vt u v" with ~9 significant digits, "f a//a b//b c//c".
        Format::Obj => (100, 40),
        // position, normal, uv (f32) and patch (u32); count byte, 3 indices, patch, patch_uv.
        Format::Ply => (36, 17 + params * 25),
        // normal, 3 corners and the attribute count.
        Format::Stl => (0, 50),
        // POSITION, NORMAL, _PATCH_UV, _PATCH; indices, triangle patch, corner params.
        Format::Glb => (36, 16 + params * 24),
    };
    Some(vertices * per_vertex + triangles * per_triangle)
}

/// A writer that counts the bytes it passes on and reports them.
struct Counted<'p, W> {
    inner: W,
    bytes: u64,
    progress: &'p mut dyn FnMut(u64),
}

impl<W: Write> Write for Counted<'_, W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.bytes += n as u64;
        (self.progress)(self.bytes);
        Ok(n)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

pub(crate) fn write_to<W: Write>(mesh: &Mesh, format: Format, w: W) -> Result<()> {
    let prepared = prepare(mesh, format)?;
    emit(mesh, &prepared, w).map_err(|source| Error::Write { path: PathBuf::from(WRITER_LABEL), source })
}

/// What a format needs computed, and checked, before its first byte is written.
enum Prepared {
    Obj,
    Ply,
    Stl { count: u32 },
    Glb(glb::GlbPlan),
}

fn prepare(mesh: &Mesh, format: Format) -> Result<Prepared> {
    check_mesh(mesh)?;
    Ok(match format {
        Format::Obj => Prepared::Obj,
        Format::Ply => Prepared::Ply,
        Format::Stl => {
            let count = u32::try_from(mesh.triangle_count()).map_err(|_| Error::FormatLimit {
                format: "STL",
                reason: format!(
                    "{} triangles exceed the binary STL limit of {}",
                    mesh.triangle_count(),
                    u32::MAX
                ),
            })?;
            Prepared::Stl { count }
        }
        Format::Glb => Prepared::Glb(glb::plan_glb(mesh)?),
    })
}

fn emit<W: Write>(mesh: &Mesh, prepared: &Prepared, w: W) -> io::Result<()> {
    let mut w = BufWriter::with_capacity(BUF_CAPACITY, w);
    match prepared {
        Prepared::Obj => obj::emit_obj(mesh, &mut w)?,
        Prepared::Ply => ply::emit_ply(mesh, &mut w)?,
        Prepared::Stl { count } => stl::emit_stl(mesh, *count, &mut w)?,
        Prepared::Glb(plan) => glb::emit_glb(mesh, plan, &mut w)?,
    }
    // An explicit flush, because BufWriter's drop would swallow the error of the last write.
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A write replaces the file through a temporary one, which it removes, and removes the
    /// temporary files of dead writers of the same output, not those of live ones.
    #[test]
    #[cfg(target_os = "linux")]
    fn writes_are_whole_and_clean_up_after_killed_runs() {
        let dir = std::env::temp_dir().join(format!("tessera-io-partials-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("m.ply");
        // A process that has exited: its pid names no process now (pids are not reused at once).
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let stale = dir.join(format!(".m.ply.tessera-partial-{dead}"));
        let live = dir.join(".m.ply.tessera-partial-1");
        let other = dir.join(format!(".n.ply.tessera-partial-{dead}"));
        for f in [&stale, &live, &other] {
            std::fs::write(f, b"partial").unwrap();
        }
        let mesh = Mesh {
            positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            normals: vec![[0.0, 0.0, 1.0]; 3],
            uvs: vec![[0.0; 2]; 3],
            vertex_patch: vec![0; 3],
            indices: vec![0, 1, 2],
            triangle_patch: vec![0],
            ..Default::default()
        };
        write_mesh(&mesh, &out).unwrap();
        assert!(!stale.exists(), "a dead writer's temporary file was kept");
        assert!(live.exists() && other.exists(), "a live writer's or another output's file was removed");
        assert!(!partial_path(&out).exists(), "the write left its own temporary file");
        assert_eq!(read_mesh(&out).unwrap().triangle_count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
    use crate::io::binary::test_meshes::*;
    use glb::write_glb;
    use obj::write_obj;
    use ply::write_ply;
    use stl::write_stl;

    #[test]
    fn read_mesh_dispatches_by_extension_and_names_the_file() {
        let dir = std::env::temp_dir().join(format!("tessera-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mesh = grid(3, true);
        for name in ["m.ply", "m.GLB"] {
            let path = dir.join(name);
            write_mesh(&mesh, &path).unwrap();
            assert_eq!(read_mesh(&path).unwrap(), mesh, "{name}");
        }
        let stl = dir.join("m.Stl");
        write_mesh(&mesh, &stl).unwrap();
        assert_eq!(read_mesh(&stl).unwrap().triangle_count(), mesh.triangle_count());

        let obj = dir.join("m.obj");
        write_mesh(&mesh, &obj).unwrap();
        let read = read_mesh(&obj).unwrap();
        assert_eq!((read.positions, read.indices), (mesh.positions.clone(), mesh.indices.clone()));

        let err = read_mesh(&dir.join("m.xyz")).unwrap_err();
        assert!(
            matches!(&err, Error::UnknownFormat { supported, .. } if supported.contains(".obj, .ply, .stl, .glb")),
            "{err}"
        );
        let missing = dir.join("absent.ply");
        assert!(matches!(read_mesh(&missing), Err(Error::Io { path, .. }) if path == missing));
        let broken = dir.join("broken.ply");
        std::fs::write(&broken, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n")
            .unwrap();
        match read_mesh(&broken) {
            Err(Error::Parse { at, reason }) => {
                assert_eq!(at.file, broken);
                assert_eq!(at.line, 3);
                assert!(reason.contains("no property y"), "{reason}");
            }
            other => panic!("{other:?}"),
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn inconsistent_meshes_are_refused_before_writing() {
        let good = grid(2, true);
        type Breaker = fn(&mut Mesh);
        let cases: [(Breaker, &str); 11] = [
            (|m| m.normals.truncate(1), "normals"),
            (|m| m.uvs.truncate(1), "uvs"),
            (|m| m.vertex_patch.truncate(1), "vertex patches"),
            (|m| m.indices.truncate(4), "multiple of 3"),
            (|m| m.triangle_patch.truncate(1), "triangle patches"),
            (|m| m.corner_params.iter_mut().for_each(|p| p.truncate(1)), "corner params"),
            (|m| m.indices[4] = 9, "triangle 1 refers to vertex 9"),
            (|m| m.positions[5][1] = f32::NAN, "vertex 5 has a non-finite position"),
            (|m| m.normals[1][0] = f32::INFINITY, "non-finite normal"),
            (|m| m.uvs[0][1] = f32::NAN, "non-finite uv"),
            (|m| m.corner_params.iter_mut().for_each(|p| p[7][0] = f32::NAN), "corner 1 of triangle 2"),
        ];
        for (break_it, expected) in cases {
            let mut mesh = good.clone();
            break_it(&mut mesh);
            for format in [Format::Obj, Format::Ply, Format::Stl, Format::Glb] {
                let mut out = Vec::new();
                match write_to(&mesh, format, &mut out) {
                    Err(Error::InvalidMesh { reason }) => {
                        assert!(reason.contains(expected), "{reason} lacks {expected}")
                    }
                    other => panic!("expected InvalidMesh({expected}), got {other:?}"),
                }
                assert!(out.is_empty(), "nothing is written for an invalid mesh");
            }
        }
    }

    struct Failing;
    impl Write for Failing {
        fn write(&mut self, _: &[u8]) -> io::Result<usize> {
            Err(io::Error::other("disk on fire"))
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn writer_errors_are_typed() {
        let mesh = grid(1, false);
        let err = write_ply(&mesh, Failing).unwrap_err();
        assert!(matches!(&err, Error::Write { path, .. } if path == Path::new("<writer>")), "{err}");
        assert!(err.to_string().contains("disk on fire"));
    }

    #[test]
    fn write_mesh_picks_the_format_by_extension() {
        let dir = std::env::temp_dir().join(format!("tessera-write-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mesh = grid(2, true);
        for (name, expected) in [
            ("a.obj", bytes(|w| write_obj(&mesh, w))),
            ("b.PLY", bytes(|w| write_ply(&mesh, w))),
            ("c.Stl", bytes(|w| write_stl(&mesh, w))),
            ("d.glb", bytes(|w| write_glb(&mesh, w))),
        ] {
            let path = dir.join(name);
            write_mesh(&mesh, &path).unwrap();
            assert_eq!(std::fs::read(&path).unwrap(), expected, "{name}");
        }
        for name in ["e.gltf", "noext"] {
            let path = dir.join(name);
            let err = write_mesh(&mesh, &path).unwrap_err();
            assert!(matches!(&err, Error::UnknownFormat { role: "output", .. }), "{err:?}");
            let m = err.to_string();
            assert!(m.contains(".obj, .ply, .stl, .glb"), "{m}");
            assert!(m.contains(name), "{m}");
            assert!(!path.exists());
        }
        // Written over a longer file of the same name, the file holds the new bytes only.
        let small = grid(1, false);
        for name in ["a.obj", "b.PLY", "c.Stl", "d.glb"] {
            let path = dir.join(name);
            let before = std::fs::metadata(&path).unwrap().len();
            let format = Format::from_path(&path).unwrap();
            let mut expected = Vec::new();
            write_to(&small, format, &mut expected).unwrap();
            assert!((expected.len() as u64) < before, "{name}");
            write_mesh(&small, &path).unwrap();
            assert_eq!(std::fs::read(&path).unwrap(), expected, "{name}");
        }
        let missing = dir.join("no/such/dir/f.obj");
        let err = write_mesh(&mesh, &missing).unwrap_err();
        assert!(matches!(&err, Error::Write { path, .. } if path == &missing), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A mesh of the real kind, several chunks long (100,866 vertices, 200,704 triangles,
    /// 98 a patch so that chunk boundaries fall inside runs of one patch), with corner params.
    fn torus_factor_7() -> Mesh {
        use crate::criterion::Plan;
        use crate::engine::{tessellate, EngineOptions};
        use crate::pattern::uniform::Uniform;
        let file = patches::read_patches(&crate::test_support::data("bench/torus_64x32.patches")).unwrap();
        let set = SurfaceSet::from_patch_file(&file, Default::default());
        let plan = Plan::uniform(&set, 7).unwrap();
        let options = EngineOptions { corner_params: true, ..Default::default() };
        let mut mesh = tessellate(&set, &plan, &Uniform, options).unwrap();
        // Strips as the PLY writer stores them: a restart every 50 indices.
        mesh.strips = Some(
            mesh.indices[..3000]
                .iter()
                .enumerate()
                .map(|(k, &i)| if k % 50 == 49 { crate::mesh::strips::RESTART } else { i })
                .collect(),
        );
        mesh
    }

    /// The writers as they were before they formatted in parallel (commit 35bba34), kept to
    /// show that the bytes did not change.
    mod sequential {
        use super::super::*;
        use glam::DVec3;

        fn f32s<W: Write>(w: &mut W, values: &[f32]) -> io::Result<()> {
            values.iter().try_for_each(|v| w.write_all(&v.to_le_bytes()))
        }

        pub fn obj(mesh: &Mesh, w: &mut Vec<u8>) -> io::Result<()> {
            writeln!(w, "# tessera")?;
            writeln!(w, "# {} vertices, {} triangles", mesh.vertex_count(), mesh.triangle_count())?;
            for p in &mesh.positions {
                writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
            }
            for n in &mesh.normals {
                writeln!(w, "vn {} {} {}", n[0], n[1], n[2])?;
            }
            for uv in &mesh.uvs {
                writeln!(w, "vt {} {}", uv[0], uv[1])?;
            }
            let mut group = None;
            for (tri, &patch) in mesh.indices.chunks_exact(3).zip(&mesh.triangle_patch) {
                if group != Some(patch) {
                    writeln!(w, "g patch_{patch}")?;
                    group = Some(patch);
                }
                let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| u64::from(i) + 1);
                writeln!(w, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}")?;
            }
            Ok(())
        }

        /// The body of the PLY file (everything after `end_header\n`).
        pub fn ply_body(mesh: &Mesh, w: &mut Vec<u8>) -> io::Result<()> {
            for (((p, n), uv), &patch) in
                mesh.positions.iter().zip(&mesh.normals).zip(&mesh.uvs).zip(&mesh.vertex_patch)
            {
                f32s(w, p)?;
                f32s(w, n)?;
                f32s(w, uv)?;
                w.write_all(&patch.to_le_bytes())?;
            }
            for (t, (tri, &patch)) in mesh.indices.chunks_exact(3).zip(&mesh.triangle_patch).enumerate() {
                w.write_all(&[3])?;
                for &i in tri {
                    w.write_all(&i.to_le_bytes())?;
                }
                w.write_all(&patch.to_le_bytes())?;
                if let Some(params) = &mesh.corner_params {
                    w.write_all(&[6])?;
                    for uv in &params[3 * t..3 * t + 3] {
                        f32s(w, uv)?;
                    }
                }
            }
            if let Some(strips) = &mesh.strips {
                w.write_all(&(strips.len() as u32).to_le_bytes())?;
                for &i in strips {
                    let v = if i == crate::mesh::strips::RESTART { -1 } else { i as i32 };
                    w.write_all(&v.to_le_bytes())?;
                }
            }
            Ok(())
        }

        pub fn stl(mesh: &Mesh, w: &mut Vec<u8>) -> io::Result<()> {
            let mut header = [0u8; 80];
            header[..7].copy_from_slice(b"tessera");
            w.write_all(&header)?;
            w.write_all(&(mesh.triangle_count() as u32).to_le_bytes())?;
            let position = |i: u32| mesh.positions[i as usize];
            for tri in mesh.indices.chunks_exact(3) {
                let [a, b, c] = [tri[0], tri[1], tri[2]].map(position);
                let [da, db, dc] = [a, b, c].map(|p| DVec3::from(p.map(f64::from)));
                let n = (db - da).cross(dc - da).normalize_or_zero().as_vec3();
                f32s(w, &n.to_array())?;
                for p in [a, b, c] {
                    f32s(w, &p)?;
                }
                w.write_all(&[0, 0])?;
            }
            Ok(())
        }

        /// The BIN chunk of the GLB (without its chunk header).
        pub fn glb_bin(mesh: &Mesh, w: &mut Vec<u8>) -> io::Result<()> {
            mesh.positions.iter().try_for_each(|p| f32s(w, p))?;
            mesh.normals.iter().try_for_each(|p| f32s(w, p))?;
            mesh.uvs.iter().try_for_each(|p| f32s(w, p))?;
            mesh.vertex_patch.iter().try_for_each(|&p| f32s(w, &[p as f32]))?;
            mesh.indices.iter().try_for_each(|i| w.write_all(&i.to_le_bytes()))?;
            mesh.triangle_patch.iter().try_for_each(|i| w.write_all(&i.to_le_bytes()))?;
            if let Some(params) = &mesh.corner_params {
                params.iter().try_for_each(|p| f32s(w, p))?;
            }
            Ok(())
        }
    }

    fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
    }

    #[test]
    fn parallel_writers_give_the_sequential_bytes_whatever_the_thread_count() {
        let mesh = torus_factor_7();
        let mut without_extras = mesh.clone();
        without_extras.corner_params = None;
        without_extras.strips = None;
        for m in [&mesh, &without_extras, &grid(3, true), &Mesh::default()] {
            let outputs = [1, 2, 3].map(|threads| {
                in_pool(threads, || {
                    [Format::Obj, Format::Ply, Format::Stl, Format::Glb].map(|f| {
                        let mut out = Vec::new();
                        write_to(m, f, &mut out).unwrap();
                        out
                    })
                })
            });
            assert!(outputs.iter().all(|o| o == &outputs[0]), "the thread count changes the bytes");
            let [obj, ply, stl, glb] = &outputs[0];
            let old = |f: fn(&Mesh, &mut Vec<u8>) -> io::Result<()>| {
                let mut out = Vec::new();
                f(m, &mut out).unwrap();
                out
            };
            assert!(*obj == old(sequential::obj), "OBJ text changed");
            assert!(*stl == old(sequential::stl), "STL bytes changed");
            let body = ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
            assert!(ply[body..] == old(sequential::ply_body), "PLY body changed");
            if m.triangle_count() > 0 {
                let bin = old(sequential::glb_bin);
                assert!(glb.ends_with(&bin), "GLB BIN chunk changed");
                assert_eq!(&glb[glb.len() - bin.len() - 4..glb.len() - bin.len()], b"BIN\0");
            }
        }
    }

    #[test]
    fn obj_output_reads_back_exactly() {
        let mesh = torus_factor_7();
        let text = bytes(|w| write_obj(&mesh, w));
        let read = obj::parse_obj(std::str::from_utf8(&text).unwrap(), Path::new("t.obj")).unwrap();
        // Shortest round-trip digits: the positions read back to the same f32 bits.
        let positions: Vec<[f32; 3]> = read.positions.iter().map(|p| p.as_vec3().to_array()).collect();
        assert!(positions == mesh.positions, "positions changed on the way through the text");
        let normals: Vec<[f32; 3]> = read.normals.iter().map(|p| p.as_vec3().to_array()).collect();
        assert!(normals == mesh.normals, "normals changed");
        assert_eq!(read.faces.len(), mesh.triangle_count());
        for (t, f) in read.faces.iter().enumerate() {
            assert_eq!(f.positions, mesh.triangle(t), "triangle {t}");
            assert_eq!(f.normals.as_deref(), Some(&mesh.triangle(t)[..]));
        }
        // The reader skips `vt`: read them here.
        let uvs: Vec<[f32; 2]> = std::str::from_utf8(&text)
            .unwrap()
            .lines()
            .filter_map(|l| l.strip_prefix("vt "))
            .map(|l| {
                let mut it = l.split(' ').map(|x| x.parse::<f32>().unwrap());
                [it.next().unwrap(), it.next().unwrap()]
            })
            .collect();
        assert!(uvs == mesh.uvs, "uvs changed");
    }

    #[test]
    // 1.06640625 is exactly an f32 whose shortest form ends on a tie: the digits are the case.
    #[allow(clippy::excessive_precision)]
    fn push_f32_prints_what_display_prints() {
        let mut cases: Vec<f32> = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            0.5,
            100.0,
            1e-5,
            1e-6,
            1e-7,
            1.5e-7,
            1e-10,
            1e12,
            1e13,
            1e14,
            1e30,
            123456789.0,
            1.06640625,
            -1.06640625,
            f32::MAX,
            f32::MIN,
            f32::MIN_POSITIVE,
            f32::EPSILON,
            f32::from_bits(1),
            f32::from_bits(0x007f_ffff),
        ];
        // Exact halfway cases, where ryu and the standard library round differently: odd
        // multiples of small powers of two, and integers times powers of two.
        for m in (1..200_000u32).step_by(2) {
            for k in [1, 2, 3, 5, 8, 11, 14, 17] {
                cases.push(m as f32 / (1u32 << k) as f32);
            }
            cases.push(m as f32 * 1024.0);
        }
        // Random bits, and a sweep of [1, 2) and of tiny numbers.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..1_000_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            cases.push(f32::from_bits(state as u32));
        }
        cases.extend((0x3f80_0000u32..0x4000_0000).step_by(61).map(f32::from_bits));
        cases.extend((0..0x0100_0000u32).step_by(97).map(f32::from_bits));
        let mut out = Vec::new();
        let mut differences = 0;
        for x in cases.into_iter().filter(|x| x.is_finite()) {
            out.clear();
            obj::push_f32(&mut out, x);
            assert_eq!(std::str::from_utf8(&out).unwrap(), format!("{x}"), "bits {:#x}", x.to_bits());
            let ryu = ryu::Buffer::new().format_finite(x).trim_end_matches(".0").to_string();
            differences += usize::from(ryu != format!("{x}"));
        }
        // Not vacuous: many cases print differently in ryu's own form (exponents, ties).
        assert!(differences > 1000, "{differences}");
    }

    /// Fails every write after `budget` bytes, as a full disk does part-way.
    struct FailAfter(usize);
    impl Write for FailAfter {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if buf.len() > self.0 {
                return Err(io::Error::other("disk full"));
            }
            self.0 -= buf.len();
            Ok(buf.len())
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn errors_part_way_are_reported() {
        let mesh = torus_factor_7();
        for format in [Format::Obj, Format::Ply, Format::Stl, Format::Glb] {
            for budget in [0, 100, 70_000, 3_000_000] {
                let err = in_pool(2, || write_to(&mesh, format, FailAfter(budget))).unwrap_err();
                assert!(
                    matches!(&err, Error::Write { path, .. } if path == Path::new("<writer>")),
                    "{format:?} {budget}: {err}"
                );
                assert!(err.to_string().contains("disk full"), "{err}");
            }
        }
        // A real full device: the error names the path written to.
        let full = Path::new("/dev/full");
        if cfg!(target_os = "linux") && full.exists() {
            let dir = std::env::temp_dir().join(format!("tessera-full-{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            for name in ["m.obj", "m.ply", "m.stl", "m.glb"] {
                let link = dir.join(name);
                #[cfg(unix)]
                std::os::unix::fs::symlink(full, &link).unwrap();
                let err = write_mesh(&mesh, &link).unwrap_err();
                assert!(matches!(&err, Error::Write { path, .. } if path == &link), "{name}: {err}");
                assert!(err.to_string().contains(&*link.to_string_lossy()), "{err}");
            }
            std::fs::remove_dir_all(&dir).unwrap();
        }
    }
}
