"""rtcost.evaluate against `rtcost eval --json`: the same document, every number but the times
equal, for named distributions, ray arrays (as a ray file) and every way to name hierarchies."""
import numpy as np
import pytest

import rtcost
from conftest import cli_json, run_cli

SCENE = "builtin:tetra:4"
TIMES = {"mrays_per_s", "time", "seconds_predicting", "seconds", "sample_seconds", "visibility_seconds",
         "sample_trace_seconds"}


def without_times(value):
    if isinstance(value, dict):
        return {k: without_times(v) for k, v in value.items() if k not in TIMES}
    if isinstance(value, list):
        return [without_times(v) for v in value]
    return value


@pytest.fixture(scope="module")
def scene():
    return rtcost.load(SCENE)


@pytest.mark.parametrize("cli_args,kwargs", [
    (["-H", "bvh-sah,grid,kd-sah", "--rays", "lines", "--count", "4000", "--seed", "2"],
     dict(hierarchies="bvh-sah,grid,kd-sah", rays="lines", count=4000, seed=2)),
    (["-H", "bvh-sah,octree:max_depth=6", "--rays", "camera", "--size", "32x32", "--estimator", "both",
      "--preset", "both"],
     dict(hierarchies=["bvh-sah", ("octree", {"max_depth": 6})], rays="camera", size="32x32",
          estimator="both", preset="both")),
    (["-H", "grid:res=woo", "--rays", "lines", "--count", "3000", "--query", "all", "--by-depth",
      "--estimator", "sampled,geometric"],
     dict(hierarchies=["grid:res=woo"], rays="lines", count=3000, query="all", by_depth=True,
          estimator=["sampled", "geometric"])),
])
def test_evaluate_is_eval_json(scene, cli_args, kwargs):
    want = cli_json("eval", SCENE, *cli_args)
    got = rtcost.evaluate(scene, table=False, **kwargs)
    assert without_times(got) == without_times(want)
    assert len(got["results"]) >= 1
    assert all(r["measured"]["cost"] > 0 for r in got["results"])


def test_a_ray_array_is_a_ray_file(scene, tmp_path):
    rays = rtcost.rays(scene, "random", count=5000, seed=9)
    path = tmp_path / "r.rays"
    rays.rays.astype("<f4").tofile(path)
    want = cli_json("eval", SCENE, "-H", "bvh-sah,kd-sah", "--rays", path, "--estimator", "sampled")
    h = scene.build("kd-sah")
    got = rtcost.evaluate(scene, ["bvh-sah", h], rays.rays, estimator="sampled", table=False)
    assert without_times(got["results"]) == without_times(want["results"])
    assert (got["rays"], got["training_rays"], got["split"]) == (want["rays"], want["training_rays"], want["split"])


def test_the_table(scene):
    df = rtcost.evaluate(scene, ["bvh-sah", scene.build("grid", res="woo")], rtcost.rays(scene, "lines", count=2000))
    assert list(df["hierarchy"]) == ["bvh-sah", "grid:res=woo"]
    assert {"predicted.cost", "measured.cost", "error", "rank_predicted", "build.N_IN"} <= set(df.columns)
    # The segments estimator (the default) leaves its sample out of the test rays.
    assert df.attrs["scene"] == SCENE and df.attrs["rays"] + df.attrs["sample_rays"] == 2000 and df.attrs["sample_rays"] > 0
    assert sorted(df["rank_measured"]) == [1, 2]


def test_bad_requests_raise_the_cli_message(scene):
    p = run_cli("eval", SCENE, "-H", "bvh-sah,nosuch", "--json", check=False)
    assert p.returncode == 2
    with pytest.raises(rtcost.InputError) as e:
        rtcost.evaluate(scene, "bvh-sah,nosuch", "lines")
    assert p.stderr.strip().endswith(str(e.value).split(": ", 1)[1])
    with pytest.raises(rtcost.InputError, match="geometric, sampled, segments"):
        rtcost.evaluate(scene, "bvh-sah", "lines", estimator="guess")
    with pytest.raises(rtcost.InputError, match="not a name"):
        rtcost.evaluate(scene, [42], "lines")
    with pytest.raises(rtcost.InputError, match=r"\(N, 8\)"):
        rtcost.evaluate(scene, "bvh-sah", np.zeros((3, 5)))
