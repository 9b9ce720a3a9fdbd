"""The toy as a dynamic tank method: masses on a square lattice filling the first vessel (cell centres, spacing
dx, each weighing W / N), linear springs to their four neighbours, compression-only springs against the floor
and the side walls, released under gravity with a damping force -m c v, stepped in compiled chunks
(kernels.advance) by the one run driver (isaflow.driver) until at rest by isaflow.rest.  The floor spring of a
column shortens by springs.strain dx under its column; c = 2 zeta omega_1 damps the column's first mode
(omega_1 = 2 sqrt(k / m) sin(pi / (2 (2 ny + 1))), a chain of ny masses on a spring).  Units cm, N, s."""

import math

import numpy as np

from ... import driver, rest as R
from ...contract import Result, wall_resultants
from ...core.units import G, VELOCITY
from ...inputs import InputError
from ...tank import vessel_counts
from . import checks
from . import kernels as K

REFERENCES = ("none: a test method (tests/test_add_a_method.py)",)


def _walls(tank):
    """(floor, left, right) wall indices of the first vessel: the horizontal wall at its floor and the vertical
    walls at its ends; InputError if the vessel is no such box."""
    (x0, x1), y0 = tank.first_vessel
    w = tank.walls

    def find(test, what):
        k = [i for i, (a, b, c, d) in enumerate(w) if test(a, b, c, d)]
        if not k:
            raise InputError(f"{tank.path}: field 'walls': the toy needs {what} of the first vessel")
        return k[0]

    return (find(lambda a, b, c, d: b == d == y0 and min(a, c) <= x0 and max(a, c) >= x1, "a flat floor"),
            find(lambda a, b, c, d: a == c == x0, "a vertical left wall"),
            find(lambda a, b, c, d: a == c == x1, "a vertical right wall"))


def check(tank, settings, start=None):
    if start is not None:
        raise InputError("--start: the toy always starts from its lattice")
    _walls(tank)


def warm_up(threads=None):
    """Compile (or load from numba's cache) the kernel a run times, on one mass on the floor."""
    par = np.array([1.0, G, 1.0, 1.0, 0.5, 1.0, 1e-3])
    K.advance(np.array([[0.5, 0.5]]), np.zeros((1, 2)), np.zeros((0, 2), np.int64), np.zeros(1, np.int64),
              np.array([[0.0, 1.0]]), np.zeros(1), par, 1, np.zeros((1, 2)), np.zeros((1, 2)), np.zeros((1, 2)))


class _Stepper:
    """The toy for driver.drive: one advance is one compiled chunk of time.chunk s, one rest sample."""

    def __init__(self, tank, s):
        self.tank, self.s = tank, s
        nx, ny, dx = checks.lattice(tank, s)
        (x0, x1), y0 = tank.first_vessel
        gx, gy = np.meshgrid(x0 + dx * (np.arange(nx) + 0.5), y0 + dx * (np.arange(ny) + 0.5))
        self.pos = np.column_stack([gx.ravel(), gy.ravel()])  # row by row: mass i = row nx + column
        self.pos0, self.vel = self.pos.copy(), np.zeros_like(self.pos)
        idx = np.arange(nx * ny).reshape(ny, nx)
        self.bonds = np.concatenate([np.column_stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()]),
                                     np.column_stack([idx[:-1].ravel(), idx[1:].ravel()])]).astype(np.int64)
        floor, left, right = _walls(tank)
        rows = [(idx[0], floor, (0.0, 1.0), y0), (idx[:, 0], left, (1.0, 0.0), x0), (idx[:, -1], right, (-1.0, 0.0), -x1)]
        self.cpart = np.concatenate([r[0] for r in rows]).astype(np.int64)
        self.cwall = np.concatenate([np.full(len(r[0]), r[1]) for r in rows])
        self.cnorm = np.concatenate([np.tile(r[2], (len(r[0]), 1)) for r in rows])
        self.coff = np.concatenate([np.full(len(r[0]), r[3]) for r in rows])
        self.n, self.ny, self.dx = nx * ny, ny, dx
        self.held = tank.weight
        m = self.held / self.n / G
        self.k = ny * m * G / (s["springs.strain"] * dx)
        self.omega1 = 2 * math.sqrt(self.k / m) * math.sin(math.pi / (2 * (2 * ny + 1)))
        self.dt = checks.time_step(tank, s)
        self.par = np.array([m, G, self.k, dx, dx / 2, 2 * s["springs.damping_ratio"] * self.omega1, self.dt])
        self.n_chunk = max(1, int(round(s["time.chunk"] / self.dt)))
        self.n_total = int(math.ceil(s["time.t_max"] / self.dt))
        self.f, self.cf, self.cf_sum = np.zeros_like(self.pos), np.zeros((len(self.cpart), 2)), np.zeros((len(self.cpart), 2))
        self.depth0 = ny * dx
        self.box = np.asarray(tank.escape_box(), float)
        self.t0, self.done, self.t, self.ke = 0.0, 0, 0.0, 0.0
        self.rec = {k: [] for k in ("time", "kinetic", "rms", "walls", "count", "contacts")}

    def _rms(self):
        return math.sqrt(2 * self.ke / (self.par[0] * self.n))

    def advance(self):
        n = min(self.n_chunk, self.n_total - self.done)
        code, done, self.ke = K.advance(self.pos, self.vel, self.bonds, self.cpart, self.cnorm, self.coff, self.par, n,
                                        self.f, self.cf, self.cf_sum)
        self.done += done
        self.t = self.t0 + self.done * self.dt
        if code == K.NONFINITE:
            return "nonfinite", f"a mass became non-finite at step {self.done} (t = {self.t:.4g} s)"
        x, y = self.pos.T
        out = (x < self.box[0]) | (x > self.box[2]) | (y < self.box[1]) | (y > self.box[3])
        if out.any():
            return "escaped", f"mass {int(np.argmax(out))} left the tank's box at step {self.done} (t = {self.t:.4g} s)"
        self.rec["contacts"].append(self.cf_sum / done)
        return None

    def record(self):
        """The chunk's sample: (t, e = KE / (W h)) for the rest monitor."""
        rec = self.rec
        rec["time"].append(self.t)
        rec["kinetic"].append(self.ke)
        rec["rms"].append(self._rms())
        rec["walls"].append(wall_resultants(self.cwall, rec["contacts"][-1], len(self.tank.walls)))
        rec["count"].append(vessel_counts(self.pos, self.tank.vessels))
        return self.t, R.energy_ratio(self.ke, self.held, self.depth0)

    def spent(self):
        return self.done >= self.n_total

    def fraction_done(self):
        return self.done / self.n_total

    def clock(self):
        return self.t, self.done

    def state(self):
        return {"pos": self.pos.copy(), "velocity": self.vel.copy()}

    def recording(self):
        s = self.s
        return driver.Recording(s["time.snapshot_every"], s["time.snapshot_megabytes"], self.tank.walls,
                                self.tank.vessels, tuple(self.box), self.dx)

    def rest_message(self, monitor):
        return (f"at rest: e = KE / (W h) < {monitor.limit:g} for {monitor.window:g} s from t = "
                f"{monitor.time_to_rest():.4g} s, reached at t = {self.t:.4g} s (step {self.done})")

    def limit_message(self, monitor):
        return f"time limit {self.s['time.t_max']:g} s reached at step {self.done}, not at rest: e = {monitor.last:.3g}"

    def progress(self, monitor):
        return f"toy: t = {self.t:.3f} s of {self.s['time.t_max']:g} s, e = {monitor.last:.3g}"

    def result(self, run):
        """contract.Result: the contacts' forces are their means over the last rest window's chunks."""
        rec = self.rec
        times = np.array(rec["time"])
        window = times >= times[-1] - run.monitor.window + 1e-12
        history = {
            "sample_time": (("sample",), times, "s", "chain time at the end of the chunk"),
            "sample_kinetic": (("sample",), np.array(rec["kinetic"]), "N cm", "kinetic energy at the chunk's end"),
            "sample_rms_speed": (("sample",), np.array(rec["rms"]), VELOCITY, "rms speed at the chunk's end"),
            "sample_wall_resultant": (("sample", "wall", "xy"), np.array(rec["walls"]), "N",
                                      "force of each wall on the masses, mean over the chunk"),
            "sample_vessel_count": (("sample", "vessel"), np.array(rec["count"], np.int64), "1", "masses in each vessel"),
        }
        rounded = abs(self.depth0 - self.tank.depth) > 1e-9
        return Result(
            method="toy", variant="damped", pos0=self.pos0, pos=self.pos.copy(), weight=np.full(self.n, self.held / self.n),
            contact_wall=self.cwall, contact_point=self.pos[self.cpart] - (np.sum(self.pos[self.cpart] * self.cnorm, 1)
                                                                            - self.coff)[:, None] * self.cnorm,
            contact_force=np.mean(np.array(rec["contacts"])[window], axis=0), status=run.status, message=run.message,
            steps=self.done, start_step=0, wall_time=run.wall_time, force_evals=self.done, residual=self._rms(),
            residual_name="rms speed", residual_units=VELOCITY, sim_time=self.t, spacing=self.dx, history=history,
            fields={"velocity": (("particle", "xy"), self.vel.copy(), VELOCITY, "velocity of each mass")},
            params={"stiffness_N_cm": self.k, "damping_rate_s": float(self.par[5]), "dt_s": self.dt,
                    "first_mode_rad_s": self.omega1, "t_max_s": self.s["time.t_max"], "layer_pitch": self.dx, "held_weight": self.held,
                    "initial_depth": self.depth0,
                    "tank_difference": (f"depth rounded to whole rows: {self.depth0:g} cm (tank {self.tank.depth:g} cm), "
                                        f"weight held at {self.held:g} N") if rounded else "none"})


def solve(tank, settings, variant, resolution, start=None, log=None, threads=None):
    """Drive the toy (driver.drive, judged at rest by isaflow.rest) -> contract.Result."""
    rest_cfg = R.load()
    stepper = _Stepper(tank, settings)
    res = driver.drive(stepper, rest_cfg, log, recording=stepper.recording())
    res.variant = variant
    return res
