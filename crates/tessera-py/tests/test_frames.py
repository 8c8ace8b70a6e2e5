"""Per-frame use: a Tessellator re-tessellating a camera walk, the GIL released while it
works, cameras, checks and domain patterns."""

import math
import threading
import time

import numpy as np
import pytest

import tessera


def orbit(s: tessera.SurfaceSet, frames: int):
    """Cameras on a circle around the set's centre, looking at it."""
    (lo, hi) = s.bounds
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    radius = 1.6 * s.diagonal
    for k in range(frames):
        angle = 2 * math.pi * k / frames
        eye = (centre[0] + radius * math.cos(angle), centre[1] + radius * math.sin(angle), centre[2] + 0.3 * radius)
        yield tessera.Camera(eye=eye, target=tuple(centre), up=(0, 0, 1), fov=40, size=(800, 600))


def test_a_camera_walk(data):
    s = tessera.load(data / "patches" / "teapot.patches")
    tess = tessera.Tessellator(s, pixel_error=1.0, cull=True)
    assert tess.scheme == "transition"
    counts, culled = [], []
    for camera in orbit(s, 8):
        mesh = tess.frame(camera)
        report = mesh.report
        assert report["bound_met"] and report["problems"] == []
        assert report["culled_patches"] < s.patch_count
        counts.append(mesh.triangle_count)
        culled.append(report["culled_patches"])
        # Each frame owns its arrays: an earlier frame is not overwritten by a later one.
        assert mesh.vertices.base is not None
    assert len(set(counts)) > 1, "the view changed, so should the tessellation"
    assert max(culled) > 0, "some patches face away from some of the cameras"
    first = tess.frame(next(orbit(s, 8)))
    assert first.triangle_count == counts[0]


def test_the_default_camera_is_the_command_lines(data, cli):
    s = tessera.load(data / "meshes" / "cow.obj")
    framing = tessera.Camera.framing(s)
    assert framing.size == (1280, 720) and framing.fov == 45.0
    assert framing.up == [0.0, 1.0, 0.0]  # OBJ: +Y up
    a = tessera.tessellate(s, pixel_error=0.5)
    b = tessera.tessellate(s, pixel_error=0.5, camera=framing)
    assert a.triangle_count == b.triangle_count
    parsed = tessera.Camera.parse("eye=0,-2,0.5,target=0,0,0,fov=40,size=1920x1080", s)
    assert parsed.eye == [0.0, -2.0, 0.5] and parsed.size == (1920, 1080)
    with pytest.raises(tessera.ParameterError):
        tessera.Camera.parse("eye=1,2", s)


# Run in a process of its own with one rayon thread, so that the tessellation leaves a core
# to this script's main thread: it then ticks every millisecond unless the GIL stops it.
GIL_PROBE = """
import json, sys, threading, time
import tessera
s = tessera.load(sys.argv[1])
window = {}
def work():
    window["start"] = time.perf_counter()
    tessera.tessellate(s, factor=40)
    window["end"] = time.perf_counter()
ticks = []
worker = threading.Thread(target=work)
worker.start()
while worker.is_alive():
    ticks.append(time.perf_counter())
    time.sleep(0.001)
worker.join()
start, end = window["start"], window["end"]
moments = [start] + [t for t in ticks if start < t < end] + [end]
print(json.dumps({"frame": end - start, "longest": max(b - a for a, b in zip(moments, moments[1:]))}))
"""


def test_the_gil_is_released_while_tessellating(data):
    import json
    import os
    import subprocess
    import sys

    env = dict(os.environ, RAYON_NUM_THREADS="1")
    out = subprocess.run(
        [sys.executable, "-c", GIL_PROBE, str(data / "bench" / "torus_64x32.patches")],
        capture_output=True, text=True, env=env,
    )
    assert out.returncode == 0, out.stderr
    probe = json.loads(out.stdout)
    assert probe["frame"] > 0.05, f"the frame ({probe['frame']:.3f} s) is too short to tell"
    # The longest stretch of the call during which the main thread could not run: with the
    # GIL held through the native frame it is the whole frame; released, a sleep and a switch.
    assert probe["longest"] < 0.25 * probe["frame"], f"the main thread stood still {probe['longest']:.3f} s of {probe['frame']:.3f} s"


def test_check_of_arrays_and_meshes(data):
    s = tessera.load(data / "meshes" / "blob.obj")
    mesh = tessera.tessellate(s, factor=3)
    report = tessera.check(mesh)
    assert report["is_closed"] and report["boundary_edges"] == 0 and report["problems"] == []
    assert 0 < report["min_angle"] <= 60 and sum(report["min_angle_histogram"]) == mesh.triangle_count
    # Dropping triangles opens the mesh, and the check says so against the input.
    opened = tessera.check((mesh.vertices, mesh.faces[10:]), set=s)
    assert opened["boundary_edges"] > 0
    assert any("closed but the mesh has" in p for p in opened["problems"])
    # Arrays of other dtypes are converted.
    again = tessera.check((mesh.vertices.astype(np.float64), mesh.faces.astype(np.int64)))
    assert again["edges"] == report["edges"]


def test_domain_patterns():
    p = tessera.pattern("transition", "quad", [5, 4, 7, 3])
    assert p.points.shape[1] == 2 and p.triangles.shape[1] == 3
    assert p.regions.shape == (len(p.triangles),) and p.region_kind == "boundary band"
    # Counter-clockwise triangles that cover the unit square once.
    a, b, c = (p.points[p.triangles[:, k]] for k in range(3))
    area = ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])) / 2
    assert (area > 0).all() and abs(area.sum() - 1.0) < 1e-12
    tri = tessera.pattern("fractional-odd", "tri", [3.5, 9.1, 2.4])
    assert tri.region_kind == "ring" and tri.inside_factors == (9.1,)
    esc = tessera.pattern("esc", "quad", level=2, mask="1")
    assert esc.region_kind == "strip"
    with pytest.raises(tessera.ParameterError, match="one factor"):
        tessera.pattern("uniform", "quad", [4, 4, 5, 4])
    with pytest.raises(tessera.ParameterError, match="triangles"):
        tessera.pattern("sd2", "quad", [3, 4, 4, 4])
