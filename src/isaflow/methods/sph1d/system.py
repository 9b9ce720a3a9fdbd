"""The truncated SPH hydrostatic column in 1D as a banded linear system A p = b.

Discrete equations (docs/sph1d.md).  Liquid column 0 <= z <= H (cm), floor at
z = 0, free surface at z = H, N particles at z_i = (i + 1/2) dx, volume V = dx (per unit
cross-section), dx = H / (N - 1/2 + g): g [dx] is the top particle's distance below the surface
(1/2 kept: dx = H / N; 0: the top particle on the surface).  The bottom particle stays dx/2
above the floor, so the mirror ghosts continue the lattice below it.  Kernel W(r, h) of core.smoothing
(support 2 h, 1D normalisation), phi(s) = dW/dz at z_i - z_j = s:
phi(s) = NORM[kind, 1] / h^2 * f'(|s| / h) * sign(s).

Row i is the SPH momentum balance at rest, grad p = -rho g e_z:

  sum_j V phi(z_i - z_j) (p_j + c p_i)  +  sum_k V phi(z_i + z_k) (p'_k + c p_i)  =  -rho g

- j runs over the liquid particles with |z_i - z_j| < 2 h, j != i.  No particle
  lies above z = H: the kernel is truncated at the free surface, which is the
  only place the free-surface condition enters (p = 0 outside).
- gradient form c: 1 = "symmetric" (p_i + p_j, the momentum-conserving form),
  0 = "plain" (p_j, the direct SPH derivative of the interpolant).
- floor: ghost k mirrors particle k at z = -z_k with pressure
  p'_k = p_k + beta 2 rho g z_k; beta = 1 "mirror_hydrostatic" (hydrostatic
  extrapolation), beta = 0 "mirror_equal" (p'_k = p_k).

Units: z, H, dx, h in cm; rho g in N/cm^3; p in N/cm^2.
"""

import numpy as np
from ...core.jit import njit

from isaflow.core.smoothing import NORM, SUPPORT, dw

JIT = dict(cache=True, nogil=True)

GRADIENT_FORMS = {"symmetric": 1.0, "plain": 0.0}
FLOORS = {"mirror_hydrostatic": 1.0, "mirror_equal": 0.0, "truncated": -1.0}


def neighbours_per_side(ratio):
    """Neighbours strictly inside the support on each side: ceil(2 h/dx) - 1 (h/dx = ratio)."""
    r = np.asarray(ratio, float)
    return (np.ceil(np.round(SUPPORT * r, 9)) - 1).astype(int)


def spacing(n, height, top_gap=0.5):
    """dx [cm] of N particles in a column of height H [cm], the top one top_gap [dx] below the surface and the
    bottom one dx/2 above the floor: H / (N - 1/2 + top_gap)."""
    return height / (n - 0.5 + top_gap)


def positions(n, height, top_gap=0.5):
    """(N,) particle heights z_i = (i + 1/2) dx [cm] of a column of height H [cm] (dx: spacing)."""
    return (np.arange(n) + 0.5) * spacing(n, height, top_gap)


def exact_pressure(z, height, rho_g):
    """(N,) exact hydrostatic pressure rho g (H - z) [N/cm^2]."""
    return rho_g * (height - np.asarray(z, float))


@njit(**JIT)
def _phi(kind, norm, h, s):
    """dW/dz at separation s = z_i - z_j [1/cm^2]."""
    q = abs(s) / h
    g = norm / (h * h) * dw(kind, q)
    return g if s > 0.0 else -g


@njit(**JIT)
def assemble_banded(n, height, ratio, kind, norm, c_self, beta, rho_g, kl, top_gap):
    """LAPACK band storage of A and the right-hand side b.

    Returns ab (2 kl + kl + 1, N) with A[i, j] = ab[2 kl + i - j, j] (the
    layout of LAPACK dgbtrf and band.band_lu, kl = ku rows of fill-in space on top) and b (N,).
    A is in 1/cm, b in N/cm^3; top_gap [dx] as in spacing.
    """
    dx = height / (n - 0.5 + top_gap)  # spacing()
    h = ratio * dx
    vol = dx
    reach = SUPPORT * h
    ab = np.zeros((3 * kl + 1, n))
    b = np.full(n, -rho_g)
    for i in range(n):
        lo = max(0, i - kl)
        hi = min(n, i + kl + 1)
        for j in range(lo, hi):
            if j == i:
                continue
            s = (i - j) * dx  # an integer multiple of dx: no round-off of the two positions
            if abs(s) >= reach:
                continue
            g = vol * _phi(kind, norm, h, s)
            ab[2 * kl + i - j, j] += g
            ab[2 * kl, i] += c_self * g
        for k in range(0, hi if beta >= 0.0 else 0):  # ghosts: distance z_i + z_k = (i + k + 1) dx
            zk = (k + 0.5) * dx
            s = (i + k + 1) * dx  # z_i + z_k, as above
            if s >= reach:
                break
            g = vol * _phi(kind, norm, h, s)
            ab[2 * kl + i - k, k] += g
            ab[2 * kl, i] += c_self * g
            b[i] -= g * beta * 2.0 * rho_g * zk
    return ab, b


def assemble(n, height, ratio, kernel, gradient="symmetric", floor="mirror_hydrostatic", rho_g=1.0, top_gap=0.5):
    """(ab, b, kl) of the column; kernel an id of core.smoothing; see module docstring."""
    kl = max(1, int(neighbours_per_side(ratio)))
    ab, b = assemble_banded(int(n), float(height), float(ratio), int(kernel), float(NORM[kernel, 1]),
                            GRADIENT_FORMS[gradient], FLOORS[floor], float(rho_g), kl, float(top_gap))
    return ab, b, kl


def dense(ab, kl):
    """(N, N) dense A from band storage (tests and small cases)."""
    n = ab.shape[1]
    a = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - kl), min(n, i + kl + 1)):
            a[i, j] = ab[2 * kl + i - j, j]
    return a
