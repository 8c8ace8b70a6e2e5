"""Every input format loads, tessellates, and gives numpy arrays of the documented shapes and
types; outputs written by Python read back."""

import base64
import json

import numpy as np
import pytest

import tessera

# A flat cubic Bézier triangle (the README's .bezt example).
BEZT = "1\n1,2,3,4,5,6,7,8,9,10\n10\n" + "".join(
    f"{x},{y},0\n" for x, y in [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2), (3, 0), (2, 1), (1, 2), (0, 3)]
)


def assert_mesh_arrays(mesh: tessera.Mesh):
    n, m = mesh.vertex_count, mesh.triangle_count
    assert n > 0 and m > 0
    for name, array, shape, dtype in [
        ("vertices", mesh.vertices, (n, 3), np.float32),
        ("normals", mesh.normals, (n, 3), np.float32),
        ("uvs", mesh.uvs, (n, 2), np.float32),
        ("patch_ids", mesh.patch_ids, (n,), np.uint32),
        ("faces", mesh.faces, (m, 3), np.uint32),
        ("face_patch_ids", mesh.face_patch_ids, (m,), np.uint32),
    ]:
        assert array.shape == shape, name
        assert array.dtype == dtype, name
        assert array.flags.c_contiguous, name
        # Zero copy: the array's memory is the engine's buffer, owned by an object of the
        # extension module, not by numpy.
        base = array
        while isinstance(base, np.ndarray):
            assert not base.flags.owndata, f"{name}: numpy owns a copy"
            base = base.base
        assert base is not None and not isinstance(base, np.ndarray), name
    assert int(mesh.faces.max()) < n
    assert np.isfinite(mesh.vertices).all()
    lengths = np.linalg.norm(mesh.normals, axis=1)
    assert np.allclose(lengths, 1.0, atol=1e-4)
    assert int(mesh.patch_ids.max()) < mesh.set.patch_count
    assert int(mesh.face_patch_ids.max()) < mesh.set.patch_count
    report = mesh.report
    assert report["vertices"] == n and report["triangles"] == m
    assert report["patches"] == mesh.set.patch_count


@pytest.mark.parametrize(
    "relative, patches",
    [("patches/teapot.patches", 32), ("patches/teacup.patches", 26), ("meshes/spot.obj", None), ("subdivision/catmark_cube.obj", 6)],
)
def test_files_of_the_shared_data(data, relative, patches):
    s = tessera.load(data / relative)
    if patches is not None:
        assert s.patch_count == patches
    mesh = tessera.tessellate(s, factor=4)
    assert_mesh_arrays(mesh)
    assert s.is_subdivision_cage == relative.startswith("subdivision/")


def test_bezier_triangles(tmp_path):
    path = tmp_path / "flat.bezt"
    path.write_text(BEZT)
    s = tessera.load(path)
    assert s.patch_count == 1
    mesh = tessera.tessellate(s, factor=8)
    assert_mesh_arrays(mesh)
    assert mesh.triangle_count == 64 and mesh.vertex_count == 45
    assert np.allclose(mesh.vertices[:, 2], 0.0)


@pytest.mark.parametrize("extension", ["ply", "stl", "glb", "obj"])
def test_written_meshes_read_back_as_pn_triangles(data, tmp_path, extension):
    spot = tessera.tessellate(tessera.load(data / "meshes" / "spot.obj"), factor=1)
    out = tmp_path / f"spot.{extension}"
    spot.write(out)
    again = tessera.load(out)
    # Factor 1 keeps the input's triangles: the written mesh is the input mesh again.
    assert again.patch_count == spot.triangle_count
    mesh = tessera.tessellate(again, factor=2)
    assert_mesh_arrays(mesh)
    assert mesh.triangle_count == 4 * spot.triangle_count


def test_gltf_with_an_embedded_buffer(tmp_path):
    # A tetrahedron as a .gltf whose buffer is a data: URI.
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
    indices = np.array([0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3], dtype=np.uint16)
    blob = positions.tobytes() + indices.tobytes()
    gltf = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 24},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"},
        ],
    }
    path = tmp_path / "tet.gltf"
    path.write_text(json.dumps(gltf))
    s = tessera.load(path)
    assert s.patch_count == 4
    assert s.up == "y"
    mesh = tessera.tessellate(s, factor=3)
    assert_mesh_arrays(mesh)
    assert mesh.report["boundary_edges"] == 0 and mesh.report["problems"] == []


def test_surface_kinds(data):
    cube = data / "subdivision" / "catmark_cube.obj"
    cc = tessera.load(cube)  # auto: a quad cage is Catmull-Clark
    pn = tessera.load(cube, surface="pn")
    assert cc.is_subdivision_cage and not pn.is_subdivision_cage
    assert pn.patch_count == 12  # the six quads as two PN triangles each
    assert sorted(set(cc.patch_faces)) == list(range(6))
    with pytest.raises(tessera.ParameterError, match="surface"):
        tessera.load(cube, surface="bezier")
    with pytest.raises(tessera.UnsupportedInputError, match="catmark_cube.obj"):
        tessera.load(cube, surface="loop")  # Loop subdivides triangles only
    tri = tessera.load(data / "subdivision" / "loop_cube.obj", surface="loop")
    assert tri.is_subdivision_cage and tri.patch_count == 24
    assert sorted(set(tri.patch_faces)) == list(range(24))
