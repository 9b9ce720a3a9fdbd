"""Run WCSPH on a tank: set up, and a stepper of compiled chunks for driver.drive -> contract.Result.

Outcomes: ``converged`` (the liquid is at rest by isaflow.rest, the one criterion of every
dynamic method: e = KE / (W h) below its ratio for its window), ``step_limit`` (the run's
time limit), ``escaped`` (a particle would cross a wall, or left the walls' bounding box,
which is open max_drop above the walls' top: a splash may rise over the walls and fall back),
``nonfinite``.  Wall loads are the wall particles' forces on the liquid averaged over the
last rest window, spread over the tank's wall panels (core.panels), one set of panels per
wetted face.  A run continued from a run file (``start``) keeps the chain's clock and step
count and rebuilds the pair list where the run it continues had built it, so that a split run
equals a straight one bit for bit.  Units cm, N, s (core.units).
"""

import collections
import math
import os
import time

import numba
import numpy as np

from ... import driver, rest as R
from ...contract import Result
from ...core import smoothing
from ...core.geometry import bounding_box
from ...core.panels import wall_panels
from ...core.units import DENSITY_2D, G, VELOCITY
from ...inputs import InputError
from ...tank import vessel_counts
from . import kernels as K
from . import particles as P
from . import settings as S

CODES = {K.CROSSED: "escaped", K.LEFT_BOX: "escaped", K.NONFINITE: "nonfinite"}


def lattice_density_sum(kind, h, dx, dy):
    """sum_b W(r_ab) [1/cm^2] over an infinite dx x dy lattice (its undisturbed summed density / mass)."""
    n = int(np.ceil(2 * h / min(dx, dy))) + 1
    gx, gy = np.meshgrid(np.arange(-n, n + 1) * dx, np.arange(-n, n + 1) * dy)
    return float(smoothing.W(smoothing.NAMES[kind], np.hypot(gx, gy).ravel(), h, 2).sum())


def density_ratio(s, c0):
    """rho / rho_ref at depth d [cm] of a liquid at rest (EOS inverted for P = rho_ref g d)."""
    if s["eos"] == "tait":
        return lambda d: (1.0 + s["gamma"] * G * np.asarray(d) / c0**2) ** (1.0 / s["gamma"])
    return lambda d: 1.0 + G * np.asarray(d) / c0**2


def pack(s, h, mass, rho_ref, c0, dt, kind, cell=0.0):
    """Settings -> the kernels' parameter vector (indices in kernels); cell: spacing [cm]."""
    par = np.zeros(K.NPAR)
    par[K.LJ_D] = 2 * G * s["max_drop"]  # v_ref^2, cm^2/s^2
    par[K.LJ_R0] = s["repulsion_radius"] * cell
    par[[K.H, K.MASS, K.RHO0, K.C0, K.GAMMA, K.ALPHA, K.DELTA, K.GRAV, K.DT]] = (
        h, mass, rho_ref, c0, s["gamma"], s["alpha"], s["delta"], G, dt)
    par[K.SKIN] = s["skin"] * h
    par[K.KERNEL] = kind
    par[K.NORM] = smoothing.NORM[kind, 2]
    par[K.TAIT] = s["eos"] == "tait"
    par[K.CLAMP] = s["negative_pressure"] == "clamp"
    par[K.SUMMATION] = s["density"] == "summation"
    par[K.WALL_VISC] = s["wall_viscosity"]
    return par


def _start_value(start, name, default):
    if name in start:
        return start[name].values
    return start.attrs.get(name, default)


def setup(tank, s, resolution, start=None, on_wall=False):
    """Initial state: dict of arrays and scalars (see _run).  start: a run Dataset to continue
    (its pos, velocity, density, list_pos, acceleration, weight, lattice cell, clock and step count)."""
    (x0, x1), floor_y = tank.first_vessel
    kind = smoothing.kernel_id(s["kernel"])
    c0 = s["sound_speed_factor"] * math.sqrt(2 * G * s["max_drop"])
    t0, step0, acc = 0.0, 0, None
    if start is not None:
        dx, dy = float(start.attrs["cell_dx"]), float(start.attrs["cell_dy"])
        pos = start["pos"].values.copy()
        vel = start["velocity"].values.copy()
        mass = float(start["weight"].values[0]) / G
        t0 = float(_start_value(start, "sim_time", 0.0))
        step0 = int(_start_value(start, "steps", 0))
        xref = start["list_pos"].values.copy() if "list_pos" in start else pos.copy()
        acc = start["acceleration"].values.copy() if "acceleration" in start else None
        depth0 = float(start.attrs.get("initial_depth", tank.depth))
    else:
        nx, ny = P.lattice_shape(x1 - x0, tank.depth, resolution.get("particles"), resolution.get("spacing"),
                                 tank.liquid_area)
        pos, (dx, dy) = P.liquid_lattice(x0, floor_y, x1 - x0, tank.depth, nx, ny, tank.vessel_polygon(0), tank.walls)
        if len(pos) < 2:
            raise InputError(f"{tank.path}: field 'liquid.depth': {len(pos)} cell(s) of {dx:.3g} x {dy:.3g} cm lie half "
                             f"a cell inside the first vessel below the depth; a liquid needs at least 2")
        vel = np.zeros_like(pos)
        mass = tank.weight / len(pos) / G
    h = s["h_factor"] * math.sqrt(dx * dy)
    rho_ref = mass * lattice_density_sum(kind, h, dx, dy) if s["density"] == "summation" else mass / (dx * dy)
    ratio = density_ratio(s, c0)
    if start is None:
        pos[:, 1] = P.hydrostatic_heights(pos[:, 1], floor_y, tank.depth, ratio)
        rho = rho_ref * ratio(tank.depth - (pos[:, 1] - floor_y))
        if on_wall:
            k = np.argmin(np.hypot(pos[:, 0] - 0.5 * (x0 + x1), pos[:, 1] - floor_y))
            pos[k, 1] = floor_y
        xref = pos.copy()
        depth0 = float(pos[:, 1].max() - floor_y + dy / 2)
    else:
        rho = start["density"].values.copy()
    two = P.wet_back(tank.walls, tank.vessels) if tank.spec.get("vessels") else None
    wpos, owner, face = P.wall_particles(tank.walls, dx, dy, 2 * h, origin=(x0, floor_y), two_faced=two)
    dt = min(s["cfl"] * h / c0, 0.25 * math.sqrt(h / G))
    return dict(pos=pos, vel=vel, rho=rho, xref=xref, wpos=wpos, owner=owner, face=face, dx=dx, dy=dy, h=h, c0=c0,
                dt=dt, mass=mass, rho_ref=rho_ref, kind=kind, t0=t0, step0=step0, depth0=depth0, acc=acc,
                par=pack(s, h, mass, rho_ref, c0, dt, kind, math.sqrt(dx * dy)))


def set_threads(threads):
    """Use ``threads`` numba threads (1: the serial passes); ValueError beyond numba's pool.

    With more than one thread, OMP_WAIT_POLICY defaults to PASSIVE (unless the caller set it) before
    numba starts its OpenMP pool: a step has seven parallel regions, and on the shared 2-core machine
    (load 4-6) the default spin-then-sleep waiting made 2 threads 15-25x slower than 1 (measured
    2,300-4,500 against 250-270 ns per particle-step at N = 20,000), passive waiting 200 ns."""
    threads = int(threads)
    if threads < 1 or threads > numba.config.NUMBA_NUM_THREADS:
        raise ValueError(f"threads = {threads}: choose 1 to {numba.config.NUMBA_NUM_THREADS} "
                         "(NUMBA_NUM_THREADS bounds numba's pool)")
    if threads > 1:
        os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
        numba.set_num_threads(threads)
    return threads


def warm_up(threads=1):
    """Compile (or load from numba's cache) the kernels so timings exclude it."""
    from ...tank import Tank

    tank = Tank("warm-up", {"name": "box", "walls": [{"name": "l", "from": [0, 4], "to": [0, 0]},
                                                      {"name": "f", "from": [0, 0], "to": [4, 0]},
                                                      {"name": "r", "from": [4, 0], "to": [4, 4]}],
                            "liquid": {"weight": 1.0, "depth": 2.0}}, "")
    for variant in ("summation", "continuity"):
        s = S.resolve(S.read_file(), "wcsph")
        s.update(density=variant, chunk_time=0.001)
        _run(tank, s, {"spacing": 1.0}, None, False, 0.002, lambda *a: None, threads)


def solve(tank, variant="wcsph", resolution=None, overrides=None, start=None, on_wall=False, t_max=None,
          settings_path=S.DEFAULT_PATH, log=print, threads=1):
    """Run SPH on a scene.Tank; returns contract.Result.

    resolution: {"particles": N} or {"spacing": cm} (ignored with start);
    overrides: {setting: value}; start: run Dataset to continue (the flow starts
    from the single vessel at rest; a continuation keeps the chain's clock and
    steps); on_wall: put the liquid particle nearest the floor's middle on the
    floor; t_max: time limit of this run, s simulated from its start (default
    t_max_single or t_max_flow from the settings, by whether the tank has
    vessels); threads: numba threads of the pair passes (results do not depend
    on it; recorded in params['threads']).
    """
    s = S.resolve(S.read_file(settings_path), variant, overrides, settings_path)
    res = _run(tank, s, resolution or {"particles": 180}, start, on_wall, t_max, log, set_threads(threads))
    res.variant = variant
    return res


def start_dataset(res):
    """The part of a run file a continuation reads (setup), from a Result: pos, velocity, density,
    list_pos, acceleration, weight, sim_time, steps and the lattice cell (xarray Dataset)."""
    import xarray as xr

    f = res.fields
    return xr.Dataset({"pos": (("particle", "xy"), res.pos), "velocity": f["velocity"][:2],
                       "density": f["density"][:2], "list_pos": f["list_pos"][:2],
                       "acceleration": f["acceleration"][:2],
                       "weight": (("particle",), res.weight), "sim_time": ((), res.sim_time),
                       "steps": ((), res.steps)},
                      attrs={k: res.params[k] for k in ("cell_dx", "cell_dy", "initial_depth")})


def _panels(walls, length, owner, face, wpos, force, dx, dy):
    """Contacts of the wall-particle forces: per face, spread over the panels (face 1: the back of a
    thin wall, its loaded panels only).  Returns (wall, point, force, side) with side 0 front (liquid
    side), 1 back."""
    out = [], [], [], []
    for f in (0, 1):
        on = face == f
        if f == 1 and not on.any():
            continue
        cw, cpt, cf = P.wall_contacts(walls, wpos[on], owner[on], force[on])
        pw, pc, pf = P.spread_to_panels(walls, length, cw, cpt, cf, dx, dy)
        if f == 1:  # only the loaded back-face panels (a dry back face adds no contacts)
            keep = np.isin(pw, np.unique(owner[on])) & (np.abs(pf).sum(1) > 0)
            pw, pc, pf = pw[keep], pc[keep], pf[keep]
        for lst, arr in zip(out, (pw, pc, pf, np.full(len(pw), f))):
            lst.append(arr)
    return tuple(np.concatenate(a) for a in out)


class _Stepper:
    """WCSPH on a tank for driver.drive: one advance is one compiled chunk (kernels.advance) of chunk_time s."""

    def __init__(self, tank, s, resolution, start, on_wall, t_max, threads, rest_cfg):
        self.tank, self.s, self.resolution, self.start, self.on_wall = tank, s, resolution, start, on_wall
        self.threads, self.rest_cfg = threads, rest_cfg
        self.st = st = setup(tank, s, resolution, start, on_wall)
        self.nf, self.nw = nf, nw = len(st["pos"]), len(st["wpos"])
        self.x = np.concatenate([st["pos"], st["wpos"]])
        self.v, self.par = st["vel"].copy(), st["par"]
        self.rho = np.concatenate([st["rho"], np.full(nw, st["rho_ref"])])
        self.p = np.zeros(nf + nw)
        self.walls = walls = tank.walls
        # the vessels are open at the top: a splash may rise above the walls and fall back in (Tank.escape_box)
        wall_box = bounding_box(walls)
        self.box = np.asarray(tank.escape_box(), float)
        rc = 2 * st["h"] + self.par[K.SKIN]
        # the cell grid depends on the tank and the lattice only, so a continuation builds the same lists
        lo, hi = np.minimum(wall_box[:2], st["wpos"].min(0)) - rc, np.maximum(wall_box[2:], st["wpos"].max(0)) + rc
        self.grid_box = np.array([lo[0], lo[1], hi[0], hi[1]])
        self.xref = st["xref"]
        self.lst = K.list_pairs(np.concatenate([self.xref, st["wpos"]]), nf, self.grid_box, rc, walls,
                                K.reach_of(self.par))
        self.wk, self.fk = np.empty(len(self.lst[0])), np.empty(len(self.lst[0]))
        self.acc = np.zeros((nf, 2))
        self.wall_force, self.force_sum = np.zeros((nw, 2)), np.zeros((nw, 2))
        pw, pc, _, _ = wall_panels(walls, s["panel_length"])
        self.npanel = np.bincount(pw, minlength=len(walls)).astype(np.int64)
        self.panel0 = np.concatenate([[0], np.cumsum(self.npanel)[:-1]]).astype(np.int64)
        self.panel_sum = np.zeros((len(pw), 2))
        K.evaluate(self.x, self.v, self.rho, self.p, nf, walls, self.par, self.lst, self.wk, self.fk, self.acc,
                   self.wall_force, self.panel0, self.npanel, self.panel_sum, threads)
        if st["acc"] is not None:  # the viscosity took the half-step velocities: the run's own accelerations
            self.acc[:] = st["acc"]
        self.diag = np.zeros(4)
        self.flow = len(tank.spec.get("vessels", [])) > 1
        self.t_max = t_max or (s["t_max_flow"] if self.flow else s["t_max_single"])
        self.dt = dt = st["dt"]
        self.n_total = max(1, int(round(self.t_max / dt)))
        self.n_chunk = max(1, int(round(s["chunk_time"] / dt)))
        self.held = st["mass"] * G * nf
        n_window = max(1, int(math.ceil(rest_cfg["window"] / (self.n_chunk * dt))))
        self.window, self.lj_window = collections.deque(maxlen=n_window), collections.deque(maxlen=n_window)
        self.vessels = tank.vessels
        self.rec = collections.defaultdict(list)
        self.t0, self.step0 = st["t0"], st["step0"]
        self.done_total, self.builds = 0, 0
        self.ke = 0.5 * st["mass"] * float(np.sum(self.v * self.v))
        self.t = self.t0
        self.started = time.perf_counter()

    def _rms(self):
        return math.sqrt(2 * self.ke / (self.st["mass"] * self.nf))

    def advance(self):
        """One chunk; (status, message) if the kernel stopped on a particle, else None."""
        x, nf, dt = self.x, self.nf, self.dt
        n = min(self.n_chunk, self.n_total - self.done_total)
        self.force_sum[:] = 0.0
        self.panel_sum[:] = 0.0
        code, done, self.lst, self.wk, self.fk = K.advance(
            x, self.v, self.rho, self.p, nf, self.walls, self.box, self.grid_box, self.par, n, self.xref, self.lst,
            self.wk, self.fk, self.acc, self.wall_force, self.force_sum, self.panel0, self.npanel, self.panel_sum,
            self.diag, self.threads)
        self.done_total += done
        self.builds += int(self.diag[2])
        self.t = t = self.t0 + self.done_total * dt
        if done:
            self.window.append(self.force_sum / done)
            self.lj_window.append(self.panel_sum / done)
            self.ke = self.diag[1]
        if code == K.OK:
            return None
        what = {K.CROSSED: "would cross a wall", K.LEFT_BOX: "left the walls' bounding box (open max_drop above)",
                K.NONFINITE: "became non-finite"}[code]
        k = int(self.diag[3])
        return CODES[code], (f"particle {k}, at ({x[k, 0]:.4g}, {x[k, 1]:.4g}) cm, {what} at step "
                             f"{self.step0 + self.done_total} (t = {t:.4g} s)")

    def record(self):
        """The chunk's diagnostic sample; returns (t, e) for the rest monitor."""
        st, rec, x, nf = self.st, self.rec, self.x, self.nf
        sample = self.t, R.energy_ratio(self.ke, self.held, st["depth0"])
        rec["sample_time"].append(self.t)
        rec["sample_rms_speed"].append(self.diag[0])
        rec["sample_kinetic"].append(self.ke)
        per_wall = np.zeros((len(self.walls), 2))
        np.add.at(per_wall, st["owner"], self.window[-1] if self.window else 0.0)
        rec["sample_wall_resultant"].append(per_wall)
        rec["sample_vessel_count"].append(vessel_counts(x[:nf], self.vessels))
        return sample

    def spent(self):
        return self.done_total >= self.n_total

    def fraction_done(self):
        return self.done_total / self.n_total

    def clock(self):
        """(chain time s, chain step) of the current state (driver.drive's snapshots)."""
        return self.t, self.step0 + self.done_total

    def state(self):
        """Copies of the liquid's positions, velocities and pressures (driver.drive's snapshots)."""
        return {"pos": self.x[:self.nf].copy(), "velocity": self.v[:self.nf].copy(), "pressure": self.p[:self.nf].copy()}

    def recording(self):
        """The driver's Recording of this run: snapshots every settings.snapshot_every_single s (single vessel) or
        _flow s (a tank of vessels), within snapshot_megabytes; the tank's walls, vessels and box; the strip
        width sqrt(dx dy) of the free surface."""
        s = self.s
        return driver.Recording(s["snapshot_every_flow"] if self.flow else s["snapshot_every_single"],
                                s["snapshot_megabytes"], self.walls, self.vessels, tuple(self.box),
                                math.sqrt(self.st["dx"] * self.st["dy"]))

    def rest_message(self, monitor):
        return (f"at rest: e = KE / (W h) < {self.rest_cfg['energy_ratio']:g} for {self.rest_cfg['window']:g} s from "
                f"t = {monitor.time_to_rest():.4g} s, reached at t = {self.t:.4g} s (step "
                f"{self.step0 + self.done_total}); rms speed {self._rms():.3g} cm/s")

    def limit_message(self, monitor):
        return (f"time limit {self.t_max:g} s reached at t = {self.t:.4g} s (step {self.step0 + self.done_total}), "
                f"not at rest: e = {monitor.last:.3g}, rms speed {self._rms():.3g} cm/s")

    def progress(self, monitor):
        now = time.perf_counter()
        return (f"sph: t = {self.t:.3f} s ({self.done_total * self.dt:.3f} / {self.t_max:g} s of this run), step "
                f"{self.step0 + self.done_total}, rms speed {self._rms():.3g} cm/s, {self.nf} particles, "
                f"{(now - self.started) / max(self.done_total, 1) / self.nf * 1e9:.0f} ns/particle-step")

    def result(self, run):
        """contract.Result of the run (variant 'custom'; solve() names it)."""
        st, s, tank, walls, x, nf, nw = self.st, self.s, self.tank, self.walls, self.x, self.nf, self.nw
        p, rho, v, acc, xref, dt = self.p, self.rho, self.v, self.acc, self.xref, self.dt
        window, lj_window, rec = self.window, self.lj_window, self.rec
        held, ke = self.held, self.ke
        t0, step0, done_total, n_chunk, t_max = self.t0, self.step0, self.done_total, self.n_chunk, self.t_max
        start, resolution, on_wall, flow, vessels = self.start, self.resolution, self.on_wall, self.flow, self.vessels
        status, message, wall_time = run.status, run.message, run.wall_time
        mean_force = np.mean(np.array(window), axis=0) if window else np.zeros((nw, 2))
        cw, cp, cf, side = _panels(walls, s["panel_length"], st["owner"], st["face"], st["wpos"], mean_force,
                                   st["dx"], st["dy"])
        if lj_window:  # the safety net's panel forces, with the front faces' panels
            front = np.flatnonzero(side == 0)
            cf[front] += np.mean(np.array(lj_window), axis=0)
        (x0, x1), floor_y = tank.first_vessel
        left = int(np.count_nonzero((x[:nf, 0] >= x0) & (x[:nf, 0] < x1)))
        history = {
            "sample_time": (("sample",), np.array(rec["sample_time"]), "s", "chain time at the end of the diagnostic chunk"),
            "sample_rms_speed": (("sample",), np.array(rec["sample_rms_speed"]), VELOCITY, "largest rms liquid speed in the chunk"),
            "sample_kinetic": (("sample",), np.array(rec["sample_kinetic"]), "N cm", "kinetic energy at the chunk's end"),
            "sample_wall_resultant": (("sample", "wall", "xy"), np.array(rec["sample_wall_resultant"]), "N",
                                      "force of each wall on the liquid, mean over the chunk"),
            "sample_vessel_count": (("sample", "vessel"), np.array(rec["sample_vessel_count"], np.int64), "1",
                                    "liquid particles in each vessel"),
            "contact_side": (("contact",), side.astype(np.int8), "1",
                             "wall face of the panel: 0 its front (left, liquid side), 1 its back (thin dividing wall)"),
        }
        fields = {
            "pressure": (("particle",), p[:nf].copy(), "N cm-2", "particle pressure (equation of state)"),
            "density": (("particle",), rho[:nf].copy(), DENSITY_2D, "particle density"),
            "velocity": (("particle", "xy"), v.copy(), VELOCITY, "particle velocity"),
            "list_pos": (("particle", "xy"), xref.copy(), "cm",
                         "positions at the last pair-list build (a continuation rebuilds the list there)"),
            "acceleration": (("particle", "xy"), acc.copy(), "cm s-2",
                             "acceleration at the end (its viscosity took the half-step velocities; a continuation "
                             "starts from it)"),
        }
        params = {}  # the settings themselves reach the run file under their dotted keys (run.write)
        initial_depth = st["depth0"]
        diff = [f"weakly compressible: the column holds {held:g} N compressed to its hydrostatic density, its "
                f"surface {initial_depth:.4g} cm (tank {tank.depth:g} cm)"] if start is None else [
                f"continues a run whose initial depth was {initial_depth:.4g} cm (tank {tank.depth:g} cm)"]
        if abs(held - tank.weight) > 1e-9 * tank.weight:
            diff.append(f"weight held {held:g} N (tank {tank.weight:g} N)")
        params.update(
            first_vessel_width=float(x1 - x0), cell_dx=st["dx"], cell_dy=st["dy"],
            smoothing_length=st["h"], sound_speed=st["c0"], dt=dt, particle_mass=st["mass"], rho_ref=st["rho_ref"],
            wall_particles=nw, two_faced_walls=", ".join(n for n, f in zip(tank.wall_names, P.wet_back(walls, vessels))
                                                         if f and flow) or "none",
            t_max=t_max, panel_length=s["panel_length"], load_window=len(window) * n_chunk * dt,
            resolution=str(resolution) if start is None else "continued", on_wall=str(bool(on_wall)),
            threads=int(self.threads), layer_pitch=st["dy"], held_weight=held, initial_depth=initial_depth,
            tank_difference="; ".join(diff),
            particles_left=left, list_builds=self.builds)
        return Result(
            method="sph", variant="custom", pos0=st["pos"], pos=x[:nf].copy(), weight=np.full(nf, st["mass"] * G),
            contact_wall=cw, contact_point=cp, contact_force=cf, status=status, message=message,
            steps=step0 + done_total, start_step=step0, wall_time=wall_time, force_evals=done_total + 1,
            residual=math.sqrt(2 * ke / (st["mass"] * nf)), residual_name="rms speed", residual_units=VELOCITY,
            sim_time=t0 + done_total * dt, history=history, fields=fields, params=params)


def _run(tank, s, resolution, start, on_wall, t_max, log, threads=1):
    """Set up the run (setup) and drive it (driver.drive) -> contract.Result; arguments as solve's."""
    rest_cfg = R.load()
    stepper = _Stepper(tank, s, resolution, start, on_wall, t_max, threads, rest_cfg)
    return driver.drive(stepper, rest_cfg, log, recording=stepper.recording())
