"""meshclash.check / meshclash.scene / meshclash.Mesh give the CLI's document for the same inputs."""

import copy

import numpy as np
import pytest

import meshclash
from conftest import MESHES, box, l_prism, run_cli, shared, write_obj

ROT = np.array(
    [[0.59, 0.20, 0.78, 1750.9], [0.48, -0.86, -0.14, 485.2], [0.65, 0.46, -0.61, 1244.6], [0, 0, 0, 1]]
)


def flat(m):
    return ",".join(repr(float(x)) for x in np.asarray(m, dtype=np.float64)[:3].ravel())


@pytest.mark.parametrize(
    "a,b,flags,kwargs",
    [
        ("fcl_env.obj", "fcl_rob.obj", [], {}),
        ("fcl_env.obj", "fcl_rob.obj", ["--transform-b", flat(ROT)], {"transform_b": ROT}),
        ("multibody.stl", "shared.STL", ["--clearance", "0.6"], {"clearance": 0.6}),
        ("shared.STL", "multibody.stl", ["--touch-tolerance", "1e-3rel", "--max-pairs", "3"],
         {"touch_tolerance": "1e-3rel", "max_pairs": 3}),
        ("pins.glb", "SimpleMeshes.gltf", ["--mode", "fast", "--penetration"], {"mode": "fast", "penetration": True}),
        ("pins.glb", "pins.glb", ["--select-a", "*", "--exclude", "node0*"], {"select_a": ["*"], "exclude": ["node0*"]}),
        ("joined_tetrahedra.obj", "joined_tetrahedra.obj", ["--first-hit"], {"first_hit": True}),
        ("pins.glb", "pins.glb", ["--detail", "parts", "--split-bodies"], {"detail": "parts", "split_bodies": True}),
    ],
)
def test_check_files_equals_cli(a, b, flags, kwargs):
    pa, pb = MESHES / a, MESHES / b
    _, want, _ = run_cli(pa, pb, "--no-timings", *flags)
    got = meshclash.check(str(pa), pb, timings=False, **kwargs)
    assert got == want


def test_check_shared_meshes_equals_cli():
    bunny = shared("stanford-bunny.obj")
    t = np.eye(4)
    t[:3, 3] = [0.01, 0.005, 0.0]
    _, want, _ = run_cli(bunny, bunny, "--no-timings", "--translate-b", "0.01,0.005,0")
    got = meshclash.check(bunny, bunny, transform_b=t, timings=False)
    assert got == want
    assert got["verdict"] == "clash" and got["summary"]["crossing_pairs"] > 0


@pytest.mark.parametrize("name", ["pins.glb", "SimpleMeshes.gltf", "multibody.stl"])
def test_scene_equals_cli(name):
    p = MESHES / name
    _, want, _ = run_cli("scene", p, "--no-timings")
    assert meshclash.scene(p, timings=False) == want


def test_scene_detail_parts_equals_cli():
    p = shared("2CylinderEngine.glb")
    _, want, _ = run_cli("scene", p, "--no-timings", "--detail", "parts")
    got = meshclash.scene(p, timings=False, detail="parts")
    assert got == want
    assert got["settings"]["detail"] == "parts" and got["pairs"] == [] and got["regions"] == []
    with pytest.raises(ValueError, match="detail must be"):
        meshclash.scene(p, detail="triangles")


def test_scene_engine_equals_cli():
    p = shared("2CylinderEngine.glb")
    _, want, _ = run_cli("scene", p, "--no-timings", "--clearance", "0.5")
    got = meshclash.scene(p, timings=False, clearance=0.5)
    assert got == want
    assert got["assembly"]["mode"] == "parts" and len(got["part_pairs"]) > 0


def as_file_doc(doc, paths):
    """The document the CLI writes for the same coordinates saved as OBJ: inputs renamed."""
    d = copy.deepcopy(doc)
    for side, p in zip("ab", paths):
        d["inputs"][side]["path"] = str(p)
        d["inputs"][side]["format"] = "obj"
    return d


CASES = {
    # name: (a arrays, b arrays, transform of b)
    "crossing boxes": (box(), box((0.5, 0.5, 0.5), (1.5, 1.5, 1.5)), None),
    "touching faces": (box(), box((1.0, 0.0, 0.0), (2.0, 1.0, 1.0)), None),
    "1 ulp apart": (box(), box((np.nextafter(1.0, 2.0), 0.2, 0.2), (2.0, 0.8, 0.8)), None),
    "contained": (box((-2, -2, -2), (3, 3, 3)), box(), None),
    "separated L prisms": (l_prism(), l_prism(), np.array([[0, -1, 0, 4.25], [1, 0, 0, 0.5], [0, 0, 1, 0.3], [0, 0, 0, 1]])),
}


@pytest.mark.parametrize("case", sorted(CASES))
@pytest.mark.parametrize("dtypes", [(np.float64, np.int64), (np.float32, np.int32), (np.float64, np.uint32)])
def test_check_arrays_equals_cli(tmp_path, case, dtypes):
    (va, fa), (vb, fb), t = CASES[case]
    fd, idt = dtypes
    va, vb = np.asarray(va, dtype=fd), np.asarray(vb, dtype=fd)
    fa, fb = fa.astype(idt), fb.astype(idt)
    pa = write_obj(tmp_path / "a.obj", va, fa, "a")
    pb = write_obj(tmp_path / "b.obj", vb, fb, "b")
    flags = ["--clearance", "0.3"] + (["--transform-b", flat(t)] if t is not None else [])
    _, want, _ = run_cli(pa, pb, "--no-timings", *flags)
    got = meshclash.check((va, fa), (vb, fb), transform_b=t, clearance=0.3, timings=False)
    assert got["inputs"]["a"]["format"] == "array" and got["inputs"]["a"]["path"] == "<array a>"
    assert as_file_doc(got, (pa, pb)) == want


def test_verdicts_of_generated_cases():
    v = {k: meshclash.check(a, b, transform_b=t)["verdict"] for k, (a, b, t) in CASES.items()}
    assert v == {
        "crossing boxes": "clash",
        "touching faces": "touching",
        "1 ulp apart": "clear",
        "contained": "clash",
        "separated L prisms": "clear",
    }
    r = meshclash.check(*[CASES["contained"][i] for i in (0, 1)])
    assert r["summary"]["contained"] == "b_in_a" and r["summary"]["crossing_pairs"] == 0


def strip_trees(doc):
    d = copy.deepcopy(doc)
    d.pop("bvh")
    for side in "ab":
        d["inputs"][side].pop("path")
        d["inputs"][side].pop("format")
    return d


@pytest.mark.parametrize("case", sorted(CASES))
def test_prepared_mesh_check_equals_fresh_check(tmp_path, case):
    """A Mesh (tree built once, placed by a transform) finds what a fresh check of the placed
    coordinates finds; only the bvh block (the prepared tree) and the input names differ."""
    (va, fa), (vb, fb), t = CASES[case]
    ma, mb = meshclash.Mesh(va, fa, "a"), meshclash.Mesh(vb, fb, "b")
    pa = write_obj(tmp_path / "a.obj", va, fa, "a")
    pb = write_obj(tmp_path / "b.obj", vb, fb, "b")
    for extra in ([], [np.array([[0, 0, 1, 0.1], [0, 1, 0, -0.2], [-1, 0, 0, 0.05], [0, 0, 0, 1]])]):
        tb = t if not extra else (extra[0] if t is None else extra[0] @ t)
        flags = ["--transform-b", flat(tb)] if tb is not None else []
        _, want, _ = run_cli(pa, pb, "--no-timings", "--clearance", "0.3", *flags)
        got = meshclash.check(ma, mb, transform_b=tb, clearance=0.3, timings=False)
        assert strip_trees(got) == strip_trees(want)
        # The same Mesh in the other role, and a Mesh against arrays.
        got2 = meshclash.check((va, fa), mb, transform_b=tb, clearance=0.3, timings=False)
        assert strip_trees(got2) == strip_trees(want)


def test_mesh_collides_and_distance():
    a = meshclash.Mesh(*box(), name="a")
    moved = lambda x: np.array([[1, 0, 0, x], [0, 1, 0, 0.25], [0, 0, 1, 0.25], [0, 0, 0, 1]], dtype=np.float64)
    assert a.collides(a, other_transform=moved(0.5))
    assert a.collides(a, other_transform=moved(1.0))  # touching counts
    assert not a.collides(a, other_transform=moved(np.nextafter(1.0, 2.0)))
    d, pa, pb, fa, fb = a.distance(a, other_transform=moved(1.5))
    assert d == 0.5 and pa[0] == 1.0 and pb[0] == 1.5
    assert a.distance(a, other_transform=moved(1.0))[0] == 0.0
    big = meshclash.Mesh(*box((-2, -2, -2), (3, 3, 3)), name="big")
    assert big.collides(a)  # containment
    assert big.distance(a)[0] == 2.0
    assert (a.vertex_count, a.face_count, a.name) == (8, 12, "a")
    assert a.bounds.tolist() == [[0, 0, 0], [1, 1, 1]]


def test_trimesh_like_input_and_paths():
    class Like:
        vertices, faces = box()

    r = meshclash.check(Like(), box((0.5, 0.5, 0.5), (2, 2, 2)))
    assert r["verdict"] == "clash"
    assert r["schema"] == "meshclash.report/2"


def test_threads_do_not_change_the_document():
    p = MESHES / "fcl_env.obj", MESHES / "fcl_rob.obj"
    one = meshclash.check(*p, threads=1, timings=False)
    two = meshclash.check(*p, threads=2, timings=False)
    assert one == two
    timed = meshclash.check(*p, threads=2)
    assert timed["settings"]["threads"] == 2 and timed["timings_ms"]["total"] >= 0
