"""Sweeps on Dask: a 3 x 3 x 2 sweep on a cluster of 2 workers gives the same numbers (every
operation count, the structure, the model's prediction; not the times) as the same jobs run one
by one in this process; a failing job is reported and loses no other; a rerun skips what is done."""
import json
import os

import pytest

import rtcost
from rtcost import _sweep
from conftest import run_cli

SPEC = {
    "scenes": ["builtin:balls:1", "builtin:balls:2", "builtin:tetra:4"],
    "hierarchies": ["bvh-sah", {"name": "grid", "params": {"res": "woo"}}, "kd-sah"],
    "distributions": [{"dist": "lines", "count": 2000, "seed": 4}, {"dist": "camera", "size": "16x16"}],
    "threads": 1,
}
TIMES = {"seconds", "mrays_per_s", "time", "seconds_predicting", "sample_seconds", "sample_trace_seconds"}


def without_times(value):
    if isinstance(value, dict):
        return {k: without_times(v) for k, v in value.items() if k not in TIMES}
    if isinstance(value, list):
        return [without_times(v) for v in value]
    return value


@pytest.fixture(scope="module")
def cluster():
    from dask.distributed import LocalCluster
    c = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0")
    yield c
    c.close()


def test_expand_is_the_product():
    jobs = _sweep.expand(SPEC)
    assert len(jobs) == 3 * 3 * 2
    assert len({j["job"] for j in jobs}) == 18
    assert jobs[0]["scene"] == "builtin:balls:1" and jobs[0]["hierarchy"] == "bvh-sah"
    assert jobs[2]["params"] == {"res": "woo"}
    swept = _sweep.expand({**SPEC, "hierarchies": [{"name": "grid", "params": {"res": ["woo", "regular"],
                                                                                "density": [1, 2]}}]})
    assert len(swept) == 3 * 4 * 2
    assert {tuple(sorted(j["params"].items())) for j in swept} == {
        (("density", d), ("res", r)) for d in (1, 2) for r in ("woo", "regular")}


def test_a_cluster_gives_the_numbers_of_the_jobs_run_one_by_one(cluster, tmp_path):
    out = tmp_path / "sweep.jsonl"
    df = rtcost.sweep(SPEC, out=str(out), scheduler=cluster.scheduler_address)
    assert df.attrs == {"jobs": 18, "ran": 18, "skipped": 0, "failed": 0}
    assert len(df) == 18 and set(df["status"]) == {"ok"}
    assert {"scene", "hierarchy", "params.res", "dist.dist", "per_ray.N_IT", "structure.N_IN"} <= set(df.columns)
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    assert len(rows) == 18
    by_job = {r["job"]: r for r in rows}
    for job in _sweep.expand(SPEC):
        alone = _sweep.run_job(job)
        assert alone["status"] == "ok", alone
        assert without_times(by_job[job["job"]]) == without_times(alone)
        assert alone["per_ray"]["N_IT"] > 0 and alone["rays"] in (2000, 256)
        # The model's row is `rtcost eval --json`'s for the same job.
        assert alone["model"]["hierarchy"] == ":".join([job["hierarchy"]] + [f"{k}={v}" for k, v in job["params"].items()])
        assert alone["model"]["predicted"]["cost"] > 0 and alone["model"]["measured"]["cost"] > 0
    d = SPEC["distributions"][0]
    want = run_cli("eval", "builtin:tetra:4", "-H", "grid:res=woo", "--rays", d["dist"], "--count", d["count"],
                   "--seed", d["seed"], "--json").stdout
    row = next(r for r in rows if r["scene"] == "builtin:tetra:4" and r["hierarchy"] == "grid"
               and r["dist"] == d)
    assert without_times(row["model"]) == without_times(json.loads(want)["results"][0])
    # The table is the rows, in the spec's order.
    assert list(df["job"]) == [j["job"] for j in _sweep.expand(SPEC)]
    assert list(df["per_ray.N_TS"]) == [by_job[j]["per_ray"]["N_TS"] for j in df["job"]]

    # A rerun finds every job done and starts no cluster.
    again = rtcost.sweep(SPEC, out=str(out), scheduler="tcp://127.0.0.1:1")
    assert again.attrs == {"jobs": 18, "ran": 0, "skipped": 18, "failed": 0}
    assert list(again["per_ray.N_IT"]) == list(df["per_ray.N_IT"])


def test_a_failing_job_is_reported_and_the_others_kept(tmp_path):
    spec = {"scenes": ["builtin:tetra:3"],
            "hierarchies": [{"name": "grid", "params": {"res": ["woo", "bogus"]}}, "bvh-sah"],
            "distributions": ["random"], "workers": 2, "out": str(tmp_path / "s.jsonl")}
    spec_file = tmp_path / "spec.json"
    spec_file.write_text(json.dumps(spec))
    p = run_cli("sweep", spec_file, "--json", check=False)
    assert p.returncode == 2, p.stderr  # the only failure is a bad parameter: bad input
    rows = [json.loads(line) for line in p.stdout.splitlines()]
    assert [r["status"] for r in rows] == ["ok", "error", "ok"]
    with pytest.raises(rtcost.InputError) as e:
        rtcost.load("builtin:tetra:3").build("grid", res="bogus")
    assert rows[1]["error"] == str(e.value) and rows[1]["error_type"] == "InputError"
    assert f"rtcost: error: builtin:tetra:3 grid res=bogus: {e.value}" in p.stderr
    assert len((tmp_path / "s.jsonl").read_text().splitlines()) == 3
    # A rerun runs the failed job again (it fails again) and skips the two done.
    df = rtcost.sweep(str(spec_file))
    assert df.attrs == {"jobs": 3, "ran": 1, "skipped": 2, "failed": 1}


def test_bad_specs_are_input_errors(tmp_path):
    spec_file = tmp_path / "bad.json"
    spec_file.write_text('{"scenes": ["builtin:tetra:3"],\n "hierarchies": ["brute"],\n "distribution": []}\n')
    p = run_cli("sweep", spec_file, check=False)
    assert p.returncode == 2
    assert p.stderr.startswith(f"rtcost: error: {spec_file}: unknown key 'distribution'")
    spec_file.write_text('{"scenes": ["builtin:tetra:3"],\n "hierarchies": [brute]}\n')
    p = run_cli("sweep", spec_file, check=False)
    assert p.returncode == 2 and p.stderr.startswith(f"rtcost: error: {spec_file}:2: Expecting value")
    with pytest.raises(rtcost.InputError, match="'distributions' is missing"):
        rtcost.sweep({"scenes": ["builtin:tetra:3"], "hierarchies": ["brute"]})
    with pytest.raises(rtcost.InputError, match="no such file"):
        rtcost.sweep(str(tmp_path / "nothing.json"))
