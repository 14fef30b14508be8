"""rtcost: build, trace, count and model ray tracing acceleration structures, from Python.

    import rtcost
    scene = rtcost.load("builtin:balls:2")
    rays = rtcost.rays(scene, "lines", count=10000, seed=1)
    h = scene.build("bvh-sah")
    result = h.trace(rays, query="closest")
    result.prim, result.t, result.counters["N_IT"]

The extension module (rtcost._rtcost, C++ through pybind11) does the work without the GIL;
errors in the input raise rtcost.InputError (a ValueError) whose text is the command line's
message after "rtcost: error: " ("FILE:LINE: problem").
"""
from typing import NamedTuple

import numpy as np

from . import _rtcost
from ._rtcost import (RAY_KINDS, Hierarchy, InputError, Scene, TraceResult, builtin_scenes, distributions,
                      hierarchies, load)

__all__ = ["RAY_KINDS", "Hierarchy", "InputError", "Rays", "Scene", "TraceResult", "builtin_scenes",
           "distributions", "evaluate", "hierarchies", "load", "rays", "sweep"]


class Rays(NamedTuple):
    """A ray set: `rays` (N, 8) float32 (ox oy oz dx dy dz tmin tmax), `kinds` (N,) uint8
    indices into RAY_KINDS, and what made it (e.g. "camera 64x64")."""
    rays: np.ndarray
    kinds: np.ndarray
    described: str

    def __len__(self):
        return len(self.rays)


def rays(scene, dist="camera", *, size=None, count=100000, seed=1):
    """The ray set `rtcost trace --rays DIST` traces: camera, lines, random, spd, shadow,
    diffuse, ao, or a ray file's path. `size` ("WxH") for the camera-based ones (default: the
    scene's), `count` and `seed` for lines and random. Returns Rays."""
    r, k, described = _rtcost._make_rays(scene, dist, size or "", int(count), int(seed))
    return Rays(r, k, described)


def _as_rays(rays, kinds):
    if isinstance(rays, Rays):
        return rays.rays, rays.kinds if kinds is None else kinds
    return np.asarray(rays), kinds


def _build(self, name, **params):
    """Builds hierarchy `name` (rtcost.hierarchies() lists them) over this scene; keyword
    arguments are its parameters, as `--set key=value` (True/False for flags)."""
    return _rtcost._build(self, name, **params)


def _trace(self, rays, *, kinds=None, query="closest", shadow="any", count=True, threads=0):
    """Traces `rays` (Rays, or any (N, 8) array of ox oy oz dx dy dz tmin tmax) as `rtcost
    trace` does: query closest, any or all; shadow and ambient-occlusion rays (by `kinds`) as
    `shadow` queries. Returns a TraceResult: `prim` (int32) and `t` (float32) per ray, and with
    count=True `counters`, the per-ray means of `trace --json`'s per_ray, and `by_kind`."""
    array, kinds = _as_rays(rays, kinds)
    return self._trace(array, kinds=kinds, query=query, shadow=shadow, count=count, threads=threads)


Scene.build = _build
Hierarchy.trace = _trace


def sweep(spec, **options):
    """Runs a sweep (scenes x hierarchies x parameters x distributions) on Dask; see
    rtcost._sweep.sweep for the spec. Returns the table of results (a pandas DataFrame)."""
    from . import _sweep
    return _sweep.sweep(spec, **options)


def evaluate(*args, **kwargs):
    """Predicted against measured cost of hierarchies on rays: the results of `rtcost eval --json`."""
    from . import _evaluate
    return _evaluate.evaluate(*args, **kwargs)
