//! glTF 2.0 binary (GLB): tessera's own mesh files, read and written.
//!
//! **Writing** ([`write_glb`]): one buffer, one mesh with one indexed triangle primitive, one
//! node and one scene, so that the Khronos glTF validator reports no error, no warning and no
//! unused object. Attributes: `POSITION` (with the min/max glTF requires), `NORMAL`, and the
//! application-specific `_PATCH_UV` (the vertex's patch parameters, two floats) and `_PATCH`
//! (its patch id as a float); indices are `u32`. The patch parameters are not `TEXCOORD_0`:
//! they are no texture coordinates, and without a material using them the validator reports
//! them unused.
//!
//! Triangle patches and corner params have no glTF accessor (glTF forbids `UNSIGNED_INT`
//! accessors outside `primitive.indices`, a float accessor would round patch ids above 2^24,
//! and glTF has no per-triangle attributes). They are byte ranges of buffer 0 named in the
//! primitive's `extras`: `{"tessera": {"trianglePatch": {"byteOffset": o, "byteLength": l},
//! "cornerParams": {...}}}` (the second key only when
//! [`Mesh::corner_params`](crate::mesh::Mesh::corner_params) is set). The
//! first holds one little-endian `u32` per triangle, the second two little-endian `f32` (u, v)
//! per triangle corner, in index order. They are not buffer views because a buffer view no
//! accessor uses is an unused object to the validator.
//!
//! **Reading** ([`parse_glb`]) takes the layout above and the one tessera wrote before
//! (`TEXCOORD_0` for the vertex parameters, `trianglePatchView`/`cornerParamsView` naming
//! buffer views): one mesh with one triangle primitive, `POSITION`, optional `NORMAL`, vertex
//! parameters and `_PATCH`, `u8`/`u16`/`u32` indices (or none), and tessera's triangle patches
//! and corner params. A file without meshes gives an empty mesh. It is written by hand rather than with the `gltf` crate because it reads
//! tessera's own data (the `_PATCH` attributes and the ranges in `extras`), and because it
//! checks every count and offset before use: the `gltf` crate's accessor iterators compute
//! `stride * (count - 1)` unchecked (a count of 0 underflows) and trust the component type,
//! which a fuzzed or lying file breaks. Outside glTF files (`.gltf` or `.glb`, any number of
//! meshes and nodes) are read as PN-triangle input by [`read_gltf_triangles`], which does use
//! the `gltf` crate, after the same checks.
//!
//! The code is in four files by responsibility: `read` (tessera's own GLB), `outside` (any
//! glTF as PN-triangle input), `uri` (which buffer files an outside `.gltf` may name, and
//! reading them) and `write` (the GLB writer).

mod outside;
mod read;
mod uri;
mod write;

pub use outside::{parse_gltf_triangles, read_gltf_triangles};
pub use read::parse_glb;
pub use uri::UriScope;
pub use write::write_glb;
pub(super) use write::{emit_glb, plan_glb, GlbPlan};

/// Largest integer an `f32` holds exactly (and with it every smaller one): the bound on vertex
/// patch ids in the GLB `_PATCH` attribute, which glTF requires to be a float.
const MAX_EXACT_F32_INT: u32 = 1 << 24;

const GLB_VERSION: u32 = 2;
const GLB_HEADER_LEN: u64 = 12;
const GLB_CHUNK_HEADER_LEN: u64 = 8;

const GLB_MAGIC: &[u8; 4] = b"glTF";
const GLB_CHUNK_JSON: u32 = u32::from_le_bytes(*b"JSON");
const GLB_CHUNK_BIN: u32 = u32::from_le_bytes(*b"BIN\0");

#[cfg(test)]
mod tests {
    use gltf_json as gj;

    use super::write::position_bounds;
    use super::*;
    use crate::error::Error;
    use crate::io::binary::test_meshes::*;
    use crate::mesh::Mesh;

    #[test]
    fn glb_round_trip() {
        for with_params in [false, true] {
            let mesh = grid(5, with_params);
            let read = parse_glb(&bytes(|w| write_glb(&mesh, w)), label()).unwrap();
            assert_eq!(read, mesh);
        }
        let empty = Mesh::default();
        assert_eq!(parse_glb(&bytes(|w| write_glb(&empty, w)), label()).unwrap(), empty);
    }

    /// Builds a GLB from a JSON text and a BIN chunk.
    fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
        let mut json = json.as_bytes().to_vec();
        json.resize(json.len().next_multiple_of(4), b' ');
        let mut bin = bin.to_vec();
        bin.resize(bin.len().next_multiple_of(4), 0);
        let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((json.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(&json);
        if !bin.is_empty() {
            out.extend((bin.len() as u32).to_le_bytes());
            out.extend(b"BIN\0");
            out.extend(&bin);
        }
        out
    }

    /// One triangle, u16 indices, positions only: everything else is filled in.
    fn minimal_glb(index_count: u32, position_count: u32, index_value: u16) -> Vec<u8> {
        let mut bin = Vec::new();
        for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
            bin.extend(c.to_le_bytes());
        }
        for i in [0u16, 1, index_value] {
            bin.extend(i.to_le_bytes());
        }
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":42}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":{position_count},"type":"VEC3"}},
                         {{"bufferView":1,"componentType":5123,"count":{index_count},"type":"SCALAR"}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}]}}"#
        );
        glb(&json, &bin)
    }

    #[test]
    fn glb_fills_missing_attributes() {
        let mesh = parse_glb(&minimal_glb(3, 3, 2), label()).unwrap();
        assert_eq!(mesh.positions, [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        assert_eq!(mesh.indices, [0, 1, 2]);
        assert_eq!(mesh.normals, [[0.0; 3]; 3]);
        assert_eq!(mesh.uvs, [[0.0; 2]; 3]);
        assert_eq!(mesh.vertex_patch, [0; 3]);
        assert_eq!(mesh.triangle_patch, [0]);
        assert_eq!(mesh.corner_params, None);
    }

    #[test]
    fn glb_errors() {
        let reason = |data: &[u8]| parse_error(parse_glb(data, label())).1;
        assert!(reason(&minimal_glb(3, 3, 7)).contains("index 2 is 7, but there are 3 vertices"));
        assert!(reason(&minimal_glb(3, 4, 2)).contains("do not fit"));
        assert!(reason(&minimal_glb(3, 1 << 30, 2)).contains("do not fit"));
        assert!(reason(&minimal_glb(1 << 31, 3, 2)).contains("do not fit"));
        assert!(reason(&minimal_glb(2, 3, 2)).contains("whole triangles"));
        assert!(reason(&glb("{\"asset\":", &[])).contains("invalid glTF JSON"));
        assert!(reason(b"glTB\x02\0\0\0\x0c\0\0\0").contains("not a GLB"));
        let mut data = minimal_glb(3, 3, 2);
        data.push(0);
        assert!(reason(&data).contains("gives a length of"));

        let mesh = grid(2, true);
        let good = bytes(|w| write_glb(&mesh, w));
        let (json, bin) = glb_chunks(&good);
        let json = std::str::from_utf8(json).unwrap().trim_end();
        let edit = |change: &dyn Fn(&mut serde_json::Value)| {
            let mut v: serde_json::Value = serde_json::from_str(json).unwrap();
            change(&mut v);
            glb(&v.to_string(), bin)
        };
        let far = edit(&|v| extras(v)["trianglePatch"]["byteOffset"] = 100000.into());
        assert!(reason(&far).contains("extras.tessera.trianglePatch spans bytes 100000.."));
        let bad = edit(&|v| extras(v)["trianglePatch"] = "x".into());
        assert!(reason(&bad).contains("trianglePatch.byteOffset is missing or not a byte count"));
        let old_key = |value: serde_json::Value| {
            edit(&move |v| {
                let e = extras(v).as_object_mut().unwrap();
                e.remove("trianglePatch");
                e.insert("trianglePatchView".into(), value.clone());
            })
        };
        assert!(reason(&old_key(50.into())).contains("buffer view 50"));
        assert!(reason(&old_key("x".into())).contains("not a buffer view"));
        let big = edit(&|v| v["buffers"][0]["byteLength"] = 100000.into());
        assert!(reason(&big).contains("spans bytes"));
        match parse_glb(&edit(&|v| v["buffers"][0]["uri"] = "x.bin".into()), label()) {
            Err(Error::Unsupported { reason, .. }) => assert!(reason.contains("external buffer")),
            other => panic!("{other:?}"),
        }
        let mut nan = good.clone();
        let at = good.len() - bin.len();
        nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(reason(&nan).contains("POSITION element 0 is not finite"));
    }

    #[test]
    fn gltf_reader_reads_tessera_output_and_refuses_short_headers() {
        let mesh = grid(3, true);
        let read =
            parse_gltf_triangles(&bytes(|w| write_glb(&mesh, w)), label(), None, UriScope::ModelFolder)
                .unwrap();
        let positions: Vec<[f32; 3]> = read.positions.iter().map(|p| p.as_vec3().to_array()).collect();
        assert_eq!(positions, mesh.positions);
        let indices: Vec<u32> = read.faces.iter().flat_map(|f| f.positions.clone()).collect();
        assert_eq!(indices, mesh.indices);
        assert!(read.faces.iter().all(|f| f.normals.as_ref() == Some(&f.positions)));
        for short in [&b"glTF"[..], b"glTF\x02\0\0\0\x05\0\0\0", b"glTF\x02\0\0\0\0\0\0\0JSON"] {
            let e = parse_gltf_triangles(short, label(), None, UriScope::ModelFolder).unwrap_err();
            assert!(e.to_string().contains("invalid glTF"), "{e}");
        }
    }

    /// tessera's part of a GLB primitive's extras, in the JSON of a GLB.
    fn extras(v: &mut serde_json::Value) -> &mut serde_json::Value {
        &mut v["meshes"][0]["primitives"][0]["extras"]["tessera"]
    }

    #[test]
    fn glb_truncation_and_corruption_never_panic() {
        let data = bytes(|w| write_glb(&grid(2, true), w));
        check_truncations(&data, parse_glb, true);
        check_corruptions(&data, parse_glb);
        let data = minimal_glb(3, 3, 2);
        check_truncations(&data, parse_glb, true);
        check_corruptions(&data, parse_glb);
    }

    /// Splits a GLB into its JSON and BIN chunks, checking the container on the way.
    pub(crate) fn glb_chunks(bytes: &[u8]) -> (&[u8], &[u8]) {
        let word = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap()) as usize;
        assert_eq!(&bytes[..4], b"glTF");
        assert_eq!(word(4), 2);
        assert_eq!(word(8), bytes.len());
        let json_len = word(12);
        assert_eq!(&bytes[16..20], b"JSON");
        assert_eq!(json_len % 4, 0);
        let json = &bytes[20..20 + json_len];
        let rest = &bytes[20 + json_len..];
        if rest.is_empty() {
            return (json, &[]);
        }
        let bin_len = word(20 + json_len);
        assert_eq!(bin_len % 4, 0);
        assert_eq!(&rest[4..8], b"BIN\0");
        assert_eq!(rest.len(), 8 + bin_len);
        (json, &rest[8..])
    }

    #[test]
    fn glb_json_is_valid_gltf_with_exact_accessors() {
        let mesh = grid(5, true);
        let bytes = bytes(|w| write_glb(&mesh, w));
        let (json, bin) = glb_chunks(&bytes);
        assert!(std::str::from_utf8(json).unwrap().ends_with(['}', ' ']));
        let root = gj::Root::from_slice(json).unwrap();
        let mut problems = Vec::new();
        gj::validation::Validate::validate(&root, &root, gj::Path::new, &mut |path, error| {
            problems.push(format!("{}: {error:?}", path()))
        });
        assert!(problems.is_empty(), "{problems:?}");
        assert_eq!(root.buffers.len(), 1);
        assert_eq!(root.buffers[0].byte_length.0 as usize, bin.len());
        assert!(root.buffers[0].uri.is_none());
        assert_eq!((root.meshes.len(), root.nodes.len(), root.scenes.len()), (1, 1, 1));
        let primitive = &root.meshes[0].primitives[0];
        let attr = |name: &str| {
            let (_, index) = primitive.attributes.iter().find(|(s, _)| s.to_string() == name).unwrap();
            &root.accessors[index.value()]
        };
        let n = mesh.vertex_count() as u64;
        for (name, ty) in
            [("POSITION", "VEC3"), ("NORMAL", "VEC3"), ("_PATCH_UV", "VEC2"), ("_PATCH", "SCALAR")]
        {
            let a = attr(name);
            assert_eq!(a.count.0, n, "{name}");
            assert_eq!(serde_json::to_value(a.type_).unwrap(), ty);
            assert_eq!(serde_json::to_value(a.component_type).unwrap(), gj::accessor::FLOAT);
        }
        let (lo, hi) = position_bounds(&mesh.positions);
        let bound = |v: &Option<serde_json::Value>| -> Vec<f32> {
            v.as_ref().unwrap().as_array().unwrap().iter().map(|x| x.as_f64().unwrap() as f32).collect()
        };
        assert_eq!(bound(&attr("POSITION").min), lo);
        assert_eq!(bound(&attr("POSITION").max), hi);
        assert_eq!(lo, [0.0, 0.0, lo[2]]);
        assert_eq!(hi[..2], [1.0, 1.0]);
        let indices = &root.accessors[primitive.indices.unwrap().value()];
        assert_eq!(indices.count.0 as usize, mesh.indices.len());
        assert_eq!(serde_json::to_value(indices.component_type).unwrap(), gj::accessor::UNSIGNED_INT);
        // The index data is where its view says.
        let view = &root.buffer_views[indices.buffer_view.unwrap().value()];
        let start = view.byte_offset.unwrap().0 as usize;
        let read: Vec<u32> = bin[start..start + view.byte_length.0 as usize]
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(read, mesh.indices);
        let extras: serde_json::Value =
            serde_json::from_str(primitive.extras.as_ref().unwrap().get()).unwrap();
        let range = |key: &str| {
            let r = &extras["tessera"][key];
            (r["byteOffset"].as_u64().unwrap() as usize, r["byteLength"].as_u64().unwrap() as usize)
        };
        let (start, len) = range("trianglePatch");
        let patches: Vec<u32> = bin[start..start + len]
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(patches, mesh.triangle_patch);
        assert_eq!(range("cornerParams").1, 24 * mesh.triangle_count());
        assert!(json.windows(8).any(|w| w == b"\"_PATCH\""));
        assert!(!json.windows(10).any(|w| w == b"TEXCOORD_0"));
    }

    /// What the Khronos validator reports as unused objects, checked without it: every
    /// accessor, buffer view, buffer, mesh and node must be referenced, the scene must be the
    /// default one, and POSITION must carry min and max.
    #[test]
    fn glb_has_no_unused_objects() {
        for with_params in [false, true] {
            let mesh = grid(4, with_params);
            let data = bytes(|w| write_glb(&mesh, w));
            let (json, _) = glb_chunks(&data);
            let v: serde_json::Value = serde_json::from_slice(json).unwrap();
            let len = |key: &str| v[key].as_array().map_or(0, Vec::len);
            let mut accessors = vec![false; len("accessors")];
            let mut views = vec![false; len("bufferViews")];
            let mut buffers = vec![false; len("buffers")];
            let mut meshes = vec![false; len("meshes")];
            let mut nodes = vec![false; len("nodes")];
            let mark = |used: &mut Vec<bool>, index: &serde_json::Value| {
                let i = index.as_u64().expect("an index") as usize;
                assert!(i < used.len(), "index {i} out of range");
                used[i] = true;
            };
            assert_eq!(v["scene"], 0);
            for scene in v["scenes"].as_array().unwrap() {
                for n in scene["nodes"].as_array().unwrap() {
                    mark(&mut nodes, n);
                }
            }
            for node in v["nodes"].as_array().unwrap() {
                mark(&mut meshes, &node["mesh"]);
            }
            for m in v["meshes"].as_array().unwrap() {
                for p in m["primitives"].as_array().unwrap() {
                    for (name, a) in p["attributes"].as_object().unwrap() {
                        assert!(
                            ["POSITION", "NORMAL"].contains(&name.as_str()) || name.starts_with('_'),
                            "{name}: a standard semantic no material uses is unused"
                        );
                        mark(&mut accessors, a);
                    }
                    mark(&mut accessors, &p["indices"]);
                    let position = &v["accessors"][p["attributes"]["POSITION"].as_u64().unwrap() as usize];
                    assert_eq!(position["min"].as_array().map(Vec::len), Some(3));
                    assert_eq!(position["max"].as_array().map(Vec::len), Some(3));
                }
            }
            for a in v["accessors"].as_array().unwrap() {
                mark(&mut views, &a["bufferView"]);
            }
            for view in v["bufferViews"].as_array().unwrap() {
                mark(&mut buffers, &view["buffer"]);
            }
            for (what, used) in [
                ("accessor", accessors),
                ("buffer view", views),
                ("buffer", buffers),
                ("mesh", meshes),
                ("node", nodes),
            ] {
                assert!(!used.is_empty(), "no {what}");
                assert!(used.iter().all(|&u| u), "an unused {what}: {used:?}");
            }
        }
    }

    /// Files tessera wrote before this layout (TEXCOORD_0, buffer views named in extras)
    /// still read back to the same mesh.
    #[test]
    fn glb_of_the_old_layout_is_still_read() {
        let mesh = grid(3, true);
        let data = bytes(|w| write_glb(&mesh, w));
        let (json, bin) = glb_chunks(&data);
        let mut v: serde_json::Value = serde_json::from_slice(json).unwrap();
        let primitive = &mut v["meshes"][0]["primitives"][0];
        let uv = primitive["attributes"].as_object_mut().unwrap().remove("_PATCH_UV").unwrap();
        primitive["attributes"]["TEXCOORD_0"] = uv;
        let tessera = primitive["extras"]["tessera"].take();
        let views = v["bufferViews"].as_array_mut().unwrap();
        let mut extras = serde_json::Map::new();
        for (key, old) in [("trianglePatch", "trianglePatchView"), ("cornerParams", "cornerParamsView")] {
            let r = &tessera[key];
            views.push(serde_json::json!({"buffer": 0, "byteOffset": r["byteOffset"], "byteLength": r["byteLength"]}));
            extras.insert(old.into(), (views.len() - 1).into());
        }
        v["meshes"][0]["primitives"][0]["extras"] = serde_json::json!({ "tessera": extras });
        assert_eq!(parse_glb(&glb(&v.to_string(), bin), label()).unwrap(), mesh);
    }

    #[test]
    fn glb_of_an_empty_mesh_holds_only_the_asset() {
        let bytes = bytes(|w| write_glb(&Mesh::default(), w));
        let (json, bin) = glb_chunks(&bytes);
        assert!(bin.is_empty());
        let root = gj::Root::from_slice(json).unwrap();
        assert!(root.meshes.is_empty() && root.buffers.is_empty() && root.accessors.is_empty());
        assert!(root.scenes.is_empty());
    }

    #[test]
    fn glb_refuses_patch_ids_a_float_cannot_hold() {
        let mut mesh = grid(1, false);
        mesh.vertex_patch[2] = (1 << 24) + 1;
        let err = write_glb(&mesh, Vec::new()).unwrap_err();
        assert!(matches!(&err, Error::FormatLimit { reason, .. } if reason.contains("vertex 2")), "{err}");
        mesh.vertex_patch[2] = 1 << 24;
        write_glb(&mesh, Vec::new()).unwrap();
    }
}
