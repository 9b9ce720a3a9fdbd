"""ISA's stepper for driver.drive: the compiled relaxation in chunks, its history and outcomes -> contract.Result.

The three update rules run relax.relax_resume; the overdamped variant (not the paper's) runs
dynamics.overdamped_resume, whose ``converged`` also needs the liquid at rest (config/rest.yaml).
Outcomes (contract.OUTCOMES): ``converged`` (max|F| < f_tol), ``cycle``
(max|F| repeats with a fixed period: a limit cycle that can never converge),
``step_limit``, ``escaped`` (a step would carry a particle across a wall, or
a particle left the walls' bounding box), ``nonfinite``.
"""

import hashlib
from contextlib import contextmanager

import numba
import numpy as np

from ... import at_rest as AT, driver, rest as REST
from ...contract import Result, wall_resultants
from ...core.geometry import bounding_box, outside_box
from ...core.units import G
from ...tank import vessel_counts
from . import dynamics as D
from . import forces as F
from . import newton as NW
from . import relax as R
from .settings import DERIVED, RULES, settings

CYCLE_WINDOW, CYCLE_MAX_PERIOD, CYCLE_RTOL = 400, 50, 1e-6
# where each outcome is detected (for the report)
DETECTED_BY = {
    "converged": "the compiled loop, before every step (relax.relax_resume, newton.newton_resume)",
    "cycle": f"detect_cycle on the last {CYCLE_WINDOW + CYCLE_MAX_PERIOD} max|F| values at every chunk end, "
             f"periods 2-{CYCLE_MAX_PERIOD}, while the particles stay put",
    "step_limit": "the solver, at solver.max_steps (newton: also when no step lowers the energy)",
    "escaped": "the compiled loop (every move is tested against the walls, core.geometry.crossed_wall) and "
               "the solver (walls' bounding box at every chunk end)",
    "nonfinite": "the compiled loop, before every step",
}


def detect_cycle(h, window=CYCLE_WINDOW, max_period=CYCLE_MAX_PERIOD, rtol=CYCLE_RTOL):
    """Smallest period 2 <= p <= max_period with h[k] == h[k - p] (to rtol)
    over the last ``window`` entries of the max|F| series h; 0 if none.

    Period 1 (a constant max|F|) is not a cycle of any update here: a fixed
    point has F = 0, and a constant max|F| is e.g. a free fall.
    """
    if len(h) < window + max_period:
        return 0
    tail = h[-(window + max_period):]
    scale = tail.max()
    if np.abs(tail[1:] - tail[:-1]).max() <= rtol * scale:
        return 0  # constant
    for p in range(2, max_period + 1):
        if np.abs(tail[p:] - tail[:-p]).max() <= rtol * scale:
            return p
    return 0


class ChunkMemo:
    """Replays a chunk of relax.relax_resume whose inputs repeat bit for bit.

    The compiled chunk is a deterministic function of its arguments (positions, FIRE velocities,
    list-build positions, kernel state, force buffer, step count; the rest is the run's constants),
    independent of the threads, so a chunk started from byte-identical arrays ends in byte-identical
    arrays: replaying it from memory changes no output, only the solver time.  Used where a run is
    meant to go on inside an exact cycle (solver.stop_on_cycle off, e.g. flow_complete_nocycle:
    30,000,000 steps of which all but the first few thousand repeat a few chunk states).  A chunk's
    outputs are stored the second time its inputs are seen (so a run that never repeats stores
    nothing), up to ``budget`` bytes.
    """

    def __init__(self, budget=256 * 2**20):
        self.budget = budget
        self.seen, self.stored = set(), {}
        self.replayed = 0

    @staticmethod
    def key(arrays, n):
        h = hashlib.sha256(str(n).encode())
        for a in arrays:
            h.update(a.tobytes())
        return h.digest()

    def get(self, key, arrays, buf):
        """Outputs (done, code, crossing) of a stored chunk, copied into arrays and buf; None if not stored."""
        hit = self.stored.get(key)
        if hit is None:
            return None
        for a, saved in zip(arrays, hit[1]):
            a[...] = saved
        buf[...] = hit[2]
        self.replayed += 1
        return hit[0]

    def put(self, key, arrays, buf, out):
        """Remember a chunk's outputs if its inputs were seen before and the budget allows."""
        if key not in self.seen:
            self.seen.add(key)
            return
        size = sum(a.nbytes for a in arrays) + buf.nbytes
        if self.budget >= size:
            self.budget -= size
            self.stored[key] = (out, [a.copy() for a in arrays], buf.copy())


def contacts(pos, walls, s):
    """(particle, wall, point, force) wall contacts of positions under settings s."""
    return F.wall_contacts(pos, walls, s["wall_l_u"], s["wall_r_u"], s["wall_p"])


def thread_count(threads=None):
    """The number of threads a solve runs on: ``threads``, or numba's current number
    (NUMBA_NUM_THREADS, else the machine's cores) when None.  Refused (ValueError) outside
    1 ... numba.config.NUMBA_NUM_THREADS."""
    t = numba.get_num_threads() if threads is None else threads
    if isinstance(t, bool) or not isinstance(t, (int, np.integer)) or not 1 <= t <= numba.config.NUMBA_NUM_THREADS:
        raise ValueError(f"threads: {threads!r} is not a whole number from 1 to {numba.config.NUMBA_NUM_THREADS} "
                         f"(NUMBA_NUM_THREADS)")
    return int(t)


@contextmanager
def numba_threads(threads):
    """Run the enclosed code on ``threads`` numba threads, restoring the previous number after."""
    before = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        yield threads
    finally:
        numba.set_num_threads(before)


def warm_up(threads=1):
    """Compile (or load from numba's cache) every kernel a solve times, with the argument types
    the solve passes them, and start numba's threads, so that solver times exclude both.

    The timed loop calls relax.relax_resume for the three step rules and
    newton.newton_resume for the newton_lm variant: exactly those are called here
    (a function compiled only as another's callee, e.g. relax_resume inside
    relax, can be typed differently and be compiled again on its first direct
    call: Table 1 once timed a 1.6 s compile as solver time).
    """
    pos = np.array([[1.0, 1.0], [1.5, 1.0]])
    walls = np.array([[0.0, 2.0, 0.0, 0.0], [0.0, 0.0, 2.0, 0.0], [2.0, 0.0, 2.0, 2.0]])
    box = np.array([0.0, 0.0, 2.0, 2.0])
    for rule in RULES.values():
        if rule in (D.OVERDAMPED, NW.NEWTON):
            continue
        for p in (1.0, 2.0):
            for resume in (False, True):
                R.relax_resume(pos.copy(), np.zeros_like(pos), np.ones(2), walls, box, 0.5, 1.0, 0.7, 1.0, rule,
                               1e-3, 1.0, 0.1, 0.1, 2, 0.1, np.zeros_like(pos), np.zeros(2), pos.copy(), np.zeros(5),
                               resume, threads, p, p, R.NO_TRAIL)
    for p in (1.0, 2.0):
        D.overdamped_resume(pos.copy(), np.zeros_like(pos), np.ones(2), walls, box, 0.5, 1.0, 0.7, 1.0, 1e-3, 1.0,
                            1.0, G, 0.1, 1e-5, 1.0, 1.0, 2, 0.1, np.zeros_like(pos), np.zeros(2), np.zeros(2),
                            pos.copy(), np.array([0.0, 0.0, -1.0, 0.0, 0.0]), False, p, p)
        F.wall_contacts(pos, walls, 0.5, 1.0, p)
    NW.warm_up(threads)
    R.start_threads(np.zeros(threads, np.int64))  # compiled whatever the count (one cache serves every count)


class _History:
    """Records of max|F| (every ``every`` steps), wall resultants and vessel counts
    (every chunk), under their run-file names (the driver keeps the snapshots)."""

    def __init__(self, hist, n_walls, vessels):
        self.every = hist.get("every", 0)
        self.walls = hist.get("walls", False)
        self.vessels = vessels if hist.get("vessels") and vessels else None
        self.n_walls = n_walls
        self.rec = {k: [] for k in ("hist_step", "hist_fmax", "hist_fmax_lo", "hist_fmax_hi", "hist_energy",
                                    "sample_step", "sample_wall_resultant", "sample_vessel_count")}

    def steps(self, step, h, origin, ke=None):
        """Record h (max|F| before steps step, step + 1, ...) in strides counted from step origin <= step;
        ke: the kinetic energies before the same steps (overdamped variant), recorded at the stride starts."""
        for k0 in range((origin - step) % self.every, len(h), self.every):
            seg = h[k0:k0 + self.every]
            self.rec["hist_step"].append(step + k0)
            self.rec["hist_fmax"].append(seg[0])
            self.rec["hist_fmax_lo"].append(seg.min())
            self.rec["hist_fmax_hi"].append(seg.max())
            if ke is not None:
                self.rec["hist_energy"].append(ke[k0])

    def chunk(self, step, pos, s, walls):
        if self.walls:
            part, wall, point, force = contacts(pos, walls, s)
            self.rec["sample_wall_resultant"].append(wall_resultants(wall, force, self.n_walls))
        if self.vessels is not None:
            self.rec["sample_vessel_count"].append(vessel_counts(pos, self.vessels))
        if self.walls or self.vessels is not None:
            self.rec["sample_step"].append(step)

    def variables(self, n):
        """{name: (dims, array, units, long_name)} of the non-empty records."""
        r = self.rec
        spec = {
            "hist_step": (("record",), np.int64, "1", "algorithm step of max|F| record"),
            "hist_fmax": (("record",), float, "N", "max|F| at hist_step"),
            "hist_fmax_lo": (("record",), float, "N", "smallest max|F| over the record stride"),
            "hist_fmax_hi": (("record",), float, "N", "largest max|F| over the record stride"),
            "hist_energy": (("record",), float, "N cm", "kinetic energy at hist_step (overdamped variant)"),
            "sample_step": (("sample",), np.int64, "1", "algorithm step of diagnostic sample"),
            "sample_wall_resultant": (("sample", "wall", "xy"), float, "N", "resultant force of wall on liquid over the run"),
            "sample_vessel_count": (("sample", "vessel"), np.int64, "1", "particles per vessel"),
        }
        out = {k: (d, np.array(r[k], t), u, ln) for k, (d, t, u, ln) in spec.items() if r[k]}
        if "sample_wall_resultant" in out:
            out["sample_sum_fx"] = (("sample",), out["sample_wall_resultant"][1][:, :, 0].sum(1), "N",
                                  "horizontal resultant of all wall reactions (0 in equilibrium)")
        return out


STATE_VARS = {  # restart state written to every run file: name -> (dims, units, long_name)
    "state_vel": (("particle", "xy"), "cm s-1", "FIRE velocity (unit masses) at the end of the run"),
    "state_pos_build": (("particle", "xy"), "cm", "positions at the last neighbour-list build"),
    "state_chunk_start": (("particle", "xy"), "cm", "positions at the start of the last chunk (cycle test)"),
    "state_moved": ((), "cm", "bound on any displacement since the last neighbour-list build"),
    "state_fire_dt": ((), "s", "FIRE time step (overdamped variant: the simulated time)"),
    "state_fire_alpha": ((), "1", "FIRE mixing parameter alpha (overdamped variant: start of the quiet stretch, s)"),
    "state_fire_n_pos": ((), "1", "FIRE steps since the power was last negative"),
    "state_recent_fmax": (("cycle_window",), "N", "last max|F| values (cycle-detection window)"),
}


def _state_fields(vel, pos_build, chunk_start, kernel, recent):
    arrays = dict(state_vel=vel, state_pos_build=pos_build, state_chunk_start=chunk_start,
                  state_moved=kernel[0], state_fire_dt=kernel[1], state_fire_alpha=kernel[2],
                  state_fire_n_pos=kernel[3], state_recent_fmax=recent)
    return {k: (d, np.asarray(arrays[k]), u, ln) for k, (d, u, ln) in STATE_VARS.items()}


def solve(scene, pos0, weight, start_step=0, log=None, state=None, rest_depth=float("nan"), threads=None):
    """Relax ``pos0`` (N, 2) cm with per-particle ``weight`` (N,) N under an ISA scene.

    start_step: steps already taken (a continued run counts from there up to
    solver.max_steps).  log(text): the driver's progress lines (step, max|F|, ETA), one every
    driver.LOG_EVERY s of wall time.
    rest_depth: depth h [cm] of the rest criterion's e = KE / (W h) (overdamped variant only).
    state: {STATE_VARS name: array} of the run this one continues (same
    scene dynamics), or None for a fresh start; with it the continued run
    repeats the uninterrupted one bit for bit, at any start_step.
    threads: numba threads of the solve (None: numba's current number, i.e.
    NUMBA_NUM_THREADS or the machine's cores); the results do not depend on
    it, and it is recorded in params['threads'].  The newton_lm variant's loop is
    serial.  Returns a contract.Result (method 'isa', variant = the update
    rule); its fields hold the restart state (STATE_VARS).
    """
    threads = thread_count(threads)
    with numba_threads(threads):
        return _solve(scene, pos0, weight, start_step, log, state, rest_depth, threads)


class _Stepper:
    """ISA relaxation for driver.drive: one advance is one compiled chunk (steps up to the next multiple of
    solver.chunk, counted from the chain's start); arguments as solve's."""

    def __init__(self, scene, pos0, weight, start_step, state, rest_depth, threads):
        self.scene, self.pos0, self.start_step = scene, pos0, start_step
        self.rest_depth, self.threads = rest_depth, threads
        self.s = s = settings(scene)
        self.walls = walls = np.ascontiguousarray(scene.walls, float)
        self.box = bounding_box(walls)
        vessels = [(v["name"], v["x"]) for v in scene.spec.get("vessels", [])]
        self.pos = pos = np.array(pos0, float, copy=True, order="C")
        self.weight = weight = np.ascontiguousarray(weight, float)
        self.force = np.zeros_like(pos)
        self.chunk = chunk = s["chunk"]
        self.newton = newton = s["variant"] == "newton_lm"
        restored = state is not None and not newton  # newton keeps no state between runs (restart.py)
        self.vel = np.array(state["state_vel"], float, order="C") if restored else np.zeros_like(pos)
        self.pos_build = np.array(state["state_pos_build"], float, order="C") if restored else pos.copy()
        self.overdamped = overdamped = RULES[s["variant"]] == D.OVERDAMPED
        self.kernel = np.array([float(state[k]) for k in ("state_moved", "state_fire_dt", "state_fire_alpha",
                                                          "state_fire_n_pos")] + [0.0]) if restored else np.zeros(5)
        if overdamped and not restored:
            self.kernel[2] = -1.0  # no quiet stretch yet
        # this run's clock at its start (a continued run's chain time)
        self.t0 = float(self.kernel[1]) if overdamped else 0.0
        self.rest_cfg = REST.load() if overdamped else None
        self.e_norm = float(np.sum(weight)) * float(rest_depth)
        if overdamped and not self.e_norm > 0:
            raise ValueError(f"overdamped variant: the rest criterion needs a positive liquid depth (got {rest_depth})")
        self.ke_buf = np.zeros(chunk) if overdamped else None
        self.max_step_move = 0.0
        self.recent = np.array(state["state_recent_fmax"], float) if restored else np.zeros(0)
        self.resume = restored and start_step % chunk != 0  # inside a chunk: continue its list and FIRE state
        self.chunk_start = np.array(state["state_chunk_start"], float) if self.resume else pos.copy()
        self.buf = np.zeros(chunk)
        self.hist = _History(s["history"], len(walls), vessels)
        self.memo = ChunkMemo() if not (s["stop_on_cycle"] or overdamped or newton) else None
        self.nstate = np.zeros(2)  # newton: (mu, nu) between chunks
        self.counts = np.zeros(4, np.int64)  # newton: Hessian assemblies, CG iterations, refused crossings, evaluations
        warm_up(threads)
        self.step = start_step
        self.period, self.bad_particle = 0, -1
        self.evals = 0
        self.n_chunk = 0
        self.fmax_last = np.nan  # max|F| before the chunk's last step
        self.quiet_end = False  # the last advance took no step and stopped: nothing to record

    def _fmax(self):
        return float(np.abs(self.force).max()) if len(self.force) else 0.0

    def advance(self):
        """One chunk and the outcome checks of its end: (status, message) or None."""
        s, pos, step, chunk, resume = self.s, self.pos, self.step, self.chunk, self.resume
        # chunks end on multiples of `chunk` counted from the chain's start, so
        # a run continued from a state file repeats an uninterrupted run exactly
        n = min(chunk - step % chunk, s["max_steps"] - step) if step < s["max_steps"] else 0
        origin = step - step % chunk if resume else step  # history strides count from here
        if not resume:
            self.chunk_start = pos.copy()
        done, code, crossing = self._run_chunk(n, resume)
        self.resume = False
        if not self.newton:
            self.max_step_move = max(self.max_step_move, float(self.kernel[4]))
        h = self.buf[:done]
        if self.hist.every:
            self.hist.steps(step, h, origin, self.ke_buf[:done] if self.overdamped else None)
        self.step = step + done
        self.n_chunk += 1
        self.recent = np.concatenate([self.recent, h])[-2000:]
        self.fmax_last = float(h[-1]) if done else np.nan
        self.quiet_end = False
        if n == 0 and code != R.NONFINITE:  # started at or past max_steps: forces evaluated once, nothing moved
            self.quiet_end = True
            return ("converged", "") if self._fmax() < s["f_tol"] else ("step_limit", self.limit_message())
        return self._outcome(code, crossing)

    def _run_chunk(self, n, resume):
        """Up to n steps of the update rule's compiled loop -> (steps done, R code, crossing)."""
        s, pos, vel, kernel, force, buf, memo = self.s, self.pos, self.vel, self.kernel, self.force, self.buf, self.memo
        if self.overdamped:
            rc = self.rest_cfg
            done, code, crossing = D.overdamped_resume(
                pos, vel, self.weight, self.walls, self.box, s["wall_l_u"], s["wall_r_u"], s["pair_l_u"],
                s["pair_r_u"], s["dt"], s["zeta"], s["lambda_max"], G, s["f_tol"], rc["energy_ratio"], self.e_norm,
                rc["window"], n, s["skin"], force, buf, self.ke_buf, self.pos_build, kernel, resume, s["wall_p"],
                s["pair_p"],
            )
            self.evals += done + 1
            return done, code, crossing
        if self.newton:
            done, code, crossing = NW.newton_resume(
                pos, self.weight, self.walls, self.box, s["wall_l_u"], s["wall_r_u"], s["pair_l_u"], s["pair_r_u"],
                s["f_tol"], n, s["skin"], force, buf, self.nstate, self.counts)
            self.evals = int(self.counts[3])  # the chunk's first evaluation and every trial step
            return done, {NW.CONVERGED: R.CONVERGED, NW.NONFINITE: R.NONFINITE, NW.STALLED: NW.STALLED}.get(code, R.RUNNING), crossing
        state_arrays = (pos, vel, self.pos_build, kernel, force)
        key = memo.key(state_arrays, n) if memo is not None and not resume else None
        out = memo.get(key, state_arrays, buf) if key is not None else None
        if out is None:
            out = R.relax_resume(
                pos, vel, self.weight, self.walls, self.box, s["wall_l_u"], s["wall_r_u"], s["pair_l_u"],
                s["pair_r_u"], RULES[s["variant"]], s["du"], s["f_ref"], s["dt_max"], s["f_tol"], n, s["skin"],
                force, buf, self.pos_build, kernel, resume, self.threads, s["wall_p"], s["pair_p"], R.NO_TRAIL,
            )
            if key is not None:
                memo.put(key, state_arrays, buf, out)
        self.evals += out[0] + 1  # one evaluation per step taken, plus the chunk's initial one
        return out

    def _outcome(self, code, crossing):
        """(status, message) of a chunk's end code and the checks after it (box, cycle), or None: go on."""
        s, pos, step = self.s, self.pos, self.step
        if code == R.CONVERGED:
            return "converged", ""
        if code == R.NONFINITE:
            self.bad_particle = crossing
            return "nonfinite", (f"non-finite position of particle {crossing} at step {step}"
                                 if not np.isfinite(pos[crossing]).all() else f"non-finite forces at step {step}")
        if code == R.CROSSED:
            i, w = divmod(crossing, self.walls.shape[0])
            return "escaped", (f"particle {i} at ({pos[i, 0]:.4g}, {pos[i, 1]:.4g}) cm would cross wall "
                               f"'{self.scene.wall_names[w]}' at step {step}; step refused, run stopped")
        if self.newton and code == NW.STALLED:
            return "step_limit", (f"max|F| = {np.abs(self.force).max():.4g} N >= f_tol = {s['f_tol']:g} N after {step} "
                                  f"steps: no step lowers the energy (Levenberg-Marquardt mu "
                                  f"{self.nstate[0]:.3g} N/cm)")
        out = outside_box(pos, self.box)
        if out.any():
            return "escaped", f"{out.sum()} particle(s) left the walls' bounding box by step {step}"
        if s["stop_on_cycle"] and not (self.overdamped or self.newton):
            period = detect_cycle(self.recent)
            # a cycle returns to its states: the net move over the chunk stays
            # within a few du, unlike a slow drift with a periodic max|F|
            if period and np.abs(pos - self.chunk_start).max() > 2 * period * s["du"]:
                period = 0
            self.period = period
            if period:
                tail = self.recent[-CYCLE_WINDOW:]
                return "cycle", (f"max|F| repeats with period {period} steps between {tail.min():.4g} and "
                                 f"{tail.max():.4g} N (f_tol {s['f_tol']:g} N) by step {step}")
        return None

    def record(self):
        """Wall resultants and vessel counts at the chunk's end (no rest samples: None)."""
        if not self.quiet_end:
            self.hist.chunk(self.step, self.pos, self.s, self.walls)
        return None

    def spent(self):
        return self.step >= self.s["max_steps"]

    def fraction_done(self):
        return (self.step - self.start_step) / max(self.s["max_steps"] - self.start_step, 1)

    def clock(self):
        """(simulated time s of the overdamped variant, NaN for the static rules; step from the chain's start)."""
        return (float(self.kernel[1]) if self.overdamped else float("nan")), self.step

    def state(self):
        """Copies of the positions and out-of-balance forces (NaN before the run's first evaluation: not known yet),
        and the overdamped variant's velocities."""
        out = {"pos": self.pos.copy(), "force": self.force.copy() if self.evals else np.full_like(self.force, np.nan)}
        if self.overdamped:
            out["velocity"] = self.vel.copy()
        return out

    def recording(self):
        """The driver's Recording of this run: a snapshot every solver.snapshot_every_single steps (single vessel)
        or _flow steps (a tank of vessels), within solver.snapshot_megabytes; the tank's walls, vessels and box
        (isaflow.tank.Tank's); the lattice spacing as the strip width."""
        from ...tank import Tank

        s, spec = self.s, self.scene.spec
        tank = Tank(self.scene.path, {"name": spec["name"], "walls": spec["walls"],
                                      **({"vessels": spec["vessels"]} if spec.get("vessels") else {})}, "")
        flow = len(spec.get("vessels", [])) > 1
        return driver.Recording(s["snapshot_every_flow"] if flow else s["snapshot_every_single"],
                                s["snapshot_megabytes"], self.walls, tank.vessels, tank.escape_box(),
                                self.scene.spacing or float("nan"), timed=False)

    def limit_message(self, monitor=None):
        return f"max|F| = {self._fmax():.4g} N >= f_tol = {self.s['f_tol']:g} N after {self.step} steps"

    def progress(self, monitor=None):
        return f"step {self.step:>9d}  max|F| = {self.fmax_last:.4g} N"

    def result(self, run):
        """contract.Result of the run (method 'isa', variant = the update rule; fields hold STATE_VARS)."""
        s, pos, vel, weight, kernel, force = self.s, self.pos, self.vel, self.weight, self.kernel, self.force
        walls = self.walls
        overdamped, newton, memo, rest_cfg, e_norm = self.overdamped, self.newton, self.memo, self.rest_cfg, self.e_norm
        step, rest_depth, t_start, pos_build, hist = self.step, self.rest_depth, self.t0, self.pos_build, self.hist
        status, message = run.status, run.message
        fmax = self._fmax()
        if status == "converged":
            message = f"max|F| = {fmax:.4g} N < f_tol = {s['f_tol']:g} N after {step} steps"
        sim_time = float("nan")
        part, wall, point, cforce = contacts(pos, walls, s)
        # the settings reach the run file under their own dotted keys (run.write, settings.attributes); here only
        # the values derived from the force laws for those the file leaves null, and the run's own diagnostics
        params = {f"solver.{k}": s[k] for k in DERIVED + (("dt",) if overdamped else ())}
        params.update(cycle_period=int(self.period), nonfinite_particle=int(self.bad_particle),
                      max_step_move=self.max_step_move, **({"damping": s["damping"]} if overdamped else {}))
        measures = {}
        if overdamped:
            sim_time = float(kernel[1])
            ke = 0.5 * float(np.sum(weight / G * np.sum(vel * vel, axis=1)))
            at_rest = kernel[2] >= 0 and sim_time - kernel[2] >= rest_cfg["window"] - 1e-12
            params.update(driver.rest_params(rest_cfg["energy_ratio"], rest_cfg["window"], ke / e_norm, t_start),
                          particle_mass=float(weight[0] / G) if len(weight) else float("nan"))
            measures["time_to_rest"] = AT.measure(  # the compiled rest test's (the driver judges no rest here)
                "time_to_rest", max(float(kernel[2]) - t_start, 0.0) if at_rest else float("nan"),
                None if at_rest else "not at rest when the run stopped")
            if status == "converged":
                message += (f", at rest (e = KE / (W h) < {rest_cfg['energy_ratio']:g} since t = {kernel[2]:.4g} s); "
                            f"t = {sim_time:.4g} s")
            else:
                message += f"; t = {sim_time:.4g} s, e = {ke / e_norm:.3g}"
        if newton:
            pos_build = pos.copy()
            c = self.counts
            params.update(hessian_assemblies=int(c[0]), cg_iterations=int(c[1]), refused_steps=int(c[2]))
        if memo is not None:
            params["replayed_chunks"] = memo.replayed
        params["threads"] = self.threads
        fields = {"force": (("particle", "xy"), force, "N", "final out-of-balance force on particle"),
                  "contact_particle": (("contact",), part.astype(np.int32), "1", "particle index of wall contact")}
        fields.update(_state_fields(vel, pos_build, self.chunk_start, kernel, self.recent))
        return Result(
            method="isa", variant=s["variant"], pos0=np.array(self.pos0, float), pos=pos, weight=weight,
            contact_wall=wall, contact_point=point, contact_force=cforce, status=status, message=message,
            steps=step, start_step=self.start_step, wall_time=run.wall_time, force_evals=self.evals, residual=fmax,
            residual_name="max|F|", residual_units="N", sim_time=sim_time,
            history=hist.variables(len(pos)), fields=fields, params=params, measures=measures,
        )


def _solve(scene, pos0, weight, start_step, log, state, rest_depth, threads):
    """Build the stepper (kernels warmed) and drive it (driver.drive) -> contract.Result; arguments as solve's."""
    stepper = _Stepper(scene, pos0, weight, start_step, state, rest_depth, threads)
    return driver.drive(stepper, None, log, recording=stepper.recording())
