"""Tests of the `pic` Python module, run by ctest as `python_tests`.

Environment (set by tests/CMakeLists.txt): PYTHONPATH=build/python, PIC_DATA_DIR (data/),
PIC_CLI (build/pic, for the round trips against the C++ results), PIC_EXAMPLES_DIR,
PIC_SCAD_DATA_DIR.
"""
import copy
import json
import math
import os
import pickle
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import pic

HERE = Path(__file__).resolve().parent
DATA = Path(os.environ.get("PIC_DATA_DIR", HERE.parents[1] / "data"))
SCAD = Path(os.environ.get("PIC_SCAD_DATA_DIR", HERE.parent / "data" / "scad"))
EXAMPLES = Path(os.environ.get("PIC_EXAMPLES_DIR", HERE.parents[1] / "examples"))
CLI = os.environ.get("PIC_CLI")

needs_cli = pytest.mark.skipif(not CLI, reason="PIC_CLI (the pic command) not given")

CUBE = (-1.0, -1.0, -1.0, 3.0)  # shared root cube of the CSG operands below


def cli(*args):
    out = subprocess.run([CLI, *map(str, args)], check=True, capture_output=True, text=True)
    return out.stdout


def mesh_volume(v, f):
    """Signed volume with numpy alone (independent of pic.volume)."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


def edges_closed_manifold(f):
    """Every undirected edge on exactly two triangles, traversed once each way."""
    directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    uniq, counts = np.unique(directed, axis=0, return_counts=True)
    if (counts != 1).any():
        return False
    keys = {tuple(e) for e in uniq.tolist()}
    return all((b, a) in keys for a, b in keys)


@pytest.fixture(scope="module")
def box():
    return pic.sample(*pic.make_box((0, 0, 0), (1, 1, 1)), depth=8, cube=CUBE)


@pytest.fixture(scope="module")
def cylinder():
    # Radius 0.25 along z through the box's centre, longer than the box.
    return pic.sample(*pic.make_cylinder((0.5, 0.5, 0.5), 0.25, 1.6, segments=256), depth=8, cube=CUBE)


BOX_V = 1.0
CYL_IN_BOX = math.pi * 0.25**2 * 1.0
CYL_V = math.pi * 0.25**2 * 1.6


# --- round trips against the C++ results ------------------------------------------------------


@needs_cli
def test_sample_same_pics_and_bytes_as_cli(tmp_path):
    out = tmp_path / "fandisk.pic"
    stats = json.loads(cli("sample", DATA / "fandisk.obj", "-o", out, "--depth", 10, "--json"))
    from_path = pic.sample(DATA / "fandisk.obj", depth=10)
    v, f = pic.read_mesh(DATA / "fandisk.obj")
    from_arrays = pic.sample(v, f, depth=10)
    assert from_path.pics == stats["pics"] == from_arrays.pics
    assert from_path.stats["pics"] == stats["pics"]
    assert from_path.stats["inside"] == stats["inside"]
    expected = out.read_bytes()
    assert from_path.serialize() == expected
    assert from_arrays.serialize() == expected
    saved = tmp_path / "py.pic"
    from_arrays.save(saved)
    assert saved.read_bytes() == expected
    assert pic.load(out).serialize() == expected


@needs_cli
def test_info_matches_cli_json(tmp_path):
    out = tmp_path / "cad.pic"
    cli("sample", DATA / "cad_part.obj", "-o", out, "--depth", 8)
    expected = json.loads(cli("info", out, "--json"))
    got = pic.load(out).info()
    assert set(got) == set(expected)
    for key, value in expected.items():
        assert _approx_nested(got[key], value), key
    assert got["self_intersections"] == 0
    assert pic.load(out).info(check=False)["self_intersections"] is None


def _approx_nested(a, b):
    if isinstance(b, dict):
        return all(_approx_nested(a[k], v) for k, v in b.items())
    if isinstance(b, list):
        return all(_approx_nested(x, y) for x, y in zip(a, b))
    if isinstance(b, float):
        return a == pytest.approx(b, rel=1e-8, abs=1e-12)  # the CLI prints %.9g
    return a == b and type(a) is type(b)


@needs_cli
def test_contour_matches_cli_mesh(tmp_path):
    out = tmp_path / "cad.pic"
    cli("sample", DATA / "cad_part.obj", "-o", out, "--depth", 8)
    expected = json.loads(cli("mesh", out, "-o", tmp_path / "cad.obj", "--json", "--no-check"))
    stats = {}
    v, f = pic.load(out).contour(stats=stats)
    assert v.dtype == np.float64 and v.shape == (expected["vertices"], 3)
    assert f.dtype == np.int64 and f.shape == (expected["triangles"], 3)
    assert stats["triangles"] == expected["triangles"] and stats["fans"] == expected["fans"]
    assert mesh_volume(v, f) == pytest.approx(expected["volume"], rel=1e-9)
    assert edges_closed_manifold(f)


@needs_cli
def test_csg_same_bytes_as_cli(tmp_path, box, cylinder):
    box.save(tmp_path / "a.pic")
    cylinder.save(tmp_path / "b.pic")
    cli("csg", tmp_path / "a.pic", "subtract", tmp_path / "b.pic", "-o", tmp_path / "r.pic")
    expected = (tmp_path / "r.pic").read_bytes()
    # The CLI's operands are the loaded files: .pic vertices are quantized (docs/pic-format.md),
    # so the same Boolean on the unquantized sampled trees may differ in the last bits.
    a, b = pic.load(tmp_path / "a.pic"), pic.load(tmp_path / "b.pic")
    assert (a - b).serialize() == expected
    assert pic.csg(a, b, "subtract").serialize() == expected
    assert pic.csg(a, b, "difference", parallel=False).serialize() == expected
    c = a.copy()
    c -= b
    assert c.pics == pic.load(tmp_path / "r.pic").pics


# --- CSG ---------------------------------------------------------------------------------------


def test_operators_known_volumes(box, cylinder):
    cases = {
        "union": (box | cylinder, BOX_V + CYL_V - CYL_IN_BOX),
        "intersect": (box & cylinder, CYL_IN_BOX),
        "subtract": (box - cylinder, BOX_V - CYL_IN_BOX),
    }
    for op, (result, expected) in cases.items():
        assert isinstance(result, pic.Octree)
        assert result.stats["op"] == op and result.stats["inplace"] is False
        assert result.stats["seconds"] >= 0 and result.stats["cells_visited"] > 0
        v, f = result.contour()
        assert edges_closed_manifold(f), op
        # Depth 8 in a cube of side 3: cells of 0.012; the 256-gon's area is 0.01 % under the circle's.
        assert mesh_volume(v, f) == pytest.approx(expected, rel=2e-3), op
        assert pic.volume(v, f) == pytest.approx(mesh_volume(v, f), rel=1e-12)
    assert (box - cylinder).serialize() == pic.csg(box, cylinder, "subtract").serialize()


def test_n_ary_booleans_through_the_csg_tree(box, cylinder):
    ball = pic.sample(*pic.make_sphere((0.5, 0.5, 1.0), 0.3, segments=48), depth=8, cube=CUBE)
    # floor(n/2) children first, as pic eval balances a union
    assert pic.union([box, cylinder, ball]).serialize() == (box | (cylinder | ball)).serialize()
    assert pic.intersection([box, cylinder]).serialize() == (box & cylinder).serialize()
    assert pic.difference(box, [cylinder, ball]).serialize() == (box - (cylinder | ball)).serialize()
    v, f = pic.union([box, cylinder, ball]).contour()
    assert edges_closed_manifold(f)


def test_operands_unchanged_by_operators(box, cylinder):
    a, b = box.serialize(), cylinder.serialize()
    _ = box | cylinder, box & cylinder, box - cylinder
    assert box.serialize() == a and cylinder.serialize() == b


def test_inplace_is_the_sculpting_path(box, cylinder):
    a = box.copy()
    before = id(a)
    b_bytes = cylinder.serialize()
    a -= cylinder
    assert id(a) == before
    assert a.stats["op"] == "subtract" and a.stats["inplace"] is True
    assert cylinder.serialize() == b_bytes
    assert box.pics != a.pics  # the fixture (copied from) is untouched
    v, f = a.contour()
    assert mesh_volume(v, f) == pytest.approx(BOX_V - CYL_IN_BOX, rel=2e-3)
    assert edges_closed_manifold(f)
    # Same solid as the copying operator (node order may differ: untouched subtrees stay put).
    assert mesh_volume(*(box - cylinder).contour()) == pytest.approx(mesh_volume(v, f), rel=1e-6)
    # A sculpting stroke: a small sphere added then removed, in place.
    ball = pic.sample(*pic.make_sphere((1.0, 1.0, 1.0), 0.2), depth=8, cube=CUBE)
    a |= ball
    grown = mesh_volume(*a.contour())
    assert grown > mesh_volume(v, f) + 0.01
    pic.csg_inplace(a, ball, "subtract")
    assert mesh_volume(*a.contour()) < grown - 0.01
    c = box.copy()
    c &= cylinder
    assert mesh_volume(*c.contour()) == pytest.approx(CYL_IN_BOX, rel=2e-3)


def test_inplace_with_itself(box):
    a = box.copy()
    a -= a
    assert a.pics == 0
    b = box.copy()
    b |= b
    assert mesh_volume(*b.contour()) == pytest.approx(BOX_V, rel=1e-3)


# --- numpy inputs ------------------------------------------------------------------------------


def test_dtypes_accepted_same_result():
    v, f = pic.make_box((0, 0, 0), (1, 1, 1))
    reference = pic.sample(v, f, depth=6, cube=CUBE).serialize()
    for vd in (np.float32, np.float64):
        for fd in (np.int32, np.int64, np.uint32):
            assert pic.sample(v.astype(vd), f.astype(fd), depth=6, cube=CUBE).serialize() == reference
    # Nested lists and non-contiguous views too.
    assert pic.sample(v.tolist(), f.tolist(), depth=6, cube=CUBE).serialize() == reference
    wide = np.zeros((len(v), 6))
    wide[:, ::2] = v
    assert pic.sample(wide[:, ::2], np.asfortranarray(f), depth=6, cube=CUBE).serialize() == reference


@pytest.mark.parametrize(
    "vertices, faces, message",
    [
        (np.zeros((4, 2)), np.zeros((1, 3), int), r"vertices must be an \(n, 3\) array, got shape \(4, 2\)"),
        (np.zeros(12), np.zeros((1, 3), int), r"vertices must be an \(n, 3\) array, got shape \(12,\)"),
        (np.zeros((4, 3)), np.zeros((1, 4), int), r"faces must be an \(n, 3\) array, got shape \(1, 4\)"),
        (np.zeros((4, 3)), np.zeros((1, 3)), r"faces must be .* integers, got dtype float64"),
        (np.zeros((4, 3), complex), np.zeros((1, 3), int), r"vertices must be .* real numbers, got dtype complex128"),
        (np.zeros((4, 3)), [[0, 1, 4]], r"faces\[0\] has vertex index 4, outside 0..3"),
        (np.zeros((4, 3)), [[0, -1, 2]], r"faces\[0\] has vertex index -1"),
        (np.zeros((4, 3)), None, r"faces is missing"),
    ],
)
def test_wrong_shapes_refused(vertices, faces, message):
    with pytest.raises(ValueError, match=message):
        pic.sample(vertices, faces)


def test_point_cloud(tmp_path):
    # Points on a sphere of radius 1 with outward normals (Fibonacci lattice).
    n = 4000
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    r = np.sqrt(1 - z * z)
    phi = i * math.pi * (3 - math.sqrt(5))
    p = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1).astype(np.float32)
    t = pic.sample_points(p, p, depth=6)
    assert t.stats["inside"] == "points" and t.stats["points_in"] == n
    v, f = t.contour()
    assert mesh_volume(v, f) == pytest.approx(4 / 3 * math.pi, rel=0.05)
    # The same cloud from an .xyz file ("x y z nx ny nz" per line) gives the same octree.
    xyz = tmp_path / "sphere.xyz"
    p64 = p.astype(np.float64)
    xyz.write_text("".join(f"{a!r} {b!r} {c!r} {a!r} {b!r} {c!r}\n" for a, b, c in p64.tolist()))
    assert pic.sample(xyz, depth=6).serialize() == pic.sample_points(p64, p64, depth=6).serialize()
    # The old spelling still works, with a warning.
    with pytest.warns(DeprecationWarning, match="sample_points"):
        assert pic.sample((p64, p64), depth=6).serialize() == pic.sample_points(p64, p64, depth=6).serialize()
    with pytest.raises(ValueError, match="differ in length"):
        pic.sample_points(p, p[:-1])
    with pytest.raises(ValueError, match=r"normals must be an \(n, 3\) array"):
        pic.sample_points(p, p[:, :2])


# --- composing: meshes as one value, Booleans of meshes ----------------------------------------


def test_sample_takes_a_mesh_value():
    mesh = pic.read_mesh(DATA / "fandisk.obj")
    assert isinstance(mesh, pic.Mesh) and isinstance(mesh, tuple)
    v, f = mesh  # still unpacks
    ref = pic.sample(v, f, depth=7).serialize()
    assert pic.sample(mesh, depth=7).serialize() == ref
    assert pic.sample((v, f), depth=7).serialize() == ref

    class TrimeshLike:  # what trimesh users pass: .vertices and .faces
        vertices = v
        faces = f.astype(np.int32)

    assert pic.sample(TrimeshLike(), depth=7).serialize() == ref
    # A (vertices, faces) tuple whose counts happen to be equal is still a mesh, not a cloud.
    tet_v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    tet_f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    t = pic.sample((tet_v, tet_f), depth=6)
    assert t.stats["inside"] == "parity" and t.stats["triangles_in"] == 4
    assert mesh_volume(*t.contour()) == pytest.approx(1 / 6, rel=0.02)


def test_csg_meshes_picks_the_shared_cube():
    model = pic.read_mesh(DATA / "fandisk.obj")
    lo, hi = model.vertices.min(axis=0), model.vertices.max(axis=0)
    centre = (lo + hi) / 2
    drill = pic.make_cylinder(tuple(centre), 0.15 * (hi - lo).min(), 2 * (hi - lo).max(), axis=0)
    holed = pic.csg_meshes(model, "subtract", drill, depth=8)
    v, f = holed.contour()
    assert edges_closed_manifold(f)
    whole = mesh_volume(*pic.sample(model, depth=8).contour())
    assert 0.5 * whole < mesh_volume(v, f) < 0.99 * whole
    assert len(holed.stats["steps"]) == 1 and holed.stats["steps"][0]["op"] == "subtract"
    # Octrees and meshes mix; bad chains are refused.
    again = pic.csg_meshes(pic.sample(model, depth=8, cube=pic.bounding_cube(np.vstack([model.vertices, drill.vertices]))),
                           "subtract", drill, depth=8)
    assert again.serialize() == holed.serialize()
    with pytest.raises(ValueError, match="alternate"):
        pic.csg_meshes(model, "subtract")


@needs_cli
def test_csg_meshes_same_bytes_as_cli(tmp_path):
    a, b = DATA / "spot.obj", DATA / "suzanne.obj"
    cli("csg", a, "subtract", b, "--depth", 7, "-o", tmp_path / "r.pic")
    r = pic.csg_meshes(pic.read_mesh(a), "subtract", str(b), depth=7)
    assert r.serialize() == (tmp_path / "r.pic").read_bytes()


# --- errors ------------------------------------------------------------------------------------


def test_errors_mapped(tmp_path, box, cylinder):
    with pytest.raises(OSError, match="no such file"):
        pic.load(tmp_path / "missing.pic")
    with pytest.raises(OSError):
        pic.read_mesh(tmp_path / "missing.obj")
    (tmp_path / "junk.pic").write_bytes(b"not a pic file at all")
    with pytest.raises(OSError):
        pic.load(tmp_path / "junk.pic")
    with pytest.raises(OSError):
        pic.deserialize(box.serialize()[:40])
    with pytest.raises(OSError):
        box.save(tmp_path / "no" / "such" / "dir" / "x.pic")
    v, f = pic.make_box((0, 0, 0), (1, 1, 1))
    with pytest.raises(ValueError, match="depth must be between 1 and 20"):
        pic.sample(v, f, depth=0)
    with pytest.raises(ValueError, match="non-finite"):
        pic.sample(np.where(v == 1, np.nan, v), f)
    with pytest.raises(ValueError, match="does not fit"):
        pic.sample(v, f, cube=(0.2, 0.2, 0.2, 0.5))
    with pytest.raises(ValueError, match=r"cube must be \(x, y, z, size\)"):
        pic.sample(v, f, cube=(0, 0, 1))
    with pytest.raises(ValueError, match="not closed"):
        pic.sample(v, f[:-1], inside="parity")
    with pytest.raises(ValueError, match="inside must be"):
        pic.sample(v, f, inside="sometimes")
    with pytest.raises(ValueError, match="unknown operation 'xor'"):
        pic.csg(box, cylinder, "xor")
    with pytest.raises(ValueError):
        pic.render(box, size=(0, 10))
    with pytest.raises(ValueError, match="unknown view|view"):
        pic.render(box, view="sideways")
    with pytest.raises(TypeError):
        _ = box - 3
    with pytest.raises(ValueError, match="unsupported|unknown"):
        pic.eval_csg("frobnicate();", depth=5)


# --- serialization, copies ---------------------------------------------------------------------


def test_pickle_and_copy(box, cylinder):
    r = box - cylinder
    data = r.serialize()
    for clone in (pickle.loads(pickle.dumps(r)), copy.copy(r), copy.deepcopy(r), r.copy(), pic.deserialize(data)):
        assert isinstance(clone, pic.Octree) and clone is not r
        assert clone.serialize() == data
    c = r.copy()
    c -= box
    assert c.pics == 0 and r.serialize() == data  # copies are independent
    assert r.depth == 8 and r.cube == CUBE and r.nodes > 1
    assert "PICs" in repr(r)


# --- GIL ---------------------------------------------------------------------------------------


def test_gil_released_during_sample():
    """A second Python thread keeps ticking while sample runs (serial, so a core stays free)."""
    v, f = pic.read_mesh(DATA / "suzanne.obj")
    ticks = []
    stop = threading.Event()

    def ticker():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    thread = threading.Thread(target=ticker)
    thread.start()
    time.sleep(0.02)
    t0 = time.perf_counter()
    tree = pic.sample(v, f, depth=9, parallel=False)
    t1 = time.perf_counter()
    stop.set()
    thread.join()
    assert tree.pics > 0
    during = [t for t in ticks if t0 < t < t1]
    assert t1 - t0 > 0.1, "the sample was too short to tell"
    # Holding the GIL, the ticker could not run at all between t0 and t1 (a tick or two at the
    # edges); released, it ticks about every millisecond.
    assert len(during) >= 20, f"{len(during)} ticks in {t1 - t0:.3f} s"


# --- render, mesh I/O, OpenSCAD ------------------------------------------------------------------


def test_render(tmp_path, box):
    img = pic.render(box, size=(160, 120))
    assert img.shape == (120, 160, 3) and img.dtype == np.uint8
    assert (img[0, 0] == (250, 250, 252)).all()  # background
    assert (img != img[0, 0]).any(axis=2).sum() > 1000  # the box covers many pixels
    drawn = pic.render(box, size=(160, 120), octree=True, points=True)
    assert (drawn != img).any()
    mesh_img = pic.render(pic.make_box((0, 0, 0), (1, 1, 1)), size=(64, 64))
    assert mesh_img.shape == (64, 64, 3)
    pic.write_png(img, tmp_path / "box.png")
    assert (tmp_path / "box.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError, match="uint8"):
        pic.write_png(img.astype(np.float32), tmp_path / "bad.png")


def test_mesh_io_round_trip(tmp_path):
    v, f = pic.make_cylinder((0, 0, 0), 1.0, 2.0, segments=32)
    for ext in ("stl", "obj", "ply", "off"):
        path = tmp_path / f"c.{ext}"
        pic.write_mesh(v.astype(np.float32), f, path)
        v2, f2 = pic.read_mesh(str(path))
        assert len(v2) == len(v) and len(f2) == len(f)
        assert mesh_volume(v2, f2) == pytest.approx(mesh_volume(v, f), rel=1e-6)


def test_eval_csg_text_and_file():
    t = pic.eval_csg((SCAD / "cube_minus_cube.csg").read_text(), depth=7)
    assert t.stats["op"] == "eval" and t.stats["booleans"] == 1
    assert mesh_volume(*t.contour()) == pytest.approx(840, rel=1e-3)
    assert pic.eval_scad(SCAD / "cube_minus_cube.csg", depth=7).serialize() == t.serialize()


@pytest.mark.skipif(shutil.which("openscad") is None, reason="openscad is not installed")
def test_eval_scad(tmp_path):
    (tmp_path / "part.scad").write_text(
        "difference() { cube(10); translate([5, 5, -1]) cylinder(r = 2, h = 12, $fn = 4); }\n")
    t = pic.eval_scad(tmp_path / "part.scad", depth=7)
    assert mesh_volume(*t.contour()) == pytest.approx(1000 - 8 * 10, abs=0.5)


# --- the example -------------------------------------------------------------------------------


def test_example_subtract_cylinder(tmp_path):
    env = dict(os.environ)
    subprocess.run([sys.executable, EXAMPLES / "subtract_cylinder.py", "--depth", "8", "--out", tmp_path],
                   check=True, env=env, capture_output=True, text=True)
    png, stl = tmp_path / "fandisk_drilled.png", tmp_path / "fandisk_drilled.stl"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    v, f = pic.read_mesh(stl)
    v0, f0 = pic.read_mesh(DATA / "fandisk.obj")
    assert 0 < mesh_volume(v, f) < 0.99 * mesh_volume(v0, f0)
    assert pic.check_validity(v, f, self_intersections=False)["boundary_edges"] == 0


def test_readme_example_runs_as_written(tmp_path):
    """The README's Python block, run as it is written (data/ beside it)."""
    readme = (HERE.parents[1] / "README.md").read_text()
    code = readme.split("```python\n", 1)[1].split("```", 1)[0]
    (tmp_path / "data").mkdir()
    shutil.copy(DATA / "spot.obj", tmp_path / "data" / "spot.obj")
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, check=True, capture_output=True, text=True)
    assert out.stdout.split()[-1] == "True"
    v, f = pic.read_mesh(tmp_path / "spot_holed.obj")
    assert edges_closed_manifold(f)


# --- the type stubs ----------------------------------------------------------------------------


def test_stubs_cover_the_module():
    """Every public function and Octree member has a stub and a docstring, and no stub is stale."""
    import ast

    tree = ast.parse((Path(pic.__file__).parent / "__init__.pyi").read_text())
    funcs = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    octree = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Octree")
    members = {n.name for n in octree.body if isinstance(n, ast.FunctionDef)}
    public = {n for n in dir(pic) if not n.startswith("_") and callable(getattr(pic, n)) and n not in ("Octree", "Mesh")}
    assert funcs == public
    octree_public = {n for n in dir(pic.Octree) if not n.startswith("_")} | {
        n for n in ("__or__", "__and__", "__sub__", "__ior__", "__iand__", "__isub__") if hasattr(pic.Octree, n)}
    assert octree_public <= members
    for name in public:
        assert getattr(pic, name).__doc__, name


def _volume(tree):
    v, f = pic.contour(tree)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


def test_offset_shell_round_thicken_volumes():
    cube_mesh = pic.make_box((0, 0, 0), (1, 1, 1))
    grown = pic.offset(cube_mesh, 0.1, depth=8)
    exact = 1 + 0.6 + 0.03 * math.pi + 4 / 3 * math.pi * 0.001
    assert abs(_volume(grown) - exact) < 5e-4 * exact
    assert abs(_volume(pic.offset(grown, -0.1, depth=8)) - 1) < 5e-3  # through an Octree's contour
    assert abs(_volume(pic.shell(cube_mesh, 0.1, depth=7)) - (1 - 0.8 ** 3)) < 1e-6
    opened = pic.round(cube_mesh, 0.1, depth=7)
    assert _volume(opened) < 1 - 1e-3
    sheet = (np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float), np.array([[0, 1, 2], [0, 2, 3]]))
    slab = pic.thicken(sheet, 0.1, depth=7)
    exact = 0.1 + 4 * math.pi * 0.01 / 8 + 4 / 3 * math.pi * 0.05 ** 3
    assert abs(_volume(slab) - exact) < 0.02 * exact


def test_volume_mesh_lies_on_the_exact_offset():
    cube_mesh = pic.make_box((0, 0, 0), (1, 1, 1))
    tree, (v, f) = pic.offset(cube_mesh, 0.1, depth=7, mesh=True)
    assert isinstance(tree, pic.Octree)
    assert edges_closed_manifold(f)
    # Distance to the unit cube from outside it: every point of the mesh is at 0.1.
    d = np.linalg.norm(np.maximum(np.abs(v - 0.5) - 0.5, 0), axis=1)
    cell = tree.cube[3] / 2 ** 7
    assert np.abs(d - 0.1).max() < 0.25 * cell
    # The Octree's own contour does not know the function: its edge points are the vertices'.
    cv, _ = pic.contour(tree)
    assert np.abs(np.linalg.norm(np.maximum(np.abs(cv - 0.5) - 0.5, 0), axis=1) - 0.1).max() >= np.abs(d - 0.1).max()
    shelled = pic.shell(cube_mesh, 0.1, depth=6, mesh=True)
    assert isinstance(shelled, tuple) and edges_closed_manifold(shelled[1][1])


def test_minkowski_round_moves_faces_by_the_support():
    ball_v, _ = pic.make_sphere((0, 0, 0), 0.1, segments=64)
    cube_mesh = pic.make_box((0, 0, 0), (1, 1, 1))
    summed = pic.minkowski_round(cube_mesh, ball_v, depth=8)
    v, f = pic.contour(summed)
    assert edges_closed_manifold(f)
    # Over the middle of the top face, the vertices lie at 1 + the ball's extent along z: most
    # exactly, those of a leaf that reaches the round's first facets (a shallow crease taken
    # for one plane) within a twentieth of a cell.
    mid = (np.abs(v[:, 0] - 0.5) < 0.3) & (np.abs(v[:, 1] - 0.5) < 0.3) & (v[:, 2] > 1)
    assert mid.sum() > 0
    off = np.abs(v[mid, 2] - (1 + ball_v[:, 2].max()))
    cell = summed.cube[3] / 2 ** 8
    assert off.max() < 0.05 * cell
    assert (off < 1e-6).mean() > 0.5
    exact = 1 + 0.6 + 0.03 * math.pi + 4 / 3 * math.pi * 0.001
    assert abs(_volume(summed) - exact) < 3e-3 * exact
    with pytest.raises(ValueError):
        pic.minkowski_round(cube_mesh, cube_mesh[0], depth=6)  # a cube is not round


def test_sample_function_box_with_cavity_matches_boolean():
    def f(p):
        q = np.abs(p) - 0.6
        box = np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)
        return np.maximum(box, 0.4 - np.linalg.norm(p, axis=1))

    t = pic.sample_function(f, (-1, -1, -1, 2), depth=6)
    assert t.stats["inside"] == "implicit"
    v, faces = pic.contour(t)
    exact = 1.2 ** 3 - 4 / 3 * math.pi * 0.4 ** 3
    assert abs(_volume(t) - exact) < 0.01 * exact
    # The box's corners are vertices: the edges stay sharp.
    corners = np.array([[x, y, z] for x in (-0.6, 0.6) for y in (-0.6, 0.6) for z in (-0.6, 0.6)])
    d = np.linalg.norm(v[None, :, :] - corners[:, None, :], axis=2).min(axis=1)
    assert d.max() < 1e-6
    with pytest.raises(ValueError):
        pic.sample_function(f, None)


def test_sample_function_asks_in_batches():
    calls, points = [], 0

    def f(p):
        nonlocal points
        calls.append(len(p))
        points += len(p)
        return np.linalg.norm(p, axis=1) - 0.5

    t = pic.sample_function(f, (-1, -1, -1, 2), depth=7)
    assert t.stats["pics"] > 1000
    # Each level's points in a few batches: far fewer calls than points.
    assert max(calls) > 1000
    assert len(calls) < points / 100
    v, _ = pic.contour(t)
    assert np.abs(np.linalg.norm(v, axis=1) - 0.5).max() < 2 / 128
