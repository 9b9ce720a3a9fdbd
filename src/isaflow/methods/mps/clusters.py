"""Free surface of liquid clusters the pressure equation would leave without a boundary condition (numba).

The pressure equation (model.assemble) couples the unknowns (fluid and wall particles off the free surface) through
every pair closer than the Laplacian's radius.  A connected set of unknowns none of which neighbours a Dirichlet
(free-surface) particle has only Neumann rows: the MPS Laplacian's rows sum to zero there, so its pressure is fixed
by the compressibility term alone, P ~ b c^2 dt^2 (model.assemble: positive definite only with diag_extra > 0 or a
Dirichlet neighbour in every cluster).  Such a set is a droplet in the air: the number-density test (n* < beta n0,
Koshizuka & Oka 1996) finds its deficient particles, but the particle-distribution test (MPS-Basic's
surface_detector/distribution.cpp: a particle is free surface only if a component of sum_j r_ij exceeds
threshold x l0) clears all of them when the droplet is small: a pair 1.07 l0 apart has sum_j r_ij of one spacing,
each component below l0.  Measured (flow_mixed_dx3.45 with sqrt pair distances, step 2,232): particles 115 and 143 at
(276.1, 4.7) and (278.5, 1.8) cm, each the other's only neighbour, n* = 1.89 against n0 = 18.98, neither on the
surface: P = 2.05e4 N/cm^2, thrown apart at 1,700 cm/s, 115 over the left wall at step 2,376.  The distribution
test is a supplement meant to keep particles inside the liquid off the surface (Khayyer et al. 2009, as MPS-Basic
describes it); a body of liquid bounded by air has a free surface on which P = 0 (Koshizuka & Oka 1996), so in a
cluster with no Dirichlet particle the particles the number-density test found are free surface after all.
A cluster without any deficient particle (a closed box full of liquid) is left as it is.
"""

import numpy as np

from ...core.jit import njit

from .operators import DUMMY, JIT, weight


@njit(**JIT)
def anchor_clusters(kind, surf, start, nbr, dist, re_l, re_s, n0_s, beta):
    """Set surf (N,) bool in place for every particle of a Dirichlet-free cluster whose number density at re_s [cm]
    is below beta n0_s.  Clusters: connected components of the non-dummy particles off the surface, linked by
    every list entry closer than re_l [cm] (dist (M,), inf where unseen: model.assemble's couplings).  Serial (one
    pass over the lists, a component at a time).  Returns the number of particles set."""
    n = kind.shape[0]
    seen = np.zeros(n, np.bool_)
    stack = np.empty(n, np.int64)
    members = np.empty(n, np.int64)
    added = 0
    for i0 in range(n):
        if kind[i0] == DUMMY or surf[i0] or seen[i0]:
            continue
        seen[i0] = True
        stack[0] = i0
        top = 1
        m = 0
        anchored = False
        while top > 0:
            top -= 1
            i = stack[top]
            members[m] = i
            m += 1
            for k in range(start[i], start[i + 1]):
                j = nbr[k]
                if dist[k] >= re_l or kind[j] == DUMMY:
                    continue
                if surf[j]:
                    anchored = True
                elif not seen[j]:
                    seen[j] = True
                    stack[top] = j
                    top += 1
        if anchored:
            continue
        for q in range(m):
            i = members[q]
            s = 0.0
            for k in range(start[i], start[i + 1]):  # every listed neighbour, as operators.number_density
                s += weight(dist[k], re_s)
            if s < beta * n0_s:
                surf[i] = True
                added += 1
    return added
