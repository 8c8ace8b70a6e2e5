//! OpenSubdiv's tag lines, read and checked: `t NAME nint/nfloat/nstring ints floats
//! strings`, with the meaning OpenSubdiv's regression tools give them
//! (`regression/common/far_utils.h` reads the shapes this way).
//!
//! | tag | arguments |
//! | --- | --- |
//! | `crease` | vertex pairs `v0 v1 …` (each an edge of the cage), one sharpness or one per pair |
//! | `corner` | vertices, one sharpness or one per vertex |
//! | `hole` | faces |
//! | `interpolateboundary` | one integer: 0 none, 1 edge and corner, 2 edge only |
//! | `creasemethod` | `normal` or `chaikin` |
//! | `smoothtriangles` | `catmark` or `smooth` |
//!
//! Sharpness is a finite number ≥ 0 ([`INFINITELY_SHARP`] and above is infinitely
//! sharp); a NaN, infinite or negative one is an error naming its line, as is an index out of
//! range or a crease between vertices that share no face edge. Unknown tags are kept in
//! [`SubdivisionTags::unknown`] for the caller to report; they are not fatal.

use std::collections::HashSet;
use std::path::Path;

use crate::error::{Error, Result};

/// How the limit surface meets the cage's boundary (OpenSubdiv's `VtxBoundaryInterpolation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BoundaryInterpolation {
    /// No limit surface on faces at the boundary (tag value 0).
    None,
    /// Boundary edges are infinitely sharp; boundary vertices of one face stay smooth
    /// (tag value 2, and the default when a cage says nothing).
    #[default]
    EdgeOnly,
    /// Boundary edges are infinitely sharp and boundary vertices of one face are corners
    /// (tag value 1).
    EdgeAndCorner,
}

/// How semi-sharp creases lose sharpness from level to level (`Sdc::Options::CreasingMethod`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CreaseMethod {
    /// Sharpness drops by one a level (`normal`, the default).
    #[default]
    Uniform,
    /// Chaikin's rule: a crease's sharpness averages with its neighbours' (`chaikin`).
    Chaikin,
}

/// Catmull-Clark's rule for the face points of triangles (`Sdc::Options::TriangleSubdivision`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TriangleRule {
    /// Catmull-Clark's own rule (`catmark`, the default).
    #[default]
    Catmark,
    /// The smoother weights for triangles (`smooth`).
    Smooth,
}

/// The rules of a cage's limit surface that are not per edge or vertex.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SubdivisionOptions {
    /// The boundary rule (`t interpolateboundary`).
    pub boundary: BoundaryInterpolation,
    /// The crease method (`t creasemethod`).
    pub crease_method: CreaseMethod,
    /// Catmull-Clark's triangle rule (`t smoothtriangles`).
    pub triangles: TriangleRule,
}

/// Sharpness at or above this is infinitely sharp (OpenSubdiv's `SHARPNESS_INFINITE`).
pub const INFINITELY_SHARP: f32 = 10.0;

/// A sharp edge: the cage edge between two vertices (0-based) and its sharpness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crease {
    /// The edge's vertices, in the tag's order.
    pub vertices: [u32; 2],
    /// Its sharpness, ≥ 0.
    pub sharpness: f32,
    /// The tag's line in its file.
    pub line: usize,
}

/// A sharp vertex (0-based) and its sharpness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    /// The vertex.
    pub vertex: u32,
    /// Its sharpness, ≥ 0.
    pub sharpness: f32,
    /// The tag's line in its file.
    pub line: usize,
}

/// A tag line tessera does not know, kept so that the caller can say it was ignored.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownTag {
    /// The tag's name.
    pub name: String,
    /// Its line.
    pub line: usize,
}

/// Everything a cage's tag lines say, checked against the cage ([`SubdivisionTags::check`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SubdivisionTags {
    /// Sharp edges, one entry per vertex pair, in file order.
    pub creases: Vec<Crease>,
    /// Sharp vertices, in file order.
    pub corners: Vec<Corner>,
    /// Faces (0-based) without a limit surface, in file order.
    pub holes: Vec<u32>,
    /// The cage-wide rules; OpenSubdiv's regression defaults where no tag says.
    pub options: SubdivisionOptions,
    /// Tags that were not understood, ignored.
    pub unknown: Vec<UnknownTag>,
    /// Tag lines read, per name (`crease`, …), for reports.
    pub lines: Vec<(String, usize)>,
    /// Vertex and face indices as written, checked by [`SubdivisionTags::check`]: (line, kind,
    /// index).
    pending: Vec<(usize, IndexKind, i64)>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum IndexKind {
    Vertex,
    Face,
}

/// One tag line split into its arguments.
struct TagLine<'t> {
    name: &'t str,
    ints: Vec<i64>,
    floats: Vec<f64>,
    strings: Vec<&'t str>,
}

impl SubdivisionTags {
    /// Whether any tag line was read.
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// Reads the tag line whose tokens after `t` are `tokens`, at `file:line`.
    ///
    /// # Errors
    ///
    /// [`Error::Parse`] at the line for a missing name or malformed `nint/nfloat/nstring`
    /// counts, fewer arguments than the counts say, a non-number, a sharpness that is not a
    /// finite number ≥ 0, and arguments a known tag cannot take (see the module table).
    ///
    /// Cost: O(line length).
    pub fn read_line<'t>(
        &mut self,
        mut tokens: impl Iterator<Item = &'t str>,
        file: &Path,
        line: usize,
    ) -> Result<()> {
        let err = |reason: String| Error::parse(file, line, reason);
        let name = tokens.next().ok_or_else(|| err("`t` needs a tag name".into()))?;
        let counts = tokens
            .next()
            .ok_or_else(|| err(format!("tag `{name}` needs its counts `nint/nfloat/nstring`")))?;
        let mut parts = counts.split('/').map(|c| c.parse::<usize>());
        let (Some(Ok(ni)), Some(Ok(nf)), Some(Ok(ns)), None) =
            (parts.next(), parts.next(), parts.next(), parts.next())
        else {
            return Err(err(format!("tag `{name}`: counts `{counts}` are not `nint/nfloat/nstring`")));
        };
        let mut next = |what: &str| {
            tokens.next().ok_or_else(|| {
                err(format!("tag `{name}` says {ni}/{nf}/{ns} arguments; a {what} is missing"))
            })
        };
        let mut tag = TagLine { name, ints: Vec::new(), floats: Vec::new(), strings: Vec::new() };
        for _ in 0..ni {
            let token = next("integer")?;
            tag.ints
                .push(token.parse().map_err(|_| err(format!("tag `{name}`: `{token}` is not an integer")))?);
        }
        for _ in 0..nf {
            let token = next("number")?;
            tag.floats
                .push(token.parse().map_err(|_| err(format!("tag `{name}`: `{token}` is not a number")))?);
        }
        for _ in 0..ns {
            tag.strings.push(next("string")?);
        }
        self.apply(&tag, line).map_err(err)?;
        match self.lines.iter_mut().find(|(n, _)| n == name) {
            Some((_, count)) => *count += 1,
            None => self.lines.push((name.to_string(), 1)),
        }
        Ok(())
    }

    /// Tag lines named `name` read so far.
    pub fn line_count(&self, name: &str) -> usize {
        self.lines.iter().find(|(n, _)| n == name).map_or(0, |&(_, c)| c)
    }

    /// Records one tag line; the error is the reason, without the location.
    fn apply(&mut self, tag: &TagLine<'_>, line: usize) -> std::result::Result<(), String> {
        let name = tag.name;
        let sharpness = |k: usize| -> std::result::Result<f32, String> {
            let s = if tag.floats.len() == 1 { tag.floats[0] } else { tag.floats[k] };
            if !(s.is_finite() && s >= 0.0) {
                return Err(format!(
                    "tag `{name}`: sharpness {s} must be a finite number ≥ 0 ({} and above is infinitely sharp)",
                    INFINITELY_SHARP
                ));
            }
            Ok(s as f32)
        };
        let one_string = |choices: &[&str]| -> std::result::Result<usize, String> {
            match tag.strings.as_slice() {
                [s] => choices
                    .iter()
                    .position(|c| c == s)
                    .ok_or_else(|| format!("tag `{name}`: `{s}` is not one of {}", choices.join(", "))),
                _ => Err(format!("tag `{name}` takes one string, one of {}", choices.join(", "))),
            }
        };
        match name {
            "crease" => {
                let pairs = tag.ints.len() / 2;
                if tag.ints.len() < 2 || tag.ints.len() % 2 != 0 {
                    return Err(format!(
                        "tag `crease` takes vertex pairs, found {} integers",
                        tag.ints.len()
                    ));
                }
                if !(tag.floats.len() == 1 || tag.floats.len() == pairs) {
                    return Err(format!(
                        "tag `crease` takes one sharpness or one per edge ({pairs}), found {}",
                        tag.floats.len()
                    ));
                }
                for k in 0..pairs {
                    let s = sharpness(k)?;
                    let [a, b] = [tag.ints[2 * k], tag.ints[2 * k + 1]];
                    self.pending.push((line, IndexKind::Vertex, a));
                    self.pending.push((line, IndexKind::Vertex, b));
                    let index = |v: i64| u32::try_from(v).unwrap_or(u32::MAX);
                    self.creases.push(Crease { vertices: [index(a), index(b)], sharpness: s, line });
                }
            }
            "corner" => {
                if tag.ints.is_empty() || !(tag.floats.len() == 1 || tag.floats.len() == tag.ints.len()) {
                    return Err(format!(
                        "tag `corner` takes vertices and one sharpness or one per vertex, found {}/{}",
                        tag.ints.len(),
                        tag.floats.len()
                    ));
                }
                for (k, &v) in tag.ints.iter().enumerate() {
                    let s = sharpness(k)?;
                    self.pending.push((line, IndexKind::Vertex, v));
                    self.corners.push(Corner {
                        vertex: u32::try_from(v).unwrap_or(u32::MAX),
                        sharpness: s,
                        line,
                    });
                }
            }
            "hole" => {
                if tag.ints.is_empty() {
                    return Err("tag `hole` takes the faces that are holes".into());
                }
                for &f in &tag.ints {
                    self.pending.push((line, IndexKind::Face, f));
                    self.holes.push(u32::try_from(f).unwrap_or(u32::MAX));
                }
            }
            "interpolateboundary" => {
                // The tag's integers are not Sdc's enum values.
                self.options.boundary = match tag.ints.as_slice() {
                    [0] => BoundaryInterpolation::None,
                    [1] => BoundaryInterpolation::EdgeAndCorner,
                    [2] => BoundaryInterpolation::EdgeOnly,
                    _ => return Err(
                        "tag `interpolateboundary` takes one integer: 0 none, 1 edge and corner, 2 edge only"
                            .into(),
                    ),
                };
            }
            "creasemethod" => {
                self.options.crease_method =
                    [CreaseMethod::Uniform, CreaseMethod::Chaikin][one_string(&["normal", "chaikin"])?];
            }
            "smoothtriangles" => {
                self.options.triangles =
                    [TriangleRule::Catmark, TriangleRule::Smooth][one_string(&["catmark", "smooth"])?];
            }
            _ => self.unknown.push(UnknownTag { name: name.to_string(), line }),
        }
        Ok(())
    }

    /// Checks the tags against the cage: every vertex index below `vertices`, every face
    /// index below `faces.len()`, every crease an edge of some face (`faces` are 0-based
    /// vertex lists). Repeated tags on one edge or vertex are kept; the last one wins.
    ///
    /// # Errors
    ///
    /// [`Error::Parse`] at the tag's line naming the index or the edge.
    ///
    /// Cost: O(face corners + tags), one hash set of the cage's edges when it has creases.
    pub fn check(&mut self, vertices: usize, faces: &[&[u32]], file: &Path) -> Result<()> {
        for &(line, kind, index) in &self.pending {
            let (count, what, whats) = match kind {
                IndexKind::Vertex => (vertices, "vertex", "vertices"),
                IndexKind::Face => (faces.len(), "face", "faces"),
            };
            if index < 0 || index as u64 >= count as u64 {
                return Err(Error::parse(
                    file,
                    line,
                    format!("tag names {what} {index}, but the cage has {count} {whats} (tag indices are 0-based)"),
                ));
            }
        }
        self.pending.clear();
        if self.creases.is_empty() {
            return Ok(());
        }
        let mut edges = HashSet::new();
        for face in faces {
            for (k, &a) in face.iter().enumerate() {
                let b = face[(k + 1) % face.len()];
                edges.insert((a.min(b), a.max(b)));
            }
        }
        for c in &self.creases {
            let [a, b] = c.vertices;
            if !edges.contains(&(a.min(b), a.max(b))) {
                return Err(Error::parse(
                    file,
                    c.line,
                    format!("tag `crease` names vertices {a} and {b}, which share no face edge"),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(lines: &[&str]) -> Result<SubdivisionTags> {
        let mut tags = SubdivisionTags::default();
        for (k, l) in lines.iter().enumerate() {
            let mut tokens = l.split_ascii_whitespace();
            assert_eq!(tokens.next(), Some("t"));
            tags.read_line(tokens, Path::new("cage.obj"), k + 1)?;
        }
        Ok(tags)
    }

    #[test]
    fn tags_read_with_opensubdivs_meaning() {
        let tags = read(&[
            "t crease 4/2/0 0 1 1 2 2.5 10",
            "t corner 1/1/0 3 4.0",
            "t hole 2/0/0 0 1",
            "t interpolateboundary 1/0/0 1",
            "t creasemethod 0/0/1 chaikin",
            "t smoothtriangles 0/0/1 smooth",
            "t facevaryingpropagatecorners 1/0/0 1",
        ])
        .unwrap();
        assert_eq!(tags.creases.len(), 2);
        assert_eq!((tags.creases[1].vertices, tags.creases[1].sharpness), ([1, 2], 10.0));
        assert_eq!(tags.corners[0].vertex, 3);
        assert_eq!(tags.holes, [0, 1]);
        let expected = SubdivisionOptions {
            boundary: BoundaryInterpolation::EdgeAndCorner,
            crease_method: CreaseMethod::Chaikin,
            triangles: TriangleRule::Smooth,
        };
        assert_eq!(tags.options, expected);
        assert_eq!(tags.unknown, [UnknownTag { name: "facevaryingpropagatecorners".into(), line: 7 }]);
        assert_eq!(tags.line_count("crease"), 1);
        // Defaults where nothing is said: edge-only boundaries, uniform creases, Catmark triangles.
        let none = read(&[]).unwrap();
        assert_eq!(none.options.boundary, BoundaryInterpolation::EdgeOnly);
        assert!(none.is_empty());
    }

    #[test]
    fn bad_tags_name_their_line_and_reason() {
        let reason = |lines: &[&str]| match read(lines) {
            Err(Error::Parse { at, reason }) => format!("{}: {reason}", at.line),
            other => panic!("{other:?}"),
        };
        assert!(reason(&["t crease 2/1/0 0 1 NaN"]).contains("1: tag `crease`: sharpness NaN"));
        assert!(reason(&["t crease 2/1/0 0 1 -1"]).contains("finite number ≥ 0"));
        assert!(reason(&["t crease 2/1/0 0 1 inf"]).contains("finite number ≥ 0"));
        assert!(reason(&["t corner 1/1/0 0 1", "t crease 3/1/0 0 1 2 1"])
            .starts_with("2: tag `crease` takes vertex pairs"));
        assert!(reason(&["t crease 2/1/0 0 1"]).contains("a number is missing"));
        assert!(reason(&["t crease 2-1-0 0 1 1"]).contains("not `nint/nfloat/nstring`"));
        assert!(reason(&["t crease 2/1/0 0 x 1"]).contains("`x` is not an integer"));
        assert!(reason(&["t interpolateboundary 1/0/0 3"]).contains("0 none, 1 edge and corner"));
        assert!(reason(&["t creasemethod 0/0/1 sharp"]).contains("`sharp` is not one of normal, chaikin"));
        assert!(reason(&["t"]).contains("needs a tag name"));
    }

    #[test]
    fn indices_and_edges_are_checked_against_the_cage() {
        let quad: &[u32] = &[0, 1, 2, 3];
        let check = |lines: &[&str]| read(lines).unwrap().check(4, &[quad], Path::new("cage.obj"));
        check(&["t crease 2/1/0 3 0 1", "t corner 1/1/0 2 1", "t hole 1/0/0 0"]).unwrap();
        let message = |lines: &[&str]| check(lines).unwrap_err().to_string();
        assert!(message(&["t crease 2/1/0 0 2 1"])
            .contains("cage.obj:1: tag `crease` names vertices 0 and 2, which share no face edge"));
        assert!(message(&["t x 0/0/0", "t corner 1/1/0 4 1"])
            .contains("cage.obj:2: tag names vertex 4, but the cage has 4 vertices"));
        assert!(message(&["t hole 1/0/0 -1"]).contains("tag names face -1"));
    }
}
