"""Sweeps: scenes x hierarchies x parameters x distributions as independent jobs on Dask.

A spec (a dict, or the path of a JSON file holding one):

    {"scenes": ["builtin:balls:2", "builtin:tetra:4"],
     "hierarchies": ["bvh-sah", {"name": "grid", "params": {"res": ["woo", "hetero"]}}],
     "distributions": [{"dist": "lines", "count": 5000, "seed": 1}, {"dist": "camera", "size": "32x32"}],
     "query": "closest", "estimator": "segments", "preset": "exact",
     "out": "sweep.jsonl", "scheduler": null, "workers": 2, "threads": 1}

Every hierarchy entry is a name or {"name", "params"}; a parameter given a list is swept over
its values (the product over parameters). One job per scene, hierarchy, parameter set and
distribution: it loads the scene, builds the hierarchy, makes the rays, traces them counting
every operation and predicts the cost with the model (the row `rtcost eval --json` gives).
Jobs run on dask.distributed: a LocalCluster of `workers` processes by default, the scheduler
at `scheduler` ("tcp://host:8786") when given; there every worker needs rtcost importable.

Each finished job is appended to `out` (JSON lines) at once; a job that fails is a row with
status "error" and its message, and the others go on. A rerun with the same `out` skips every
job whose result is there (failed ones are run again). The result is one table: a pandas
DataFrame (columns flattened: params.res, dist.count, per_ray.N_IT, ...), or the list of rows
without pandas.
"""
import hashlib
import itertools
import json
import os
import sys
import traceback

_SPEC_KEYS = {"scenes", "hierarchies", "distributions", "query", "estimator", "preset", "out", "scheduler",
              "workers", "threads"}
_DIST_KEYS = {"dist", "size", "count", "seed"}


def _error(where, problem):
    from . import InputError
    return InputError(f"{where}: {problem}")


def load_spec(spec):
    """The spec as a dict, and the name errors in it are reported under (its file or "spec")."""
    if isinstance(spec, (str, os.PathLike)):
        path = os.fspath(spec)
        try:
            with open(path) as f:
                text = f.read()
        except OSError as e:
            raise _error(path, "no such file" if isinstance(e, FileNotFoundError) else e.strerror) from None
        try:
            data = json.loads(text)
        except json.JSONDecodeError as e:
            raise _error(f"{path}:{e.lineno}", e.msg) from None
        if not isinstance(data, dict):
            raise _error(path, "a sweep spec is a JSON object")
        return data, path
    return dict(spec), "spec"


def _list(value, where, key):
    if value is None:
        raise _error(where, f"'{key}' is missing")
    values = value if isinstance(value, list) else [value]
    if not values:
        raise _error(where, f"'{key}' is empty")
    return values


def expand(spec, where="spec"):
    """Every job of `spec`, in order (scene, hierarchy, parameter set, distribution)."""
    unknown = set(spec) - _SPEC_KEYS
    if unknown:
        raise _error(where, f"unknown key '{sorted(unknown)[0]}' (keys: {', '.join(sorted(_SPEC_KEYS))})")
    scenes = _list(spec.get("scenes"), where, "scenes")
    variants = []
    for i, h in enumerate(_list(spec.get("hierarchies"), where, "hierarchies")):
        if isinstance(h, str):
            h = {"name": h}
        if not isinstance(h, dict) or not isinstance(h.get("name"), str) or set(h) - {"name", "params"}:
            raise _error(where, f"hierarchies[{i}]: a name or {{\"name\": ..., \"params\": {{...}}}}")
        params = h.get("params") or {}
        keys = sorted(params)
        choices = [v if isinstance(v, list) else [v] for v in (params[k] for k in keys)]
        for combo in itertools.product(*choices):
            variants.append((h["name"], dict(zip(keys, combo))))
    dists = []
    for i, d in enumerate(_list(spec.get("distributions"), where, "distributions")):
        if isinstance(d, str):
            d = {"dist": d}
        if not isinstance(d, dict) or "dist" not in d or set(d) - _DIST_KEYS:
            raise _error(where, f"distributions[{i}]: a name or {{\"dist\", \"size\", \"count\", \"seed\"}}")
        dists.append(d)
    common = {"query": spec.get("query", "closest"), "estimator": spec.get("estimator", "segments"),
              "preset": spec.get("preset", "exact"), "threads": int(spec.get("threads", 1))}
    jobs = []
    for scene, (name, params), dist in itertools.product(scenes, variants, dists):
        job = {"scene": scene, "hierarchy": name, "params": params, "dist": dist, **common}
        job["job"] = job_key(job)
        jobs.append(job)
    return jobs


def job_key(job):
    """A stable name for a job: what it computes, not how (threads are left out)."""
    what = {k: job[k] for k in ("scene", "hierarchy", "params", "dist", "query", "estimator", "preset")}
    return hashlib.sha1(json.dumps(what, sort_keys=True).encode()).hexdigest()[:16]


def run_job(job):
    """Runs one job where it is called and returns its row; never raises for a job's own
    failure (the row then has status "error" and the message)."""
    import rtcost
    row = {k: job[k] for k in ("job", "scene", "hierarchy", "params", "dist", "query", "estimator", "preset")}
    try:
        scene = rtcost.load(job["scene"])
        d = job["dist"]
        rays = rtcost.rays(scene, d["dist"], size=d.get("size"), count=d.get("count", 100000), seed=d.get("seed", 1))
        h = scene.build(job["hierarchy"], **job["params"])
        result = h.trace(rays, query=job["query"], threads=job["threads"])
        row.update(status="ok", primitives=scene.primitives, rays=result.rays, hits=result.hits,
                   seconds=result.seconds, structure=h.structure(), per_ray=result.counters)
        row["model"] = _predict(scene, job)
    except Exception as e:  # a job's failure is its row, so that the others go on
        row.update(status="error", error=str(e), error_type=type(e).__name__)
    return row


def _predict(scene, job):
    """The job's row of `rtcost eval --json` (predicted beside measured cost) for the same
    hierarchy, parameters and rays: rtcost.evaluate with the job's estimator and preset."""
    import rtcost
    from . import _rtcost
    if not hasattr(_rtcost, "_evaluate"):
        return None
    d = job["dist"]
    label = ":".join([job["hierarchy"], *(f"{k}={_text(v)}" for k, v in sorted(job["params"].items()))])
    doc = rtcost.evaluate(scene, [label], d["dist"], size=d.get("size"), count=d.get("count", 100000),
                          seed=d.get("seed", 1), estimator=job["estimator"], preset=job["preset"],
                          query=job["query"], threads=job["threads"], table=False)
    return doc["results"][0]


def _text(v):
    return ("1" if v else "0") if isinstance(v, bool) else str(v)


def _read_done(out):
    done = {}
    if out and os.path.exists(out):
        with open(out) as f:
            for line in f:
                line = line.strip()
                if not line:
                    continue
                try:
                    row = json.loads(line)
                except json.JSONDecodeError:
                    continue  # a line cut short by an interrupted run: the job is run again
                if row.get("status") == "ok":
                    done[row["job"]] = row
    return done


class _Progress:
    """"sweep 3/18 jobs" on stderr, only when it is a terminal."""

    def __init__(self, total, quiet):
        self.total, self.active = total, not quiet and sys.stderr.isatty()

    def update(self, done):
        if self.active:
            sys.stderr.write(f"\rsweep {done}/{self.total} jobs")
            sys.stderr.flush()

    def finish(self):
        if self.active:
            sys.stderr.write("\r\033[K")
            sys.stderr.flush()


def _client(scheduler, workers):
    from dask.distributed import Client, LocalCluster
    if scheduler:
        return Client(scheduler), None
    cluster = LocalCluster(n_workers=int(workers or os.cpu_count() or 1), threads_per_worker=1, processes=True,
                           dashboard_address=":0")
    return Client(cluster), cluster


def sweep(spec, *, out=None, scheduler=None, workers=None, quiet=False, table=True):
    """Runs `spec`'s jobs on Dask and returns every row (this run's and those found in `out`),
    as a DataFrame when pandas is there and `table`. Keyword arguments override the spec's."""
    spec, where = load_spec(spec)
    jobs = expand(spec, where)
    out = out if out is not None else spec.get("out")
    scheduler = scheduler if scheduler is not None else spec.get("scheduler")
    workers = workers if workers is not None else spec.get("workers")
    done = _read_done(out)
    todo = [j for j in jobs if j["job"] not in done]
    rows = {j["job"]: done[j["job"]] for j in jobs if j["job"] in done}
    if todo:
        rows.update(_run(todo, out, scheduler, workers, quiet))
    ordered = [rows[j["job"]] for j in jobs]
    stats = {"jobs": len(jobs), "ran": len(todo), "skipped": len(jobs) - len(todo),
             "failed": sum(r["status"] != "ok" for r in ordered)}
    return _table(ordered, stats) if table else (ordered, stats)


def _run(todo, out, scheduler, workers, quiet):
    from dask.distributed import as_completed
    client, cluster = _client(scheduler, workers)
    rows = {}
    progress = _Progress(len(todo), quiet)
    sink = open(out, "a") if out else None
    try:
        futures = {client.submit(run_job, job, key=f"rtcost-{job['job']}", pure=False): job for job in todo}
        for n, future in enumerate(as_completed(futures), 1):
            job = futures[future]
            if future.status == "error":  # the job's process died, or the worker was lost
                e = future.exception()
                row = {k: job[k] for k in ("job", "scene", "hierarchy", "params", "dist", "query", "estimator",
                                           "preset")}
                row.update(status="error", error=str(e) or repr(e), error_type=type(e).__name__)
            else:
                row = future.result()
            rows[job["job"]] = row
            if sink:
                sink.write(json.dumps(row) + "\n")
                sink.flush()
            progress.update(n)
    finally:
        progress.finish()
        if sink:
            sink.close()
        client.close()
        if cluster is not None:
            cluster.close()
    return rows


def _table(rows, stats):
    try:
        import pandas as pd
    except ImportError:
        return rows
    df = pd.json_normalize(rows, max_level=1)
    df.attrs.update(stats)
    return df


def main(argv=None):
    """`rtcost sweep SPEC.json [--out FILE] [--scheduler ADDR] [--workers N] [--json]`."""
    import argparse
    p = argparse.ArgumentParser(prog="rtcost sweep", description=__doc__.split("\n\n")[0])
    p.add_argument("spec")
    p.add_argument("--out")
    p.add_argument("--scheduler")
    p.add_argument("--workers", type=int)
    p.add_argument("--json", action="store_true", help="print the rows as JSON lines")
    p.add_argument("--quiet", action="store_true")
    a = p.parse_args(argv)
    from . import InputError
    try:
        rows, stats = sweep(a.spec, out=a.out, scheduler=a.scheduler, workers=a.workers, quiet=a.quiet, table=False)
    except InputError as e:
        print(f"rtcost: error: {e}", file=sys.stderr)
        return 2
    except Exception:
        traceback.print_exc()
        return 1
    if a.json:
        for r in rows:
            print(json.dumps(r))
    else:
        _print_table(rows)
    if not a.quiet:
        print(f"sweep: {stats['jobs']} jobs: {stats['ran']} run, {stats['skipped']} found in the output, "
              f"{stats['failed']} failed", file=sys.stderr)
    for r in rows:
        if r["status"] != "ok":
            print(f"rtcost: error: {r['scene']} {r['hierarchy']} {_params(r['params'])}: {r['error']}",
                  file=sys.stderr)
    # Exit 2 (bad input) when every failed job failed on its input (a scene, a parameter or a
    # distribution the spec names wrongly), 1 when some job failed otherwise.
    failed = [r for r in rows if r["status"] != "ok"]
    if not failed:
        return 0
    return 2 if all(r.get("error_type") == "InputError" for r in failed) else 1


def _params(params):
    return ",".join(f"{k}={v}" for k, v in sorted(params.items())) or "-"


def _dist(d):
    return " ".join([d["dist"]] + [f"{k}={d[k]}" for k in ("size", "count", "seed") if k in d])


def _print_table(rows):
    print(f"{'scene':<18} {'hierarchy':<11} {'params':<16} {'rays':<26} {'N_IT':>9} {'N_TS':>9} "
          f"{'predicted':>10} {'measured':>10}")
    for r in rows:
        head = f"{r['scene']:<18} {r['hierarchy']:<11} {_params(r['params']):<16} {_dist(r['dist']):<26}"
        if r["status"] != "ok":
            print(f"{head} error: {r['error']}")
            continue
        pr, model = r["per_ray"], r.get("model") or {}
        pred = (model.get("predicted") or {}).get("cost")
        meas = (model.get("measured") or {}).get("cost")
        print(f"{head} {pr['N_IT']:>9.3f} {pr['N_TS']:>9.3f} "
              f"{'' if pred is None else f'{pred:.3f}':>10} {'' if meas is None else f'{meas:.3f}':>10}")


if __name__ == "__main__":
    sys.exit(main())
