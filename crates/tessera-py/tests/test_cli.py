"""The Python mesh is the command line's: the same `.ply` byte for byte (positions, normals,
parameters, patch ids, triangles and corner parameters), the same `--stats` counts, report
and repairs; trimesh finds it watertight where the input is closed."""

import json

import pytest

import tessera

# (model, CLI flags, Python keyword arguments): every patch model, three meshes, a cage.
CASES = [
    ("patches/teapot.patches", ["--factor", "6"], dict(factor=6)),
    ("patches/teapot.patches", ["--tolerance", "0.1%"], dict(tolerance="0.1%")),
    ("patches/teacup.patches", ["--pixel-error", "0.5", "--scheme", "semi-uniform"], dict(pixel_error=0.5, scheme="semi-uniform")),
    ("patches/teapot_teasetorig.patches", ["--scheme", "fractional-odd", "--factor", "6.4"], dict(scheme="fractional-odd", factor=6.4)),
    ("meshes/spot.obj", ["--tolerance", "0.05%"], dict(tolerance="0.05%")),
    ("meshes/cow.obj", ["--scheme", "sd2", "--silhouette", "1:7"], dict(scheme="sd2", silhouette=(1, 7))),
    (
        "meshes/bunny_closed.obj",
        ["--pixel-error", "1", "--cull", "--camera", "eye=0.3,0.2,0.4,target=0,0.1,0,fov=40,size=800x600"],
        dict(pixel_error=1.0, cull=True, camera_spec="eye=0.3,0.2,0.4,target=0,0.1,0,fov=40,size=800x600"),
    ),
    ("subdivision/catmark_torus_creases0.obj", ["--pixel-error", "0.5"], dict(pixel_error=0.5)),
]

# Figures that are times or the CLI's own: everything else must be equal.
NOT_COMPARED = {"seconds", "mtri_per_s", "stages", "repeat", "input", "scheme", "threads"}


@pytest.mark.parametrize("model, flags, options", CASES, ids=lambda c: str(c))
def test_python_mesh_equals_the_command_line(data, cli, tmp_path, model, flags, options):
    path = data / model
    cli_ply = tmp_path / "cli.ply"
    out = cli("mesh", path, "-o", cli_ply, "--stats", *flags)
    stats = json.loads(out.stdout)

    s = tessera.load(path)
    options = dict(options)
    spec = options.pop("camera_spec", None)
    camera = tessera.Camera.parse(spec, s) if spec else None
    # The command line writes a .ply with the corners' patch parameters.
    mesh = tessera.tessellate(s, camera=camera, corner_params=True, **options)
    py_ply = tmp_path / "python.ply"
    mesh.write(py_ply)

    assert mesh.triangle_count == stats["triangles"] and mesh.vertex_count == stats["vertices"]
    assert py_ply.read_bytes() == cli_ply.read_bytes(), "the .ply files differ"
    report = mesh.report
    for key, value in stats.items():
        if key not in NOT_COMPARED:
            assert report[key] == value, key
    assert report["scheme"] == stats["scheme"].split(",")[0]
    if s.topology["is_closed"] and report["culled_patches"] == 0:
        assert mesh.to_trimesh().is_watertight, "trimesh: a closed input gave an open mesh"


def test_measured_error_equals_the_command_lines(data, cli):
    path = data / "patches" / "teacup.patches"
    stats = json.loads(cli("mesh", path, "--tolerance", "0.2%", "--measure-error", "--stats").stdout)
    mesh = tessera.tessellate(tessera.load(path), tolerance="0.2%", corner_params=True)
    measured = mesh.measure_error()
    assert measured["max"] == stats["max_error"] and measured["rms"] == stats["rms_error"]
    assert 0 < measured["max"] <= stats["guaranteed_bound"]
    with pytest.raises(tessera.ParameterError, match="corner_params"):
        tessera.tessellate(tessera.load(path), factor=2).measure_error()
