"""An equilibrium solver for the static problem (variant ``newton_lm``, not the paper's update; numba).

The ISA forces derive from the energy (cm, N, N cm)

    E(x) = sum_i w_i y_i + sum_walls k_b / 2 (l_bu - d_iw)_+^2 + sum_pairs k_p / 2 (l_pu - d_ij)_+^2,

k = r_u / l_u, so F = -grad E and the equilibrium max|F| < f_tol is a
stationary point of E.  E is smooth except where a contact opens or closes
(its Hessian jumps there), and a compressed repulsive contact has a negative
stiffness across its line (the exact Hessian of a pair is
k [n n^T - (l_u / d - 1)(I - n n^T)]), so the exact Hessian is indefinite
away from an equilibrium.

Method: Levenberg-Marquardt (a trust-region Newton method) on E with the
Hessian of the active contacts (d < l_u (1 + ACTIVE_TOL): a contact just at
the end of its range counts, so a lattice that starts exactly at l_u sees its
contacts).  Every iteration solves (H + mu I) p = F by conjugate gradients
with a 2x2 block-Jacobi preconditioner, with H the exact Hessian when
H + mu I is positive definite (CG meets no negative curvature), else with half
of the negative cross-line terms, else without them (Gauss-Newton, positive
semi-definite: THETAS), then evaluates E and F at x + p: the step is taken when E
decreases, and mu follows the ratio of actual to predicted decrease
(Nielsen's rule).  A step that would carry a particle across a wall is
refused before any evaluation and mu grows.  The Gauss-Newton fallback
keeps the early, large steps on the path of the gradient flow (the capped
update); the exact Hessian converges quadratically near the end.

Why a compiled loop and not scipy.optimize: the max-norm stopping rule, the
wall-crossing refusal, the neighbour-list rebuilds and an exact count of
force evaluations all sit inside the loop, every sum keeps a fixed order
(bit-identical reruns), and a Python-level callback per evaluation would cost
more than the evaluation itself on the paper's lattices.

Counts: one force evaluation = E and F at one point (the start, and every
trial step, accepted or not); Hessian assemblies and CG iterations (Hessian
products) are counted separately.
"""

import numpy as np
from ...core.jit import njit

from ...core.geometry import crossed_wall, segment_closest
from ...core.neighbours import build_pairs
from .forces import pair_push, track_max, wall_push

JIT = dict(cache=True, nogil=True)

NEWTON = 4  # rule code (settings.RULES); relax.PAPER, CAPPED, FIRE are 0-2, dynamics.OVERDAMPED 3
RUNNING, CONVERGED, NONFINITE, STALLED = 0, 1, 2, 4
ACTIVE_TOL = 1e-6  # a contact within l_u (1 + ACTIVE_TOL) is in the Hessian
MU_START = 1e-2  # first mu as a fraction of the pair stiffness k_p [N/cm]
MU_MIN, MU_MAX = 1e-12, 1e12  # bounds on mu / k_p; above MU_MAX no step is possible: stalled
THETAS = (1.0, 0.5, 0.0)  # share of the negative cross-line terms in the Hessian, tried in this order
CG_ETA = 0.01  # CG stops when max|r| <= max(CG_F_TOL f_tol, CG_ETA max|F|)
CG_F_TOL = 0.25
CG_MAX_FACTOR = 4  # CG iterations <= CG_MAX_FACTOR * 2N + 50


@njit(**JIT)
def energy_forces(pos, weight, walls, wall_l_u, wall_r_u, pair_l_u, pair_r_u, pi, pj, m, y_ref, f):
    """Energy E - sum w y_ref [N cm] and forces f (N, 2) [N] at pos; returns (E, max|F|, bad).

    Forces are summed as forces.forces sums them (weight and walls per
    particle, then pairs in list order); bad is the first particle whose
    position or force is not finite (max|F| NaN), else -1.  The pair list
    (pi, pj)[:m] must hold every pair closer than pair_l_u.
    """
    n = pos.shape[0]
    kb = wall_r_u / wall_l_u
    kp = pair_r_u / pair_l_u
    e_grav = 0.0
    e_wall = 0.0
    for i in range(n):
        px = pos[i, 0]
        py = pos[i, 1]
        e_grav += weight[i] * (py - y_ref)
        fx = 0.0
        fy = -weight[i]
        for w in range(walls.shape[0]):
            cx, cy = segment_closest(px, py, walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3])
            d2 = (px - cx) ** 2 + (py - cy) ** 2
            if d2 < wall_l_u * wall_l_u:
                g = wall_l_u - np.sqrt(d2)
                e_wall += 0.5 * kb * g * g
                gx, gy = wall_push(px, py, walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3], wall_l_u, wall_r_u, 1.0)
                fx += gx
                fy += gy
        f[i, 0] = fx
        f[i, 1] = fy
    e_pair = 0.0
    for k in range(m):
        i = pi[k]
        j = pj[k]
        dx = pos[i, 0] - pos[j, 0]
        dy = pos[i, 1] - pos[j, 1]
        d2 = dx * dx + dy * dy
        if d2 < pair_l_u * pair_l_u:
            g = pair_l_u - np.sqrt(d2)
            e_pair += 0.5 * kp * g * g
            gx, gy = pair_push(dx, dy, pair_l_u, pair_r_u, 1.0)
            f[i, 0] += gx
            f[i, 1] += gy
            f[j, 0] -= gx
            f[j, 1] -= gy
    fmax = 0.0
    bad = -1
    for i in range(n):
        fmax, finite = track_max(f[i, 0], f[i, 1], fmax, (abs(pos[i, 0]) < np.inf) & (abs(pos[i, 1]) < np.inf))
        if not finite and bad < 0:
            bad = i
    if bad >= 0:
        return np.nan, np.nan, bad
    return e_grav + e_wall + e_pair, fmax, -1


@njit(inline="always", **JIT)
def _contact_block(nx, ny, k, t):
    """2x2 Hessian block (b00, b01, b11) [N/cm] of a contact along unit n with stiffness k and
    cross-line factor t: k [n n^T - t (I - n n^T)]."""
    return k * (nx * nx - t * (1.0 - nx * nx)), k * (nx * ny + t * nx * ny), k * (ny * ny - t * (1.0 - ny * ny))


@njit(**JIT)
def assemble(pos, walls, wall_l_u, wall_r_u, pair_l_u, pair_r_u, pi, pj, m, theta, diag, blk):
    """Hessian of E at pos: diag (N, 3) the particles' 2x2 blocks (xx, xy, yy) [N/cm], blk (M, 3) the
    pair blocks (the off-diagonal block of pair k is -blk[k]).  theta scales the negative cross-line
    terms (1: exact Hessian of the active contacts; 0: Gauss-Newton, positive semi-definite).
    Contacts within l_u (1 + ACTIVE_TOL) are active."""
    n = pos.shape[0]
    kb = wall_r_u / wall_l_u
    kp = pair_r_u / pair_l_u
    reach_w = wall_l_u * (1.0 + ACTIVE_TOL)
    reach_p = pair_l_u * (1.0 + ACTIVE_TOL)
    for i in range(n):
        px = pos[i, 0]
        py = pos[i, 1]
        a00 = 0.0
        a01 = 0.0
        a11 = 0.0
        for w in range(walls.shape[0]):
            x0, y0, x1, y1 = walls[w, 0], walls[w, 1], walls[w, 2], walls[w, 3]
            cx, cy = segment_closest(px, py, x0, y0, x1, y1)
            dx = px - cx
            dy = py - cy
            d = np.sqrt(dx * dx + dy * dy)
            if d >= reach_w:
                continue
            ex = x1 - x0
            ey = y1 - y0
            if d > 0.0:
                nx = dx / d
                ny = dy / d
            else:  # on the wall: pushed along its left normal
                L = np.sqrt(ex * ex + ey * ey)
                nx = -ey / L
                ny = ex / L
            at_end = (cx == x0 and cy == y0) or (cx == x1 and cy == y1)
            t = theta * max(0.0, wall_l_u / d - 1.0) if at_end and d > 0.0 else 0.0
            b00, b01, b11 = _contact_block(nx, ny, kb, t)
            a00 += b00
            a01 += b01
            a11 += b11
        diag[i, 0] = a00
        diag[i, 1] = a01
        diag[i, 2] = a11
    for k in range(m):
        i = pi[k]
        j = pj[k]
        dx = pos[i, 0] - pos[j, 0]
        dy = pos[i, 1] - pos[j, 1]
        d = np.sqrt(dx * dx + dy * dy)
        if d >= reach_p:
            blk[k, 0] = 0.0
            blk[k, 1] = 0.0
            blk[k, 2] = 0.0
            continue
        if d > 0.0:
            nx = dx / d
            ny = dy / d
            t = theta * max(0.0, pair_l_u / d - 1.0)
        else:
            nx = 1.0
            ny = 0.0
            t = 0.0
        b00, b01, b11 = _contact_block(nx, ny, kp, t)
        blk[k, 0] = b00
        blk[k, 1] = b01
        blk[k, 2] = b11
        diag[i, 0] += b00
        diag[i, 1] += b01
        diag[i, 2] += b11
        diag[j, 0] += b00
        diag[j, 1] += b01
        diag[j, 2] += b11


@njit(**JIT)
def hess_vec(diag, blk, pi, pj, m, mu, x, y):
    """y = (H + mu I) x for the Hessian of :func:`assemble` (x, y (N, 2))."""
    n = x.shape[0]
    for i in range(n):
        y[i, 0] = (diag[i, 0] + mu) * x[i, 0] + diag[i, 1] * x[i, 1]
        y[i, 1] = diag[i, 1] * x[i, 0] + (diag[i, 2] + mu) * x[i, 1]
    for k in range(m):
        b00 = blk[k, 0]
        b01 = blk[k, 1]
        b11 = blk[k, 2]
        if b00 == 0.0 and b01 == 0.0 and b11 == 0.0:
            continue
        i = pi[k]
        j = pj[k]
        y[i, 0] -= b00 * x[j, 0] + b01 * x[j, 1]
        y[i, 1] -= b01 * x[j, 0] + b11 * x[j, 1]
        y[j, 0] -= b00 * x[i, 0] + b01 * x[i, 1]
        y[j, 1] -= b01 * x[i, 0] + b11 * x[i, 1]


@njit(inline="always", **JIT)
def _precondition(diag, mu, r, z):
    """z = the 2x2 block-Jacobi preconditioner of H + mu I applied to r (N, 2); returns r . z."""
    rz = 0.0
    for i in range(r.shape[0]):
        a = diag[i, 0] + mu
        c = diag[i, 1]
        d = diag[i, 2] + mu
        det = a * d - c * c
        z[i, 0] = (d * r[i, 0] - c * r[i, 1]) / det
        z[i, 1] = (a * r[i, 1] - c * r[i, 0]) / det
        rz += r[i, 0] * z[i, 0] + r[i, 1] * z[i, 1]
    return rz


@njit(**JIT)
def pcg(diag, blk, pi, pj, m, mu, b, x, tol, max_iter, r, z, p, q):
    """Solve (H + mu I) x = b (N, 2) by conjugate gradients with the 2x2 block-Jacobi preconditioner.

    Stops when max|r| <= tol or after max_iter iterations.  Returns
    (iterations, positive definite): False when a diagonal block or a search
    direction shows H + mu I is not positive definite (x is then unusable).
    r, z, p, q (N, 2) are scratch.
    """
    n = b.shape[0]
    for i in range(n):
        a = diag[i, 0] + mu
        d = diag[i, 2] + mu
        if not (a > 0.0 and d > 0.0 and a * d - diag[i, 1] * diag[i, 1] > 0.0):
            return 0, False
    x[:, :] = 0.0
    r[:, :] = b
    rz = _precondition(diag, mu, r, z)
    p[:, :] = z
    rmax = np.abs(r).max() if n else 0.0
    it = 0
    while rmax > tol and it < max_iter:
        hess_vec(diag, blk, pi, pj, m, mu, p, q)
        pq = 0.0
        for i in range(n):
            pq += p[i, 0] * q[i, 0] + p[i, 1] * q[i, 1]
        if not pq > 0.0:
            return it, False
        alpha = rz / pq
        rmax = 0.0
        for i in range(n):
            x[i, 0] += alpha * p[i, 0]
            x[i, 1] += alpha * p[i, 1]
            r[i, 0] -= alpha * q[i, 0]
            r[i, 1] -= alpha * q[i, 1]
            rmax = max(rmax, abs(r[i, 0]), abs(r[i, 1]))
        rz_new = _precondition(diag, mu, r, z)
        beta = rz_new / rz
        rz = rz_new
        for i in range(n):
            p[i, 0] = z[i, 0] + beta * p[i, 0]
            p[i, 1] = z[i, 1] + beta * p[i, 1]
        it += 1
    return it, True


@njit(**JIT)
def _first_crossing(pos, trial, walls):
    """(particle, wall) of the lowest-numbered particle whose move pos -> trial crosses a wall, or (-1, -1)."""
    for i in range(pos.shape[0]):
        w = crossed_wall(pos[i, 0], pos[i, 1], trial[i, 0], trial[i, 1], walls)
        if w >= 0:
            return i, w
    return -1, -1


@njit(**JIT)
def _max_shift(a, b):
    """Largest per-particle displacement |a_i - b_i| [cm] (NaN-propagating)."""
    s = 0.0
    for i in range(a.shape[0]):
        d = np.sqrt((a[i, 0] - b[i, 0]) ** 2 + (a[i, 1] - b[i, 1]) ** 2)
        if not d <= s:
            s = d
    return s


@njit(**JIT)
def newton_resume(pos, weight, walls, box, wall_l_u, wall_r_u, pair_l_u, pair_r_u, f_tol, n_steps, skin, force,
                  fmax_hist, nstate, counts):
    """Up to n_steps Levenberg-Marquardt steps in place (module docstring); the whole loop is compiled.

    pos (N, 2) cm, weight (N,) N, walls (W, 4) cm, box (4,) cm of the cell
    grid; force (N, 2) receives the final forces [N]; fmax_hist[k] the max|F|
    [N] before step k.  A step is one trial point (one force evaluation);
    refused wall crossings are not steps.  nstate (2,) = (mu [N/cm], nu), in
    and out: mu <= 0 starts afresh (mu = MU_START k_p).  counts (4,) int64
    accumulate (Hessian assemblies, CG iterations, refused crossings, force
    evaluations).  Returns (steps_done, status, bad): status CONVERGED
    (max|F| < f_tol), NONFINITE (bad = the first non-finite particle),
    STALLED (mu above MU_MAX k_p: no decreasing step left), else RUNNING.
    """
    n = pos.shape[0]
    kp = pair_r_u / pair_l_u
    rc = pair_l_u + skin
    y_ref = 0.0
    for i in range(n):
        y_ref = min(y_ref, pos[i, 1]) if i else pos[i, 1]
    pi, pj, m = build_pairs(pos, box, rc)
    pos_build = pos.copy()
    energy, fmax, bad = energy_forces(pos, weight, walls, wall_l_u, wall_r_u, pair_l_u, pair_r_u, pi, pj, m, y_ref,
                                      force)
    counts[3] += 1
    mu = nstate[0] if nstate[0] > 0.0 else MU_START * kp
    nu = nstate[1] if nstate[1] >= 2.0 else 2.0
    diag = np.empty((n, 3))
    blk = np.empty((pi.shape[0], 3))
    step_ = np.empty((n, 2))
    trial = np.empty((n, 2))
    f_trial = np.empty((n, 2))
    r = np.empty((n, 2))
    z = np.empty((n, 2))
    pdir = np.empty((n, 2))
    q = np.empty((n, 2))
    max_cg = CG_MAX_FACTOR * 2 * n + 50
    status = RUNNING
    done = 0
    while True:
        if done < n_steps:
            fmax_hist[done] = fmax
        if bad >= 0:
            status = NONFINITE
            break
        if fmax < f_tol:
            status = CONVERGED
            break
        if done >= n_steps:
            break
        if mu > MU_MAX * kp:
            status = STALLED
            break
        tol = max(CG_F_TOL * f_tol, CG_ETA * fmax)
        ok = False
        theta = 1.0
        for theta in THETAS:  # the exact Hessian if H + mu I is positive definite, else less of its cross-line terms
            if blk.shape[0] < pi.shape[0]:
                blk = np.empty((pi.shape[0], 3))
            assemble(pos, walls, wall_l_u, wall_r_u, pair_l_u, pair_r_u, pi, pj, m, theta, diag, blk)
            counts[0] += 1
            its, ok = pcg(diag, blk, pi, pj, m, mu, force, step_, tol, max_cg, r, z, pdir, q)
            counts[1] += its
            if ok:
                break
        if not ok:  # cannot happen for mu > 0 with theta = 0; guard against round-off
            mu *= nu
            nu *= 2.0
            continue
        for i in range(n):
            trial[i, 0] = pos[i, 0] + step_[i, 0]
            trial[i, 1] = pos[i, 1] + step_[i, 1]
        c, w = _first_crossing(pos, trial, walls)
        if c >= 0:
            counts[2] += 1
            mu *= nu
            nu *= 2.0
            continue
        # predicted decrease of the model (H without mu): F.p - p.H.p / 2
        hess_vec(diag, blk, pi, pj, m, 0.0, step_, q)
        fp = 0.0
        php = 0.0
        for i in range(n):
            fp += force[i, 0] * step_[i, 0] + force[i, 1] * step_[i, 1]
            php += step_[i, 0] * q[i, 0] + step_[i, 1] * q[i, 1]
        pred = fp - 0.5 * php
        if _max_shift(trial, pos_build) > 0.5 * skin:
            tpi, tpj, tm = build_pairs(trial, box, rc)
            rebuilt = True
        else:
            tpi, tpj, tm = pi, pj, m
            rebuilt = False
        e_trial, f_max_trial, bad_trial = energy_forces(trial, weight, walls, wall_l_u, wall_r_u, pair_l_u,
                                                        pair_r_u, tpi, tpj, tm, y_ref, f_trial)
        counts[3] += 1
        done += 1
        if bad_trial >= 0:  # a non-finite trial is refused like a rising energy
            rho = -1.0
        else:
            rho = (energy - e_trial) / pred if pred > 0.0 else -1.0
        if rho > 0.0 and e_trial < energy:
            pos[:, :] = trial
            force[:, :] = f_trial
            energy = e_trial
            fmax = f_max_trial
            if rebuilt:
                pi, pj, m = tpi, tpj, tm
                pos_build[:, :] = trial
            rr = 2.0 * min(rho, 1.0) - 1.0
            mu = max(mu * max(1.0 / 3.0, 1.0 - rr * rr * rr), MU_MIN * kp)
            nu = 2.0
        else:
            mu *= nu
            nu *= 2.0
    nstate[0] = mu
    nstate[1] = nu
    return done, status, bad


def warm_up(threads=1):
    """Compile (or load) newton_resume with the argument types solver.solve passes."""
    pos = np.array([[1.0, 1.0], [1.5, 1.0]])
    walls = np.array([[0.0, 2.0, 0.0, 0.0], [0.0, 0.0, 2.0, 0.0], [2.0, 0.0, 2.0, 2.0]])
    box = np.array([0.0, 0.0, 2.0, 2.0])
    newton_resume(pos.copy(), np.ones(2), walls, box, 0.5, 1.0, 0.7, 1.0, 0.1, 2, 0.1, np.zeros_like(pos),
                  np.zeros(2), np.zeros(2), np.zeros(4, np.int64))
