"""The Python module against the command line: the same scene, the same rays, the same hits
(exactly) and the same counters (exactly) as `rtcost trace`; bad input raises InputError with
the CLI's message."""
import os
import threading

import numpy as np
import pytest

import rtcost
from conftest import cli_json, run_cli

SCENE = "builtin:balls:2"


@pytest.fixture(scope="module")
def scene():
    return rtcost.load(SCENE)


def test_scene_matches_info(scene):
    info = cli_json("info", SCENE)
    assert scene.primitives == info["primitives"] == len(scene)
    assert scene.by_kind == info["by_kind"]
    lo, hi = scene.bounds
    assert list(lo) == pytest.approx(info["bounds"]["lo"], rel=0, abs=0)
    assert list(hi) == pytest.approx(info["bounds"]["hi"], rel=0, abs=0)
    assert scene.camera == info["camera"]
    assert scene.info() == info


def test_rays_are_the_cli_ray_file(scene, tmp_path):
    r = rtcost.rays(scene, "lines", count=3000, seed=5)
    assert r.rays.shape == (3000, 8) and r.rays.dtype == np.float32
    assert r.kinds.shape == (3000,) and set(r.kinds) == {rtcost.RAY_KINDS.index("line")}
    path = tmp_path / "lines.rays"
    run_cli("rays", SCENE, "--dist", "lines", "--count", 3000, "--seed", 5, "--out", path)
    assert np.array_equal(np.fromfile(path, dtype="<f4").reshape(-1, 8), r.rays)
    from_file = rtcost.rays(scene, str(path))
    assert np.array_equal(from_file.rays, r.rays) and set(from_file.kinds) == {rtcost.RAY_KINDS.index("file")}
    cam = rtcost.rays(scene, "camera", size="16x8")
    assert cam.rays.shape == (128, 8) and cam.described == "camera 16x8"


def hits_of_cli(tmp_path, rays, hierarchy, query, sets=()):
    ray_file, hit_file = tmp_path / "in.rays", tmp_path / "out.hits"
    np.ascontiguousarray(rays, dtype="<f4").tofile(ray_file)
    args = ["trace", SCENE, "-H", hierarchy, "--rays", ray_file, "--query", query, "--hits", hit_file]
    for s in sets:
        args += ["--set", s]
    j = cli_json(*args)
    hits = np.fromfile(hit_file, dtype=[("prim", "<i4"), ("t", "<f4")])
    return hits, j


@pytest.mark.parametrize("hierarchy,query,params", [
    ("bvh-sah", "closest", {}), ("kd-sah", "closest", {}), ("grid", "closest", {"res": "woo"}),
    ("octree", "any", {"traversal": "recursive"}), ("bvh-median", "all", {}), ("rc5d", "closest", {}),
])
def test_hits_and_counters_equal_the_cli(scene, tmp_path, hierarchy, query, params):
    rays = rtcost.rays(scene, "random", count=4000, seed=3).rays
    h = scene.build(hierarchy, **params)
    got = h.trace(rays, query=query)
    hits, j = hits_of_cli(tmp_path, rays, hierarchy, query, [f"{k}={v}" for k, v in params.items()])
    assert got.prim.dtype == np.int32 and got.t.dtype == np.float32
    assert np.array_equal(got.prim, hits["prim"])
    assert np.array_equal(got.t, hits["t"])  # +inf for misses on both sides
    assert got.hits == j["trace"]["hits"] and got.hits == int((got.prim >= 0).sum())
    assert got.hits > 100
    assert got.counters == j["trace"]["per_ray"]
    assert got.counters["N_IT"] > 0
    assert h.params == j["params"]
    s = h.structure()  # after tracing: the lazily built rc5d has grown since the CLI's report
    for k in () if hierarchy == "rc5d" else ("N_IN", "N_V", "N_EV", "N_OIV", "depth", "bytes"):
        assert s[k] == j["build"][k], k


def test_ray_sets_by_kind_equal_the_cli(scene):
    """Shadow rays are any-hit queries by their kind, as `trace --rays shadow` traces them."""
    r = rtcost.rays(scene, "shadow", size="24x24")
    got = scene.build("bvh-sah").trace(r)
    j = cli_json("trace", SCENE, "-H", "bvh-sah", "--rays", "shadow", "--size", "24x24")
    assert got.counters == j["trace"]["per_ray"]
    assert got.by_kind == j["trace"]["by_kind"]
    assert set(got.by_kind) == {"shadow"}


def test_any_array_of_rays_is_accepted(scene):
    r = rtcost.rays(scene, "camera", size="8x8").rays
    h = scene.build("bvh-sah")
    as_list = h.trace(r.astype(np.float64).tolist(), count=False)
    assert as_list.counters is None
    strided = np.asfortranarray(r.astype(np.float64))
    assert np.array_equal(h.trace(strided).prim, as_list.prim)
    assert np.array_equal(h.trace(r).t, as_list.t)


def test_builtins_and_lists():
    names = [h["name"] for h in rtcost.hierarchies()]
    assert "bvh-sah" in names and "grid" in names and names == sorted(names)
    grid = next(h for h in rtcost.hierarchies() if h["name"] == "grid")
    assert any(p["name"] == "res" for p in grid["params"])
    assert "lines" in rtcost.distributions()
    assert "balls" in rtcost.builtin_scenes()


def cli_error(*args):
    p = run_cli(*args, check=False)
    assert p.returncode == 2, p.stderr
    prefix = "rtcost: error: "
    assert p.stderr.startswith(prefix), p.stderr
    return p.stderr[len(prefix):].strip()


def test_bad_input_raises_with_the_cli_message(scene, tmp_path):
    bad = tmp_path / "bad.nff"
    bad.write_text("v\nfrom 0 0 1\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 4 4\ns 0 0 0 nan\n")
    with pytest.raises(rtcost.InputError) as e:
        rtcost.load(str(bad))
    assert str(e.value) == cli_error("info", bad)
    assert str(e.value).startswith(f"{bad}:8: ")
    assert isinstance(e.value, ValueError)

    missing = tmp_path / "missing.nff"
    with pytest.raises(rtcost.InputError) as e:
        rtcost.load(str(missing))
    assert str(e.value) == cli_error("info", missing)

    with pytest.raises(rtcost.InputError) as e:
        scene.build("no-such-tree")
    assert str(e.value) == cli_error("build", SCENE, "-H", "no-such-tree")
    with pytest.raises(rtcost.InputError) as e:
        scene.build("grid", res="bogus")
    assert str(e.value) == cli_error("build", SCENE, "-H", "grid", "--set", "res=bogus")
    with pytest.raises(rtcost.InputError) as e:
        scene.build("grid", nosuch=1)
    assert str(e.value) == cli_error("build", SCENE, "-H", "grid", "--set", "nosuch=1")


def test_bad_rays_raise_as_a_bad_ray_file(scene, tmp_path):
    r = rtcost.rays(scene, "camera", size="4x4").rays.copy()
    r[3, 0] = np.nan
    h = scene.build("bvh-sah")
    with pytest.raises(rtcost.InputError) as e:
        h.trace(r)
    assert str(e.value) == "rays: ray 3: origin is not finite"
    path = tmp_path / "nan.rays"
    r.astype("<f4").tofile(path)
    assert cli_error("trace", SCENE, "--rays", path).endswith("ray 3 (byte 96): origin is not finite")
    r[3, 0] = 0
    r[5, 6], r[5, 7] = 2, 1
    with pytest.raises(rtcost.InputError, match="ray 5: tmin > tmax"):
        h.trace(r)
    with pytest.raises(rtcost.InputError, match=r"\(N, 8\)"):
        h.trace(np.zeros((4, 7), np.float32))
    with pytest.raises(rtcost.InputError, match="not one of closest, any, all"):
        h.trace(r[:2], query="nearest")
    with pytest.raises(rtcost.InputError) as e:
        rtcost.rays(scene, "camera", size="12by4")
    assert str(e.value) == cli_error("rays", SCENE, "--dist", "camera", "--size", "12by4", "--out", tmp_path / "x")


def test_the_gil_is_released_while_tracing():
    """This thread runs Python while another thread's trace is inside C++: with the GIL held it
    could not run a single bytecode in the middle of that call."""
    import time
    big = rtcost.load("builtin:balls")
    h = big.build("brute")
    r = rtcost.rays(big, "random", count=4000, seed=1).rays
    window, started = [], threading.Event()

    def work():
        started.set()
        t0 = time.perf_counter()
        h.trace(r, threads=1, count=False)
        window.extend([t0, time.perf_counter()])

    t = threading.Thread(target=work)
    t.start()
    started.wait()
    stamps = []
    while t.is_alive():
        stamps.append(time.perf_counter())
    t.join()
    t0, t1 = window
    lo, hi = t0 + 0.1 * (t1 - t0), t1 - 0.1 * (t1 - t0)
    inside = sum(lo < s < hi for s in stamps)
    assert inside > 100, f"{inside} of {len(stamps)} iterations ran during the trace ({t1 - t0:.3f} s)"


def test_hierarchy_keeps_its_scene_alive():
    h = rtcost.load("builtin:tetra:3").build("bvh-sah")
    import gc
    gc.collect()
    r = np.array([[0.1, 0.2, 5, 0, 0, -1, 0, np.inf]], np.float32)
    assert h.trace(r).rays == 1
