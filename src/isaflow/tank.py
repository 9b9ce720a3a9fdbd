"""Tanks (config/tanks/*.yaml): the walls, vessels and liquid every method shares.

A tank file is validated against ``tank.schema.json`` and its geometry is
checked (:func:`check_walls`, :func:`check_geometry`); errors name the file
and the field.  The tank's liquid (weight W per unit thickness and depth h in
the first vessel) fixes the hydrostatic theory every method is judged against
(theory.py): rho g = W / (B h), B the first vessel's width.  Units: cm, N.
The checks are pure Python (the workflow checks tanks while it is parsed);
the arrays a solver needs come from NumPy, imported when asked for.
"""

import hashlib
import json
import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from . import inputs
from .inputs import InputError

SCHEMA = json.loads(resources.files("isaflow").joinpath("tank.schema.json").read_text())
MAX_COORD = 1e7  # cm: largest accepted |coordinate| of a wall (100 km)
TOL = 1e-9  # cm: two wall ends closer than this are one point
TANK_DIR = Path("config") / "tanks"


def _segments(spec):
    """[(x0, y0, x1, y1)] of a tank mapping's walls (floats)."""
    return [tuple(float(c) for c in w["from"] + w["to"]) for w in spec["walls"]]


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
        import numpy as np

        return np.array(_segments(self.spec), float)

    @property
    def wall_names(self):
        return [w["name"] for w in self.spec["walls"]]

    @property
    def vessels(self):
        """[(name, (xmin, xmax) cm)] of the tank's vessels; one spanning the walls if it names none."""
        named = [(v["name"], tuple(float(c) for c in v["x"])) for v in self.spec.get("vessels", [])]
        if named:
            return named
        xs = [c for s in _segments(self.spec) for c in (s[0], s[2])]
        return [("vessel", (min(xs), max(xs)))]

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
        return min(s[1] for s in _segments(self.spec) if abs(s[1] - s[3]) <= TOL
                   and min(max(s[0], s[2]), x1) - max(min(s[0], s[2]), x0) > TOL)

    @property
    def rho_g(self):
        """Specific weight rho g [N/cm^2] of the tank's liquid: W / (B h), B the first vessel's width."""
        x0, x1 = self.vessels[0][1]
        return self.weight / ((x1 - x0) * self.depth)

    def escape_box(self):
        """(4,) xmin, ymin, xmax, ymax [cm] of the region a dynamic method's particle must stay in: the walls'
        bounding box, open upwards by the tank's own height (a splash may rise above the open top and fall
        back; one rising higher than the tank is tall carries energy no jet of this tank has).  A tuple (pure
        Python: the workflow's checks use it while it is parsed)."""
        segs = _segments(self.spec)
        xs = [c for s in segs for c in (s[0], s[2])]
        ys = [c for s in segs for c in (s[1], s[3])]
        return (min(xs), min(ys), max(xs), max(ys) + (max(ys) - min(ys)))

    @property
    def digest(self):
        """sha256 of the validated tank (canonical JSON)."""
        return hashlib.sha256(json.dumps(self.spec, sort_keys=True).encode()).hexdigest()

    def attrs(self):
        """Run-file attributes of the tank's liquid (the theory every method is judged against)."""
        return {"tank": self.name, "tank_weight": self.weight, "tank_depth": self.depth, "tank_rho_g": self.rho_g,
                "tank_floor_y": self.floor_y(0)}


def check_walls(path, spec):
    """Wall segments finite, of non-zero length, uniquely named, within MAX_COORD cm; vessels ordered.
    Returns the segments [(x0, y0, x1, y1)]."""
    walls = _segments(spec)
    names = [w["name"] for w in spec["walls"]]
    if not all(math.isfinite(c) and abs(c) <= MAX_COORD for s in walls for c in s):
        raise InputError(f"{path}: field 'walls': coordinates must be finite and within +-{MAX_COORD:g} cm")
    for name, s in zip(names, walls):
        if math.hypot(s[2] - s[0], s[3] - s[1]) == 0:
            raise InputError(f"{path}: field 'walls' ({name}): segment has zero length")
    if len(set(names)) != len(names):
        raise InputError(f"{path}: field 'walls': wall names must be unique")
    for v in spec.get("vessels", []):
        if not v["x"][0] < v["x"][1]:
            raise InputError(f"{path}: field 'vessels' ({v['name']}): x must be [xmin, xmax] with xmin < xmax")
    return walls


def _same(p, q):
    return abs(p[0] - q[0]) <= TOL and abs(p[1] - q[1]) <= TOL


def _horizontal(s):
    return abs(s[1] - s[3]) <= TOL


def _chain(walls):
    """Indices of the outline: the chain of walls joined end to start, head to tail, that runs through the
    lowest horizontal wall; in traversal order (None if no wall is horizontal)."""
    floors = [k for k, s in enumerate(walls) if _horizontal(s)]
    if not floors:
        return None
    order = [min(floors, key=lambda k: walls[k][1])]
    while True:  # walk back: the one wall whose end is this one's start
        prev = [k for k, s in enumerate(walls) if k not in order and _same(s[2:], walls[order[0]][:2])]
        if len(prev) != 1:
            break
        order.insert(0, prev[0])
    while True:  # and forward
        nxt = [k for k, s in enumerate(walls) if k not in order and _same(s[:2], walls[order[-1]][2:])]
        if len(nxt) != 1:
            break
        order.append(nxt[0])
    return order


def _cross(a, b):
    """True if segments a, b (x0, y0, x1, y1) intersect other than at a shared end point."""
    px, py, rx, ry = a[0], a[1], a[2] - a[0], a[3] - a[1]
    qx, qy, tx, ty = b[0], b[1], b[2] - b[0], b[3] - b[1]
    den = rx * ty - ry * tx
    lr, lt = math.hypot(rx, ry), math.hypot(tx, ty)
    wx, wy = qx - px, qy - py
    if abs(den) <= TOL * lr * lt:  # parallel: overlapping collinear segments cross
        if abs(wx * ry - wy * rx) > TOL * lr * lr:
            return False
        rr = rx * rx + ry * ry
        s0, s1 = sorted(((wx * rx + wy * ry) / rr, ((wx + tx) * rx + (wy + ty) * ry) / rr))
        return min(s1, 1.0) - max(s0, 0.0) > TOL
    u = (wx * ty - wy * tx) / den
    v = (wx * ry - wy * rx) / den
    inside = -TOL <= u <= 1 + TOL and -TOL <= v <= 1 + TOL
    ends = (abs(u) <= TOL or abs(u - 1) <= TOL) and (abs(v) <= TOL or abs(v - 1) <= TOL)
    return inside and not ends


def check_geometry(path, spec, walls):
    """A tank that can hold its liquid: one outline of joined walls (down the left side, along the floors, up
    the right side: the liquid on every wall's left), no crossing walls, every vessel inside the outline on a
    floor, the liquid's top below the outline's wall tops.  InputError naming the file and field otherwise."""
    names = [w["name"] for w in spec["walls"]]
    where = f"{path}: field 'walls'"
    order = _chain(walls)
    if order is None:
        raise InputError(f"{where}: no horizontal wall: a tank needs a floor")
    first, last = walls[order[0]], walls[order[-1]]
    if not (first[1] > first[3] and last[3] > last[1]):
        raise InputError(f"{where}: the walls joined to the floor do not run down one side and up the other "
                         f"({names[order[0]]} ... {names[order[-1]]}): the tank is not closed below its top, or a "
                         f"wall is reversed (walls are oriented with the liquid on their left)")
    for k in order:
        if _horizontal(walls[k]) and walls[k][2] < walls[k][0]:
            raise InputError(f"{where} ({names[k]}): a floor must run left to right (the liquid on its left)")
    for i in range(len(walls)):
        for j in range(i + 1, len(walls)):
            if _cross(walls[i], walls[j]):
                raise InputError(f"{where}: walls '{names[i]}' and '{names[j]}' cross")
    x_lo, x_hi = first[0], last[2]
    top = min(first[1], last[3])
    for k in range(len(walls)):
        s = walls[k]
        if k not in order and (min(s[0], s[2]) < x_lo - TOL or max(s[0], s[2]) > x_hi + TOL):
            raise InputError(f"{where} ({names[k]}): a wall outside the tank's outline [{x_lo:g}, {x_hi:g}] cm")
    vessels = spec.get("vessels") or [{"name": "(whole tank)", "x": [x_lo, x_hi]}]
    floor_y = None
    for v in vessels:
        x0, x1 = v["x"]
        if x0 < x_lo - TOL or x1 > x_hi + TOL:
            raise InputError(f"{path}: field 'vessels' ({v['name']}): [{x0:g}, {x1:g}] cm lies outside the walls "
                             f"[{x_lo:g}, {x_hi:g}] cm")
        under = [walls[k] for k in order if _horizontal(walls[k]) and min(walls[k][0], walls[k][2]) <= x1
                 and max(walls[k][0], walls[k][2]) >= x0]
        if not under:
            raise InputError(f"{path}: field 'vessels' ({v['name']}): no floor under [{x0:g}, {x1:g}] cm")
        if floor_y is None:
            floor_y = min(s[1] for s in under)
    for a, b in zip(vessels, vessels[1:]):
        if b["x"][0] < a["x"][1] - TOL:
            raise InputError(f"{path}: field 'vessels' ({b['name']}): overlaps '{a['name']}'")
    depth = float(spec["liquid"]["depth"])
    if floor_y + depth > top + TOL:
        raise InputError(f"{path}: field 'liquid.depth': {depth:g} cm above the first floor (y = {floor_y:g} cm) "
                         f"reaches over the wall tops (y = {top:g} cm)")


def check_positions(path, field, pos, walls):
    """Refuse positions that are non-finite or outside the walls' bounding box (NaN counts as outside);
    pos (N, 2) array [cm], walls (W, 4) segments [cm]."""
    import numpy as np

    if not np.isfinite(pos).all():
        raise InputError(f"{path}: field '{field}': positions must be finite")
    ends = np.asarray(walls, float).reshape(-1, 2)
    lo, hi = ends.min(0), ends.max(0)
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
