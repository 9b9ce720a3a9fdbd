"""The toy's checks (pure Python): its lattice, its time step and its cost from the settings alone."""

import math

from ... import budget
from ...core.units import G
from ...inputs import InputError


def lattice(tank, s):
    """(nx, ny, dx) of the square lattice filling the first vessel below the tank's depth (cell centres)."""
    (x0, x1), dx = tank.vessels[0][1], s["lattice.spacing"]
    return int((x1 - x0) / dx + 1e-9), int(tank.depth / dx + 1e-9), dx


def time_step(tank, s):
    """dt [s] = courant sqrt(m / k), k = ny m g / (strain dx): the floor spring of a column, compressed by its
    column's weight, shortens by strain dx."""
    _, ny, dx = lattice(tank, s)
    return s["time.courant"] * math.sqrt(s["springs.strain"] * dx / (max(ny, 1) * G))


def plausible(tank, s, stability=False):
    nx, ny, dx = lattice(tank, s)
    if nx < 1 or ny < 1:
        raise InputError(f"field 'lattice.spacing': {dx:g} cm leaves {nx} x {ny} cells in the first vessel")


def cost(tank, s, particles=None):
    nx, ny, _ = lattice(tank, s)
    n = particles or nx * ny
    return [budget.Cost(n, s["time.t_max"] / time_step(tank, s), 200.0 * n, 50.0)]
