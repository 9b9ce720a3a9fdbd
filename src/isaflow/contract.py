"""The method contract: what every method's solver returns.

Every method is ``solve(...) -> Result``; ``runfile.to_dataset`` turns any
Result into the same run-file fields, so metrics, figures and the report
never branch on the method (only labels do).  Units: cm, N, s (core.units).

Wall loads are *contacts*: (wall index, point on the wall, force of the wall
on the liquid).  A point-particle method reports one contact per particle in
range of a wall; a continuum method (SPH, MPS) integrates its wall pressure
over panels of the wall (core.panels) and reports one contact per panel, at
the panel's centre.  The same hydrostatic theory (theory.contact_theory) then
judges both.

Every tank method also states how its liquid differs from the tank it runs on,
in ``Result.params`` (run-file attributes), so that no difference is silent:
- ``layer_pitch`` [cm]: vertical distance between the particle layers of its
  initial lattice (square lattice: dy; MPS: l0; ISA's rhombic lattice: a / 2);
  the free surface of a particle method is its top particle centres plus half
  of it (metrics.surface_of);
- ``held_weight`` [N]: the liquid weight the method holds (sum of m g);
- ``initial_depth`` [cm]: the depth of its initial liquid in the first vessel,
  top layer plus half a pitch above the floor (the tank's ``liquid.depth``
  unless rows were rounded);
- ``tank_difference``: one line saying what differs from the tank ("none" if
  nothing), e.g. "depth rounded to whole rows: 75 cm (tank 72.5 cm), weight held
  at 9000 N".
Dynamic methods judge rest with isaflow.rest (one criterion for all) and
record ``rest_energy_ratio`` and ``rest_window`` (attributes: the criterion) and the
variable ``time_to_rest`` [s] (at_rest.AT_REST, written by the driver): the start
of the quiet stretch that made the run at rest, counted from the start of this run
(its own t0: the release of its liquid, the opening for a flow), in every method.
"""

from dataclasses import dataclass, field

import numpy as np

from .settings import OUTCOMES  # noqa: E402,F401 (the shared outcome list, defined with the accept vocabulary)


# History names (every method): a variable's prefix names its first dimension, and a quantity more than one method
# records has one name, dimensions and units (checked when a run file is written: history_problems)
PREFIX_DIM = {"hist_": "record", "sample_": "sample", "snap_": "snapshot"}
SHARED_HISTORY = {  # name -> (dims, units)
    "sample_time": (("sample",), "s"),  # time of the sample on the chain's clock (dynamic methods)
    "sample_step": (("sample",), "1"),  # step of the sample, counted from the start of the chain
    "sample_vessel_count": (("sample", "vessel"), "1"),  # liquid particles in each vessel
    "sample_wall_resultant": (("sample", "wall", "xy"), "N"),  # force of each wall on the liquid
    "sample_rms_speed": (("sample",), "cm s-1"),
    "sample_kinetic": (("sample",), "N cm"),
    # the driver's snapshots (driver.Recording): every method's stored states, one set of names
    "snap_time": (("snapshot",), "s"),  # chain time of the snapshot (methods with a clock)
    "snap_step": (("snapshot",), "1"),  # step of the snapshot, counted from the start of the chain
    "snap_pos": (("snapshot", "particle", "xy"), "cm"),
    "snap_velocity": (("snapshot", "particle", "xy"), "cm s-1"),
    "snap_pressure": (("snapshot", "particle"), "N cm-2"),
    "snap_force": (("snapshot", "particle", "xy"), "N"),  # out-of-balance force (static methods)
    "snap_vessel": (("snapshot", "particle"), "1"),  # index of the vessel whose x range holds it, -1 none
    "snap_status": (("snapshot", "particle"), "1"),  # at_rest.STATUS: 0 in the tank, 1 past its walls
}


def history_problems(history):
    """The ways a Result.history breaks the naming rule above: [] when it keeps it."""
    bad = []
    for name, (dims, _, units, *_rest) in history.items():
        want = next((d for p, d in PREFIX_DIM.items() if name.startswith(p)), None)
        if want is not None and (not dims or dims[0] != want):
            bad.append(f"{name}: dims {dims}, its prefix says '{want}' first")
        if name in SHARED_HISTORY and (tuple(dims), units) != SHARED_HISTORY[name]:
            bad.append(f"{name}: dims {tuple(dims)} units '{units}', shared as {SHARED_HISTORY[name]}")
    return bad


@dataclass
class Result:
    """Outcome of one run of any method (arrays in cm, N, s).

    history / fields / measures map a run-file variable name to (dims, array, units,
    long_name[, attrs]); history names start with hist_ (dims ("record",), per
    record), sample_ (("sample", ...), per diagnostic sample) or snap_
    (("snapshot", ...)), the quantities of SHARED_HISTORY under their shared
    names; fields dims start with "particle"; measures are the at-rest and wall numbers
    every driven run gets from the driver (at_rest.AT_REST: their names, dims and units).  A run file holds no NaN: a variable whose values may be
    missing says why in attrs {"missing": "..."} (runfile.finite).
    """

    method: str  # registry name, e.g. "isa", "sph", "mps"
    variant: str  # registry variant name, e.g. "paper"
    pos0: np.ndarray  # (N, 2) initial positions, cm
    pos: np.ndarray  # (N, 2) final positions, cm
    weight: np.ndarray  # (N,) particle weight m g, N
    contact_wall: np.ndarray  # (C,) int wall index of each contact / panel
    contact_point: np.ndarray  # (C, 2) point on the wall, cm
    contact_force: np.ndarray  # (C, 2) force of the wall on the liquid, N
    status: str  # one of OUTCOMES
    message: str  # one line: why it stopped, with the step
    steps: int  # total steps at the end, counted from the start of the chain
    start_step: int  # steps already taken by the runs this one continues
    wall_time: float  # s, solver only (compilation excluded)
    force_evals: int  # force (or pressure-solve) evaluations in this run
    residual: float  # final value of the method's convergence measure
    residual_name: str  # e.g. "max|F|" or "kinetic energy"
    residual_units: str
    sim_time: float = float("nan")  # s of physical time simulated (dynamic methods)
    spacing: float = float("nan")  # cm, initial particle spacing (free-surface strip width)
    history: dict = field(default_factory=dict)
    fields: dict = field(default_factory=dict)
    params: dict = field(default_factory=dict)  # scalar settings, written as attributes
    measures: dict = field(default_factory=dict)  # at_rest.AT_REST variables (driver.drive writes them)

    def __post_init__(self):
        if self.status not in OUTCOMES:
            raise ValueError(f"unknown outcome '{self.status}'")


def wall_resultants(contact_wall, contact_force, n_walls):
    """(W, 2) resultant force [N] of each wall on the liquid, summed over its contacts."""
    out = np.zeros((n_walls, 2))
    np.add.at(out, np.asarray(contact_wall, int), np.asarray(contact_force, float))
    return out
