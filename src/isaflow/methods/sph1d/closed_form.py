"""One neighbour per side (1/2 < h/dx <= 1): the explicit solution and quadratic error.

With one neighbour the interior row of the symmetric form is
V F (p_{i-1} - p_{i+1}) = -rho g, F = dW/dr(dx) < 0, so the discrete slope is
kappa times the exact one, kappa = 1 / (2 dx^2 |F|) = r^2 / (2 sigma |f'(1/r)|)
(r = h/dx, W = sigma/h f(r/h) in 1D).  Solving the surface row and the floor row
(docs/sph1d.md) gives, for 0-based i and beta = 1 (hydrostatic ghosts) or 0
(equal-pressure ghosts):

    p_i = kappa p_exact,i + (-1)^i rho g dx (kappa - beta) / 2

and the relative quadratic error

    E^2 = (kappa - 1)^2 + [6 (kappa - 1)(kappa - beta) + 3 (kappa - beta)^2] / (4 N^2 - 1),

which tends to the residue |kappa - 1| as N -> infinity: no convergence unless kappa = 1.
"""

import numpy as np

from isaflow.core.smoothing import NORM, dw, kernel_id

from .system import FLOORS, exact_pressure, positions


def kappa(kernel, ratio):
    """Slope factor kappa(h/dx) (1) of the one-neighbour interior row; kernel a name or id."""
    kind = kernel_id(kernel) if isinstance(kernel, str) else int(kernel)
    r = np.asarray(ratio, float)
    slope = np.vectorize(lambda x: dw(kind, x))(1.0 / r)
    return r**2 / (2.0 * NORM[kind, 1] * np.abs(slope))


def residue(kernel, ratio):
    """Limit of the relative quadratic error as N -> infinity: |kappa - 1| (1)."""
    return np.abs(kappa(kernel, ratio) - 1.0)


def pressure(n, ratio, kernel, floor="mirror_hydrostatic", height=100.0, rho_g=1.0):
    """(N,) closed-form pressure [N/cm^2] of the symmetric form with one neighbour per side."""
    beta = FLOORS[floor]
    if beta < 0:
        raise ValueError("closed form needs a mirrored floor")
    k = kappa(kernel, ratio)
    dx = height / n
    sign = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    return k * exact_pressure(positions(n, height), height, rho_g) + sign * rho_g * dx * (k - beta) / 2.0


def error(n, ratio, kernel, floor="mirror_hydrostatic"):
    """Closed-form relative quadratic error (1) of the symmetric form with one neighbour per side."""
    beta = FLOORS[floor]
    k = kappa(kernel, ratio)
    return np.sqrt((k - 1) ** 2 + (6 * (k - 1) * (k - beta) + 3 * (k - beta) ** 2) / (4.0 * n**2 - 1))
