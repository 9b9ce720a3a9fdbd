"""Drive the compiled solid step loop in chunks: one quasi-static load increment at a time.

Units: cm, N, s; E in N/cm^2, rho in N s^2/cm^4 (isaflow.core.units).
"""

import logging
import time
from dataclasses import dataclass, field

import numpy as np

from isaflow.contract import Result

from . import kernels as K

log = logging.getLogger("isaflow.solid")

VARIANT_FLAGS = {"paper": (0, 0), "hooke": (1, 1), "objective": (1, 2)}  # (Poisson coupling, shear springs)
STATUS = {K.RUNNING: "step_limit", K.CONVERGED: "converged", K.UNSTABLE: "escaped", K.NONFINITE: "nonfinite"}


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


def relax(st, tol, max_steps, dt=0.0, min_steps=10, chunk=20000, log_every=10.0, label="", cap=True, vfloor=0.0):
    """Step until the residual max|F_free| / max|f_link| < tol, instability, or max_steps.

    dt = 0: the paper's rule (eqs. 26-27; cap=False: eq. 27 alone, V_max floored at vfloor [cm/s] > 0);
    dt > 0: that fixed step [s].  Returns (status, message, residual, disk force (2,) N).
    """
    if not cap and not vfloor > 0.0 and dt <= 0.0:
        raise ValueError("relax: eq. 27 without the eq. 26 cap needs a speed floor vfloor > 0 (dt = 0.1 dx / V_max)")
    poisson, shear = VARIANT_FLAGS[st.variant]
    b, m = st.block, st.mat
    done, last = 0, time.perf_counter()
    t0 = last
    while True:
        n = min(chunk, max_steps - done)
        steps, code, resid, gx, gy = K.relax(
            st.pos, st.vel, b.ref, st.target, st.free, st.mass, st.size, b.la, b.lb, b.d0, b.axis, b.partners,
            st.disk, m.E, m.nu, m.G, m.rho, b.dim, poisson, shear, st.push, float(dt), float(tol), min_steps, n,
            st.sig, st.strain, st.frc, st.pres, st.clock, st.fext, st.damp, int(bool(cap)), float(vfloor))
        done += steps
        min_steps = max(0, min_steps - steps)
        now = time.perf_counter()
        if now - last > log_every:
            log.info("%s step %d residual %.3g", label, st.steps, resid)
            last = now
        if code != K.RUNNING or done >= max_steps:
            break
    st.wall_time += time.perf_counter() - t0
    status = STATUS[code]
    msg = {
        "converged": f"max|F_free| / max|f_link| = {resid:.2e} < {tol:g} at step {st.steps}",
        "step_limit": f"{max_steps} steps without reaching residual {tol:g} (residual {resid:.2e}) at step {st.steps}",
        "escaped": f"unstable: a particle moved a full particle width at step {st.steps} (dt {st.clock[3]:.3g} s)",
        "nonfinite": f"NaN or infinite force or position at step {st.steps}",
    }[status]
    return status, msg, float(resid), np.array([gx, gy])


def prescribe(st, mask, disp):
    """Prescribe dofs: mask (N, 3) bool are held at ref + disp (N, 3) or (3,) [cm]."""
    st.free = np.where(mask, 0.0, 1.0)
    st.target = st.block.ref + np.broadcast_to(disp, st.pos.shape)
    st.pos[mask] = st.target[mask]
    st.vel[mask] = 0.0


def warmup():
    """Load (or compile) the kernels on a 2-particle chain, so solver times exclude compilation."""
    from .lattice import block

    b = block(2, 1, 1, 1.0)
    st = State(b, Material(1.0, 0.3, 1.0), "hooke", np.ones((2, 3)), push=1)
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
