"""The at-rest and wall numbers every run driven by isaflow.driver holds, defined once (:data:`AT_REST`).

Computed from what the driver saw (its rest samples, snapshots and final state): the time to rest, the residual
rms speed over sqrt(g h), the free surface's drift and each wall's load (mean and standard deviation) over the last
rest window (isaflow.rest's criterion), the particles found past a wall, and for a static method (ISA) max|F| and
rms|F| at the stop.  A particle is *past a wall* when it lies outside the tank (:func:`outside_tank`): below the
walls seen from above, or out of the tank's box.  They are written by the runs, so they are defined here, in every
run's code (isaflow.metrics, whose measures read run files, is in none: editing it reruns no run); metrics.at_rest_row
makes them the comparison table's columns.  Units: cm, N, s.
"""

import math

import numpy as np

from . import theory
from .rest import window_stats

# --- at rest and on the walls: the numbers the driver writes into every run file (driver.drive) ---------------

STATUS = {0: "in the tank", 1: "past a wall: outside the tank's walls or its box"}  # codes of snap_status
AT_REST = {  # name -> (dims, units, long_name): one name, dims and units for every method
    "time_to_rest": ((), "s", "from this run's start to the start of the quiet stretch that made it at rest "
                              "(isaflow.rest)"),
    "residual_speed_ratio": ((), "1", "rms liquid speed over the last rest window / sqrt(g h): sqrt(2 e), e = KE / (W h) "
                                      "averaged over the window's samples (isaflow.rest)"),
    "surface_drift": (("vessel",), "cm", "free surface of each vessel at the stop minus at the start of the last rest "
                                         "window (top particle centres per strip one spacing wide)"),
    "wall_crossings": ((), "1", "particles found past a wall (outside the tank, rest.outside_tank) in any snapshot "
                                "or at the stop"),
    "wall_load_mean": (("wall",), "N", "|force of each wall on the liquid|, mean over the samples of the last rest window"),
    "wall_load_std": (("wall",), "N", "|force of each wall on the liquid|, standard deviation over the samples of the "
                                      "last rest window"),
    "force_max": ((), "N", "max|F| at the stop: the largest out-of-balance force component max(|Fx|, |Fy|) of a "
                           "particle (the stop rule's measure, papadopoulos2016 section 3.3)"),
    "force_rms": ((), "N", "rms over the particles of the out-of-balance force's magnitude |F| at the stop"),
}


def measure(name, value, missing=None):
    """The run-file variable (dims, value, units, long_name[, attrs]) of an AT_REST number; missing: why its
    NaN values are not applicable (a run file holds no NaN unless a variable says why, runfile.finite)."""
    dims, units, long_name = AT_REST[name]
    value = np.asarray(value, np.int64 if name == "wall_crossings" else float)
    return (dims, value, units, long_name) + (({"missing": missing},) if missing else ())


def vessel_of(pos, vessels):
    """(N,) int8: index of the vessel whose x range [xmin, xmax) holds each particle, -1 for none (the rule of
    tank.vessel_counts, per particle).  vessels: [(name, (xmin, xmax))]."""
    x = np.asarray(pos, float)[:, 0]
    out = np.full(len(x), -1, np.int8)
    for k, (_, (a, b)) in enumerate(vessels):
        out[(x >= a) & (x < b) & (out < 0)] = k
    return out


def outside_tank(pos, walls, box):
    """(N,) bool: the particle lies outside the tank, i.e. past a wall.

    The tank is open at the top: a point is inside when a vertical ray down from it meets its non-vertical
    walls an odd number of times (each wall over the half-open x range [min, max) of its ends, so a shared end
    counts once), and it lies within the tank's box (x0, y0, x1, y1), which extends above the walls (a splash
    over them is not past a wall).  Thin dividing walls are vertical, so they never decide."""
    pos, walls = np.asarray(pos, float), np.asarray(walls, float)
    x, y = pos[:, 0:1], pos[:, 1:2]
    x0, y0, x1, y1 = (walls[:, k][None, :] for k in range(4))
    lo, hi = np.minimum(x0, x1), np.maximum(x0, x1)
    slanted = hi > lo
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(slanted, (x - x0) / np.where(slanted, x1 - x0, 1.0), 0.0)
    below = slanted & (x >= lo) & (x < hi) & (y0 + t * (y1 - y0) <= y)
    odd = np.count_nonzero(below, axis=1) % 2 == 1
    bx0, by0, bx1, by1 = box
    in_box = (pos[:, 0] >= bx0) & (pos[:, 0] <= bx1) & (pos[:, 1] >= by0) & (pos[:, 1] <= by1)
    return ~(odd & in_box)


def surface_levels(pos, spacing, vessels):
    """(V,) top-centre level [cm] of each vessel (theory.free_surface_level over strips ``spacing`` wide; NaN
    for an empty vessel): the free surface less half a layer pitch, so differences of it are the surface's."""
    return np.array([theory.free_surface_level(pos, spacing, xr) for _, xr in vessels], float)


def residual_speed_ratio(times, ratios, window):
    """rms speed over sqrt(g h) of the last ``window`` s of rest samples (t s, e = KE / (W h)): e = <v^2> / (2 g h)
    for equal masses, so sqrt(2 e) with e the window's mean (window_stats); NaN without samples."""
    e_mean = window_stats(times, ratios, window)[0]
    return math.sqrt(2.0 * e_mean) if e_mean >= 0 else math.nan


def wall_load_stats(times, resultants, window):
    """((W,) mean, (W,) standard deviation) [N] of |R| of each wall over the samples of the last ``window`` s
    (times (S,) s ascending, resultants (S, W, 2) N of each wall on the liquid); NaN without samples."""
    times, res = np.asarray(times, float), np.asarray(resultants, float)
    if not len(times):
        return np.full(res.shape[1:2], np.nan), np.full(res.shape[1:2], np.nan)
    mag = np.hypot(res[..., 0], res[..., 1])[times >= times[-1] - float(window) + 1e-12]
    return mag.mean(axis=0), mag.std(axis=0)


def force_stats(force):
    """(max|F|, rms |F|) [N] of an out-of-balance force field (N, 2) N: max|F| as the stop rule reads it (the
    largest component magnitude, AT_REST force_max), the rms of the magnitudes over the particles."""
    force = np.asarray(force, float).reshape(-1, 2)
    if not len(force):
        return 0.0, 0.0
    return float(np.abs(force).max()), float(np.sqrt(np.sum(force * force, axis=1).mean()))
