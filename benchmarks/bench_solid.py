"""Cost per particle-step of the solid step loop (marko2017) against its floor, and of the coupled vessel steps.

The floor: the same per-link arithmetic (eqs. 15-16, the shear springs, the rotations of the 'objective'
springs), the same integration and stress update, over the same links, fused into one compiled loop of
(N, 2) arrays with everything inline (:func:`floor_steps`, 2D lattices, their unlinked contacts and disk).
It must give the project's numbers to the bit (checked on every case it times), so it does the same work.

Cases: the elastic floor plate (505 particles, 'objective', the workflow's floor_* runs), the Hertz plate
(510, unlinked contacts and the disk), 2D plates of 10^4 and 9 x 10^4 particles under each
variant, 3D blocks (the 3D layout, no floor), and the section 4.4 vessel with water under both couplings
(per coupled step: water forces from one reused list, the stop contacts from it, the ring's step).
Timings: repeats interleaved (project loop, floor, project loop, ...), medians.

Writes benchmarks/results/solid_step_cost.csv (case, n particles, dim, variant, steps, s, ns per
particle-step, floor ns per particle-step, ratio project / floor).
Run: python benchmarks/bench_solid.py   (about a minute on one quiet core), or snakemake -c1 benchmarks/results/solid_step_cost.csv
"""

import csv
import statistics
import time
from pathlib import Path

import numpy as np

from isaflow import driver
from isaflow.core.jit import njit
from isaflow.core.units import KG, PA
from isaflow.core.neighbours import build_pairs
from isaflow.methods.solid import cases, floor, lattice, settings, solve, water
from isaflow.methods.solid import kernels as K
from isaflow.methods.solid.kernels import add_pair2

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "solid_step_cost.csv"
CFG = settings.checked_values(ROOT / "config" / "methods" / "solid.yaml")
MAT = solve.Material(207e9 * PA, 0.3, 7800 * KG / 1e6)
REPEATS = 5


@njit(cache=True, nogil=True)
def floor_steps(pos, vel, ref, target, free, mass, size, fext, la, lb, L0, e, laxis, cnt, E, nu, G, rho, poisson,
                shear, n_steps, sig, strain, frc, vir, grad, rot, state, pi, pj, m, disk, pres):
    """n_steps of the solid loop for a 2D lattice (kinetic damping, eqs. 26-27), every pass inline; arrays as
    kernels.relax's 2D layout; the unlinked pairs (pi, pj, m) that may push, found before (the project's loop
    finds them at its start), and the disk.  Returns the last residual."""
    n = pos.shape[0]
    smin = size.min()
    dt_max = smin / (4.0 * np.sqrt(E / rho))
    area0 = smin
    resid = 0.0
    for _ in range(n_steps):
        if shear == 2:
            for a in range(n):
                grad[a, 0] = 0.0
                grad[a, 1] = 0.0
            for k in range(la.shape[0]):
                a, b, u = la[k], lb[k], laxis[k]
                i = 1 - u
                g = ((pos[b, i] - ref[b, i]) - (pos[a, i] - ref[a, i])) / L0[k]
                grad[a, u] += g
                grad[b, u] += g
        for a in range(n):
            if shear == 2:
                gyx = grad[a, 0] / cnt[a, 0] if cnt[a, 0] > 0.0 else grad[a, 0]
                gxy = grad[a, 1] / cnt[a, 1] if cnt[a, 1] > 0.0 else grad[a, 1]
                rot[a, 0] = 0.5 * (gyx - gxy)
            frc[a, 0] = fext[a, 0]
            frc[a, 1] = fext[a, 1]
            vir[a, 0] = 0.0
            vir[a, 1] = 0.0
            vir[a, 2] = 0.0
        fmax = 0.0
        for k in range(la.shape[0]):
            a, b, u = la[k], lb[k], laxis[k]
            o = 1 - u
            dx = pos[b, 0] - pos[a, 0]
            dy = pos[b, 1] - pos[a, 1]
            r = np.sqrt(dx * dx + dy * dy)
            l0 = L0[k]
            eu = 0.5 * (strain[a, u] + strain[b, u])
            eo = 0.5 * (strain[a, o] + strain[b, o])
            eps_p = 0.0
            if poisson:
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
                dn = dx * e[k, 0] + dy * e[k, 1]
                c = G * area0 * (1.0 + eo) / l0
                tx = dx - dn * e[k, 0]
                ty = dy - dn * e[k, 1]
                if shear == 2:
                    c *= 2.0
                    if u == 0:
                        ty -= 0.5 * l0 * (rot[a, 0] + rot[b, 0])
                    else:
                        tx += 0.5 * l0 * (rot[a, 0] + rot[b, 0])
                fx += c * tx
                fy += c * ty
            add_pair2(a, b, fx, fy, dx, dy, frc, vir)
        for k in range(m):  # unlinked pairs closer than their mean size push
            a, b = pi[k], pj[k]
            dx = pos[b, 0] - pos[a, 0]
            dy = pos[b, 1] - pos[a, 1]
            r = np.sqrt(dx * dx + dy * dy)
            r0 = 0.5 * (size[a] + size[b])
            if r >= r0 or r == 0.0:
                continue
            fn = E * min(size[a], size[b]) * (r - r0) / r0
            fx = fn * dx / r
            fy = fn * dy / r
            add_pair2(a, b, fx, fy, dx, dy, frc, vir)
        if disk[3] != 0.0:  # the rigid disk
            for a in range(n):
                pres[a] = 0.0
                dx = pos[a, 0] - disk[0]
                dy = pos[a, 1] - disk[1]
                D = np.sqrt(dx * dx + dy * dy)
                pen = disk[2] + 0.5 * size[a] - D
                if pen <= 0.0:
                    continue
                f = 2.0 * E * size[a] * pen / size[a]
                fx = f * dx / D
                fy = f * dy / D
                frc[a, 0] += fx
                frc[a, 1] += fy
                vir[a, 0] += fx * (-0.5 * size[a] * dx / D) * 2.0
                vir[a, 1] += fy * (-0.5 * size[a] * dy / D) * 2.0
                pres[a] = f
        fres = 0.0
        vmax = 0.0
        for a in range(n):
            fres = max(fres, abs(frc[a, 0]) * free[a, 0])
            fres = max(fres, abs(frc[a, 1]) * free[a, 1])
            vmax = max(vmax, np.sqrt(vel[a, 0] ** 2 + vel[a, 1] ** 2))
        resid = fres / fmax if fmax > 0.0 else fres
        dt = dt_max if vmax == 0.0 else min(dt_max, 0.1 * smin / vmax)
        ke = 0.0
        for a in range(n):
            vel[a, 0] = (vel[a, 0] + dt * frc[a, 0] / mass[a]) * free[a, 0]
            ke += 0.5 * mass[a] * vel[a, 0] ** 2
            vel[a, 1] = (vel[a, 1] + dt * frc[a, 1] / mass[a]) * free[a, 1]
            ke += 0.5 * mass[a] * vel[a, 1] ** 2
        damped = ke < state[0]
        state[0] = 0.0 if damped else ke
        for a in range(n):
            mv = 0.0
            for u in range(2):
                if damped:
                    vel[a, u] = 0.0
                if free[a, u] > 0.0:
                    pos[a, u] += dt * vel[a, u]
                    mv += (dt * vel[a, u]) ** 2
                else:
                    pos[a, u] = target[a, u]
            mv = np.sqrt(mv) / size[a]
            if not mv <= state[6]:
                state[6] = mv
            V2 = 2.0 * size[a] ** 2
            s0 = vir[a, 0] / V2
            s1 = vir[a, 1] / V2
            s2 = nu * (s0 + s1) if poisson else 0.0
            sig[a, 0] = s0
            sig[a, 1] = s1
            sig[a, 2] = s2
            sig[a, 3] = vir[a, 2] / V2
            if poisson:
                strain[a, 0] = (s0 - nu * (s1 + s2)) / E
                strain[a, 1] = (s1 - nu * (s2 + s0)) / E
            else:
                strain[a, 0] = s0 / E
                strain[a, 1] = s1 / E
        state[1] += dt
        state[2] = min(state[2], dt)
        state[3] = max(state[3], dt)
        state[5] += 1
    return resid


def run_floor(st, n):
    """(seconds, stepper of st's 2D layout after n steps of :func:`floor_steps`)."""
    stp = solve.Stepper(st, 0.0, n, min_steps=n, chunk=n)
    b, m = st.block, st.mat
    L0, e, cnt = b.geometry
    pi, pj, npush = np.zeros(1, np.int32), np.zeros(1, np.int32), 0
    if st.push:  # the unlinked pairs as the project's loop finds them (cutoff 1.5 size + 0.25 size)
        box = np.array([*stp.pos.min(0), *(stp.pos.max(0) + 1e-9)])
        pi, pj, npush = build_pairs(stp.pos, box, 1.5 * st.size.max() + 0.25 * st.size.min())
        npush = K.unlinked(pi, pj, npush, b.partners)
    t = time.perf_counter()
    floor_steps(stp.pos, stp.vel, stp.ref, stp.target, stp.free, st.mass, st.size, stp.fext, b.la, b.lb, L0, e,
                b.axis, cnt, m.E, m.nu, m.G, m.rho, stp.poisson, stp.shear, n, stp.sig, stp.strain, stp.frc, stp.vir,
                stp.grad, stp.rot, st.clock, pi, pj, npush, st.disk, st.pres)
    return time.perf_counter() - t, stp


def run_project(st, n):
    """(seconds, stepper) of n steps of the project's loop (one solve.Stepper advance, tol 0: never converged)."""
    stp = solve.Stepper(st, 0.0, n, min_steps=n, chunk=n)
    t = time.perf_counter()
    stp.advance()
    return time.perf_counter() - t, stp


def floor_plate():
    st, top, _ = floor.plate(CFG)
    st.fext[np.flatnonzero(top), 1] = -CFG["floor"]["weight_N"] / top.sum()
    return st


def plate(nx, ny, variant):
    b = lattice.block(nx, ny, 1, 0.0159)
    st = solve.State(b, MAT, variant, np.ones((b.n, 3)))
    mask = np.zeros((b.n, 3), bool)
    mask[b.index[:, 1] == 0] = True
    mask[:, 2] = True
    disp = np.zeros((b.n, 3))
    disp[b.index[:, 1] == ny - 1, 1] = 1e-6
    solve.prescribe(st, mask, disp)
    return st


def hertz(variant):
    st = cases.hertz_state(CFG, variant)
    cases.set_depth(st, CFG["hertz"]["radius_mm"] * 0.1, CFG["hertz"]["depths_um"][0] * 1e-4)
    return st


def block3(n, variant):
    b = lattice.block(n, n, n, 0.0159)
    st = solve.State(b, MAT, variant, np.ones((b.n, 3)))
    mask = np.zeros((b.n, 3), bool)
    mask[b.index[:, 1] == 0] = True
    disp = np.zeros((b.n, 3))
    disp[b.index[:, 1] == n - 1, 1] = 1e-6
    solve.prescribe(st, mask, disp)
    return st


def timed(make, steps, with_floor):
    """Median seconds of the project's loop and of the floor (None without), repeats interleaved; the floor's
    positions, velocities and stresses checked equal to the loop's."""
    run_project(make(), 2)
    if with_floor:
        run_floor(make(), 2)
    tp, tf = [], []
    for _ in range(REPEATS):
        t, sp = run_project(make(), steps)
        tp.append(t)
        if with_floor:
            t, sf = run_floor(make(), steps)
            tf.append(t)
            if not all(np.array_equal(getattr(sp, k), getattr(sf, k)) for k in ("pos", "vel", "sig", "strain")) or \
                    not np.array_equal(sp.st.pres, sf.st.pres):
                raise AssertionError("the floor's numbers differ from the project's loop: not the same arithmetic")
    return statistics.median(tp), statistics.median(tf) if with_floor else None


def vessel(coupling, steps):
    """(median seconds of `steps` coupled steps of the settings' vessel with water: the driven loop only, its
    records included; particles, water and ring)."""
    cfg = {**CFG, "vessel": {**CFG["vessel"], "coupling": coupling}}
    dt = CFG["vessel"]["dt_ns"] * 1e-9
    water.coupled_history(cfg, dt, 2, 1)
    out = []
    for _ in range(REPEATS):
        c = water.Coupled(cfg, dt, steps, CFG["vessel"]["record_every"])
        driver.drive(c)
        out.append(c.st.wall_time)
    return statistics.median(out), c.nw + c.st.block.n


def main():
    rows = []

    def row(case, n, dim, variant, steps, s, s_floor):
        ns = s / (n * steps) * 1e9
        nf = s_floor / (n * steps) * 1e9 if s_floor is not None else None
        rows.append({"case": case, "n": n, "dim": dim, "variant": variant, "steps": steps, "seconds": round(s, 4),
                     "ns_per_particle_step": round(ns, 2), "floor_ns_per_particle_step": round(nf, 2) if nf else "",
                     "ratio": round(ns / nf, 3) if nf else ""})
        print(rows[-1], flush=True)

    s, f = timed(floor_plate, 20000, True)
    row("floor_plate", floor_plate().block.n, 2, CFG["floor"]["solid_model"], 20000, s, f)
    for v in ("paper", "hooke"):
        s, f = timed(lambda: hertz(v), 20000, True)
        row("hertz_plate", hertz(v).block.n, 2, v, 20000, s, f)
    for nx, steps in ((100, 1000), (300, 100)):
        for v in ("paper", "hooke", "objective"):
            s, f = timed(lambda: plate(nx, nx, v), steps, True)
            row(f"plate_{nx}x{nx}", nx * nx, 2, v, steps, s, f)
    for n, steps in ((11, 2000), (30, 100)):
        for v in ("paper", "hooke"):
            s, _ = timed(lambda: block3(n, v), steps, False)
            row(f"block_{n}^3", n**3, 3, v, steps, s, None)
    for coupling in ("mirror_pressure", "stop_at_boundary"):
        s, n = vessel(coupling, 400)
        row(f"vessel_water_{coupling}", n, 2, CFG["vessel"]["solid_model"], 400, s, None)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    with open(OUT, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()
