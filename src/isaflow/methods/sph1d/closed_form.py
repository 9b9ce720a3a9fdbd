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

which tends to the residue |kappa - 1| as N -> infinity: no convergence unless kappa = 1.  In general, with the top
particle g dx below the surface (g = 1/2 above; input surface_placement), b = rho g dx (kappa - beta) / 2:

    symmetric (p_i + p_j):  p_i = kappa rho g dx (N - 1/2 - i) + (-1)^i b
    plain (p_j):            p_i = kappa rho g dx (N - i) + ((-1)^i - (-1)^N) b

(the interior rows are the same; the plain form's surface row is p_{N-2} = 2 kappa rho g dx and its floor row
p_1 - p_0 = (beta - 2 kappa) rho g dx), whose error :func:`error` sums: the limit is |kappa - 1| in every case.
"""

import numpy as np

from isaflow.core.smoothing import NORM, dw, kernel_id

from .system import FLOORS, exact_pressure, positions, spacing
from .column import quadratic_error


def kappa(kernel, ratio):
    """Slope factor kappa(h/dx) (1) of the one-neighbour interior row; kernel a name or id."""
    kind = kernel_id(kernel) if isinstance(kernel, str) else int(kernel)
    r = np.asarray(ratio, float)
    slope = np.vectorize(lambda x: dw(kind, x))(1.0 / r)
    return r**2 / (2.0 * NORM[kind, 1] * np.abs(slope))


def residue(kernel, ratio):
    """Limit of the relative quadratic error as N -> infinity: |kappa - 1| (1)."""
    return np.abs(kappa(kernel, ratio) - 1.0)


def pressure(n, ratio, kernel, floor="mirror_hydrostatic", height=100.0, rho_g=1.0, top_gap=0.5, gradient="symmetric"):
    """(N,) closed-form pressure [N/cm^2] with one neighbour per side (module docstring)."""
    beta = FLOORS[floor]
    if beta < 0:
        raise ValueError("closed form needs a mirrored floor")
    k = kappa(kernel, ratio)
    dx = spacing(n, height, top_gap)
    i = np.arange(n)
    sign = np.where(i % 2 == 0, 1.0, -1.0)
    b = rho_g * dx * (k - beta) / 2.0
    if gradient == "symmetric":
        return k * rho_g * dx * (n - 0.5 - i) + sign * b
    return k * rho_g * dx * (n - i) + (sign - (-1.0) ** n) * b


def error(n, ratio, kernel, floor="mirror_hydrostatic", top_gap=0.5, gradient="symmetric"):
    """Closed-form relative quadratic error (1) with one neighbour per side: the formula of the module docstring for
    the symmetric form with the top particle dx/2 below the surface, else the sum over :func:`pressure`."""
    beta = FLOORS[floor]
    k = kappa(kernel, ratio)
    if top_gap == 0.5 and gradient == "symmetric":
        return np.sqrt((k - 1) ** 2 + (6 * (k - 1) * (k - beta) + 3 * (k - beta) ** 2) / (4.0 * n**2 - 1))
    p_ex = exact_pressure(positions(n, 1.0, top_gap), 1.0, 1.0)
    return np.array([quadratic_error(pressure(n, r, kernel, floor, 1.0, 1.0, top_gap, gradient), p_ex)
                     for r in np.atleast_1d(ratio)]).reshape(np.shape(k))
