"""What makes an ISA run plausible, and what it will cost, from its settings alone (pure Python).

The scene checks (isa.scene: particles inside the walls, derived stiffness
and step numbers finite, memory of the built lattice) run when the run is
prepared; these run while the workflow is parsed too.  :func:`plausible`
refuses a step du longer than half the pair range (a particle could step past
its neighbour's whole repulsion); :func:`cost` estimates particles, steps
(max_steps) and memory for isaflow.budget.  Units: cm, N, bytes.
"""

import math

from ... import budget
from ...plausible import require, tank_field, within
from ...tank import bounds, check_points
from .settings import SKIN_FRACTION

NS_PER_PARTICLE_STEP = 20.0  # fastest measured relax step (benchmarks/), rounded down
BYTES_PER_PARTICLE = 640  # solver + compiled loop + contacts + the run file's copy (measured order, rounded up)
MAX_GRID_CELLS = 10**9  # cells of the neighbour grid (int32 cell starts)
BYTES_PER_SNAPSHOT_PARTICLE = 26  # a particle in a snapshot (driver.drive): position, force, vessel, status
BYTES_PER_RECORD = 4 * 56  # hist_fmax/lo/hi/step records held as Python lists, then arrays
DU = "a step moves a particle by du; longer than half the pair range l_pu it can carry a particle through its " \
     "neighbour's whole repulsion (the paper: du = 0.01 cm against l_pu = 7.07 cm)"


def particles_field(part):
    """The settings field a particle count comes from: particles.points or particles.lattice."""
    return "particles.points" if part.get("points") is not None else "particles.lattice"


def particle_count(part, tank=None):
    """Particles a lattice or points block will create, without creating them; a lattice of rows null fills the
    tank's first vessel with its weight in particles of particles.weight (scene.vessel_fill)."""
    if part.get("points"):
        return len(part["points"])
    if part.get("fill"):
        return part["fill"]["count"]
    lat = part["lattice"]
    if lat["rows"] is None:
        return fill_count(tank.weight, part["weight"])
    rows, lengths = lat["rows"], lat["row_lengths"]
    full, rest = divmod(rows, len(lengths))
    return full * sum(lengths) + sum(lengths[:rest])


def fill_count(weight, w):
    """Particles of about w [N] that hold a liquid of weight [N]: round(weight / w), at least one (a count that
    overflows: inf)."""
    n = weight / w
    return max(1, round(n)) if math.isfinite(n) else n


def lattice_corners(lat):
    """(x, y) [cm] of the corners of the lattice's bounding box, its jitter aside (scene.rhombic_lattice,
    square_lattice: the widest row's ends, the bottom and top rows)."""
    pitch = lat["a"] if lat.get("kind", "rhombic") == "square" else lat["a"] / 2
    half = (max(lat["row_lengths"][:lat["rows"]]) - 1) / 2 * lat["a"]
    top = lat["bottom_y"] + (lat["rows"] - 1) * pitch
    return [(lat["center_x"] + dx, y) for dx in (-half, half) for y in (lat["bottom_y"], top)]


def check_grid(path, walls, rc, walls_field):
    """Refuse a neighbour grid over the walls' bounding box of more than MAX_GRID_CELLS cells of rc [cm] (the
    pair range plus skin), naming what makes it large, the walls (walls_field) or forces.pair.l_u: the one
    farther from 1 cm.  Returns the cells."""
    x0, y0, x1, y1 = bounds(walls)
    cells = max(1.0, (x1 - x0) / rc) * max(1.0, (y1 - y0) / rc)
    big = abs(math.log10(max(x1 - x0, y1 - y0))) > abs(math.log10(rc))
    require(cells <= MAX_GRID_CELLS, path, walls_field if big else "forces.pair.l_u",
            f"the neighbour grid over the walls' bounding box ({x1 - x0:g} x {y1 - y0:g} cm) would have {cells:.3g} "
            f"cells of {rc:.3g} cm, the pair range plus skin (limit {MAX_GRID_CELLS:.0e})")
    return cells


def plausible(tank, s, stability=False):
    """Refuse implausible settings (InputError naming the file and the setting, with the reason)."""
    part = s.tree("particles")
    if part.get("points") is not None:
        check_points(s.path, "particles.points", part["points"], tank.walls_list())
    elif part["lattice"]["rows"] is not None:  # rows null: the lattice fills the vessel (scene.vessel_fill)
        check_points(s.path, "particles.lattice", lattice_corners(part["lattice"]), tank.walls_list(),
                     "lattice corner(s)")
    within(s.path, "solver.du", s["solver.du"], None, s["forces.pair.l_u"] / 2, DU, stability=stability)
    check_grid(s.path, tank.walls_list(), s["forces.pair.l_u"] + (s["solver.skin"] or SKIN_FRACTION * s["forces.pair.l_u"]),
               tank_field(tank, "walls"))
    reach = max(abs(c) for w in tank.walls_list() for c in w)
    require(s["solver.du"] > math.ulp(reach), s.path, "solver.du",
            f"{s['solver.du']:g} cm is below the round-off of a position in this tank ({math.ulp(reach):g} cm at "
            f"{reach:g} cm): no particle could move")
    if s.variant == "newton_lm":  # its energy and Hessian are the linear laws' (methods/isa/newton.py)
        for side in ("wall", "pair"):
            require(s[f"forces.{side}.law"] == "linear", s.path, f"forces.{side}.law",
                    f"the newton_lm variant implements the linear law only, not '{s[f'forces.{side}.law']}'")


def cost(tank, s, particles=None):
    """budget.Cost of a run: the lattice or points (or a start file's `particles`), max_steps steps."""
    part = s.tree("particles")
    n = particle_count(part, tank) if particles is None else particles
    steps = s["solver.max_steps"]
    hist = s["solver.history"] or {}
    records = steps / hist["every"] if hist.get("every") else 0
    snaps = s["solver.snapshot_megabytes"] * 1e6 + 3 * n * BYTES_PER_SNAPSHOT_PARTICLE
    nbytes = n * BYTES_PER_PARTICLE + records * BYTES_PER_RECORD + snaps
    big = max((n * BYTES_PER_PARTICLE, particles_field(part)), (records * BYTES_PER_RECORD, "solver.history.every"),
              (snaps, "solver.snapshot_megabytes"))
    return [budget.Cost(n, steps, nbytes, NS_PER_PARTICLE_STEP,
                        {"particles": particles_field(part), "steps": "solver.max_steps", "bytes": big[1]},
                        f"max_steps = {steps:.3g}")]
