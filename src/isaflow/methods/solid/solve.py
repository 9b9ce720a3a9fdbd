"""The solid's stepper (isaflow.driver.drive runs the compiled step loop in chunks): one quasi-static load
increment, or one fixed-length time history, at a time.

Units: cm, N, s; E in N/cm^2, rho in N s^2/cm^4 (isaflow.core.units).
"""

import logging
from dataclasses import dataclass, field

import numpy as np

from isaflow import driver
from isaflow.contract import Result

from . import kernels as K

log = logging.getLogger("isaflow.solid")

VARIANT_FLAGS = {"paper": (0, 0), "hooke": (1, 1), "objective": (1, 2)}  # (Poisson coupling, shear springs)
OUTCOME = {K.CONVERGED: "converged", K.UNSTABLE: "escaped", K.NONFINITE: "nonfinite"}  # kernel codes


@dataclass
class Material:
    E: float  # Young's modulus, N/cm^2
    nu: float  # Poisson's ratio
    rho: float  # density, N s^2/cm^4

    @property
    def G(self):
        """Shear modulus E / (2 (1 + nu)) [N/cm^2] (eq. 18)."""
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def c(self):
        """Bar wave speed sqrt(E / rho) [cm/s]: the C_s of eq. 26 (inferred)."""
        return float(np.sqrt(self.E / self.rho))


@dataclass
class State:
    """Particles of one solid run (see lattice.Block); arrays (N, 3) unless noted."""

    block: object
    mat: Material
    variant: str
    free: np.ndarray  # 1.0 free dof, 0.0 prescribed
    pos: np.ndarray = None
    vel: np.ndarray = None
    target: np.ndarray = None
    sig: np.ndarray = None  # (N, 6) xx, yy, zz, yx, zy, zx (shear: traction along the first axis on planes normal to the second), N/cm^2
    strain: np.ndarray = None
    frc: np.ndarray = None  # last force (reactions on prescribed dofs), N
    pres: np.ndarray = None  # (N,) disk contact force, N
    disk: np.ndarray = field(default_factory=lambda: np.zeros(4))  # cx, cy, R cm, on
    clock: np.ndarray = None  # kernel state: [ke, sim time, dt min, dt max, -, steps, max step move / dx]
    push: int = 0  # unlinked pairs push (2D only)
    damp: int = 1  # kinetic damping on (1) or off (0: undamped time history)
    fext: np.ndarray = None  # (N, 3) external loads, N (per unit thickness in 2D)
    wall_time: float = 0.0

    def __post_init__(self):
        b = self.block
        self.pos = b.ref.copy() if self.pos is None else self.pos
        self.vel = np.zeros_like(self.pos)
        self.target = self.pos.copy()
        self.sig = np.zeros((b.n, 6))
        self.strain = np.zeros((b.n, 3))
        self.frc = np.zeros((b.n, 3))
        self.pres = np.zeros(b.n)
        self.fext = np.zeros((b.n, 3)) if self.fext is None else self.fext
        self.clock = np.array([0.0, 0.0, np.inf, 0.0, 0.0, 0.0, 0.0])
        self.mass = np.full(b.n, self.mat.rho * b.dx**b.dim)
        self.size = np.full(b.n, b.dx)

    @property
    def dt_max(self):
        """Eq. 26: dx / (4 C_s) [s]."""
        return self.block.dx / (4.0 * self.mat.c)

    @property
    def steps(self):
        return int(self.clock[5])


class Stepper:
    """One relaxation (or fixed-length stepping) of a State for isaflow.driver.drive: one advance is one
    compiled chunk of up to ``chunk`` steps (kernels.relax), stopped by the kernel's outcomes (converged:
    residual below tol once min_steps are done; escaped; nonfinite) or by the budget of max_steps (the
    driver's ``step_limit``).  sample(stepper): called after every advance (record); the solid is judged by
    its own residual, not by isaflow.rest, so record returns no rest sample.

    A 2D block whose z is inert (z of positions, targets, velocities and loads all 0) steps in the 2D layout
    (kernels: (N, 2) arrays, 3-component virial), copied from the State at the start and back after every
    advance; otherwise (or with flat=False) the State's own (N, 3) arrays step in the 3D layout.  dt = 0: the
    paper's rule (eqs. 26-27; cap=False: eq. 27 alone, V_max floored at vfloor [cm/s] > 0); dt > 0: that fixed
    step [s]."""

    t0 = 0.0  # the solid's runs have no chain clock (rest_message is never asked: no rest monitor)

    def __init__(self, st, tol, max_steps, dt=0.0, min_steps=10, chunk=20000, label="", cap=True, vfloor=0.0,
                 sample=None, flat=None):
        if not cap and not vfloor > 0.0 and dt <= 0.0:
            raise ValueError("relax: eq. 27 without the eq. 26 cap needs a speed floor vfloor > 0 (dt = 0.1 dx / V_max)")
        self.st, self.tol, self.max_steps, self.dt, self.min_steps, self.chunk = st, tol, max_steps, dt, min_steps, chunk
        self.label, self.cap, self.vfloor, self.sample = label, int(bool(cap)), float(vfloor), sample
        self.poisson, self.shear = VARIANT_FLAGS[st.variant]
        b = st.block
        if b.geometry is None:
            b.geometry = K.link_geometry(b.d0, b.la, b.lb, b.axis, b.n)
        inert = b.dim == 2 and not any(np.any(x[:, 2]) for x in (b.ref, st.pos, st.target, st.vel, st.fext))
        self.flat = inert if flat is None else bool(flat) and inert
        if self.flat:  # the 2D layout: contiguous copies of the x, y columns
            self.pos, self.vel, self.frc = (np.ascontiguousarray(x[:, :2]) for x in (st.pos, st.vel, st.frc))
            self.ref, self.target, self.free, self.fext = (np.ascontiguousarray(x[:, :2]) for x in
                                                             (b.ref, st.target, st.free, st.fext))
            self.sig, self.strain = np.ascontiguousarray(st.sig[:, :4]), np.ascontiguousarray(st.strain[:, :2])
            self.vir, self.rot, self.grad = np.zeros((b.n, 3)), np.zeros((b.n, 1)), np.zeros((b.n, 2))
        else:
            self.pos, self.vel, self.frc, self.ref, self.target = st.pos, st.vel, st.frc, b.ref, st.target
            self.free, self.fext, self.sig, self.strain = st.free, st.fext, st.sig, st.strain
            self.vir, self.rot, self.grad = np.zeros((b.n, 6)), np.zeros((b.n, 9)), np.zeros((b.n, 9))
        self.anchor, self.box = np.zeros_like(self.pos), np.zeros(4)
        self.pi, self.pj = np.zeros(1, np.int32), np.zeros(1, np.int32)  # the unlinked pairs (push)
        self.done, self.code, self.resid, self.g = 0, K.RUNNING, np.inf, np.zeros(2)

    def advance(self):
        st, b, m = self.st, self.st.block, self.st.mat
        L0, e, cnt = b.geometry
        n = min(self.chunk, self.max_steps - self.done)
        steps, self.code, self.resid, gx, gy, self.pi, self.pj = K.relax(
            self.pos, self.vel, self.ref, self.target, self.free, st.mass, st.size, b.la, b.lb, L0, e, b.axis, cnt,
            b.partners, st.disk, m.E, m.nu, m.G, m.rho, b.dim, self.poisson, self.shear, st.push, float(self.dt),
            float(self.tol), self.min_steps, n, self.sig, self.strain, self.frc, st.pres, st.clock, self.fext,
            st.damp, self.cap, self.vfloor, self.vir, self.rot, self.grad, self.anchor, self.pi, self.pj, self.box)
        self.g[:] = gx, gy
        self.done += steps
        self.min_steps = max(0, self.min_steps - steps)
        if self.flat:
            st.pos[:, :2], st.vel[:, :2], st.frc[:, :2] = self.pos, self.vel, self.frc
            st.sig[:, :4], st.strain[:, :2] = self.sig, self.strain
        if self.code == K.RUNNING:
            return None
        return OUTCOME[self.code], self.message(OUTCOME[self.code])

    def message(self, status):
        st, r = self.st, self.resid
        return {"converged": f"max|F_free| / max|f_link| = {r:.2e} < {self.tol:g} at step {st.steps}",
                "escaped": f"unstable: a particle moved a full particle width at step {st.steps} (dt {st.clock[3]:.3g} s)",
                "nonfinite": f"NaN or infinite force or position at step {st.steps}",
                "step_limit": f"{self.max_steps} steps without reaching residual {self.tol:g} (residual {r:.2e}) at "
                              f"step {st.steps}"}[status]

    def record(self):
        if self.sample is not None:
            self.sample(self)

    def spent(self):
        return self.done >= self.max_steps

    def fraction_done(self):
        return self.done / self.max_steps if self.max_steps else 1.0

    def limit_message(self, monitor):
        return self.message("step_limit")

    def progress(self, monitor):
        return f"{self.label} step {self.st.steps} residual {self.resid:.3g}"

    def result(self, run):
        """(status, message, residual, disk force (2,) N); the loop's time is added to the State's."""
        self.st.wall_time += run.wall_time
        return run.status, run.message, float(self.resid), self.g.copy()


def relax(st, tol, max_steps, dt=0.0, min_steps=10, chunk=20000, label="", cap=True, vfloor=0.0, sample=None):
    """Step until the residual max|F_free| / max|f_link| < tol, instability, or max_steps (a Stepper run by
    isaflow.driver.drive).  Returns (status, message, residual, disk force (2,) N)."""
    return driver.drive(Stepper(st, tol, max_steps, dt, min_steps, chunk, label, cap, vfloor, sample), log=log.info)


def prescribe(st, mask, disp):
    """Prescribe dofs: mask (N, 3) bool are held at ref + disp (N, 3) or (3,) [cm]."""
    st.free = np.where(mask, 0.0, 1.0)
    st.target = st.block.ref + np.broadcast_to(disp, st.pos.shape)
    st.pos[mask] = st.target[mask]
    st.vel[mask] = 0.0


def warmup():
    """Load (or compile) the relaxation kernels, so solver times exclude compilation: a 2-particle chain in the 2D
    and the 3D layout (the vessel with water has its own, water.warmup; outputs.write_run calls both)."""
    from .lattice import block

    for shape in ((2, 1, 1), (2, 1, 2)):
        b = block(*shape, 1.0)
        st = State(b, Material(1.0, 0.3, 1.0), "hooke", np.ones((b.n, 3)), push=1)
        relax(st, 1e-3, 2)


def result(st, case, status, msg, resid, history, params, start=None):
    """contract.Result of a solid state: (x, y) in pos, z and stresses in fields, no wall contacts."""
    b = st.block
    fields = {
        "pos_z0": (("particle",), b.ref[:, 2], "cm", "initial particle z"),
        "pos_z": (("particle",), st.pos[:, 2], "cm", "final particle z"),
        "stress": (("particle", "stress_component"), st.sig, "N cm-2",
                   "particle virial stress xx, yy, zz, yx, zy, zx (dim 2: per unit thickness, zz plane strain)"),
        "lattice_index": (("particle", "axis"), b.index.astype(np.int32), "1", "lattice index i, j, k"),
    }
    return Result(
        method="solid", variant=st.variant, pos0=b.ref[:, :2].copy(), pos=st.pos[:, :2].copy(),
        weight=st.mass * 981.0, contact_wall=np.zeros(0, int), contact_point=np.zeros((0, 2)),
        contact_force=np.zeros((0, 2)), status=status, message=msg, steps=st.steps, start_step=0,
        wall_time=st.wall_time, force_evals=st.steps, residual=resid,
        residual_name="max|F_free| / max|f_link|", residual_units="1", sim_time=float(st.clock[1]),
        history=history, fields=fields,
        params={"case": case, "dim": b.dim, "dx_cm": b.dx, "E_N_cm2": st.mat.E, "nu": st.mat.nu,
                "rho_N_s2_cm4": st.mat.rho, "dt_min_s": float(st.clock[2]), "dt_max_s": float(st.clock[3]),
                "max_step_move_over_dx": float(st.clock[6]),
                "dt_rule_s": st.dt_max, **params})
