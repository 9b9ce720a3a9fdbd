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

from .operators import DUMMY, JIT

UNSEEN, BOUNDED, FREE = 0, 1, 2  # a particle's cluster: not searched yet, has a Dirichlet particle, has none


@njit(**JIT)
def anchor_clusters(kind, surf, low, start, nbr, dist, re_l):
    """Set surf (N,) bool in place for the particles of every Dirichlet-free cluster that the number-density test
    found (low (N,): n* < beta n0 at the surface radius).  Clusters: connected components of the non-dummy particles
    off the surface, linked by every list entry closer than re_l [cm] (dist (M,), inf where unseen: model.assemble's
    couplings).  Only a cleared particle (low, not surf) can change, so a search starts from each such particle
    not yet placed and stops at the first Dirichlet neighbour (or a particle already known to be bounded), its
    particles then bounded; a search that ends without one has covered a whole free cluster.  Near a liquid's
    surface a search ends within a few rows.  Serial.  Returns the number of particles set."""
    n = kind.shape[0]
    state = np.zeros(n, np.int8)
    stack = np.empty(n, np.int64)
    members = np.empty(n, np.int64)
    added = 0
    for i0 in range(n):
        if not low[i0] or surf[i0] or kind[i0] == DUMMY or state[i0] != UNSEEN:
            continue
        state[i0] = FREE  # provisionally: the search's particles
        stack[0] = i0
        top = 1
        m = 0
        bounded = False
        while top > 0 and not bounded:
            top -= 1
            i = stack[top]
            members[m] = i
            m += 1
            for k in range(start[i], start[i + 1]):
                j = nbr[k]
                if dist[k] >= re_l or kind[j] == DUMMY:
                    continue
                if surf[j] or state[j] == BOUNDED:
                    bounded = True
                    break
                if state[j] == UNSEEN:
                    state[j] = FREE
                    stack[top] = j
                    top += 1
        if bounded:  # every particle the search reached (popped or waiting) is in this bounded cluster
            for q in range(m):
                state[members[q]] = BOUNDED
            for q in range(top):
                state[stack[q]] = BOUNDED
            continue
        for q in range(m):
            i = members[q]
            if low[i]:
                surf[i] = True
                added += 1
    return added
