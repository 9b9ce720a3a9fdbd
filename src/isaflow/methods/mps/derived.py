"""Numbers computed from an MPS run file for the claims on Hattori et al. (config/claims/hattori.yaml
``derived``; rule ``derived`` writes each to results/derived/mps/<name>.nc, which the claims read as any run file):

- :func:`step_check`: one MPS step from the run's final state checked against eqs. (1)-(2) (hat-eq5-implicit,
  prj-hat-mps-step).  The step is the project's own (solver.step), the collision model off (it is no term of
  eqs. 1-3); every operator of eqs. (1)-(2) is then recomputed independently of the solver;
- :func:`dilation`: the run's source term on a uniformly dilated lattice of its spacing against eq. (6) with the
  paper's Rho* and with the project's (hat-eq4-rho-star).

Units: cm, N, s.
"""

from pathlib import Path

import numpy as np
import xarray as xr

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


def step_check(ds):
    """The Dataset of :func:`one_step` on run Dataset ds: one scalar variable per VARIABLES entry."""
    st = one_step(ds)
    return xr.Dataset({k: ((), np.float64(st[k]) if k != "particles" else np.int64(st[k]), {"units": u, "long_name": n})
                       for k, u, n in VARIABLES})



DILATION = 1e-4  # the dilation e of :func:`dilation` (measurement design, not a tolerance)


def dilation(ds, e=DILATION):
    """The run's source term on a uniform dilation, as a Dataset: on a square lattice of the run's spacing dilated
    uniformly by (1 + e) in 2D (det(dU*/dxi) = (1 + e)^2, V* = e U[n] / dt, div V* = 2 e / ((1 + e) dt) with
    respect to U*), the project's source of the run's variant (model.source_term, unrelaxed) at the centre
    particle (s_model), eq. (6) with Rho* = rho0 / det (s_det) and with Rho* = rho0 n*/n0 (s_nd) [N/cm^4], and
    the sensitivity d ln(n*/n0) / d ln(1/det) (1; central difference); the run's relaxation and its scope."""
    cfg = run_settings(ds)
    l0, dt, rho0 = float(ds.attrs["spacing"]), float(ds.attrs["dt_s"]), float(ds.attrs["rho0_N_s2_cm4"])
    re = cfg["model.re_density"] * l0
    k = int(np.ceil(cfg["model.re_density"])) + 2
    grid = np.arange(-k, k + 1) * l0
    x, y = np.meshgrid(grid, grid)
    base = np.column_stack([x.ravel(), y.ravel()])
    centre = int(np.argmin(np.hypot(*base.T)))

    def density(scale):
        pos = base * scale
        kind = np.zeros(len(pos), np.int64)
        box = np.array([pos[:, 0].min() - l0, pos[:, 1].min() - l0, pos[:, 0].max() + l0, pos[:, 1].max() + l0])
        start, nbr = model.neighbour_list(pos, kind, box, re, np.full(len(pos), -1, np.int64),
                                          np.ones(len(pos), np.int64), np.zeros((0, 4)))
        return float(model.number_density(start, nbr, model.distances(pos, start, nbr), re)[centre])

    n0 = density(1.0)
    n_star = density(1.0 + e)
    det = (1.0 + e) ** 2
    div = 2.0 * e / ((1.0 + e) * dt)
    source = model.SOURCES[str(ds.attrs["variant"])]
    s_model = float(model.source_term(n_star, div, n0, rho0, dt, source, cfg["model.gamma_mixed"], 1.0))

    def eq6(rho_star):
        return (rho0 - rho_star) / dt**2 + (rho0 - rho_star) / dt * div

    sens = (np.log(density(1.0 + e)) - np.log(density(1.0 - e))) / (2 * np.log(1 - e) - 2 * np.log(1 + e))
    values = (("dilation", e, "1", "uniform dilation e of the lattice (positions times 1 + e)"),
              ("s_model", s_model, "N cm-4", "the run's source term (unrelaxed) at the centre particle"),
              ("s_det", eq6(rho0 / det), "N cm-4", "eq. (6) with Rho* = rho0 / det(dU*/dxi)"),
              ("s_nd", eq6(rho0 * n_star / n0), "N cm-4", "eq. (6) with Rho* = rho0 n*/n0"),
              ("sensitivity", float(sens), "1", "d ln(n*/n0) / d ln(1/det), central difference (1 for the Jacobian)"),
              ("n0", n0, "1", "number density of the undilated lattice at the centre particle"),
              ("n0_file", float(ds.attrs["n0_density"]), "1", "reference number density the run file records"),
              ("relaxation", cfg["model.relaxation"], "1", "the run's relaxation coefficient"))
    out = xr.Dataset({k: ((), np.float64(v), {"units": u, "long_name": n}) for k, v, u, n in values})
    out.attrs.update(relaxation_scope=str(cfg["model.relaxation_scope"]), source_term=str(ds.attrs["variant"]))
    return out
