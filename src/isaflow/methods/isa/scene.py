"""An ISA scene: a tank, the ISA settings of one resolution and an update rule, as one problem.

:func:`build` assembles the scene's mapping (walls and vessels of the tank,
particles, force laws and solver settings of config/methods/isa.yaml) from a
validated tank (isaflow.tank) and settings read by the one settings loader
(isaflow.settings, against methods.isa.settings.VALUES), so nothing is validated
twice; it checks only what neither can: the particles against the walls
(before anything large is allocated, methods.isa.budget).  Units: length cm,
force N.  An error names the settings file (or the tank) and the field.
"""

import hashlib
import json
from dataclasses import dataclass, field

import numpy as np

from ...inputs import InputError
from ...tank import check_positions, check_walls

SceneError = InputError  # invalid scene, tank or settings: the message names the file and the field


@dataclass
class Scene:
    """A validated scene.  ``spec`` is the resolved YAML mapping (with overrides)."""

    path: str
    spec: dict
    text: str
    overrides: list = field(default_factory=list)
    pos0: np.ndarray = None  # (N, 2) cm initial positions of a lattice or points scene, built once at load

    @property
    def name(self):
        return self.spec["name"]

    @property
    def walls(self):
        """(W, 4) float64 wall segments x0, y0, x1, y1 [cm]."""
        return np.array([w["from"] + w["to"] for w in self.spec["walls"]], float)

    @property
    def wall_names(self):
        return [w["name"] for w in self.spec["walls"]]

    @property
    def vessels(self):
        """[(name, (xmin, xmax) cm)] of the scene's vessels (empty if it names none)."""
        return [(v["name"], tuple(float(c) for c in v["x"])) for v in self.spec.get("vessels", [])]

    @property
    def spacing(self):
        """Lattice diagonal a [cm] (sets the free-surface strip width), or None."""
        lat = self.spec["particles"].get("lattice")
        return float(lat["a"]) if lat else None

    @property
    def digest(self):
        """sha256 of the resolved scene (canonical JSON)."""
        return hashlib.sha256(json.dumps(self.spec, sort_keys=True).encode()).hexdigest()

    def law(self, which):
        """(l_u [cm], r_u [N]) of the 'wall' or 'pair' force law."""
        law = self.spec["forces"][which]
        return float(law["l_u"]), float(law["r_u"])

    def stiffness(self, which):
        """Stiffness r_u / l_u [N/cm] of the 'wall' or 'pair' force law."""
        l_u, r_u = self.law(which)
        return r_u / l_u


def rhombic_lattice(a, rows, row_lengths, center_x, bottom_y):
    """Rhombic lattice (paper section 5): (N, 2) positions [cm].

    Row r sits at bottom_y + r a / 2 and holds row_lengths[r % len] particles
    a apart, centred on center_x; neighbours in adjacent rows are a / sqrt(2)
    apart.
    """
    pts = []
    for r in range(rows):
        n = row_lengths[r % len(row_lengths)]
        x = center_x + (np.arange(n) - (n - 1) / 2) * a
        pts.append(np.column_stack([x, np.full(n, bottom_y + r * a / 2)]))
    return np.concatenate(pts)


def square_lattice(a, rows, row_lengths, center_x, bottom_y):
    """Square lattice (a named alternative to the rhombic one, not the paper's): (N, 2) positions [cm].

    Row r sits at bottom_y + r a and holds row_lengths[r % len] particles a apart, centred on center_x.
    With a = the rhomb side a_r / sqrt(2) it is the rhombic lattice turned by 45 degrees: the same nearest
    distance and count of nearest neighbours, with no diagonal vertical.
    """
    pts = []
    for r in range(rows):
        n = row_lengths[r % len(row_lengths)]
        x = center_x + (np.arange(n) - (n - 1) / 2) * a
        pts.append(np.column_stack([x, np.full(n, bottom_y + r * a)]))
    return np.concatenate(pts)


def vessel_fill(fill, lattice, walls):
    """(N, 2) positions [cm] of a lattice filling a vessel (rows null): the rhombic (or square) lattice of the
    settings' a, centred on the vessel (fill['center_x']), its first row fill['clearance'] above the vessel's floor
    and in phase with a first row of row_lengths[0] particles (odd: one on the centre), every site inside the
    vessel's polygon at least fill['clearance'] (the wall law's range l_bu) from its edges and the walls
    (core.geometry.inside_vessel); the lowest fill['count'] sites, row by row from the floor (the last row's
    nearest the centre), ordered as rhombic_lattice orders them.  In the paper's vessel (100 cm, a = 10 cm, l_bu =
    5 cm, 9000 N of 50 N particles) it is the paper's lattice: 19 rows of 9 and 10, 5 cm from every wall."""
    from ...core.geometry import inside_vessel

    a, square = float(lattice["a"]), lattice.get("kind", "rhombic") == "square"
    pitch = a if square else a / 2
    poly = np.asarray(fill["polygon"], float)
    cx, c, need = float(fill["center_x"]), float(fill["clearance"]), int(fill["count"])
    bottom_y = float(fill["floor_y"]) + c
    half = max(abs(poly[:, 0].min() - cx), abs(poly[:, 0].max() - cx))
    m = int(np.ceil(half / a)) + 1
    odd = lattice["row_lengths"][0] % 2 == 1
    rows, taken, r = [], 0, 0
    while taken < need:
        y = bottom_y + r * pitch
        if y > poly[:, 1].max():
            raise InputError(f"{fill['path']}: field 'particles.lattice.rows': null fills the first vessel with "
                             f"{need} particles (the tank's weight over particles.weight), but only {taken} sites of "
                             f"a = {a:g} cm lie {c:g} cm inside its walls (forces.wall.l_u) below their top")
        n = 2 * m + 1 if odd == (square or r % 2 == 0) else 2 * m + 2
        x = cx + (np.arange(n) - (n - 1) / 2) * a
        pts = np.column_stack([x, np.full(n, bottom_y + r * pitch)])
        pts = pts[inside_vessel(pts, poly, walls, c)]
        if taken + len(pts) > need:  # the last row: its sites nearest the centre, in order along the row
            keep = np.sort(np.argsort(np.abs(pts[:, 0] - cx), kind="stable")[: need - taken])
            pts = pts[keep]
        rows.append(pts)
        taken += len(pts)
        r += 1
    return np.concatenate(rows)


def layer_pitch(lattice):
    """Vertical pitch [cm] of a lattice's particle layers: a / 2 (rhombic), a (square)."""
    return float(lattice["a"]) if lattice.get("kind", "rhombic") == "square" else float(lattice["a"]) / 2


def _check_geometry(scene):
    """Physical checks the schema cannot express, and the memory the run needs, before any allocation."""
    from . import budget

    path = scene.path
    walls = check_walls(path, scene.spec)
    budget.check_settings(scene)
    part = scene.spec["particles"]
    if "from_run" in part:
        return
    budget.check_count(scene, budget.particle_count(part), budget.particles_field(part))
    pos = scene.pos0 = initial_positions(scene)
    check_positions(path, "particles.points" if "points" in part else "particles.lattice", pos, walls)
    budget.check_memory(scene, pos)


def initial_state(scene):
    """(pos0 (N, 2) cm, weight (N,) N, start_step, spacing cm) of a scene.

    A ``from_run`` scene continues the final state of that run file.
    """
    if "from_run" in scene.spec["particles"]:
        st = start_file(scene)
        return st["pos"], st["weight"], st["steps"], st["spacing"]
    part = scene.spec["particles"]
    pos = scene.pos0 if scene.pos0 is not None else initial_positions(scene)
    return pos, np.full(len(pos), float(part["weight"])), 0, scene.spacing or np.nan


def start_file(scene):
    """The checked state a ``from_run`` scene continues (methods.isa.restart.start_file)."""
    from .restart import start_file as _start_file

    return _start_file(scene)


def initial_positions(scene):
    """(N, 2) initial positions [cm] of a lattice or points scene."""
    part = scene.spec["particles"]
    if "lattice" in part:
        lat = part["lattice"]
        build = square_lattice if lat.get("kind", "rhombic") == "square" else rhombic_lattice
        if "fill" in part:
            pos = vessel_fill(part["fill"], lat, scene.walls)
        else:
            pos = build(lat["a"], lat["rows"], lat["row_lengths"], lat["center_x"], lat["bottom_y"])
        if lat.get("jitter", 0.0) > 0:  # a named alternative (disordered packing), not the paper's
            rng = np.random.default_rng(int(lat.get("seed", 0)))
            pos = pos + rng.uniform(-1.0, 1.0, pos.shape) * float(lat["jitter"]) * float(lat["a"])
        return pos
    if "points" in part:
        return np.array(part["points"], float).reshape(-1, 2)
    raise SceneError(f"{scene.path}: field 'particles.from_run': positions come from a run file")


def spec_of(tank, settings, variant, start=None):
    """The scene mapping of a tank, resolved ISA settings (isaflow.settings.Settings) and update rule.

    start: path of the run file to continue (its final positions), or None for the settings'
    lattice or points.  Unset optional solver values (null) take their defaults (settings.settings).
    """
    t = settings.tree()
    part = {"weight": t["particles"]["weight"]}
    if start is not None:
        part["from_run"] = str(start)
    elif t["particles"].get("points") is not None:
        part["points"] = t["particles"]["points"]
    else:
        part["lattice"] = t["particles"]["lattice"]
        if part["lattice"]["rows"] is None:  # fill the first vessel with the tank's weight (vessel_fill)
            from .checks import fill_count

            _, (x0, x1) = tank.vessels[0]
            n = fill_count(tank.weight, part["weight"])
            part["weight"] = tank.weight / n if n else part["weight"]
            part["fill"] = {"count": n, "polygon": [list(p) for p in tank.vessel_polygon(0)],
                            "floor_y": tank.floor_y(0), "center_x": 0.5 * (x0 + x1),
                            "clearance": float(t["forces"]["wall"]["l_u"]), "path": settings.path}
    solver = {k: v for k, v in t["solver"].items() if v is not None}
    spec = {"name": tank.name, "description": tank.spec.get("description", ""),
            "walls": tank.spec["walls"], "particles": part, "forces": t["forces"],
            "solver": {"variant": variant, **solver}}
    if tank.spec.get("vessels"):
        spec["vessels"] = tank.spec["vessels"]
    return spec


def build(tank, settings, variant, start=None):
    """Validated Scene of a tank (isaflow.tank.Tank), resolved settings and update rule; start as spec_of.

    Raises InputError naming the settings file and the field.
    """
    scene = Scene(settings.path, spec_of(tank, settings, variant, start), tank.text)
    _check_geometry(scene)
    return scene


def of_run(tank_name, resolution, variant, overrides=(), settings_path="config/methods/isa.yaml", start=None):
    """Validated Scene of a tank name, an ISA resolution, an update rule and overrides (see isaflow.settings)."""
    from ... import settings as S
    from ... import tank as T
    from .settings import VALUES

    s = S.load(settings_path, VALUES, variant, resolution, overrides)
    return build(T.load(T.path_of(tank_name)), s, variant, start)
