"""Lennard-Jones repulsion of the wall segments on the liquid particles of the SPH (numba), a safety net.

Units: cm, N, s.
"""

import numpy as np
from ...core.jit import njit

JIT = dict(cache=True, nogil=True)


@njit(**JIT)
def wall_repulsion(x, near, walls, panel0, npanel, D, r0, mass, acc, panel_force):
    """Lennard-Jones wall repulsion (marko2017 eq. 7, Monaghan 1994: M = 12, N = 4) as a safety net.

    A liquid particle of ``near`` (int array: the candidates, in order) closer than r0 [cm] to a
    wall segment (either side) gets
    D ((r0/d)^12 - (r0/d)^4) / d [cm/s^2] along the wall's normal through it
    (D [cm^2/s^2]; mass [N s^2/cm] of a particle).  The force of the wall on the liquid is added to
    panel_force[panel0[w] + k] (N) for the panel k of the wall's npanel[w] equal panels.
    """
    if r0 <= 0.0:
        return
    for e in range(near.shape[0]):
        a = near[e]
        px = x[a, 0]
        py = x[a, 1]
        for w in range(walls.shape[0]):
            ex = walls[w, 2] - walls[w, 0]
            ey = walls[w, 3] - walls[w, 1]
            L2 = ex * ex + ey * ey
            cross = ex * (py - walls[w, 1]) - ey * (px - walls[w, 0])
            if cross * cross > (1.0 + 1e-6) * r0 * r0 * L2:
                continue  # farther than r0 from the wall's line, so from the segment (d >= r0 below)
            t = ((px - walls[w, 0]) * ex + (py - walls[w, 1]) * ey) / L2
            t = min(1.0, max(0.0, t))
            dx = px - (walls[w, 0] + t * ex)
            dy = py - (walls[w, 1] + t * ey)
            d = np.sqrt(dx * dx + dy * dy)
            if d >= r0 or d == 0.0:
                continue
            q4 = (r0 / d) ** 4
            f = D * (q4 * q4 * q4 - q4) / (d * d)
            acc[a, 0] += f * dx
            acc[a, 1] += f * dy
            k = panel0[w] + min(npanel[w] - 1, int(t * npanel[w]))
            panel_force[k, 0] += mass * f * dx
            panel_force[k, 1] += mass * f * dy
