"""rtcost.evaluate: predicted against measured cost, the results of `rtcost eval --json`."""
import numpy as np

from . import _rtcost


def _label(h):
    """A hierarchy request as `eval -H` takes it: "name[:key=value...]"."""
    if isinstance(h, str):
        return h
    if isinstance(h, _rtcost.Hierarchy):
        return ":".join([h.name, *h._assignments])
    if isinstance(h, (tuple, list)) and len(h) == 2 and isinstance(h[0], str) and isinstance(h[1], dict):
        return ":".join([h[0], *(f"{k}={_text(v)}" for k, v in h[1].items())])
    raise _rtcost.InputError(f"hierarchies: {h!r} is not a name, 'name:key=value', (name, params) or a Hierarchy")


def _text(v):
    return ("1" if v else "0") if isinstance(v, bool) else str(v)


def _list(v):
    return [v] if isinstance(v, str) else list(v)


def evaluate(scene, hierarchies="all", rays="camera", *, size=None, count=100000, seed=1, kinds=None,
             estimator="segments", preset="exact", query="closest", shadow="any", sample=0, sample_file=None,
             costs=None, threads=0, by_depth=False, table=True):
    """Builds each hierarchy over `scene`, predicts its cost per ray with the model, measures it on
    the same rays, and ranks them: what `rtcost eval --json` prints.

    `hierarchies`: "all", "a,b:key=value", or a list of names, "name:key=value" strings,
    (name, {params}) pairs or built Hierarchy objects (evaluated afresh with their parameters).
    `rays`: a distribution name or ray file (with `size`, `count`, `seed`, as `--rays`), Rays,
    or any (N, 8) array (with `kinds`). `estimator` (geometric, sampled, segments, both, all)
    and `preset` (exact, paper, both) may be lists: every one is evaluated, the first is the
    headline. `sample`, `sample_file`, `costs` (a costs file), `threads`, `by_depth`: as
    `eval --sample`, `--sample-file`, `--costs`, `--threads`, `--by-depth`. Returns a pandas DataFrame of the result rows (the
    document's other fields in `df.attrs`), or the document itself with table=False or without
    pandas."""
    from . import Rays
    if isinstance(hierarchies, str):
        names = hierarchies
    else:
        names = ",".join(_label(h) for h in hierarchies)
    if isinstance(rays, Rays):
        rays, kinds = rays.rays, rays.kinds if kinds is None else kinds
    if not isinstance(rays, str):
        rays = np.asarray(rays)
    doc = _rtcost._evaluate(scene, names, rays, kinds, size or "", int(count), int(seed), _list(estimator),
                            _list(preset), query, shadow, int(sample), sample_file or "", costs or "", int(threads),
                            bool(by_depth))
    if not table:
        return doc
    try:
        import pandas as pd
    except ImportError:
        return doc
    key = "results" if "results" in doc else "rows"
    df = pd.json_normalize(doc.get(key, []), max_level=1)
    df.attrs.update({k: v for k, v in doc.items() if k != key})
    return df
