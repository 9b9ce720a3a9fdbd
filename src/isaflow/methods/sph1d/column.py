"""Solve one truncated SPH column: banded LU and 1-norm condition number (Higham's estimate), both ``band``'s
plain loops, and the quadratic error against the exact hydrostatic pressure (numpy's pairwise sums, not BLAS:
the same bits on every machine)."""

from dataclasses import dataclass

import numpy as np
from isaflow.core import fixed_order as FO
from isaflow.core.smoothing import kernel_id

from . import band, system


@dataclass
class ColumnSolution:
    z: np.ndarray  # (N,) particle heights, cm
    p: np.ndarray  # (N,) SPH pressure, N/cm^2 (NaN if A is singular)
    p_exact: np.ndarray  # (N,) rho g (H - z), N/cm^2
    error: float  # relative quadratic error ||p - p_exact||_2 / ||p_exact||_2 (1; inf if singular)
    error_max: float  # relative max-norm error ||p - p_exact||_inf / ||p_exact||_inf (1; inf if singular)
    cond: float  # 1-norm condition number of A (Higham's lower-bound estimate; inf if singular)
    status: str  # "converged" (solved) or "solver_failed" (A exactly singular)


def quadratic_error(p, p_exact):
    """Relative discrete L2 error sqrt(sum (p - p_ex)^2 dx) / sqrt(sum p_ex^2 dx) (dx cancels)."""
    return FO.norm(p - p_exact) / FO.norm(p_exact)


def max_error(p, p_exact):
    """Relative max-norm error max |p - p_ex| / max |p_ex| (registry input error_norm's other value)."""
    return float(np.abs(p - p_exact).max() / np.abs(p_exact).max())


def solve_column(n, ratio, kernel, gradient="symmetric", floor="mirror_hydrostatic", height=100.0, rho_g=1.0,
                 top_gap=0.5):
    """Assemble and solve A p = b for N particles, h/dx = ratio, kernel a name or core.smoothing id; top_gap [dx]
    the top particle's distance below the surface (system.positions)."""
    kind = kernel_id(kernel) if isinstance(kernel, str) else int(kernel)
    ab, b, kl = system.assemble(n, height, ratio, kind, gradient, floor, rho_g, top_gap)
    z = system.positions(n, height, top_gap)
    p_ex = system.exact_pressure(z, height, rho_g)
    anorm = np.abs(ab[kl:]).sum(axis=0).max()  # 1-norm: largest column sum
    lu, ipiv, info = band.band_lu(ab, kl)
    if info != 0 or anorm == 0.0:
        nan = np.full(n, np.nan)
        return ColumnSolution(z, nan, p_ex, np.inf, np.inf, np.inf, "solver_failed")
    p = b.copy()
    band.band_solve(lu, ipiv, kl, p, False)
    cond = float(anorm * band.inverse_norm_1(lu, ipiv, kl))
    if not np.all(np.isfinite(p)):
        return ColumnSolution(z, p, p_ex, np.inf, np.inf, cond, "solver_failed")
    return ColumnSolution(z, p, p_ex, quadratic_error(p, p_ex), max_error(p, p_ex), cond, "converged")
