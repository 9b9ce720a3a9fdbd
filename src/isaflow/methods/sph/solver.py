"""Run WCSPH on a tank: set up, advance the compiled loop in chunks, classify -> contract.Result.

Outcomes: ``converged`` (rms speed below rest_speed for rest_window s),
``step_limit`` (time limit), ``escaped`` (a particle crossed a wall or left
the walls' bounding box), ``nonfinite``.  Wall loads are the wall particles'
forces on the liquid averaged over the last rest_window s, summed over the
tank's wall panels (core.panels).  Units cm, N, s (core.units).
"""

import collections
import math
import time

import numpy as np

from ...contract import Result
from ...core import smoothing
from ...core.geometry import bounding_box
from ...core.panels import wall_panels
from ...core.units import DENSITY_2D, G, VELOCITY
from . import kernels as K
from . import particles as P
from . import settings as S

CODES = {K.CROSSED: "escaped", K.LEFT_BOX: "escaped", K.NONFINITE: "nonfinite"}


def vessels_of(tank):
    """[(name, (xmin, xmax) cm)] of the tank's vessels; one spanning the walls if it names none."""
    w = tank.walls
    return tank.vessels or [("vessel", (float(w[:, [0, 2]].min()), float(w[:, [0, 2]].max())))]


def first_vessel(tank):
    """(x0, x1, floor_y) [cm] of the tank's first vessel (its lowest horizontal wall)."""
    x0, x1 = vessels_of(tank)[0][1]
    walls = tank.walls
    horiz = np.isclose(walls[:, 1], walls[:, 3])
    over = np.minimum(walls[:, [0, 2]].max(1), x1) - np.maximum(walls[:, [0, 2]].min(1), x0) > 1e-9
    return x0, x1, float(walls[horiz & over, 1].min())


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


def setup(tank, s, resolution, start=None, on_wall=False):
    """Initial state: dict of arrays and scalars (see solve).  start: a run Dataset
    to continue (its pos, velocity, density and lattice cell)."""
    x0, x1, floor_y = first_vessel(tank)
    kind = smoothing.kernel_id(s["kernel"])
    c0 = s["sound_speed_factor"] * math.sqrt(2 * G * s["max_drop"])
    if start is not None:
        dx, dy = float(start.attrs["cell_dx"]), float(start.attrs["cell_dy"])
        pos = start["pos"].values.copy()
        vel = start["velocity"].values.copy()
        mass = float(start["weight"].values[0]) / G
    else:
        nx, ny = P.lattice_shape(x1 - x0, tank.depth, resolution.get("particles"), resolution.get("spacing"))
        pos, (dx, dy) = P.liquid_lattice(x0, floor_y, x1 - x0, tank.depth, nx, ny)
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
    else:
        rho = start["density"].values.copy()
    wpos, owner = P.wall_particles(tank.walls, dx, dy, 2 * h, origin=(x0, floor_y))
    dt = min(s["cfl"] * h / c0, 0.25 * math.sqrt(h / G))
    return dict(pos=pos, vel=vel, rho=rho, wpos=wpos, owner=owner, dx=dx, dy=dy, h=h, c0=c0, dt=dt,
                mass=mass, rho_ref=rho_ref, kind=kind, par=pack(s, h, mass, rho_ref, c0, dt, kind, math.sqrt(dx * dy)))


def warm_up():
    """Compile (or load from numba's cache) the kernels so timings exclude it."""
    from ...tank import Tank

    tank = Tank("warm-up", {"name": "box", "walls": [{"name": "l", "from": [0, 4], "to": [0, 0]},
                                                      {"name": "f", "from": [0, 0], "to": [4, 0]},
                                                      {"name": "r", "from": [4, 0], "to": [4, 4]}],
                            "liquid": {"weight": 1.0, "depth": 2.0}}, "")
    for variant in ("summation", "continuity"):
        s = {k: v["value"] for k, v in S.load()["settings"].items()}
        s.update(density=variant, t_max_single=0.002, chunk_time=0.001)
        _run(tank, s, {"spacing": 1.0}, None, False, None, lambda *a: None)


def solve(tank, variant="wcsph", resolution=None, overrides=None, start=None, on_wall=False, t_max=None,
          settings_path=S.DEFAULT_PATH, log=print):
    """Run SPH on a scene.Tank; returns contract.Result.

    resolution: {"particles": N} or {"spacing": cm} (ignored with start);
    overrides: {setting: value}; start: run Dataset to continue (the flow starts
    from the single vessel at rest); on_wall: put the liquid particle nearest
    the floor's middle on the floor; t_max: time limit s (default t_max_single
    or t_max_flow from the settings, by whether the tank has vessels).
    """
    s = S.resolve(S.load(settings_path), variant, overrides)
    res = _run(tank, s, resolution or {"particles": 180}, start, on_wall, t_max, log)
    res.variant = variant
    return res


def _run(tank, s, resolution, start, on_wall, t_max, log):
    st = setup(tank, s, resolution, start, on_wall)
    nf, nw = len(st["pos"]), len(st["wpos"])
    x = np.concatenate([st["pos"], st["wpos"]])
    v, par = st["vel"].copy(), st["par"]
    rho = np.concatenate([st["rho"], np.full(nw, st["rho_ref"])])
    p = np.zeros(nf + nw)
    walls = tank.walls
    box = bounding_box(walls)
    lo, hi = x.min(0) - 2 * st["h"], x.max(0) + 2 * st["h"]
    grid_box = np.array([min(lo[0], box[0]), min(lo[1], box[1]), max(hi[0], box[2]), max(hi[1], box[3])])
    pi, pj, m = K.list_pairs(x, nf, grid_box, 2 * st["h"] + par[K.SKIN])
    wk, fk = np.empty(len(pi)), np.empty(len(pi))
    acc = np.zeros((nf, 2))
    wall_force, wsum, force_sum = np.zeros((nw, 2)), np.zeros((nw, 3)), np.zeros((nw, 2))
    K.evaluate(x, v, rho, p, nf, pi, pj, m, wk, fk, par, acc, wall_force, wsum)
    xref, diag = x[:nf].copy(), np.zeros(4)
    pw, pc, _, _ = wall_panels(walls, s["panel_length"])
    npanel = np.bincount(pw, minlength=len(walls)).astype(np.int64)
    panel0 = np.concatenate([[0], np.cumsum(npanel)[:-1]]).astype(np.int64)
    panel_sum = np.zeros((len(pw), 2))
    lj_window = collections.deque()
    flow = len(tank.spec.get("vessels", [])) > 1
    t_max = t_max or (s["t_max_flow"] if flow else s["t_max_single"])
    dt = st["dt"]
    n_chunk = max(1, int(round(s["chunk_time"] / dt)))
    window = collections.deque(maxlen=max(1, int(math.ceil(s["rest_window"] / (n_chunk * dt)))))
    vessels = vessels_of(tank)
    rec = collections.defaultdict(list)
    snaps = sorted(s["snapshot_times"])
    steps, t, rest, status, message = 0, 0.0, 0.0, None, ""
    started = last_log = time.perf_counter()
    while status is None:
        while snaps and snaps[0] <= t + 0.5 * dt:
            rec["snap_time"].append(t)
            rec["snap_pos"].append(x[:nf].copy())
            snaps.pop(0)
        n = min(n_chunk, max(1, int(round((t_max - t) / dt))))
        force_sum[:] = 0.0
        panel_sum[:] = 0.0
        code, done, pi, pj, m, wk, fk = K.advance(x, v, rho, p, nf, walls, box, grid_box, par, n, xref, pi, pj, m,
                                                   wk, fk, acc, wall_force, wsum, force_sum, panel0, npanel,
                                                   panel_sum, diag)
        steps += done
        t += done * dt
        if done:
            window.append(force_sum / done)
            lj_window.append(panel_sum / done)
            while len(lj_window) > window.maxlen:
                lj_window.popleft()
        rest = rest + done * dt if diag[0] < s["rest_speed"] else 0.0
        rec["sample_time"].append(t)
        rec["sample_vrms"].append(diag[0])
        rec["sample_kinetic"].append(diag[1])
        per_wall = np.zeros((len(walls), 2))
        np.add.at(per_wall, st["owner"], window[-1] if window else 0.0)
        rec["sample_wall_resultant"].append(per_wall)
        rec["sample_vessel_weight"].append([st["mass"] * G * np.count_nonzero((x[:nf, 0] >= a) & (x[:nf, 0] < b))
                                            for _, (a, b) in vessels])
        if code != K.OK:
            status = CODES[code]
            what = {K.CROSSED: "crossed a wall", K.LEFT_BOX: "left the walls' bounding box",
                    K.NONFINITE: "became non-finite"}[code]
            k = int(diag[3])
            message = f"particle {k}, at ({x[k, 0]:.4g}, {x[k, 1]:.4g}) cm before the step, {what} at step {steps} (t = {t:.4g} s)"
        elif rest >= s["rest_window"] - 0.5 * dt:
            status = "converged"
            message = (f"at rest: rms speed < {s['rest_speed']:g} cm/s for {s['rest_window']:g} s "
                       f"at t = {t:.4g} s (step {steps})")
        elif t >= t_max - 0.5 * dt:
            status = "step_limit"
            message = f"time limit {t_max:g} s reached at step {steps}, rms speed {diag[0]:.3g} cm/s"
        now = time.perf_counter()
        if now - last_log > 30.0:
            log(f"sph: t = {t:.3f} s / {t_max:g} s, step {steps}, rms speed {diag[0]:.3g} cm/s, "
                f"{nf} particles, {(now - started) / max(steps, 1) / nf * 1e9:.0f} ns/particle-step")
            last_log = now
    wall_time = time.perf_counter() - started
    mean_force = np.mean(np.array(window), axis=0) if window else np.zeros((nw, 2))
    cw, cpt, cf = P.wall_contacts(walls, st["wpos"], st["owner"], mean_force)
    pw, pc, pf = P.spread_to_panels(walls, s["panel_length"], cw, cpt, cf, st["dx"], st["dy"])
    if lj_window:
        pf = pf + np.mean(np.array(lj_window), axis=0)
    history = {
        "sample_time": (("sample",), np.array(rec["sample_time"]), "s", "time at the end of the diagnostic chunk"),
        "sample_vrms": (("sample",), np.array(rec["sample_vrms"]), VELOCITY, "largest rms liquid speed in the chunk"),
        "sample_kinetic": (("sample",), np.array(rec["sample_kinetic"]), "N cm", "kinetic energy at the chunk's end"),
        "sample_wall_resultant": (("sample", "wall", "xy"), np.array(rec["sample_wall_resultant"]), "N",
                                  f"force of each wall on the liquid, mean over the last {s['rest_window']:g} s"),
        "sample_vessel_weight": (("sample", "vessel"), np.array(rec["sample_vessel_weight"]), "N",
                                 "weight of the liquid in each vessel"),
        "snap_time": (("snapshot",), np.array(rec["snap_time"]), "s", "time of the position snapshot"),
        "snap_pos": (("snapshot", "particle", "xy"), np.array(rec["snap_pos"]), "cm", "liquid particle positions"),
    }
    fields = {
        "pressure": (("particle",), p[:nf].copy(), "N cm-2", "particle pressure (equation of state)"),
        "density": (("particle",), rho[:nf].copy(), DENSITY_2D, "particle density"),
        "velocity": (("particle", "xy"), v.copy(), VELOCITY, "particle velocity"),
    }
    params = {f"sph_{k}": (str(v_) if isinstance(v_, (bool, list)) else v_) for k, v_ in s.items()}
    params.update(liquid_depth=tank.depth, first_vessel_width=float(np.diff(first_vessel(tank)[:2])[0]), cell_dx=st["dx"], cell_dy=st["dy"], smoothing_length=st["h"], sound_speed=st["c0"], dt=dt,
                  particle_mass=st["mass"], rho_ref=st["rho_ref"], wall_particles=nw, t_max=t_max,
                  panel_length=s["panel_length"], load_window=len(window) * n_chunk * dt,
                  resolution=str(resolution) if start is None else "continued", on_wall=str(bool(on_wall)))
    return Result(
        method="sph", variant="custom", pos0=st["pos"], pos=x[:nf].copy(), weight=np.full(nf, st["mass"] * G),
        contact_wall=pw, contact_point=pc, contact_force=pf, status=status, message=message,
        steps=steps, start_step=0, wall_time=wall_time, force_evals=steps + 1,
        residual=float(diag[0]), residual_name="rms speed", residual_units=VELOCITY, sim_time=t,
        history=history, fields=fields, params=params)
