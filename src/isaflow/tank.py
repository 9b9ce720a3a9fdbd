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

    def escape_box(self):
        """(4,) xmin, ymin, xmax, ymax [cm] of the region a dynamic method's particle must stay in: the walls'
        bounding box, open upwards by the tank's own height (a splash may rise above the open top and fall
        back; one rising higher than the tank is tall carries energy no jet of this tank has)."""
        w = self.walls
        lo, hi = w.reshape(-1, 2).min(0), w.reshape(-1, 2).max(0)
        return np.array([lo[0], lo[1], hi[0], hi[1] + (hi[1] - lo[1])])

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


def _chain(walls, tol=1e-9):
    """Walls (indices) of the outline: the chain of walls joined end to start, head to tail, that runs through
    the lowest horizontal wall; returned in traversal order (None if the walls do not join into one chain)."""
    floors = [k for k, w in enumerate(walls) if abs(w[1] - w[3]) <= tol]
    if not floors:
        return None
    start = min(floors, key=lambda k: walls[k, 1])
    order = [start]
    while True:  # walk back: a wall whose end is this one's start
        prev = [k for k, w in enumerate(walls) if k not in order and np.allclose(w[2:], walls[order[0], :2], atol=tol)]
        if len(prev) != 1:
            break
        order.insert(0, prev[0])
    while True:  # and forward
        nxt = [k for k, w in enumerate(walls) if k not in order and np.allclose(w[:2], walls[order[-1], 2:], atol=tol)]
        if len(nxt) != 1:
            break
        order.append(nxt[0])
    return order


def _cross(a, b, tol=1e-9):
    """True if segments a, b (x0, y0, x1, y1) intersect other than at a shared end point."""
    p, r = a[:2], a[2:] - a[:2]
    q, t = b[:2], b[2:] - b[:2]
    den = r[0] * t[1] - r[1] * t[0]
    if abs(den) <= tol * np.hypot(*r) * np.hypot(*t):  # parallel: overlapping collinear segments cross
        if abs((q - p)[0] * r[1] - (q - p)[1] * r[0]) > tol * np.hypot(*r) ** 2:
            return False
        s0, s1 = sorted(((q - p) @ r / (r @ r), (q + t - p) @ r / (r @ r)))
        return min(s1, 1.0) - max(s0, 0.0) > tol
    u = ((q - p)[0] * t[1] - (q - p)[1] * t[0]) / den
    v = ((q - p)[0] * r[1] - (q - p)[1] * r[0]) / den
    inside = -tol <= u <= 1 + tol and -tol <= v <= 1 + tol
    ends = (abs(u) <= tol or abs(u - 1) <= tol) and (abs(v) <= tol or abs(v - 1) <= tol)
    return inside and not ends


def check_geometry(path, spec, walls):
    """A tank that can hold its liquid: one outline of joined walls (down the left side, along the floors, up
    the right side: the liquid on every wall's left), no crossing walls, every vessel inside the outline on a
    floor, the liquid's top below the outline's wall tops.  InputError naming the file and field otherwise."""
    names = [w["name"] for w in spec["walls"]]
    order = _chain(walls)
    where = f"{path}: field 'walls'"
    if order is None:
        raise InputError(f"{where}: no horizontal wall: a tank needs a floor")
    outline = walls[order]
    if not (outline[0, 1] > outline[0, 3] and outline[-1, 3] > outline[-1, 1]):
        raise InputError(f"{where}: the walls joined to the floor do not run down one side and up the other "
                         f"({names[order[0]]} ... {names[order[-1]]}): the tank is not closed below its top, or a "
                         f"wall is reversed (walls are oriented with the liquid on their left)")
    for k in order:
        w = walls[k]
        if abs(w[1] - w[3]) <= 1e-9 and w[2] < w[0]:
            raise InputError(f"{where} ({names[k]}): a floor must run left to right (the liquid on its left)")
    for i in range(len(walls)):
        for j in range(i + 1, len(walls)):
            if _cross(walls[i], walls[j]):
                raise InputError(f"{where}: walls '{names[i]}' and '{names[j]}' cross")
    x_lo, x_hi = outline[0, 0], outline[-1, 2]
    top = min(outline[0, 1], outline[-1, 3])
    others = [k for k in range(len(walls)) if k not in order]
    for k in others:
        w = walls[k]
        if min(w[0], w[2]) < x_lo - 1e-9 or max(w[0], w[2]) > x_hi + 1e-9:
            raise InputError(f"{where} ({names[k]}): a wall outside the tank's outline [{x_lo:g}, {x_hi:g}] cm")
    vessels = spec.get("vessels") or [{"name": "(whole tank)", "x": [x_lo, x_hi]}]
    floor_y = None
    for n, v in enumerate(vessels):
        x0, x1 = v["x"]
        if x0 < x_lo - 1e-9 or x1 > x_hi + 1e-9:
            raise InputError(f"{path}: field 'vessels' ({v['name']}): [{x0:g}, {x1:g}] cm lies outside the walls "
                             f"[{x_lo:g}, {x_hi:g}] cm")
        under = [w for w in outline if abs(w[1] - w[3]) <= 1e-9 and min(w[0], w[2]) <= x1 and max(w[0], w[2]) >= x0]
        if not under:
            raise InputError(f"{path}: field 'vessels' ({v['name']}): no floor under [{x0:g}, {x1:g}] cm")
        if n == 0:
            floor_y = min(w[1] for w in under)
    for a, b in zip(vessels, vessels[1:]):
        if b["x"][0] < a["x"][1] - 1e-9:
            raise InputError(f"{path}: field 'vessels' ({b['name']}): overlaps '{a['name']}'")
    depth = float(spec["liquid"]["depth"])
    if floor_y + depth > top + 1e-9:
        raise InputError(f"{path}: field 'liquid.depth': {depth:g} cm above the first floor (y = {floor_y:g} cm) "
                         f"reaches over the wall tops (y = {top:g} cm)")


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
    walls = check_walls(path, spec)
    check_geometry(path, spec, walls)
    return Tank(path, spec, text)
