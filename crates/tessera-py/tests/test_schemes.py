"""Every scheme through the Python front door: watertight on closed inputs (tessera's own
check and trimesh's), error bounds met, strips that decode to the triangle list."""

from collections import Counter

import numpy as np
import pytest

import tessera

# A closed model of each domain: bicubic patches (a torus) and triangles (PN triangles).
QUADS = "bench/torus_64x32.patches"
TRIANGLES = "meshes/blob.obj"

CASES = [
    ("uniform", QUADS, dict(factor=5)),
    ("uniform", TRIANGLES, dict(tolerance="0.5%")),
    ("transition", QUADS, dict(tolerance="0.05%")),
    ("transition", TRIANGLES, dict(pixel_error=1.0)),
    ("transition", TRIANGLES, dict(silhouette=(1, 8))),
    ("semi-uniform", QUADS, dict(pixel_error=2.0, max_level=4)),
    ("semi-uniform", TRIANGLES, dict(silhouette=(1, 16))),
    ("sd2", TRIANGLES, dict(silhouette=(1, 7), strips=True)),
    ("sd2", TRIANGLES, dict(distance=(2, 7), warp=True)),
    ("integer", QUADS, dict(factor=5.3)),
    ("pow2", TRIANGLES, dict(distance=(1, 9))),
    ("fractional-odd", QUADS, dict(factor=6.4)),
    ("fractional-even", TRIANGLES, dict(silhouette=(2, 9))),
    ("esc", QUADS, dict(quality="high", strips=True)),
    ("esc", QUADS, dict(level=2, threshold=0.01)),
]


def test_every_scheme_is_covered():
    assert {scheme for scheme, _, _ in CASES} == set(tessera.SCHEMES)


@pytest.fixture(scope="module")
def sets(data):
    return {name: tessera.load(data / name) for name in (QUADS, TRIANGLES)}


@pytest.mark.parametrize("scheme, model, options", CASES, ids=lambda c: str(c))
def test_closed_inputs_give_watertight_meshes(sets, scheme, model, options):
    s = sets[model]
    assert s.topology["is_closed"]
    mesh = tessera.tessellate(s, scheme=scheme, **options)
    report = mesh.report
    assert report["scheme"] == scheme
    assert report["problems"] == [], report["problems"]
    assert report["boundary_edges"] == 0 and report["nonmanifold_edges"] == 0
    assert report["euler_characteristic"] == s.topology["euler_characteristic"]
    assert mesh.to_trimesh().is_watertight
    if "tolerance" in options or "pixel_error" in options:
        assert report["bound_met"] is True
        if "tolerance" in options:
            assert report["guaranteed_bound"] <= report["tolerance"]
    if options.get("strips"):
        assert Counter(map(canonical, decode(mesh.strips))) == Counter(map(canonical, mesh.faces.tolist()))
    else:
        assert mesh.strips is None


def test_adaptive_uses_fewer_triangles_than_uniform_for_the_same_bound(data):
    s = tessera.load(data / "patches" / "teapot.patches")
    adaptive = tessera.tessellate(s, tolerance="0.05%", scheme="transition")
    uniform = tessera.tessellate(s, tolerance="0.05%", scheme="uniform")
    assert adaptive.report["bound_met"] and uniform.report["bound_met"]
    assert adaptive.triangle_count < uniform.triangle_count


def test_corner_params_and_culling(data, sets):
    s = sets[QUADS]
    mesh = tessera.tessellate(s, pixel_error=1.0, cull=True, corner_params=True)
    assert mesh.corner_params.shape == (mesh.triangle_count, 3, 2)
    assert mesh.corner_params.dtype == np.float32
    assert ((mesh.corner_params >= 0) & (mesh.corner_params <= 1)).all()
    culled = mesh.report["culled_patches"]
    assert 0 < culled < s.patch_count
    # A culled mesh is open by request, not a problem; it holds only the vertices it uses.
    assert mesh.report["problems"] == []
    assert len(np.unique(mesh.faces)) == mesh.vertex_count


def decode(strips):
    """Triangle strips (restart index 0xFFFFFFFF) to triangles, each keeping the first one's
    orientation; triangles with a repeated index (joints, ESC's virtual vertices) dropped."""
    out = []
    for strip in np.split(strips, np.flatnonzero(strips == 0xFFFFFFFF)):
        strip = strip[strip != 0xFFFFFFFF].tolist()
        for i in range(len(strip) - 2):
            a, b, c = strip[i : i + 3]
            t = (a, b, c) if i % 2 == 0 else (b, a, c)
            if len(set(t)) == 3:
                out.append(t)
    return out


def canonical(t):
    """A triangle's smallest rotation (orientation kept)."""
    t = tuple(t)
    k = t.index(min(t))
    return t[k:] + t[:k]


def test_the_taylor_bound_keeps_the_guarantee_with_fewer_triangles(data):
    s = tessera.load(data / "patches" / "teapot.patches")
    hessian = tessera.tessellate(s, tolerance="0.1%", corner_params=True)
    taylor = tessera.tessellate(s, tolerance="0.1%", bound="taylor", corner_params=True)
    assert hessian.report["bound_met"] and taylor.report["bound_met"]
    assert taylor.triangle_count <= 0.8 * hessian.triangle_count
    expansion = tessera.tessellate(s, tolerance="0.1%", bound="expansion")
    assert expansion.report["bound_met"]
    assert taylor.triangle_count < expansion.triangle_count < hessian.triangle_count
    with pytest.raises(tessera.ParameterError, match="bound="):
        tessera.tessellate(s, tolerance="0.1%", bound="exact")
