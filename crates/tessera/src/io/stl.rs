//! STL: reading (binary and ASCII) and writing (binary).
//!
//! **Reading** takes untrusted files (every count is checked against the bytes present, never
//! a panic or an allocation sized by a header). Binary is assumed when the size matches the
//! header's triangle count or the file does not start with `solid`. Corners with equal
//! positions (bit-identical, with `-0.0` equal to `0.0`) are welded into one vertex, in order
//! of first appearance, because STL stores every triangle's corners separately. Facet normals
//! are not kept; normals and uvs are zero, patches 0.
//!
//! **Writing** ([`write_stl`]) stores positions and a facet normal per triangle only.

use std::collections::HashMap;
use std::io::{self, Write};
use std::path::Path;

use glam::DVec3;

use super::binary::{all_finite, fill_missing, le_floats, put_u32, write_chunks, BIN_CHUNK};
use super::Format;
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// Size of a binary STL header plus the triangle count.
const STL_HEADER: usize = 84;
/// Size of one binary STL triangle record.
const STL_RECORD: usize = 50;

/// Parses STL `data`, binary or ASCII; `file` only labels errors. Binary is assumed when the
/// size matches the header's triangle count or the file does not start with `solid`.
/// See the module documentation for welding and what is filled in.
///
/// Preconditions: none; any bytes give a mesh or an error.
///
/// Cost: O(`data.len()`) expected time (one hash lookup per corner); memory proportional to
/// the triangles present, never to a header count the data cannot back.
pub fn parse_stl(data: &[u8], file: &Path) -> Result<Mesh> {
    let declared = data.get(80..STL_HEADER).map(|b| u64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])));
    let binary_len = declared.map(|n| STL_HEADER as u64 + STL_RECORD as u64 * n);
    let starts_solid = {
        let text = data.trim_ascii_start();
        text.len() >= 5 && text[..5].eq_ignore_ascii_case(b"solid")
    };
    // "solid" also starts the header of some binary files, so an exact binary size wins.
    if binary_len != Some(data.len() as u64) && starts_solid {
        return parse_stl_ascii(data, file);
    }
    let (Some(count), Some(need)) = (declared, binary_len) else {
        return Err(Error::parse(
            file,
            0,
            format!("file is {} bytes, shorter than the {STL_HEADER}-byte binary STL header", data.len()),
        ));
    };
    if need > data.len() as u64 {
        return Err(Error::parse(
            file,
            0,
            format!(
                "binary STL header at byte offset 80 declares {count} triangles needing {need} \
                 bytes, but the file has {}",
                data.len()
            ),
        ));
    }
    let mut welder = Welder::with_capacity(count as usize);
    for (t, record) in data[STL_HEADER..need as usize].chunks_exact(STL_RECORD).enumerate() {
        let f = |k: usize| {
            let b = &record[4 * k..4 * k + 4];
            f32::from_le_bytes([b[0], b[1], b[2], b[3]])
        };
        for corner in 0..3 {
            // Floats 0..3 are the facet normal, which is derived data and not kept.
            let base = 3 + 3 * corner;
            let p = [f(base), f(base + 1), f(base + 2)];
            let offset = STL_HEADER + STL_RECORD * t + 4 * base;
            welder.push(p).map_err(|reason| {
                Error::parse(file, 0, format!("triangle {t}: {reason} at byte offset {offset}"))
            })?;
        }
    }
    Ok(welder.finish())
}

/// Merges equal corner positions into shared vertices.
struct Welder {
    mesh: Mesh,
    ids: HashMap<[u32; 3], u32>,
}

impl Welder {
    fn with_capacity(triangles: usize) -> Welder {
        let mut mesh = Mesh::default();
        mesh.indices.reserve(triangles.saturating_mul(3));
        // Closed meshes have about half as many vertices as triangles.
        mesh.positions.reserve(triangles / 2);
        Welder { mesh, ids: HashMap::with_capacity(triangles / 2) }
    }

    fn push(&mut self, p: [f32; 3]) -> std::result::Result<(), String> {
        if !all_finite(&p) {
            return Err(format!("non-finite vertex {p:?}"));
        }
        // Adding +0.0 turns -0.0 into +0.0, so the two zeros weld.
        let key = p.map(|c| (c + 0.0).to_bits());
        let next = self.mesh.positions.len();
        let id = match self.ids.get(&key) {
            Some(&id) => id,
            None => {
                let id = u32::try_from(next).map_err(|_| "more than 2^32 distinct vertices".to_string())?;
                self.ids.insert(key, id);
                self.mesh.positions.push(p);
                id
            }
        };
        self.mesh.indices.push(id);
        Ok(())
    }

    fn finish(mut self) -> Mesh {
        fill_missing(&mut self.mesh);
        self.mesh
    }
}

fn parse_stl_ascii(data: &[u8], file: &Path) -> Result<Mesh> {
    #[derive(PartialEq)]
    enum State {
        /// Between solids: expect `solid` or the end of the file.
        Outside,
        /// Inside a solid: expect `facet` or `endsolid`.
        Solid,
        /// After `facet`: expect `outer loop`.
        Facet,
        /// Inside a loop: expect `vertex` or `endloop`.
        Loop,
        /// After `endloop`: expect `endfacet`.
        EndLoop,
    }
    let mut state = State::Outside;
    let mut solids = 0usize;
    let mut corners = 0usize;
    // Each facet takes well over 100 bytes of text; the bound only limits preallocation.
    let mut welder = Welder::with_capacity(data.len() / 100);
    let mut line_no = 0;
    // Without the final newline, split would yield one empty line past the end of the file.
    let text = data.strip_suffix(b"\n").unwrap_or(data);
    for raw in text.split(|&b| b == b'\n') {
        line_no += 1;
        let err = |reason: String| Error::parse(file, line_no, reason);
        let Ok(line) = std::str::from_utf8(raw) else {
            return Err(err("line is not valid UTF-8".into()));
        };
        let mut tokens = line.split_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        let keyword = keyword.to_ascii_lowercase();
        match (&state, keyword.as_str()) {
            (State::Outside, "solid") => {
                state = State::Solid;
                solids += 1;
            }
            (State::Solid, "facet") => state = State::Facet,
            (State::Solid, "endsolid") => state = State::Outside,
            (State::Facet, "outer") => {
                if !tokens.next().is_some_and(|t| t.eq_ignore_ascii_case("loop")) {
                    return Err(err("expected \"outer loop\"".into()));
                }
                state = State::Loop;
                corners = 0;
            }
            (State::Loop, "vertex") => {
                let coords: Vec<&str> = tokens.collect();
                let parsed: Vec<f32> = coords.iter().filter_map(|t| t.parse().ok()).collect();
                if coords.len() != 3 || parsed.len() != 3 {
                    return Err(err(format!("expected 3 numbers after vertex, found {coords:?}")));
                }
                corners += 1;
                if corners > 3 {
                    return Err(err("facet has more than 3 vertices".into()));
                }
                welder.push([parsed[0], parsed[1], parsed[2]]).map_err(err)?;
            }
            (State::Loop, "endloop") => {
                if corners != 3 {
                    return Err(err(format!("facet has {corners} vertices; 3 are needed")));
                }
                state = State::EndLoop;
            }
            (State::EndLoop, "endfacet") => state = State::Solid,
            _ => {
                let expected = match state {
                    State::Outside => "solid",
                    State::Solid => "facet or endsolid",
                    State::Facet => "outer loop",
                    State::Loop => "vertex or endloop",
                    State::EndLoop => "endfacet",
                };
                return Err(err(format!("expected {expected}, found {keyword:?}")));
            }
        }
    }
    if state != State::Outside || solids == 0 {
        return Err(Error::parse(file, line_no, "file ends inside a solid (missing endsolid); truncated?"));
    }
    Ok(welder.finish())
}

// =============================================================================================
// Writing

/// Writes `mesh` as binary STL to `w`: an 80-byte header starting with `tessera`, the triangle
/// count, and per triangle the unit facet normal computed from the positions (zero for a
/// degenerate triangle), its three corners and a zero attribute word. Vertex normals, uvs and
/// patches are not stored.
///
/// Preconditions: as [`write_mesh`](super::write_mesh), and at most `u32::MAX` triangles, else
/// [`Error::InvalidMesh`] or [`Error::FormatLimit`]. I/O errors are [`Error::Write`] labelled `<writer>`.
///
/// Cost: O(triangles) time, the facets filled in parallel chunks on the rayon threads and
/// written in order (the bytes do not depend on the thread count); memory: a few MiB of chunk
/// buffers.
pub fn write_stl<W: Write>(mesh: &Mesh, w: W) -> Result<()> {
    super::write_to(mesh, Format::Stl, w)
}

// STL

pub(super) fn emit_stl<W: Write>(mesh: &Mesh, count: u32, w: &mut W) -> io::Result<()> {
    let mut header = [0u8; 80];
    header[..7].copy_from_slice(b"tessera");
    w.write_all(&header)?;
    put_u32(w, count)?;
    let position = |i: u32| mesh.positions[i as usize];
    // 50-byte facets (normal, three corners, a zero attribute word), filled in parallel
    // chunks and written in order (binary::write_chunks).
    const FACET: usize = 50;
    write_chunks(w, mesh.triangle_count(), BIN_CHUNK, |range, out| {
        out.resize(range.len() * FACET, 0);
        for (rec, t) in out.chunks_exact_mut(FACET).zip(range) {
            let [a, b, c] = mesh.triangle(t).map(position);
            // In f64 so that tiny but valid triangles do not underflow to a zero normal.
            let [da, db, dc] = [a, b, c].map(|p| DVec3::from(p.map(f64::from)));
            let n = (db - da).cross(dc - da).normalize_or_zero().as_vec3();
            le_floats(&mut rec[0..12], n.to_array());
            le_floats(&mut rec[12..24], a);
            le_floats(&mut rec[24..36], b);
            le_floats(&mut rec[36..48], c);
            rec[48..50].fill(0);
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::binary::test_meshes::*;

    #[test]
    fn stl_round_trip_up_to_welding() {
        let mesh = grid(4, false);
        let read = parse_stl(&bytes(|w| write_stl(&mesh, w)), label()).unwrap();
        assert_eq!(read.vertex_count(), mesh.vertex_count(), "all grid positions are distinct");
        assert_eq!(read.indices.len(), mesh.indices.len());
        for (a, b) in read.indices.iter().zip(&mesh.indices) {
            assert_eq!(read.positions[*a as usize], mesh.positions[*b as usize]);
        }
        assert_eq!(read.normals, vec![[0.0; 3]; read.vertex_count()]);
        assert_eq!(read.uvs, vec![[0.0; 2]; read.vertex_count()]);
        assert_eq!(read.vertex_patch, vec![0; read.vertex_count()]);
        assert_eq!(read.triangle_patch, vec![0; read.triangle_count()]);
        assert_eq!(read.corner_params, None);
    }

    const ASCII_STL: &str = "solid square
  facet normal 0 0 1
    outer loop
      vertex 0 0 0
      vertex 1 0 0
      vertex 1 1 0
    endloop
  endfacet
  FACET NORMAL 0 0 1
    OUTER LOOP
      VERTEX 0 0 -0
      VERTEX 1 1 0
      VERTEX 0 1 0
    ENDLOOP
  ENDFACET
endsolid square
solid second

endsolid
";

    #[test]
    fn ascii_stl_is_welded() {
        let mesh = parse_stl(ASCII_STL.as_bytes(), label()).unwrap();
        assert_eq!(mesh.positions, [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
        assert_eq!(mesh.indices, [0, 1, 2, 0, 2, 3], "-0 welds with 0");
        assert_eq!(mesh.triangle_patch, [0, 0]);
    }

    #[test]
    fn ascii_stl_errors_name_the_line() {
        let replace = |from: &str, to: &str| ASCII_STL.replacen(from, to, 1);
        let cases = [
            (replace("vertex 1 0 0", "vertex 1 0"), 5, "expected 3 numbers"),
            (replace("vertex 1 0 0", "vertex 1 0 inf"), 5, "non-finite"),
            (replace("vertex 1 0 0", "vertex 1 0 0\nvertex 2 2 2"), 7, "more than 3"),
            (replace("      vertex 1 1 0\n", ""), 6, "2 vertices"),
            (replace("outer loop", "outer lop"), 3, "outer loop"),
            (replace("endfacet", "endfacets"), 8, "expected endfacet"),
            (ASCII_STL[..ASCII_STL.len() - 9].to_string(), 18, "missing endsolid"),
        ];
        for (text, line, expected) in cases {
            let (at, reason) = parse_error(parse_stl(text.as_bytes(), label()));
            assert!(reason.contains(expected), "{reason:?} lacks {expected:?}");
            assert_eq!(at, line, "{reason}");
        }
    }

    #[test]
    fn binary_stl_checks() {
        let mesh = grid(2, false);
        let data = bytes(|w| write_stl(&mesh, w));
        // A binary header that happens to start with "solid" is still binary when the size fits.
        let mut solid = data.clone();
        solid[..7].copy_from_slice(b"solid x");
        assert_eq!(parse_stl(&solid, label()).unwrap(), parse_stl(&data, label()).unwrap());

        let mut lying = data.clone();
        lying[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        let (line, reason) = parse_error(parse_stl(&lying, label()));
        assert_eq!(line, 0);
        assert!(reason.contains("4294967295 triangles"), "{reason}");

        let mut nan = data.clone();
        nan[84 + 50 + 16..84 + 50 + 20].copy_from_slice(&f32::NAN.to_le_bytes());
        let (_, reason) = parse_error(parse_stl(&nan, label()));
        assert!(reason.contains("triangle 1") && reason.contains("byte offset 146"), "{reason}");

        let (_, reason) = parse_error(parse_stl(b"tiny", label()));
        assert!(reason.contains("shorter than the 84-byte"), "{reason}");
    }

    #[test]
    fn stl_truncation_and_corruption_never_panic() {
        let data = bytes(|w| write_stl(&grid(2, false), w));
        check_truncations(&data, parse_stl, true);
        check_corruptions(&data, parse_stl);
        check_truncations(ASCII_STL.as_bytes(), parse_stl, false);
        check_corruptions(ASCII_STL.as_bytes(), parse_stl);
    }

    #[test]
    fn stl_layout_and_normals() {
        let mut mesh = grid(2, false);
        // Make the last triangle degenerate: its normal must be zero, not NaN.
        let last = mesh.triangle(mesh.triangle_count() - 1);
        mesh.indices.truncate(mesh.indices.len() - 3);
        mesh.indices.extend([last[0], last[0], last[1]]);
        let bytes = bytes(|w| write_stl(&mesh, w));
        let t = mesh.triangle_count();
        assert_eq!(bytes.len(), 84 + 50 * t);
        assert!(bytes.starts_with(b"tessera"));
        assert_eq!(u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize, t);
        for (k, rec) in bytes[84..].chunks_exact(50).enumerate() {
            let f = |i: usize| f32::from_le_bytes(rec[4 * i..4 * i + 4].try_into().unwrap());
            let n = glam::Vec3::new(f(0), f(1), f(2));
            let corner = |c: usize| glam::Vec3::new(f(3 + 3 * c), f(4 + 3 * c), f(5 + 3 * c));
            let tri = mesh.triangle(k);
            for (c, &i) in tri.iter().enumerate() {
                assert_eq!(corner(c).to_array(), mesh.positions[i as usize]);
            }
            assert_eq!(&rec[48..], &[0, 0]);
            if k == t - 1 {
                assert_eq!(n, glam::Vec3::ZERO);
            } else {
                assert!((n.length() - 1.0).abs() < 1e-6);
                let geometric = (corner(1) - corner(0)).cross(corner(2) - corner(0)).normalize();
                assert!(n.dot(geometric) > 0.9999, "normal follows the counter-clockwise order");
            }
        }
    }
}
