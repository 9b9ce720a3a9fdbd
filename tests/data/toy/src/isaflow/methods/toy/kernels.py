"""The toy's compiled loop: masses on a square lattice, linear springs to their four neighbours and
compression-only springs against the walls, gravity and a damping force -m c v; symplectic Euler steps.
Units cm, N, s."""

import numpy as np

from ...core.jit import njit

JIT = dict(cache=True, nogil=True)
OK, NONFINITE = range(2)


@njit(**JIT)
def forces(pos, vel, bonds, cpart, cnorm, coff, par, f, cf):
    """f (N, 2): the force on each mass; cf (C, 2): each wall contact's force on its mass.
    par: m, g, k, rest length of a bond, rest gap of a wall contact, damping rate c [1/s], dt."""
    m, g, k, rest, gap, c = par[0], par[1], par[2], par[3], par[4], par[5]
    for i in range(len(pos)):
        f[i, 0] = -m * c * vel[i, 0]
        f[i, 1] = -m * g - m * c * vel[i, 1]
    for b in range(len(bonds)):
        i, j = bonds[b, 0], bonds[b, 1]
        dx, dy = pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1]
        r = np.sqrt(dx * dx + dy * dy)
        s = k * (r - rest) / r
        f[i, 0] += s * dx
        f[i, 1] += s * dy
        f[j, 0] -= s * dx
        f[j, 1] -= s * dy
    for q in range(len(cpart)):
        i = cpart[q]
        d = pos[i, 0] * cnorm[q, 0] + pos[i, 1] * cnorm[q, 1] - coff[q]  # distance from the wall's line
        push = k * (gap - d) if d < gap else 0.0
        cf[q, 0], cf[q, 1] = push * cnorm[q, 0], push * cnorm[q, 1]
        f[i, 0] += cf[q, 0]
        f[i, 1] += cf[q, 1]


@njit(**JIT)
def advance(pos, vel, bonds, cpart, cnorm, coff, par, n, f, cf, cf_sum):
    """n steps; cf_sum (C, 2) the contacts' forces summed over them.  Returns (code, steps done, kinetic energy)."""
    m, dt = par[0], par[6]
    cf_sum[:] = 0.0
    for step in range(n):
        forces(pos, vel, bonds, cpart, cnorm, coff, par, f, cf)
        cf_sum += cf
        for i in range(len(pos)):
            vel[i, 0] += dt * f[i, 0] / m
            vel[i, 1] += dt * f[i, 1] / m
            pos[i, 0] += dt * vel[i, 0]
            pos[i, 1] += dt * vel[i, 1]
            if not (np.isfinite(pos[i, 0]) and np.isfinite(pos[i, 1])):
                return NONFINITE, step + 1, np.nan
    return OK, n, 0.5 * m * np.sum(vel * vel)
