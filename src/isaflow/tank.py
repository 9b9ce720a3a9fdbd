"""Tanks (config/tanks/*.yaml): the walls, vessels and liquid every method shares.

A tank file is validated against ``tank.schema.json`` and its geometry is
checked (:func:`check_walls`); errors name the file and the field.  The
tank's liquid (weight W per unit thickness and depth h in the first vessel)
fixes the hydrostatic theory every method is judged against (theory.py):
rho g = W / (B h), B the first vessel's width.  Units: cm, N.  Pure Python
plus NumPy for the geometry.
"""

import hashlib
import json
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from . import inputs
from .inputs import InputError

SCHEMA = json.loads(resources.files("isaflow").joinpath("tank.schema.json").read_text())
MAX_COORD = 1e7  # cm: largest accepted |coordinate| of a wall (100 km)
TANK_DIR = Path("config") / "tanks"


@dataclass
class Tank:
    """A validated tank: ``spec`` is the file's mapping, ``text`` its text."""

    path: str
    spec: dict
    text: str

    @property
    def name(self):
        return self.spec["name"]

    @property
    def walls(self):
        """(W, 4) float64 wall segments x0, y0, x1, y1 [cm], oriented with the liquid on their left."""
        return np.array([w["from"] + w["to"] for w in self.spec["walls"]], float)

    @property
    def wall_names(self):
        return [w["name"] for w in self.spec["walls"]]

    @property
    def vessels(self):
        """[(name, (xmin, xmax) cm)] of the tank's vessels; one spanning the walls if it names none."""
        named = [(v["name"], tuple(float(c) for c in v["x"])) for v in self.spec.get("vessels", [])]
        if named:
            return named
        w = self.walls
        return [("vessel", (float(w[:, [0, 2]].min()), float(w[:, [0, 2]].max())))]

    @property
    def weight(self):
        """Liquid weight W [N] per unit thickness."""
        return float(self.spec["liquid"]["weight"])

    @property
    def depth(self):
        """Liquid depth h [cm] in the first vessel (its hydrostatic depth at rest)."""
        return float(self.spec["liquid"]["depth"])

    def floor_y(self, vessel=0):
        """y [cm] of a vessel's floor: the lowest horizontal wall over its x range."""
        x0, x1 = self.vessels[vessel][1]
        w = self.walls
        horiz = np.isclose(w[:, 1], w[:, 3])
        over = np.minimum(w[:, [0, 2]].max(1), x1) - np.maximum(w[:, [0, 2]].min(1), x0) > 1e-9
        return float(w[horiz & over, 1].min())

    @property
    def rho_g(self):
        """Specific weight rho g [N/cm^2] of the tank's liquid: W / (B h), B the first vessel's width."""
        x0, x1 = self.vessels[0][1]
        return self.weight / ((x1 - x0) * self.depth)

    @property
    def digest(self):
        """sha256 of the validated tank (canonical JSON)."""
        return hashlib.sha256(json.dumps(self.spec, sort_keys=True).encode()).hexdigest()

    def attrs(self):
        """Run-file attributes of the tank's liquid (the theory every method is judged against)."""
        return {"tank": self.name, "tank_weight": self.weight, "tank_depth": self.depth, "tank_rho_g": self.rho_g,
                "tank_floor_y": self.floor_y(0)}


def check_walls(path, spec):
    """Wall segments finite, of non-zero length, uniquely named, within MAX_COORD cm; vessels ordered."""
    walls = np.array([w["from"] + w["to"] for w in spec["walls"]], float)
    names = [w["name"] for w in spec["walls"]]
    if not np.isfinite(walls).all() or (np.abs(walls) > MAX_COORD).any():
        raise InputError(f"{path}: field 'walls': coordinates must be finite and within +-{MAX_COORD:g} cm")
    for name, w in zip(names, walls):
        if np.hypot(w[2] - w[0], w[3] - w[1]) == 0:
            raise InputError(f"{path}: field 'walls' ({name}): segment has zero length")
    if len(set(names)) != len(names):
        raise InputError(f"{path}: field 'walls': wall names must be unique")
    for v in spec.get("vessels", []):
        if not v["x"][0] < v["x"][1]:
            raise InputError(f"{path}: field 'vessels' ({v['name']}): x must be [xmin, xmax] with xmin < xmax")
    return walls


def check_positions(path, field, pos, walls):
    """Refuse positions that are non-finite or outside the walls' bounding box (NaN counts as outside)."""
    if not np.isfinite(pos).all():
        raise InputError(f"{path}: field '{field}': positions must be finite")
    lo, hi = walls.reshape(-1, 2).min(0), walls.reshape(-1, 2).max(0)
    out = ~((pos >= lo) & (pos <= hi)).all(1)  # NaN counts as outside
    if out.any():
        x, y = pos[np.argmax(out)]
        raise InputError(
            f"{path}: field '{field}': {out.sum()} particle(s) lie outside the walls' "
            f"bounding box [{lo[0]}, {hi[0]}] x [{lo[1]}, {hi[1]}] cm, e.g. ({x:g}, {y:g})"
        )


def path_of(name):
    """config/tanks/<name>.yaml of a tank name."""
    return str(TANK_DIR / f"{name}.yaml")


def load(path):
    """Read and validate a tank file; InputError naming the file and the field."""
    path = str(path)
    text, spec = inputs.load(path, SCHEMA, "tank")
    check_walls(path, spec)
    return Tank(path, spec, text)
