"""Tanks (config/tanks/*.yaml): the walls, vessels and liquid every method shares.

A tank file is validated against ``tank.schema.json`` and checked by functions
of one signature, ``check_*(path, spec)`` (:func:`check_walls`,
:func:`check_geometry`, :func:`check_depth`); positions of another file (a
method's points and probes) by :func:`check_points` / :func:`check_positions`
``(path, field, points, walls)``; errors name the file and the field.  Walls may
slope; a vessel's polygon is the outline between its x bounds
(:func:`vessel_polygon`).  The tank's liquid (weight W per unit thickness and
depth h in the first vessel) fills that vessel's polygon below floor + h and
fixes the hydrostatic theory every method is judged against (theory.py):
rho g = W / A, A that area (:func:`liquid_area`; B h in a rectangular vessel of
width B).  Units: cm, N.
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


def vessel_counts(pos, vessels):
    """(V,) int64: particles of pos (N, 2) [cm] whose x lies in each vessel's [xmin, xmax) range;
    vessels: [(name, (xmin, xmax) cm)] (Tank.vessels)."""
    import numpy as np

    x = np.asarray(pos, float)[:, 0]
    return np.array([np.count_nonzero((x >= a) & (x < b)) for _, (a, b) in vessels], np.int64)


def vessel_floor(walls, x0, x1):
    """y [cm] of the floor of a vessel over (x0, x1): the lowest point of the walls that are not vertical over the
    part of them running inside that range (a floor only touching its end belongs to the next vessel): the lowest
    horizontal wall, or the bottom of sloping walls (a V's vertex); None if there is none.
    walls: [(x0, y0, x1, y1)]."""
    ys = []
    for s in walls:
        lo, hi = max(min(s[0], s[2]), x0), min(max(s[0], s[2]), x1)
        if hi - lo <= TOL:
            continue
        if abs(s[1] - s[3]) <= TOL:
            ys.append(s[1])
        else:  # a sloping wall: its lowest point over [lo, hi] is at one end of that part
            ys.append(min(_y_at(s, lo), _y_at(s, hi)))
    return min(ys) if ys else None


def _y_at(s, x):
    """y [cm] of the (not vertical) wall segment s at x."""
    if x <= min(s[0], s[2]):
        return s[1] if s[0] <= s[2] else s[3]
    if x >= max(s[0], s[2]):
        return s[3] if s[0] <= s[2] else s[1]
    return s[1] + (s[3] - s[1]) * (x - s[0]) / (s[2] - s[0])


def side_top(walls, x):
    """Highest y [cm] of the walls that are not floors where they meet the vertical line at x (a vessel's side);
    None if no such wall reaches it."""
    ys = []
    for x0, y0, x1, y1 in walls:
        if abs(y0 - y1) <= TOL or not min(x0, x1) - TOL <= x <= max(x0, x1) + TOL:
            continue
        ys += [max(y0, y1)] if abs(x1 - x0) <= TOL else [y0 + (y1 - y0) * (x - x0) / (x1 - x0)]
    return max(ys) if ys else None


def bounds(walls):
    """(xmin, ymin, xmax, ymax) [cm] of the walls' bounding box (pure Python)."""
    xs = [c for s in walls for c in (s[0], s[2])]
    ys = [c for s in walls for c in (s[1], s[3])]
    return min(xs), min(ys), max(xs), max(ys)


def check_points(path, field, points, walls, what="point(s)"):
    """Refuse points (x, y) [cm] outside the walls' bounding box (NaN counts as outside), naming the first;
    points: a sequence of pairs; walls: [(x0, y0, x1, y1)]."""
    box = bounds(walls)
    out = [(x, y) for x, y in points if not (box[0] <= x <= box[2] and box[1] <= y <= box[3])]
    if out:
        _outside(path, field, len(out), box, out[0], what)


def _outside(path, field, count, box, first, what="point(s)"):
    raise InputError(f"{path}: field '{field}': {count} {what} lie outside the walls' bounding box "
                     f"[{box[0]:g}, {box[2]:g}] x [{box[1]:g}, {box[3]:g}] cm, e.g. ({first[0]:g}, {first[1]:g})")


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

    def walls_list(self):
        """[(x0, y0, x1, y1)] wall segments [cm] (pure Python)."""
        return _segments(self.spec)

    def perimeter(self):
        """Total length [cm] of the walls."""
        return sum(math.hypot(s[2] - s[0], s[3] - s[1]) for s in _segments(self.spec))

    def panel_count(self, length):
        """Wall panels of about ``length`` cm (core.panels: at least one per wall), a float that cannot
        overflow an integer."""
        return sum(max(1.0, math.hypot(s[2] - s[0], s[3] - s[1]) / length) for s in _segments(self.spec))

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
    def first_vessel(self):
        """((xmin, xmax) cm, floor y cm) of the first vessel, where every method's liquid starts (vessel_floor)."""
        return self.vessels[0][1], self.floor_y(0)

    @property
    def weight(self):
        """Liquid weight W [N] per unit thickness."""
        return float(self.spec["liquid"]["weight"])

    @property
    def depth(self):
        """Liquid depth h [cm] in the first vessel (its hydrostatic depth at rest)."""
        return float(self.spec["liquid"]["depth"])

    def floor_y(self, vessel=0):
        """y [cm] of a vessel's floor: the lowest wall point over its x range (vessel_floor)."""
        return vessel_floor(_segments(self.spec), *self.vessels[vessel][1])

    def vessel_polygon(self, vessel=0):
        """[(x, y)] cm of a vessel's polygon (vessel_polygon: the outline cut to the vessel's x range)."""
        return vessel_polygon(_segments(self.spec), self.vessels[vessel][1])

    @property
    def liquid_area(self):
        """Area [cm^2] the tank's liquid fills at rest in the first vessel: its polygon below floor + h
        (liquid_area: B h for a rectangular vessel)."""
        return liquid_area(self.vessel_polygon(0), self.floor_y(0), self.depth)

    @property
    def rho_g(self):
        """Specific weight rho g [N/cm^2] of the tank's liquid: W / A, A the first vessel's polygon below floor + h
        (B h in a rectangular vessel of width B)."""
        return self.weight / self.liquid_area

    def escape_box(self):
        """(4,) xmin, ymin, xmax, ymax [cm] of the region a dynamic method's particle must stay in: the walls'
        bounding box, open upwards by the tank's own height (a splash may rise above the open top and fall
        back; one rising higher than the tank is tall carries energy no jet of this tank has).  A tuple (pure
        Python: the workflow's checks use it while it is parsed)."""
        x0, y0, x1, y1 = bounds(_segments(self.spec))
        return (x0, y0, x1, y1 + (y1 - y0))

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
    lowest wall point (from the wall reaching it, a horizontal one first: the lowest floor, or a V's vertex); in
    traversal order (None if there is no wall)."""
    if not walls:
        return None
    order = [min(range(len(walls)), key=lambda k: (min(walls[k][1], walls[k][3]), not _horizontal(walls[k]), k))]
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


def outline_points(walls, order=None):
    """[(x, y)] cm of the outline's vertices (the chain _chain finds: down the left side, along the floors, up the
    right side), closed across the top from its last point back to its first (pure Python)."""
    order = _chain(walls) if order is None else order
    return [tuple(walls[order[0]][:2])] + [tuple(walls[k][2:]) for k in order]


def _signed_area(points):
    """Shoelace signed area [cm^2] of a closed polygon (positive: counter-clockwise), about its first vertex."""
    x0, y0 = points[0]
    rel = [(x - x0, y - y0) for x, y in points]
    return 0.5 * sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(rel, rel[1:] + rel[:1]))


def _clip(points, inside, cross):
    """Sutherland-Hodgman: the part of a closed polygon where inside(p) holds, cross(p, q) the crossing point."""
    out = []
    for k, q in enumerate(points):
        p = points[k - 1]
        if inside(q):
            if not inside(p):
                out.append(cross(p, q))
            out.append(q)
        elif inside(p):
            out.append(cross(p, q))
    return out


def _tidy(points):
    """The polygon without repeated vertices and without vertices on the line through their neighbours (straight
    runs and the zero-width spikes clipping leaves along a boundary)."""
    pts = list(points)
    changed = True
    while changed and len(pts) > 2:
        changed = False
        for k in range(len(pts)):
            a, b, c = pts[k - 1], pts[k], pts[(k + 1) % len(pts)]
            ab, bc = math.hypot(b[0] - a[0], b[1] - a[1]), math.hypot(c[0] - b[0], c[1] - b[1])
            if ab <= TOL or bc <= TOL or abs((b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])) <= TOL * ab * bc:
                del pts[k]
                changed = True
                break
    return pts if len(pts) > 2 else []


def vessel_polygon(walls, x_range):
    """[(x, y)] cm, counter-clockwise: a vessel's polygon, the tank's outline (outline_points: closed across the
    top of its end walls) cut to the vessel's [xmin, xmax] (pure Python).  The liquid of every method starts in
    the first vessel's polygon; the tank's theory integrates over it (liquid_area)."""
    x0, x1 = x_range

    def at_x(x):
        return lambda p, q: (x, p[1] + (q[1] - p[1]) * (x - p[0]) / (q[0] - p[0]))

    pts = _clip(outline_points(walls), lambda p: p[0] >= x0, at_x(x0))
    pts = _clip(pts, lambda p: p[0] <= x1, at_x(x1))
    return _tidy(pts)


def below(polygon, level):
    """The part of a polygon [(x, y)] below y = level (pure Python)."""
    cut = _clip(polygon, lambda p: p[1] <= level,
                lambda p, q: (p[0] + (q[0] - p[0]) * (level - p[1]) / (q[1] - p[1]), level))
    return _tidy(cut)


def is_box(polygon):
    """True if the polygon is an axis-aligned rectangle (four corners of its bounding box)."""
    if len(polygon) != 4:
        return False
    xs, ys = sorted({round(x / TOL) for x, _ in polygon}), sorted({round(y / TOL) for _, y in polygon})
    return len(xs) == 2 and len(ys) == 2


def liquid_area(polygon, floor, depth):
    """Area [cm^2] of a vessel's polygon below floor + depth [cm]: width x depth in closed form where that part is a
    rectangle (a vessel of vertical sides on a flat floor), else the polygon's area (shoelace)."""
    if depth <= 0:
        return 0.0
    part = below(polygon, floor + depth)
    if not part:
        return 0.0
    if is_box(part):
        return (max(x for x, _ in part) - min(x for x, _ in part)) * depth
    return abs(_signed_area(part))


def check_geometry(path, spec):
    """A tank that can hold its liquid: one outline of joined walls (down the left side, along the floors, up
    the right side: the liquid on every wall's left), no crossing walls, every vessel inside the outline on a
    floor.  InputError naming the file and field otherwise."""
    walls, names = _segments(spec), [w["name"] for w in spec["walls"]]
    where = f"{path}: field 'walls'"
    order = _chain(walls)
    first, last = walls[order[0]], walls[order[-1]]
    if not (first[1] > first[3] and last[3] > last[1]) or _signed_area(outline_points(walls, order)) <= 0:
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
    for k in range(len(walls)):
        s = walls[k]
        if k not in order and (min(s[0], s[2]) < x_lo - TOL or max(s[0], s[2]) > x_hi + TOL):
            raise InputError(f"{where} ({names[k]}): a wall outside the tank's outline [{x_lo:g}, {x_hi:g}] cm")
    vessels = spec.get("vessels") or [{"name": "(whole tank)", "x": [x_lo, x_hi]}]
    outline = [walls[k] for k in order]
    for v in vessels:
        x0, x1 = v["x"]
        if x0 < x_lo - TOL or x1 > x_hi + TOL:
            raise InputError(f"{path}: field 'vessels' ({v['name']}): [{x0:g}, {x1:g}] cm lies outside the walls "
                             f"[{x_lo:g}, {x_hi:g}] cm")
        if vessel_floor(outline, x0, x1) is None:
            raise InputError(f"{path}: field 'vessels' ({v['name']}): no floor under [{x0:g}, {x1:g}] cm")
    for a, b in zip(vessels, vessels[1:]):
        if b["x"][0] < a["x"][1] - TOL:
            raise InputError(f"{path}: field 'vessels' ({b['name']}): overlaps '{a['name']}'")


def check_depth(path, spec):
    """The liquid's top, its depth above the first vessel's own floor, below that vessel's walls: the tops of the
    outline's end walls and of the walls on the vessel's two sides (a tank that passed check_geometry)."""
    walls = _segments(spec)
    outline = [walls[k] for k in _chain(walls)]
    top = min(outline[0][1], outline[-1][3])
    (x0, x1), name = (spec["vessels"][0]["x"], f"vessel '{spec['vessels'][0]['name']}'") if spec.get("vessels") \
        else ((outline[0][0], outline[-1][2]), "the tank")
    floor = vessel_floor(outline, x0, x1)
    sides = [t for t in (side_top(walls, x0), side_top(walls, x1)) if t is not None]
    top = min([top, *sides])
    depth = float(spec["liquid"]["depth"])
    if floor + depth > top + TOL:
        raise InputError(f"{path}: field 'liquid.depth': {depth:g} cm above the floor of {name} (y = {floor:g} cm) "
                         f"reaches over its walls (y = {top:g} cm)")


def check_positions(path, field, pos, walls):
    """Refuse positions that are non-finite or outside the walls' bounding box (NaN counts as outside);
    pos (N, 2) array [cm], walls (W, 4) segments [cm]."""
    import numpy as np

    if not np.isfinite(pos).all():
        raise InputError(f"{path}: field '{field}': positions must be finite")
    box = bounds(np.asarray(walls, float).tolist())
    out = ~((pos >= box[:2]) & (pos <= box[2:])).all(1)  # NaN counts as outside
    if out.any():
        _outside(path, field, int(out.sum()), box, pos[np.argmax(out)], "particle(s)")


def path_of(name):
    """config/tanks/<name>.yaml of a tank name."""
    return str(TANK_DIR / f"{name}.yaml")


def load(path):
    """Read and validate a tank file; InputError naming the file and the field."""
    path = str(path)
    text, spec = inputs.load(path, SCHEMA, "tank")
    for check in (check_walls, check_geometry, check_depth):  # in this order: each relies on the ones before
        check(path, spec)
    return Tank(path, spec, text)
