"""meshclash.check / meshclash.scene take the command line's units, scale, fail-on, baseline,
self-check and cache flags with its meaning: the same inputs and flags give the CLI's JSON,
byte for byte (the native call's text) and as a document (the public call's dict)."""

import json
import subprocess

import pytest

import meshclash
from meshclash import _meshclash
from conftest import MESHES, cli_binary, run_cli


def cli_text(*args, expect=(0, 1)):
    """The CLI's stdout text and exit code."""
    p = subprocess.run([str(cli_binary()), *map(str, args)], capture_output=True, text=True)
    assert p.returncode in expect, (p.returncode, p.stderr)
    return p.stdout, p.returncode


def same_text(native, cli):
    """The native call's JSON text is the CLI's stdout (which ends its document with a newline)."""
    assert native.rstrip("\n") == cli.rstrip("\n")


CHECK_CASES = [
    # (a, b, CLI flags, keywords)
    ("fcl_env.obj", "fcl_rob.obj", ["--units", "mm"], {"units": "mm"}),
    ("fcl_env.obj", "fcl_rob.obj", ["--units", "cm", "--units-a", "mm", "--units-b", "in"],
     {"units": "cm", "units_a": "mm", "units_b": "in"}),
    ("multibody.stl", "shared.STL", ["--units-b", "m", "--scale-a", "2.5", "--clearance", "0.6"],
     {"units_b": "m", "scale_a": 2.5, "clearance": 0.6}),
    ("pins.glb", "SimpleMeshes.gltf", ["--units", "mm", "--scale-b", "1000"], {"units": "mm", "scale_b": 1000.0}),
    ("shared.STL", "multibody.stl", ["--fail-on", "touching"], {"fail_on": "touching"}),
    ("shared.STL", "multibody.stl", ["--fail-on", "never"], {"fail_on": "never"}),
    ("multibody.stl", "shared.STL", ["--fail-on", "clearance", "--clearance", "2"],
     {"fail_on": "clearance", "clearance": 2.0}),
]


@pytest.mark.parametrize("a,b,flags,kwargs", CHECK_CASES)
def test_check_flags_equal_cli(a, b, flags, kwargs):
    pa, pb = MESHES / a, MESHES / b
    text, code = cli_text(pa, pb, "--no-timings", *flags)
    native = _meshclash.check_json(str(pa), str(pb), timings=False, **kwargs)
    same_text(native, text)
    got = meshclash.check(pa, pb, timings=False, **kwargs)
    assert got == json.loads(text)
    # The gate's answer is in the document: exit 1 exactly when it says the run fails.
    assert code == (1 if got["failed"] else 0)


SCENE_CASES = [
    ("pins.glb", ["--units", "mm"], {"units": "mm"}),
    ("multibody.stl", ["--units-a", "in", "--scale-a", "3"], {"file_units": "in", "scale": 3.0}),
    ("multibody.stl", ["--units", "mm", "--units-a", "cm"], {"units": "mm", "file_units": "cm"}),
    ("pins.glb", ["--self"], {"self_check": True}),
    ("multibody.stl", ["--self", "--self-fail-on", "open,degenerate"],
     {"self_check": True, "self_fail_on": ["open", "degenerate"]}),
    ("SimpleMeshes.gltf", ["--self", "--fail-on", "touching"], {"self_check": True, "fail_on": "touching"}),
    ("pins.glb", ["--fail-on", "never"], {"fail_on": "never"}),
]


@pytest.mark.parametrize("name,flags,kwargs", SCENE_CASES)
def test_scene_flags_equal_cli(name, flags, kwargs):
    p = MESHES / name
    text, code = cli_text("scene", p, "--no-timings", *flags)
    native = _meshclash.scene_json(str(p), timings=False, **{k: v for k, v in kwargs.items()})
    same_text(native, text)
    got = meshclash.scene(p, timings=False, **kwargs)
    assert got == json.loads(text)
    assert code == (1 if got["failed"] else 0)


def test_baseline_and_fail_on_new_equal_cli(tmp_path):
    a, b = MESHES / "shared.STL", MESHES / "multibody.stl"
    # A baseline of a different placement, so that some findings are new and some resolved.
    base = tmp_path / "base.json"
    text, _ = cli_text(a, b, "--no-timings", "--translate-b", "0.5,0,0")
    base.write_text(text)
    for flags, kwargs in [
        (["--baseline", base], {"baseline": base}),
        (["--baseline", base, "--fail-on", "new"], {"baseline": base, "fail_on": "new"}),
    ]:
        text, code = cli_text(a, b, "--no-timings", *flags)
        native = _meshclash.check_json(str(a), str(b), timings=False, **{k: str(v) if k == "baseline" else v
                                                                         for k, v in kwargs.items()})
        same_text(native, text)
        got = meshclash.check(a, b, timings=False, **kwargs)
        assert got == json.loads(text)
        assert "baseline" in got
        assert code == (1 if got["failed"] else 0)
    # The scene of a file against its own earlier report: nothing new, nothing resolved.
    scene = MESHES / "pins.glb"
    base2 = tmp_path / "scene.json"
    text, _ = cli_text("scene", scene, "--no-timings")
    base2.write_text(text)
    text, _ = cli_text("scene", scene, "--no-timings", "--baseline", base2, "--fail-on", "new")
    assert meshclash.scene(scene, timings=False, baseline=base2, fail_on="new") == json.loads(text)


def test_cache_equals_cli(tmp_path):
    a, b = MESHES / "fcl_env.obj", MESHES / "fcl_rob.obj"
    # The CLI stores the outcome; the package then hits the CLI's entry, as a second CLI run does.
    cache = tmp_path / "cache"
    cli_text(a, b, "--no-timings", "--cache", cache)
    hit = meshclash.check(a, b, timings=False, cache=cache)
    again, _ = cli_text(a, b, "--no-timings", "--cache", cache)
    assert hit == json.loads(again)
    assert "cache" in hit
    # The package stores (a miss, with a size bound and units); the CLI hits the package's entry.
    other = tmp_path / "other"
    kw = {"cache": other, "cache_max_bytes": 1 << 30, "units": "mm"}
    miss = meshclash.check(a, b, timings=False, **kw)
    text, _ = cli_text(a, b, "--no-timings", "--cache", other, "--cache-max-bytes", 1 << 30, "--units", "mm")
    assert json.loads(text) == meshclash.check(a, b, timings=False, **kw)
    plain, _ = cli_text(a, b, "--no-timings", "--units", "mm")
    assert {k: v for k, v in miss.items() if k != "cache"} == json.loads(plain)


def test_bad_flags_are_value_errors_as_the_cli_refuses_them(tmp_path):
    a, b = MESHES / "fcl_env.obj", MESHES / "fcl_rob.obj"
    with pytest.raises(ValueError, match="units must be one of"):
        meshclash.check(a, b, units="furlong")
    with pytest.raises(ValueError, match="scale-a must be a finite number > 0"):
        meshclash.check(a, b, scale_a=0.0)
    with pytest.raises(ValueError, match="fail_on must be"):
        meshclash.check(a, b, fail_on="sometimes")
    # The pipeline's own refusals, worded as the CLI's (exit 2 there).
    _, _, err = run_cli(a, b, "--fail-on", "new", expect=(2,))
    with pytest.raises(ValueError) as e:
        meshclash.check(a, b, fail_on="new")
    assert err.strip().splitlines()[-1] == f"meshclash: error: {e.value}"
    with pytest.raises(ValueError, match="self_fail_on needs self_check"):
        meshclash.scene(MESHES / "pins.glb", self_fail_on=["open"])
    with pytest.raises(ValueError, match="unknown condition"):
        meshclash.scene(MESHES / "pins.glb", self_check=True, self_fail_on=["wobbly"])
    missing = tmp_path / "nope.json"
    _, _, err = run_cli(a, b, "--baseline", missing, expect=(2,))
    with pytest.raises(ValueError) as e:
        meshclash.check(a, b, baseline=missing)
    assert err.strip().splitlines()[-1] == f"meshclash: error: {e.value}"
