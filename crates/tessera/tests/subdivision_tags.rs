//! Every subdivision cage of the shared data reads with its OpenSubdiv tags, and what it reads
//! agrees with the data folder's own description of the cage (its README table: faces by size,
//! vertices, tag lines per name) — a source written independently of tessera.

use std::collections::BTreeMap;

use tessera::io::obj::read_obj;
use tessera::subdivision::BoundaryInterpolation;
use tessera::test_support::data;

/// One README row: faces by corner count, vertices, tag lines by name.
struct Described {
    faces: BTreeMap<usize, usize>,
    vertices: usize,
    tags: BTreeMap<String, usize>,
}

/// The `subdivision/` rows of the data README's table.
fn described() -> BTreeMap<String, Described> {
    let readme = std::fs::read_to_string(data("README.md")).expect("the shared data's README");
    let mut rows = BTreeMap::new();
    for line in readme.lines().filter(|l| l.starts_with("| `subdivision/")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let name = cells[1].trim_matches('`').to_string();
        let (faces_text, vertices_text) = cells[3].split_once(';').expect("faces; vertices");
        let mut faces = BTreeMap::new();
        for part in faces_text.split(',').map(str::trim) {
            let (count, kind) = part.split_once(' ').expect("N kind");
            let corners = match kind {
                "tri" => 3,
                "quad" => 4,
                gon => gon.trim_end_matches("-gon").parse().expect("N-gon"),
            };
            faces.insert(corners, count.parse().expect("a face count"));
        }
        let vertices = vertices_text.trim().trim_end_matches(" v").parse().expect("a vertex count");
        let mut tags = BTreeMap::new();
        if cells[4] != "—" {
            for part in cells[4].split(',').map(str::trim) {
                let (tag, count) = part.rsplit_once(' ').expect("tag N");
                tags.insert(tag.to_string(), count.parse().expect("a tag count"));
            }
        }
        rows.insert(name, Described { faces, vertices, tags });
    }
    rows
}

#[test]
fn every_cage_reads_as_the_data_readme_describes_it() {
    let rows = described();
    assert!(rows.len() >= 50, "the README lists {} subdivision cages", rows.len());
    for (name, row) in &rows {
        let mesh = read_obj(&data(name)).unwrap_or_else(|e| panic!("{e}"));
        let mut faces = BTreeMap::new();
        for f in &mesh.faces {
            *faces.entry(f.positions.len()).or_insert(0usize) += 1;
        }
        assert_eq!(faces, row.faces, "{name}: faces by corner count");
        assert_eq!(mesh.positions.len(), row.vertices, "{name}: vertices");
        let tags: BTreeMap<String, usize> = mesh.tags.lines.iter().cloned().collect();
        assert_eq!(tags, row.tags, "{name}: tag lines");
        assert!(mesh.tags.unknown.is_empty(), "{name}: {:?}", mesh.tags.unknown);
        if row.tags.get("crease").is_some_and(|&n| n > 0) {
            assert!(!mesh.tags.creases.is_empty(), "{name}");
        }
    }
}

#[test]
fn tags_carry_opensubdivs_meaning_on_known_cages() {
    let read = |name: &str| read_obj(&data(name)).unwrap_or_else(|e| panic!("{e}"));
    // Four holes on one tag line.
    let holes = read("subdivision/catmark_hole_test2.obj");
    assert_eq!(holes.tags.holes.len(), 4);
    // `interpolateboundary 1` is OpenSubdiv's edge-and-corner; a cage without the tag gets
    // the regression tools' edge-only.
    assert_eq!(
        read("subdivision/catmark_edgecorner.obj").tags.options.boundary,
        BoundaryInterpolation::EdgeAndCorner
    );
    assert_eq!(read("subdivision/catmark_torus.obj").tags.options.boundary, BoundaryInterpolation::EdgeOnly);
    // The torus with creases: 8 sharp edges, each an edge of the cage.
    let creased = read("subdivision/catmark_torus_creases0.obj");
    assert_eq!(creased.tags.creases.len(), 8);
    assert!(creased.tags.creases.iter().all(|c| c.sharpness > 0.0));
}
