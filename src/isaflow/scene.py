"""Scenes: YAML files validated against ``scene.schema.json``, turned into arrays.

Units: length cm, force N.  A scene error names the file and the field.
"""

import hashlib
import json
from dataclasses import dataclass, field
from importlib import resources

import numpy as np

from . import inputs
from .inputs import InputError

SCHEMA = json.loads(resources.files("isaflow").joinpath("scene.schema.json").read_text())

SceneError = InputError  # invalid scene, tank or settings: the message names the file and the field
MAX_COORD = 1e7  # cm: largest accepted |coordinate| of a wall (100 km)


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


def _set(spec, dotted, value, path, shown):
    keys = dotted.split(".")
    if not all(keys):
        raise SceneError(f"{path}: override '{shown}': empty field name")
    node = spec
    for i, k in enumerate(keys[:-1]):
        if not isinstance(node, dict):
            raise SceneError(f"{path}: override '{shown}': field '{'.'.join(keys[:i])}' is not a mapping")
        if k not in node:
            raise SceneError(f"{path}: override '{shown}': no field '{k}'")
        node = node[k]
    if not isinstance(node, dict):
        raise SceneError(f"{path}: override '{shown}': field '{'.'.join(keys[:-1])}' is not a mapping")
    node[keys[-1]] = value


def apply_overrides(spec, overrides, path):
    """Set every 'dotted.key=value' override (value parsed as hardened YAML) in spec, in order."""
    for item in overrides:
        if not isinstance(item, str) or "=" not in item:
            raise SceneError(f"{path}: override '{inputs.printable(str(item))}' is not of the form key=value")
        key, value = item.split("=", 1)
        bad = inputs.bad_string(key) or inputs.bad_string(value)
        if bad:
            raise SceneError(f"{path}: override '{inputs.printable(item)}': {bad}")
        try:
            parsed = inputs.parse_yaml(value)
        except InputError as err:
            raise SceneError(f"{path}: override '{inputs.printable(item)}': {err}") from None
        _set(spec, key.strip(), parsed, path, inputs.printable(key.strip()))


def load(path, overrides=()):
    """Read, override and validate a scene file.

    overrides: strings 'dotted.key=value' (value parsed as YAML), e.g.
    'forces.pair.r_u=1000'.  Raises SceneError naming the file and field.
    Nothing large is allocated before the particle count and the memory the
    run needs are checked (methods.isa.budget).
    """
    path = str(path)
    text, spec = inputs.read_yaml(path, "scene")
    apply_overrides(spec, overrides, path)
    inputs.validate(spec, SCHEMA, path)
    scene = Scene(path, spec, text, list(overrides))
    _check_geometry(scene)
    return scene


def check_walls(path, spec):
    """Wall segments finite, of non-zero length, uniquely named, within MAX_COORD cm."""
    walls = np.array([w["from"] + w["to"] for w in spec["walls"]], float)
    names = [w["name"] for w in spec["walls"]]
    if not np.isfinite(walls).all() or (np.abs(walls) > MAX_COORD).any():
        raise SceneError(f"{path}: field 'walls': coordinates must be finite and within +-{MAX_COORD:g} cm")
    for name, w in zip(names, walls):
        if np.hypot(w[2] - w[0], w[3] - w[1]) == 0:
            raise SceneError(f"{path}: field 'walls' ({name}): segment has zero length")
    if len(set(names)) != len(names):
        raise SceneError(f"{path}: field 'walls': wall names must be unique")
    for v in spec.get("vessels", []):
        if not v["x"][0] < v["x"][1]:
            raise SceneError(f"{path}: field 'vessels' ({v['name']}): x must be [xmin, xmax] with xmin < xmax")
    return walls


def check_positions(path, field, pos, walls):
    """Refuse positions that are non-finite or outside the walls' bounding box (NaN counts as outside)."""
    if not np.isfinite(pos).all():
        raise SceneError(f"{path}: field '{field}': positions must be finite")
    lo, hi = walls.reshape(-1, 2).min(0), walls.reshape(-1, 2).max(0)
    out = ~((pos >= lo) & (pos <= hi)).all(1)  # NaN counts as outside
    if out.any():
        x, y = pos[np.argmax(out)]
        raise SceneError(
            f"{path}: field '{field}': {out.sum()} particle(s) lie outside the walls' "
            f"bounding box [{lo[0]}, {hi[0]}] x [{lo[1]}, {hi[1]}] cm, e.g. ({x:g}, {y:g})"
        )


def _check_geometry(scene):
    """Physical checks the schema cannot express, and the memory the run needs, before any allocation."""
    from .methods.isa import budget

    path = scene.path
    walls = check_walls(path, scene.spec)
    budget.check_settings(scene)
    part = scene.spec["particles"]
    if "from_run" in part:
        return
    budget.check_count(scene, budget.particle_count(part), "particles")
    pos = scene.pos0 = initial_positions(scene)
    check_positions(path, "particles", pos, walls)
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
    from .methods.isa.restart import start_file as _start_file

    return _start_file(scene)


def initial_positions(scene):
    """(N, 2) initial positions [cm] of a lattice or points scene."""
    part = scene.spec["particles"]
    if "lattice" in part:
        lat = part["lattice"]
        return rhombic_lattice(lat["a"], lat["rows"], lat["row_lengths"], lat["center_x"], lat["bottom_y"])
    if "points" in part:
        return np.array(part["points"], float).reshape(-1, 2)
    raise SceneError(f"{scene.path}: field 'particles.from_run': positions come from a run file")


TANK_SCHEMA = json.loads(resources.files("isaflow").joinpath("tank.schema.json").read_text())


@dataclass
class Tank:
    """A validated tank (config/tanks/*.yaml): walls, vessels and the liquid's weight and depth."""

    path: str
    spec: dict
    text: str

    name = property(lambda self: self.spec["name"])
    walls = Scene.walls
    wall_names = Scene.wall_names
    digest = Scene.digest

    vessels = Scene.vessels

    @property
    def weight(self):
        """Total liquid weight W [N] per unit thickness."""
        return float(self.spec["liquid"]["weight"])

    @property
    def depth(self):
        """Hydrostatic depth [cm] of the liquid in the first vessel."""
        return float(self.spec["liquid"]["depth"])


def load_tank(path):
    """Read and validate a tank file; raises SceneError naming the file and field."""
    path = str(path)
    text, spec = inputs.load(path, TANK_SCHEMA, "tank")
    tank = Tank(path, spec, text)
    check_walls(path, spec)
    return tank
