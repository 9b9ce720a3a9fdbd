"""Hooke's-law solid particles (marko2017 section 3, eqs. 11-16, 26-27): the compiled step loop.

Plain arrays only (numba); units cm, N, s.  Two layouts of one loop (:func:`relax`), told apart by the
width of the arrays:

- **2D layout** (a 2D block whose z is inert, solve.Stepper): positions, velocities, forces (N, 2),
  virial (N, 3) xx, yy, yx, stress (N, 4) xx, yy, zz, yx, strain diagonal (N, 2), rotation (N, 1);
- **3D layout** (3D blocks): (N, 3), virial (N, 6) xx, yy, zz, yx, zy, zx, stress (N, 6), strain (N, 3),
  rotation (N, 9) (row-major 3 x 3).

Both give the same numbers operation for operation where they overlap (a 2D run's z terms are exact
zeros in the 3D layout).  Per link the geometry is computed once per block (:func:`link_geometry`:
rest length L0 and unit vector e of d0); nothing is allocated per step.

Links (the paper's contact matrix): pairs (a, b) of lattice neighbours with
reference vector d0 = ref_b - ref_a along lattice axis u (0, 1, 2).  A link
pushes and pulls; unlinked particles only push, when closer than their mean
size.  Per link, with the particles' strain diagonal Ebar (mean of a and b,
previous step):

    strain = (r - L0 (1 + eps_p)) / (L0 (1 + Ebar_u))          eq. 15
    f_n    = E dx^(d-1) (1 + Ebar_v)(1 + Ebar_w) strain         eq. 16 (force, not dv)
    f_t    = G dx^(d-1) (d - (d.e) e) / L0      (variant 'hooke' only)
    f_t    = 2 G dx^(d-1) (d - (d.e) e - L0 W e) / L0   (shear mode 2, 'objective': W the mean
             small rotation (antisymmetric displacement gradient) of a and b, so a rigid rotation
             carries no shear force and the shear stress is G gamma in every lattice orientation)

eps_p = -nu (sigma_v + sigma_w) / E (variant 'hooke' only; 0 in 'paper'):
the Poisson contraction of the particle's natural size.  Particle stress is
the virial sigma = sum_b f_ab (x) r_ab / (2 V), V = dx^d; its strain diagonal
E_u = sigma_u / E (paper, eq. 14) or (sigma_u - nu (sigma_v + sigma_w)) / E
(hooke).  2D is plane strain in 'hooke' (sigma_z = nu (sigma_x + sigma_y)).

Time integration as section 3: accelerations -> velocities -> positions ->
stresses; dt = min(dx / (4 c), 0.1 dx / V_max) (eqs. 26-27; V_max the largest particle
speed at the start of the step) unless a fixed dt is given; cap = 0 drops eq. 26's cap
(dt = 0.1 dx / max(V_max, vfloor), the sentence after eq. 27 read alone).  The largest
move of any free particle in one step, over its size, is kept in state[6].  Settling: kinetic damping (all velocities zeroed when the kinetic
energy falls; not in the paper, which only says the particles "settle"); damp = 0
runs undamped (time histories).  fext (N, d) [N]: prescribed external loads.
"""

import numpy as np
from ...core.jit import njit

from isaflow.core.neighbours import build_pairs

from .rotation import rotations

JIT = dict(cache=True, nogil=True)

# status codes of relax()
RUNNING, CONVERGED, UNSTABLE, NONFINITE = 0, 1, 2, 3


@njit(**JIT)
def link_geometry(d0, la, lb, laxis, n):
    """(L0 (L,) cm, e (L, 3) unit vectors of d0, cnt (n, 3) links of each particle along each lattice axis),
    from the reference vectors d0 (L, 3) of links (la, lb) along axes laxis of n particles."""
    m = d0.shape[0]
    L0 = np.empty(m)
    e = np.empty((m, 3))
    cnt = np.zeros((n, 3))
    for k in range(m):
        L0[k] = np.sqrt(d0[k, 0] ** 2 + d0[k, 1] ** 2 + d0[k, 2] ** 2)
        cnt[la[k], laxis[k]] += 1.0
        cnt[lb[k], laxis[k]] += 1.0
        for i in range(3):
            e[k, i] = d0[k, i] / L0[k]
    return L0, e, cnt


@njit(**JIT)
def link_forces(pos, la, lb, d0, laxis, sig, strain, E, nu, G, area0, poisson, shear, rot, frc, vir):
    """3D layout, one force pass: add every link's force to frc (N, 3) [N] and its virial to vir (N, 6) [N cm];
    rot (N, 3, 3).  vir columns: f_x d_x, f_y d_y, f_z d_z, f_x d_y, f_y d_z, f_x d_z (the last three: shear
    tractions on planes normal to y, z, z; not symmetrised, as the shear springs of a link carry only the
    traction on the plane normal to it).  Returns the largest |f_n| [N]."""
    L0, e, _ = link_geometry(d0, la, lb, laxis, pos.shape[0])
    return links3(pos, la, lb, L0, e, laxis, sig, strain, E, nu, G, area0, poisson, shear,
                  rot.reshape((rot.shape[0], 9)), frc, vir)


@njit(**JIT)
def links3(pos, la, lb, L0, e, laxis, sig, strain, E, nu, G, area0, poisson, shear, rot, frc, vir):
    """:func:`link_forces` in the loop's 3D layout: L0, e from :func:`link_geometry`, rot (N, 9)."""
    fmax = 0.0
    for k in range(la.shape[0]):
        a = la[k]
        b = lb[k]
        u = laxis[k]
        v = (u + 1) % 3
        w = (u + 2) % 3
        dx = pos[b, 0] - pos[a, 0]
        dy = pos[b, 1] - pos[a, 1]
        dz = pos[b, 2] - pos[a, 2]
        r = np.sqrt(dx * dx + dy * dy + dz * dz)
        l0 = L0[k]
        eu = 0.5 * (strain[a, u] + strain[b, u])
        ev = 0.5 * (strain[a, v] + strain[b, v])
        ew = 0.5 * (strain[a, w] + strain[b, w])
        eps_p = 0.0
        if poisson:
            eps_p = -nu * 0.5 * (sig[a, v] + sig[b, v] + sig[a, w] + sig[b, w]) / E
        s = (r - l0 * (1.0 + eps_p)) / (l0 * (1.0 + eu))
        fn = E * area0 * (1.0 + ev) * (1.0 + ew) * s
        fmax = max(fmax, abs(fn))
        fx = fn * dx / r
        fy = fn * dy / r
        fz = fn * dz / r
        if shear:
            ex = e[k, 0]
            ey = e[k, 1]
            ez = e[k, 2]
            dn = dx * ex + dy * ey + dz * ez
            c = G * area0 * (1.0 + ev) * (1.0 + ew) / l0
            tx = dx - dn * ex
            ty = dy - dn * ey
            tz = dz - dn * ez
            if shear == 2:  # objective: remove the pair's mean rigid rotation W d0, shear stress G gamma
                c *= 2.0
                tx -= 0.5 * l0 * (rot[a, u] + rot[b, u])
                ty -= 0.5 * l0 * (rot[a, 3 + u] + rot[b, 3 + u])
                tz -= 0.5 * l0 * (rot[a, 6 + u] + rot[b, 6 + u])
            fx += c * tx
            fy += c * ty
            fz += c * tz
        add_pair(a, b, fx, fy, fz, dx, dy, dz, frc, vir)
    return fmax


@njit(**JIT)
def links2(pos, la, lb, L0, e, laxis, sig, strain, E, nu, G, area0, poisson, shear, rot, frc, vir):
    """The force pass in the 2D layout (links along x and y only): frc (N, 2), vir (N, 3) xx, yy, yx, sig
    (N, 4), strain (N, 2), rot (N, 1) the small rotation W_yx.  The same arithmetic as :func:`links3` without
    its zero z terms: the other in-plane axis o carries the strain factor (the z factor is 1 + 0), and W_xy =
    -W_yx exactly.  Returns the largest |f_n| [N]."""
    fmax = 0.0
    for k in range(la.shape[0]):
        a = la[k]
        b = lb[k]
        u = laxis[k]
        o = 1 - u
        dx = pos[b, 0] - pos[a, 0]
        dy = pos[b, 1] - pos[a, 1]
        r = np.sqrt(dx * dx + dy * dy)
        l0 = L0[k]
        eu = 0.5 * (strain[a, u] + strain[b, u])
        eo = 0.5 * (strain[a, o] + strain[b, o])
        eps_p = 0.0
        if poisson:  # sigma_v + sigma_w in the 3D order: (y, z) along x, (z, x) along y
            if u == 0:
                eps_p = -nu * 0.5 * (sig[a, 1] + sig[b, 1] + sig[a, 2] + sig[b, 2]) / E
            else:
                eps_p = -nu * 0.5 * (sig[a, 2] + sig[b, 2] + sig[a, 0] + sig[b, 0]) / E
        s = (r - l0 * (1.0 + eps_p)) / (l0 * (1.0 + eu))
        fn = E * area0 * (1.0 + eo) * s
        fmax = max(fmax, abs(fn))
        fx = fn * dx / r
        fy = fn * dy / r
        if shear:
            ex = e[k, 0]
            ey = e[k, 1]
            dn = dx * ex + dy * ey
            c = G * area0 * (1.0 + eo) / l0
            tx = dx - dn * ex
            ty = dy - dn * ey
            if shear == 2:
                c *= 2.0
                if u == 0:
                    ty -= 0.5 * l0 * (rot[a, 0] + rot[b, 0])
                else:
                    tx += 0.5 * l0 * (rot[a, 0] + rot[b, 0])
            fx += c * tx
            fy += c * ty
        add_pair2(a, b, fx, fy, dx, dy, frc, vir)
    return fmax


@njit(inline="always", **JIT)
def add_pair(a, b, fx, fy, fz, dx, dy, dz, frc, vir):
    """3D layout: force (fx, fy, fz) on a from b (minus on b), separation d = x_b - x_a; both virials."""
    frc[a, 0] += fx
    frc[a, 1] += fy
    frc[a, 2] += fz
    frc[b, 0] -= fx
    frc[b, 1] -= fy
    frc[b, 2] -= fz
    for p in (a, b):
        vir[p, 0] += fx * dx
        vir[p, 1] += fy * dy
        vir[p, 2] += fz * dz
        vir[p, 3] += fx * dy
        vir[p, 4] += fy * dz
        vir[p, 5] += fx * dz


@njit(inline="always", **JIT)
def add_pair2(a, b, fx, fy, dx, dy, frc, vir):
    """2D layout: :func:`add_pair` without z (virial xx, yy, yx)."""
    frc[a, 0] += fx
    frc[a, 1] += fy
    frc[b, 0] -= fx
    frc[b, 1] -= fy
    vir[a, 0] += fx * dx
    vir[a, 1] += fy * dy
    vir[a, 2] += fx * dy
    vir[b, 0] += fx * dx
    vir[b, 1] += fy * dy
    vir[b, 2] += fx * dy


@njit(**JIT)
def unlinked(pi, pj, m, partners):
    """The first m pairs (pi, pj) without the linked ones (partners (N, 6)), in their order, in place; returns
    their count."""
    kept = 0
    for k in range(m):
        a = pi[k]
        b = pj[k]
        linked = False
        for q in range(partners.shape[1]):
            if partners[a, q] == b:
                linked = True
        if not linked:
            pi[kept] = a
            pj[kept] = b
            kept += 1
    return kept


@njit(**JIT)
def push_forces(pos, size, pi, pj, m, E, dim, frc, vir):
    """Unlinked pairs (the first m of pi, pj: :func:`unlinked`) closer than (s_a + s_b) / 2 push apart (never
    pull): springs of two half-particles in series, k = E A / ((s_a + s_b) / 2), A = min(s)^(d-1).  Either
    layout."""
    flat = pos.shape[1] == 2
    for k in range(m):
        a = pi[k]
        b = pj[k]
        dx = pos[b, 0] - pos[a, 0]
        dy = pos[b, 1] - pos[a, 1]
        dz = 0.0 if flat else pos[b, 2] - pos[a, 2]
        r = np.sqrt(dx * dx + dy * dy + dz * dz)
        r0 = 0.5 * (size[a] + size[b])
        if r >= r0 or r == 0.0:
            continue
        area = min(size[a], size[b]) ** (dim - 1)
        fn = E * area * (r - r0) / r0  # < 0: push
        if flat:
            add_pair2(a, b, fn * dx / r, fn * dy / r, dx, dy, frc, vir)
        else:
            add_pair(a, b, fn * dx / r, fn * dy / r, fn * dz / r, dx, dy, dz, frc, vir)


@njit(**JIT)
def disk_forces(pos, size, free, disk, E, dim, frc, vir, pres):
    """Rigid disk (cx, cy, R, on): a particle whose centre is closer than R + s/2 to the disk
    centre is pushed out radially by a half-particle spring k = 2 E A / s (rigid partner).
    pres (N,) receives the contact force magnitude per particle [N]; returns the force (fx, fy)
    of the particles on the disk [N].  Either layout (x and y only)."""
    gx = 0.0
    gy = 0.0
    if disk[3] == 0.0:
        return gx, gy
    for a in range(pos.shape[0]):
        pres[a] = 0.0
        dx = pos[a, 0] - disk[0]
        dy = pos[a, 1] - disk[1]
        D = np.sqrt(dx * dx + dy * dy)
        pen = disk[2] + 0.5 * size[a] - D
        if pen <= 0.0:
            continue
        area = size[a] ** (dim - 1)
        f = 2.0 * E * area * pen / size[a]
        fx = f * dx / D
        fy = f * dy / D
        frc[a, 0] += fx
        frc[a, 1] += fy
        # contact point at distance s/2 from the centre, towards the disk
        vir[a, 0] += fx * (-0.5 * size[a] * dx / D) * 2.0
        vir[a, 1] += fy * (-0.5 * size[a] * dy / D) * 2.0
        pres[a] = f
        gx -= fx
        gy -= fy
    return gx, gy


@njit(**JIT)
def stresses(vir, size, dim, E, nu, poisson, sig, strain):
    """Particle stress sigma [N/cm^2] = virial / (2 V) and strain diagonal, either layout: 3D (vir, sig (N, 6)
    columns as link_forces, strain (N, 3)); 2D (vir xx, yy, yx -> sig (N, 4) xx, yy, zz, yx, zz the plane-strain
    nu (xx + yy) in 'hooke', else 0; strain (N, 2)), with the 3D layout's arithmetic."""
    if vir.shape[1] == 3:
        for a in range(vir.shape[0]):
            V = size[a] ** dim
            s0 = vir[a, 0] / (2.0 * V)
            s1 = vir[a, 1] / (2.0 * V)
            s2 = nu * (s0 + s1) if poisson else 0.0
            sig[a, 0] = s0
            sig[a, 1] = s1
            sig[a, 2] = s2
            sig[a, 3] = vir[a, 2] / (2.0 * V)
            if poisson:
                strain[a, 0] = (s0 - nu * (s1 + s2)) / E
                strain[a, 1] = (s1 - nu * (s2 + s0)) / E
            else:
                strain[a, 0] = s0 / E
                strain[a, 1] = s1 / E
        return
    for a in range(vir.shape[0]):
        V = size[a] ** dim
        for c in range(6):
            sig[a, c] = vir[a, c] / (2.0 * V)
        if dim == 2:
            sig[a, 2] = nu * (sig[a, 0] + sig[a, 1]) if poisson else 0.0
        for u in range(3):
            e = sig[a, u]
            if poisson:
                e -= nu * (sig[a, (u + 1) % 3] + sig[a, (u + 2) % 3])
            strain[a, u] = e / E
        if dim == 2:
            strain[a, 2] = 0.0


@njit(**JIT)
def relax(pos, vel, ref, target, free, mass, size, la, lb, L0, e, laxis, cnt, partners, disk,
          E, nu, G, rho, dim, poisson, shear, push, dt_fixed, tol, min_steps, n_steps,
          sig, strain, frc, pres, state, fext, damp, cap, vfloor, vir, rot, grad, anchor, pi, pj, box):
    """Run up to n_steps steps of the section 3 loop (forces, residual, velocities, positions, stresses) in
    either layout; stop early when converged (residual < tol once min_steps are done) or unstable.

    target: positions of the prescribed dofs (free == 0).  L0, e, cnt: :func:`link_geometry`.  vir, rot, grad,
    anchor (N, d), box (4,): work arrays of the layout.  state (7,) float64 carries between chunks: [kinetic
    energy of the previous step, sim time s, smallest dt, largest dt, -, steps, largest move of a free particle
    in one step / its size].  dt_fixed > 0: that step [s]; else eqs. 26-27 with cap = 1, eq. 27 alone with cap
    = 0 (V_max floored at vfloor [cm/s], > 0).  push: the unlinked pairs that may push (pi, pj: their arrays,
    cutoff 1.5 max size + a skin of 0.25 min size, :func:`unlinked`) are found at the call's start and again
    whenever a particle has moved half the skin.  Returns (steps, status, residual = max free |F| / max link
    |f_n|, disk force x, disk force y, pi, pj); a step counts once it moved the particles (UNSTABLE, and
    NONFINITE found after the move; CONVERGED and a NONFINITE residual stop before it).
    """
    n = pos.shape[0]
    d = pos.shape[1]
    d3 = d == 3
    smin = size.min()
    dt_max = smin / (4.0 * np.sqrt(E / rho))  # eq. 26
    area0 = smin ** (dim - 1)
    rc = 1.5 * size.max()
    skin = 0.25 * size.min()
    m = 0
    rebuild = True
    status = RUNNING
    resid = np.inf
    gx = 0.0
    gy = 0.0
    for k in range(n_steps):
        if push:
            if not rebuild:
                for a in range(n):
                    if (pos[a, 0] - anchor[a, 0]) ** 2 + (pos[a, 1] - anchor[a, 1]) ** 2 > 0.25 * skin * skin:
                        rebuild = True
                        break
            if rebuild:
                box[0] = pos[:, 0].min()
                box[1] = pos[:, 1].min()
                box[2] = pos[:, 0].max() + 1e-9
                box[3] = pos[:, 1].max() + 1e-9
                pi, pj, m = build_pairs(pos, box, rc + skin)
                m = unlinked(pi, pj, m, partners)
                anchor[:, :] = pos
                rebuild = False
        for a in range(n):
            frc[a, 0] = fext[a, 0]
            frc[a, 1] = fext[a, 1]
            vir[a, 0] = 0.0
            vir[a, 1] = 0.0
            vir[a, 2] = 0.0
            if d3:
                frc[a, 2] = fext[a, 2]
                vir[a, 3] = 0.0
                vir[a, 4] = 0.0
                vir[a, 5] = 0.0
        if shear == 2:
            rotations(pos, ref, la, lb, L0, laxis, cnt, grad, rot)
        if d3:
            fmax = links3(pos, la, lb, L0, e, laxis, sig, strain, E, nu, G, area0, poisson, shear, rot, frc, vir)
        else:
            fmax = links2(pos, la, lb, L0, e, laxis, sig, strain, E, nu, G, area0, poisson, shear, rot, frc, vir)
        if m > 0:
            push_forces(pos, size, pi, pj, m, E, dim, frc, vir)
        gx, gy = disk_forces(pos, size, free, disk, E, dim, frc, vir, pres)
        # residual: out-of-balance force on free dofs against the largest link force
        fres = 0.0
        vmax = 0.0
        for a in range(n):
            fres = max(fres, abs(frc[a, 0]) * free[a, 0])
            fres = max(fres, abs(frc[a, 1]) * free[a, 1])
            v2 = vel[a, 0] ** 2 + vel[a, 1] ** 2
            if d3:
                fres = max(fres, abs(frc[a, 2]) * free[a, 2])
                v2 += vel[a, 2] ** 2
            vmax = max(vmax, np.sqrt(v2))  # eq. 27's V_max: speed
        resid = fres / fmax if fmax > 0.0 else fres
        if not np.isfinite(resid):
            return k, NONFINITE, resid, gx, gy, pi, pj
        if k >= min_steps and resid < tol:
            return k, CONVERGED, resid, gx, gy, pi, pj
        dt = dt_fixed
        if dt <= 0.0 and cap:
            dt = dt_max if vmax == 0.0 else min(dt_max, 0.1 * smin / vmax)  # eqs. 26-27
        elif dt <= 0.0:
            dt = 0.1 * smin / max(vmax, vfloor)  # eq. 27 alone
        ke = 0.0
        for a in range(n):
            for u in range(d):
                vel[a, u] = (vel[a, u] + dt * frc[a, u] / mass[a]) * free[a, u]
                ke += 0.5 * mass[a] * vel[a, u] ** 2
        damped = damp != 0 and ke < state[0]  # kinetic damping: past a peak of kinetic energy
        state[0] = 0.0 if damped else ke
        bad = False
        for a in range(n):
            mv = 0.0
            for u in range(d):
                if damped:
                    vel[a, u] = 0.0
                if free[a, u] > 0.0:
                    pos[a, u] += dt * vel[a, u]
                    mv += (dt * vel[a, u]) ** 2
                else:
                    pos[a, u] = target[a, u]
                if not abs(pos[a, u] - ref[a, u]) < size[a]:  # a particle moved a full width: blow-up
                    bad = True
            mv = np.sqrt(mv) / size[a]
            if not mv <= state[6]:  # also a non-finite move
                state[6] = mv
        # last step of the section 3 loop: stresses and strains from this step's virial
        stresses(vir, size, dim, E, nu, poisson, sig, strain)
        state[1] += dt
        state[2] = min(state[2], dt)
        state[3] = max(state[3], dt)
        state[5] += 1
        if bad:
            status = UNSTABLE
            for a in range(n):
                for u in range(d):
                    if not np.isfinite(pos[a, u]):
                        status = NONFINITE
            return k + 1, status, resid, gx, gy, pi, pj
    return n_steps, status, resid, gx, gy, pi, pj
