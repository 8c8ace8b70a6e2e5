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

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::surface::{BuildOptions, SurfaceSet};
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

/// Loads the surfaces of the input at `path`, choosing the format by the extension
/// (case-insensitive):
///
/// - `.patches`: bicubic Bézier patches ([`patches::read_patches`],
///   [`SurfaceSet::from_patch_file`]);
/// - `.bezt`: cubic Bézier triangles ([`bezt::read_bezt`],
///   [`SurfaceSet::from_bezier_triangle_file`]);
/// - `.obj`, `.ply`, `.stl`, `.glb`, `.gltf`: a triangle mesh, made into PN triangles
///   ([`SurfaceSet::pn_from_mesh`]) with the file's normals where every corner of a face has a
///   non-zero one. `.obj` is read by [`obj::read_obj`], `.ply` and `.stl` by [`read_mesh`], and
///   glTF by [`glb::read_gltf_triangles`] (every triangle primitive of the default scene, in
///   world coordinates), so a `.glb` from any tool works, tessera's own included.
///
/// `options` say how control points or vertices are welded and how the set is oriented.
///
/// Errors: an unknown or missing extension is [`Error::UnknownFormat`] naming the supported
/// list; otherwise the reader's errors, which name `path`, the line where there is one, and
/// the reason; and [`Error::Unsupported`] naming `path` when no patch is left after the
/// repairs (every patch collapsed to a single point, for example by too wide a weld).
///
/// Cost: one read of the file, the parse (O(file size)), and building the set (O(patches)
/// hashing).
pub fn load(path: &Path, options: BuildOptions) -> Result<SurfaceSet> {
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    let set = match ext.as_deref() {
        Some("patches") => SurfaceSet::from_patch_file(&patches::read_patches(path)?, options),
        Some("bezt") => SurfaceSet::from_bezier_triangle_file(&bezt::read_bezt(path)?, options),
        Some("obj") => SurfaceSet::pn_from_mesh(&obj::read_obj(path)?, path, options)?,
        Some("ply" | "stl") => {
            SurfaceSet::pn_from_mesh(&obj::ObjMesh::from_mesh(&read_mesh(path)?), path, options)?
        }
        Some("glb" | "gltf") => SurfaceSet::pn_from_mesh(&glb::read_gltf_triangles(path)?, path, options)?,
        other => return Err(unknown(path, "input", other, INPUT_EXTENSIONS)),
    };
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
    let data = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    parse(&data, path)
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
/// I/O failures are [`Error::Write`] naming `path`; a failure part-way leaves a partial file.
///
/// Cost: O(vertices + triangles) time; memory: a 64 KiB buffer, plus the GLB JSON (a few KiB,
/// independent of the mesh size).
pub fn write_mesh(mesh: &Mesh, path: &Path) -> Result<()> {
    let format = Format::from_path(path)?;
    let prepared = prepare(mesh, format)?;
    let write_error = |source| Error::Write { path: path.to_path_buf(), source };
    let file = File::create(path).map_err(write_error)?;
    emit(mesh, &prepared, file).map_err(write_error)
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
        let missing = dir.join("no/such/dir/f.obj");
        let err = write_mesh(&mesh, &missing).unwrap_err();
        assert!(matches!(&err, Error::Write { path, .. } if path == &missing), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
