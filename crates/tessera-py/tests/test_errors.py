"""Bad input raises a tessera.Error subclass that names the file (and the line); nothing a
fuzzer found, and no garbage, takes the interpreter down or escapes as a panic."""

import random
from pathlib import Path

import numpy as np
import pytest

import tessera

REGRESSIONS = Path(__file__).resolve().parents[3] / "fuzz" / "regressions"
EXTENSIONS = ["patches", "bezt", "obj", "ply", "stl", "glb", "gltf"]


def test_exception_classes_are_the_builtin_kinds():
    assert issubclass(tessera.ParseError, tessera.Error) and issubclass(tessera.ParseError, ValueError)
    assert issubclass(tessera.FileError, OSError)
    assert issubclass(tessera.OutputTooLargeError, MemoryError)
    assert issubclass(tessera.ParameterError, ValueError)


def test_a_malformed_patch_file_names_its_line(tmp_path):
    path = tmp_path / "bad.patches"
    path.write_text("1\n1,2,3\n")
    with pytest.raises(tessera.ParseError) as e:
        tessera.load(path)
    assert e.value.file == str(path) and e.value.line == 2
    assert str(e.value).startswith(f"{path}:2: ")


def test_a_two_corner_face_names_its_line(tmp_path):
    path = tmp_path / "cube.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n")
    with pytest.raises(tessera.ParseError, match=r"cube.obj:5: .*2 corners") as e:
        tessera.load(path)
    assert e.value.line == 5


def test_bad_cage_tags_name_their_line(data, tmp_path):
    cage = (data / "subdivision" / "catmark_cube.obj").read_text()
    path = tmp_path / "nan_crease.obj"
    path.write_text(cage + "t crease 2/1/0 1 2 nan\n")
    with pytest.raises(tessera.Error) as e:
        tessera.load(path)
    assert e.value.file == str(path) and e.value.line == cage.count("\n") + 1
    assert isinstance(e.value, ValueError)


def test_missing_files_and_unknown_formats(tmp_path):
    with pytest.raises(tessera.FileError, match="nowhere.obj") as e:
        tessera.load(tmp_path / "nowhere.obj")
    assert isinstance(e.value, OSError)
    weird = tmp_path / "model.xyz"
    weird.write_text("1 2 3\n")
    with pytest.raises(tessera.UnsupportedInputError, match=r"model\.xyz"):
        tessera.load(weird)


def test_non_manifold_cages_are_refused_naming_the_file(data):
    path = data / "subdivision" / "catmark_fan.obj"
    with pytest.raises(tessera.UnsupportedInputError, match="catmark_fan.obj"):
        tessera.load(path)


@pytest.mark.parametrize(
    "options, needle",
    [
        (dict(factor=4, tolerance="1%"), "one criterion"),
        (dict(scheme="bogus"), "scheme"),
        (dict(tolerance="abc"), "tolerance"),
        (dict(tolerance=-1.0), "positive"),
        (dict(scheme="integer", tolerance="1%"), "integer"),
        (dict(scheme="sd2", factor=3), "teapot.patches"),
        (dict(factor=0), "factor"),
        (dict(warp=True), "sd2"),
        (dict(mapping="cubic", distance=(1, 4)), "mapping"),
    ],
)
def test_refused_requests(data, options, needle):
    s = tessera.load(data / "patches" / "teapot.patches")
    with pytest.raises(tessera.ParameterError, match=needle):
        tessera.tessellate(s, **options)


def test_outputs_past_the_limit_are_refused_before_allocation(data):
    s = tessera.load(data / "patches" / "teapot.patches")
    with pytest.raises(tessera.OutputTooLargeError) as e:
        tessera.tessellate(s, factor=64, max_triangles=1000)
    assert e.value.triangles > 1000 and e.value.vertices > 0 and e.value.bytes > 0
    with pytest.raises(tessera.ParameterError):
        tessera.Camera(eye=(0, 0, 0), target=(0, 0, 0))


def test_check_refuses_bad_arrays():
    vertices = np.zeros((3, 3), dtype=np.float32)
    with pytest.raises(tessera.ParameterError, match="out of range"):
        tessera.check((vertices, np.array([[0, 1, 7]], dtype=np.uint32)))
    with pytest.raises(tessera.ParameterError, match="shape"):
        tessera.check((np.zeros((3, 2), dtype=np.float32), np.array([[0, 1, 2]], dtype=np.uint32)))


def survive(path: Path):
    """Loads and tessellates `path`: either works or raises a tessera.Error (a Rust panic
    would surface as pyo3's PanicException, a BaseException, and fail the test)."""
    try:
        s = tessera.load(path)
    except tessera.Error:
        return "refused"
    try:
        tessera.tessellate(s, factor=2).report
    except tessera.Error:
        return "refused"
    return "tessellated"


def fuzz_inputs():
    """Every saved fuzz finding, under its own extension and, for the engine's byte inputs,
    under every extension."""
    for target in ["obj", "patches"]:
        for f in sorted((REGRESSIONS / target).iterdir()):
            yield f.read_bytes(), [target]
    for f in sorted((REGRESSIONS / "engine").iterdir()):
        yield f.read_bytes(), EXTENSIONS


def test_fuzz_regressions_never_crash(tmp_path):
    seen = 0
    for k, (content, extensions) in enumerate(fuzz_inputs()):
        for extension in extensions:
            path = tmp_path / f"case{k}.{extension}"
            path.write_bytes(content)
            assert survive(path) in ("refused", "tessellated")
            seen += 1
    assert seen >= 6


def test_garbage_of_every_format_is_refused_or_read(data, tmp_path):
    rng = random.Random(1234)
    sources = [
        (data / "patches" / "teacup.patches").read_bytes(),
        (data / "subdivision" / "catmark_cube.obj").read_bytes(),
        (data / "meshes" / "blob.obj").read_bytes()[:4000],
    ]
    outcomes = set()
    for k in range(60):
        base = bytearray(rng.choice(sources))
        for _ in range(rng.randint(1, 8)):
            i = rng.randrange(len(base))
            base[i] = rng.choice(b"0123456789-.,/ \nfvtxe" + bytes([rng.randrange(256)]))
        if rng.random() < 0.3:
            del base[rng.randrange(len(base)) :]
        path = tmp_path / f"garbage{k}.{rng.choice(EXTENSIONS)}"
        path.write_bytes(bytes(base))
        outcomes.add(survive(path))
    assert "refused" in outcomes
