"""Quantities of WCSPH run files the claims registry reads (isaflow.quantities; the rows state runs and comparisons).
Units: cm, N, s."""

import math

import numpy as np

from ... import metrics as M, rest as REST
from ...core import fixed_order as FO
from ...core.units import G
from ...quantities import Value, quantity


@quantity("at rest (1) or not (0)")
def at_rest(ds, rest_ratio=None):
    """1 when the run came to rest by the project's criterion (config/rest.yaml), or by a swept energy ratio
    (rest_ratio) over its sampled kinetic energy; else 0."""
    if rest_ratio is None:
        return Value(int(ds.attrs["status"] == "converged"), f"{ds.attrs['status']} at t = {float(ds['sim_time']):.3g} s")
    e = ds["sample_kinetic"].values / (float(ds["weight"].values.sum()) * float(ds.attrs["initial_depth"]))
    mon = REST.Monitor(rest_ratio, float(ds.attrs["rest_window"]))
    return int(any(mon.update(t, x) for t, x in zip(ds["sample_time"].values, e)))


@quantity("dominant frequency of the side-wall load over the first sloshing mode", fmt=".3g")
def dominant_over_sloshing(ds):
    """The dominant frequency of the side walls' total |load| (linear trend removed) over the vessel's first sloshing
    frequency, omega^2 = g k tanh(k h), k = pi / B."""
    names = [str(n) for n in ds["wall"].values]
    walls = ds["wall_segment"].values
    side = [k for k in range(len(names)) if np.isclose(walls[k, 0], walls[k, 2])]
    t = ds["sample_time"].values
    y = np.abs(ds["sample_wall_resultant"].values[:, side, 0]).sum(1)
    y = FO.residual(t, y)
    spec = np.abs(np.fft.rfft(y)) ** 2
    f = float(np.fft.rfftfreq(len(y), float(np.median(np.diff(t))))[1:][np.argmax(spec[1:])])
    k = math.pi / M.vessel_view(ds)["width"]
    f0 = math.sqrt(G * k * math.tanh(k * float(ds.attrs["tank_depth"]))) / (2 * math.pi)
    return Value(f / f0, f"{f:.3g} Hz against {f0:.3f} Hz")


@quantity("largest non-affine displacement of a periodic block", "spacing", fmt=".3g")
def nonaffine_max(ds):
    """The largest finite distance of a particle of a periodic block run (methods.sph.block) from its affine
    position over the spacing, with when it peaked and the smallest pair distance; a run that blew up counts by
    what it reached before."""
    na, t = ds["nonaffine_over_dx_t"].values, ds["sample_time"].values
    fin = np.isfinite(na)
    if not fin.any():
        return Value(float("nan"), f"{ds.attrs['status']}: no finite sample")
    k = int(np.flatnonzero(fin)[np.argmax(na[fin])])
    pair = float(np.nanmin(ds["min_pair_over_dx_t"].values))
    return Value(float(na[k]), f"at t = {t[k]:.3g} s, smallest pair distance {pair:.2f} spacing, {ds.attrs['status']}")
