"""The rest criterion of every dynamic method, defined once (pure Python: read while the workflow is parsed).

A liquid is at rest when e = KE / (W h) -- its kinetic energy over its weight
times its depth, i.e. <|v|^2> / (2 g h) for equal masses, the dynamic pressure
rho v^2 / 2 in units of the hydrostatic pressure rho g h -- stays below
``energy_ratio`` at every sample over the last ``window`` seconds (settings in config/rest.yaml).

The at-rest and wall numbers every run file holds are isaflow.at_rest's.
Units: cm, N, s.
"""

import collections
import math
from pathlib import Path

from . import inputs
from .core.units import G

DEFAULT_PATH = Path(__file__).resolve().parents[2] / "config" / "rest.yaml"
_ITEM = {"type": "object", "additionalProperties": False, "required": ["value", "source"],
         "properties": {"value": {"type": "number", "exclusiveMinimum": 0}, "source": {"type": "string", "minLength": 8}}}
SCHEMA = {"type": "object", "additionalProperties": False, "required": ["rest"],
          "properties": {"rest": {"type": "object", "additionalProperties": False,
                                  "required": ["energy_ratio", "window"],
                                  "properties": {"energy_ratio": _ITEM, "window": _ITEM}}}}


def load(path=DEFAULT_PATH):
    """{'energy_ratio': e_rest (1), 'window': s} of the rest settings file (InputError naming file and field)."""
    spec = inputs.load(path, SCHEMA, "rest settings")[1]["rest"]
    return {k: float(v["value"]) for k, v in spec.items()}


def energy_ratio(kinetic_energy, weight, depth):
    """e = KE / (W h) (1): kinetic energy [N cm] over liquid weight [N] times depth [cm]."""
    return float(kinetic_energy) / (float(weight) * float(depth))


def speed_at(ratio, depth):
    """rms speed [cm/s] of equal masses at energy ratio ``ratio`` in a column ``depth`` cm deep."""
    return math.sqrt(2.0 * G * depth * ratio)


def window_stats(times, ratios, window):
    """(mean, max) of e over the samples of the last ``window`` s (times [s] ascending, ratios e (1)): the final
    state of a run is quoted over the rest window, never as a single sample.  (nan, nan) without samples."""
    times, ratios = [float(t) for t in times], [float(e) for e in ratios]
    if not times:
        return math.nan, math.nan
    last = [e for t, e in zip(times, ratios) if t >= times[-1] - float(window) + 1e-12]
    return math.fsum(last) / len(last), max(last)


class Monitor:
    """Tracks e(t) sample by sample; ``at_rest`` once every sample of the last window is below the ratio.

    The window is measured from the first sample below the ratio after the last one above it, so
    a run is at rest only after ``window`` s of simulated time spent entirely below the ratio.
    """

    def __init__(self, energy_ratio, window):
        self.limit, self.window = float(energy_ratio), float(window)
        self.quiet_since = None  # time of the first sample of the current run below the limit
        self.last = math.nan
        self.history = collections.deque()

    def update(self, t, ratio):
        """Record e = ratio at time t [s]; returns True when at rest."""
        self.last = float(ratio)
        if not ratio < self.limit:  # NaN counts as moving
            self.quiet_since = None
        elif self.quiet_since is None:
            self.quiet_since = float(t)
        return self.at_rest(t)

    def at_rest(self, t):
        return self.quiet_since is not None and t - self.quiet_since >= self.window - 1e-12

    def time_to_rest(self):
        """Start of the quiet stretch that made the run at rest [s] (NaN when not at rest)."""
        return math.nan if self.quiet_since is None else self.quiet_since
