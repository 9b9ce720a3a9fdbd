"""One MPS step checked against Hattori et al.'s eqs. (1)-(2), from the final state of a run: the rule
``mps_step_check`` writes results/mps/step_check_<run>.nc, which the claims read (hat-eq5-implicit,
prj-hat-mps-step) as they read any run file.

The step is the project's own (solver.step), the collision model off (it is no term of eqs. 1-3); every
operator of eqs. (1)-(2) is then recomputed independently of the solver.  Units: cm, N, s.
"""

from pathlib import Path

import numpy as np
import xarray as xr

from ... import runfile
from ...core import units
from ...tank import load as load_tank
from . import model, settings, solver

ROOT = Path(__file__).resolve().parents[4]
# the check's numbers: (name, units, long name)
VARIABLES = (
    ("res1_star", "1", "largest relative residual of eq. (1) over the liquid, grad P at U*"),
    ("res1_new", "1", "largest relative residual of eq. (1) over the liquid, grad P at U[n+1]"),
    ("res2", "1", "largest |(U[n+1] - U[n]) / dt - V[n+1]| over max |V[n+1]| (eq. 2)"),
    ("scale", "cm s-2", "largest acceleration term of eq. (1): the residuals' unit"),
    ("dt", "s", "time step of the checked step"),
    ("particles", "1", "liquid particles"),
    ("solve_residual", "1", "relative residual of the step's pressure solve"),
    ("shift", "cm", "largest |U[n+1] - U*|"),
    ("grad_change", "cm s-2", "largest |grad P(U[n+1]) - grad P(U*)| / rho0"),
    ("rho0", "N s2 cm-4", "reference density of the step"),
    ("rho0_file", "N s2 cm-4", "reference density the run file records"),
)


def _file(path):
    """A path recorded in a run file (relative to the repository root when relative)."""
    p = Path(path)
    return p if p.is_absolute() or p.is_file() else ROOT / p


def run_settings(ds):
    """The MPS settings of a run file: its settings file, variant and resolution, and the run's own 'set'
    overrides when its id is declared there (isaflow.settings.Settings)."""
    cfg = settings.resolved(_file(ds.attrs["settings_file"]), variant=ds.attrs["variant"],
                        resolution=ds.attrs["resolution"])
    decl = cfg.runs().get(str(ds.attrs.get("run_id", "")), {})
    return cfg.with_overrides(decl.get("set", {}), what="run") if decl.get("set") else cfg


def one_step(ds):
    """One MPS step (solver.step, the project's own) from the final state of run file ds, the collision
    model off (it is no term of eqs. 1-3), then eqs. (1)-(2) checked with every operator recomputed.

    Returns dict: res1_star, res1_new (max over fluid particles of |(V[n+1] - V[n])/dt - (nu lap V[n] + g -
    grad P[n+1] / rho0)| over the largest term, grad P at U* and at U[n+1]), res2 (|(U[n+1] - U[n])/dt -
    V[n+1]| over max |V[n+1]|), scale [cm/s^2] (largest acceleration term), dt [s], particles, the solve's
    residual, the largest |U[n+1] - U*| [cm] and the largest |grad P(U[n+1]) - grad P(U*)| / rho0 [cm/s^2].
    """
    tank = load_tank(_file(ds.attrs["tank_file"]))
    cfg = run_settings(ds).with_overrides(**{"model.collision_distance": 0.0})
    l0, dt = float(ds.attrs["spacing"]), float(ds.attrs["dt_s"])
    s = solver.State(tank, cfg, l0, ds["pos"].values.astype(float), ds["velocity"].values.astype(float))
    pos_n, vel_n = s.pos.copy(), s.vel.copy()
    _, resid, _ = solver.step(s, dt, ds.attrs["variant"], cfg)
    f = slice(0, s.nf)
    nu = cfg["model.kinematic_viscosity"]
    g = np.array([0.0, -units.G])
    s.neighbours(pos_n)  # eq. (3) recomputed: V* = V[n] + dt (nu lap V[n] + g), U* = U[n] + dt V*
    lap = model.laplacian(vel_n, s.kind, s.start, s.nbr, model.distances(pos_n, s.start, s.nbr), s.re_l, s.n0_l,
                          s.lam)
    u_star = pos_n.copy()
    u_star[f] = pos_n[f] + dt * (vel_n[f] + dt * (nu * lap[f] + g))

    def grad_at(pos):
        s.neighbours(pos)
        d = model.distances(pos, s.start, s.nbr)
        return model.gradient(pos, s.p, s.kind, s.start, s.nbr, d, s.re_g, s.n_grad, s.grad_mode)

    g_star, g_new = grad_at(u_star), grad_at(s.pos)
    lhs = (s.vel[f] - vel_n[f]) / dt
    rhs_star = nu * lap[f] + g - g_star[f] / s.rho0
    scale = float(max(np.abs(nu * lap[f]).max(), units.G, np.abs(g_star[f] / s.rho0).max()))
    res1_star = float(np.abs(lhs - rhs_star).max() / scale)
    res1_new = float(np.abs(lhs - (nu * lap[f] + g - g_new[f] / s.rho0)).max() / scale)
    res2 = float(np.abs((s.pos[f] - pos_n[f]) / dt - s.vel[f]).max() / np.abs(s.vel[f]).max())
    return dict(res1_star=res1_star, res1_new=res1_new, res2=res2, scale=scale, dt=dt, particles=s.nf,
                solve_residual=float(resid), shift=float(np.hypot(*(s.pos[f] - u_star[f]).T).max()),
                grad_change=float(np.abs(g_new[f] - g_star[f]).max() / s.rho0), rho0=s.rho0,
                rho0_file=float(ds.attrs["rho0_N_s2_cm4"]))


def checked(ds):
    """The Dataset of :func:`one_step` on run Dataset ds: one scalar variable per VARIABLES entry."""
    st = one_step(ds)
    return xr.Dataset({k: ((), np.float64(st[k]) if k != "particles" else np.int64(st[k]), {"units": u, "long_name": n})
                       for k, u, n in VARIABLES})


def write(run, outputs):
    """Rule mps_step_check: the check of run file ``run`` written to outputs[0] (with provenance; the rule binds
    the MPS kernel generation, params.kernels)."""
    started = runfile.now()
    ds = runfile.read(run)
    out = checked(ds)
    out.attrs.update(method="mps", checked_run=str(ds.attrs.get("run_id", Path(run).stem)), started=started,
                     finished=runfile.now(), **runfile.provenance({"checked_run": run}))
    runfile.write(out, outputs[0])
