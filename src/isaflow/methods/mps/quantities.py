"""Quantities of MPS run files the claims registry reads (isaflow.quantities; the rows state runs and comparisons).
Units: cm, N, s."""

import math

import numpy as np

from ...core import fixed_order as FO
from ...quantities import Value, quantity


def noise(ds, window=None):
    """(high-frequency noise std/mean of the side-wall panel loads over the final window after removing a linear
    trend, effective sample count); (inf, 0) for a run that escaped before its window."""
    t = ds["sample_time"].values
    win = ds["in_window"].values.astype(bool)
    if window is not None:
        win = t >= t[-1] - window + 1e-12
    if ds.attrs["status"] == "escaped" or win.sum() < 4:
        return float("inf"), 0
    walls = ds["wall_segment"].values
    side = np.isclose(walls[ds["contact_wall"].values, 0], walls[ds["contact_wall"].values, 2])
    f = ds["sample_panel_force"].values[win][:, side]
    mag = np.sqrt(f[..., 0] ** 2 + f[..., 1] ** 2)
    tt = t[win]
    mean = mag.mean(0)
    wet = mean > 0.01 * mean.max()
    res = np.array([FO.residual(tt, mag[:, k]) for k in np.flatnonzero(wet)]).T
    rel = float(np.mean(res.std(0) / mean[wet]))
    tot = res.sum(1)
    s = 0.0
    for k in range(1, len(tot) // 2):
        r = np.corrcoef(tot[:-k], tot[k:])[0, 1]
        if not r > 0:
            break
        s += r
    return rel, len(tot) / (1 + 2 * s)


@quantity("largest / smallest high-frequency wall-load noise over its threshold, 0 unless monotone in dt", fmt=".3g", over="runs")
def noise_trend(runs, min_ratio, window=None):
    """Runs in order of their time step: their high-frequency side-wall noise (std/mean after a linear trend over the
    final window); the largest over the smallest, divided by the threshold max(min_ratio, 1 + 2 sqrt(2) /
    sqrt(2 (n_eff - 1))) that two noise levels of n_eff effective samples must exceed to differ; 0 when the noise is
    not monotone in dt."""
    vals = [(float(ds.attrs["time.courant"]), *noise(ds, window)) for ds in runs]
    x = [v[1] for v in vals]
    neff = min((v[2] for v in vals if v[2] > 1), default=0)
    thr = max(min_ratio, 1 + 2 * math.sqrt(2) / math.sqrt(2 * (neff - 1))) if neff > 1 else min_ratio
    mono = all(a < b for a, b in zip(x, x[1:])) or all(a > b for a, b in zip(x, x[1:]))
    fin = [v for v in x if np.isfinite(v)]
    ratio = max(x) / min(fin) if fin else float("nan")
    text = ", ".join(f"Courant {c:g}: {n:.3g}" for c, n, _ in vals) + (
        f"; {'grows' if x[-1] > x[0] else 'falls'} with dt, ratio {ratio:.3g} against {thr:.3g} (n_eff {neff:.0f})")
    return Value(ratio / thr if mono else 0.0, text)


# ------------------------------------------------------------------------- Hattori et al.: the printed equations
@quantity("largest relative residual of eqs. (1)-(2) after (3), (4), (5), exact rationals", over="numbers", fmt=".3g")
def eq1_5_residual(numbers, particles, seed):
    """Eqs. (3) then (5) then (4) on a random 2D instance in exact rational arithmetic (an identity leaves exactly 0):
    per particle and component V[n], U[n], the viscous Laplacian sum, the pressure gradient dP[n+1]/dU[n+1] (one
    symbol in eqs. 1 and 5), and mu, Rho[n], Rho[n+1], dt; g = (0, -981) cm/s^2.  The largest residual of eq. (1)
    over its largest term and of eq. (2) over max(|V[n+1]|, 1)."""
    from fractions import Fraction
    import random

    rng = random.Random(seed)

    def q(lo=-50, hi=50, den=7):
        return Fraction(rng.randint(lo, hi), rng.randint(1, den))

    mu, rho_n, rho_1, dt = q(1, 9), q(1, 9), q(1, 9), Fraction(1, rng.randint(50, 500))
    r1 = r2 = Fraction(0)
    for _ in range(particles):
        for g in (Fraction(0), Fraction(-981)):
            v_n, u_n, lap, grad = q(), q(), q(), q()
            v_s = v_n + dt * (mu / rho_n * lap + g)  # eq. (3)
            u_s = u_n + dt * v_s
            v_p = -dt / rho_1 * grad  # eq. (5)
            v_1, u_1 = v_s + v_p, u_s + dt * v_p  # eq. (4)
            terms = max(abs(t) for t in (mu / rho_n * lap, grad / rho_1, g))
            r1 = max(r1, abs((v_1 - v_n) / dt - (mu / rho_n * lap - grad / rho_1 + g)) / terms)  # eq. (1)
            r2 = max(r2, abs((u_1 - u_n) / dt - v_1) / max(abs(v_1), Fraction(1)))  # eq. (2)
    return Value(float(max(r1, r2)), f"eq. (1) {float(r1):.3g}, eq. (2) {float(r2):.3g} on {particles} particles")


@quantity("smallest observed order in eps of ||S6 - S|| / ||S||", over="numbers", fmt=".3f")
def eq6_order(numbers, eps, density_offset=0.0, linearisation="density at *"):
    """Eq. (6)'s source S6 = (rho0 - Rho*)/dt^2 + (rho0 - Rho*)/dt div V* against the source eqs. (4)-(5) give with
    Rho[n+1] = rho0, on the manufactured V* = (sin 2x cos y + 0.4 x, 0.5 cos x sin 3y + 0.3 y) cm/s at 9 x 9 points of
    [0.1, 1.5]^2 cm, dt = eps / max|div V*| for each eps; Rho* = Rho[n] / det(I + dt grad V*), Rho[n] = rho0 (1 +
    density_offset) (input reference_configuration).  linearisation (input continuity_linearisation): 'density at *'
    Rho[n+1] = Rho* (1 - div U') gives S = (rho0 / Rho*)(rho0 - Rho*)/dt^2; 'density at n+1' Rho[n+1] (1 + div U') =
    Rho* gives (rho0 - Rho*)/dt^2.  The smallest order log2 of successive ratios."""
    x, y = (a.ravel() for a in np.meshgrid(np.linspace(0.1, 1.5, 9), np.linspace(0.1, 1.5, 9)))
    gxx, gxy = 2 * np.cos(2 * x) * np.cos(y) + 0.4, -np.sin(2 * x) * np.sin(y)
    gyx, gyy = -0.5 * np.sin(x) * np.sin(3 * y), 1.5 * np.cos(x) * np.cos(3 * y) + 0.3
    div, rho0, rel = gxx + gyy, 1.0, []
    for e in eps:
        dt = e / np.abs(div).max()
        rho_s = rho0 * (1.0 + density_offset) / ((1 + dt * gxx) * (1 + dt * gyy) - dt**2 * gxy * gyx)
        s6 = (rho0 - rho_s) / dt**2 + (rho0 - rho_s) / dt * div
        s = (rho0 - rho_s) / dt**2 * (rho0 / rho_s if linearisation == "density at *" else 1.0)
        rel.append(math.sqrt(math.fsum((s6 - s) ** 2)) / math.sqrt(math.fsum(s**2)))
    q = [math.log2(a / b) for a, b in zip(rel, rel[1:])]
    return Value(min(q), "relative differences " + ", ".join(f"{r:.3g}" for r in rel) + " at eps " + ", ".join(
        f"{e:g}" for e in eps) + "; orders " + ", ".join(f"{o:.3f}" for o in q))


# ------------------------------------------------------------------------- Hattori et al.: one MPS step of a run
@quantity("number of one MPS step from the run's final state", fmt=".3g")
def step_value(ds, var):
    """A number of the derived step check (methods.mps.derived.step_check: one step, collision off) with the step."""
    return Value(float(ds[var]), f"dt {float(ds['dt']):.4g} s, {int(ds['particles'])} particles, U[n+1] - U* up to "
                                 f"{float(ds['shift']):.3g} cm, pressure-solve residual {float(ds['solve_residual']):.2g}")


@quantity("offset of the run's source from eq. (6) with Rho* = rho0/det over its offset with rho0 n*/n0", fmt=".3g")
def rho_star_offsets(ds):
    """The derived dilation (methods.mps.derived.dilation: the run's source term on a uniformly dilated lattice): how
    far the project's source is from eq. (6) with the paper's Rho* = rho0 / det, over how far from eq. (6) with rho0
    n*/n0 (both relative to the first); < 1 when the project follows the paper's definition."""
    from . import model

    off_det = abs(float(ds.s_model) - float(ds.s_det)) / abs(float(ds.s_det))
    off_nd = abs(float(ds.s_model) - float(ds.s_nd)) / abs(float(ds.s_det))
    a_d, a_v = model.relaxation_factors(model.SOURCES[ds.attrs["source_term"]],
                                        model.RELAX_SCOPES[ds.attrs["relaxation_scope"]], float(ds.relaxation))
    return Value(off_det / off_nd if off_nd > 0 else float("inf"),
                 f"source '{ds.attrs['source_term']}', dilation {float(ds.dilation):g}: {off_det:.3g} from rho0/det, "
                 f"{off_nd:.3g} from rho0 n*/n0; d ln(n*/n0) / d ln(1/det) = {float(ds.sensitivity):.4f} (1 for the "
                 f"Jacobian); the run's relaxation multiplies the density term by {a_d:g}, the divergence term by {a_v:g}")
