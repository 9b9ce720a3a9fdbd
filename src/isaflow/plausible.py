"""Physical plausibility checks of a run's settings: the helpers every method's checks use.

A method's ``checks`` module states each check once, with the reason its
message cites.  Two kinds:

- :func:`require`: a run with this value cannot mean anything (no neighbour
  inside the kernel, a disk pressed through its plate, a liquid with no
  particle across its depth); always refused.
- :func:`within`: the value lies outside the range the method's literature
  allows (CFL and Courant numbers, smoothing length, Tait exponent...);
  refused unless the run is a declared stability case (``stability: true``
  in its declaration, ``isaflow run --stability-case``), whose point is to
  go outside it.

Every refusal is one line naming the file and the setting the user wrote
(InputError): a field is a dotted key of the settings file, or (file, field) of
another file, e.g. the tank's (:func:`tank_field`); a derived number names the
input it follows (:func:`extreme`, :func:`lattice_field`, :func:`liquid_field`).
Pure Python.
"""

import math

from .inputs import InputError


def _fmt(x):
    return f"{x:.4g}" if isinstance(x, float) else str(x)


def where(path, field):
    """'<file>: field '<field>'' of a settings field, or of (file, field) of another file."""
    return f"{field[0]}: field '{field[1]}'" if isinstance(field, tuple) else f"{path}: field '{field}'"


def require(ok, path, field, message):
    """Refuse unless ok: '<path>: field '<field>': <message>' (field: a key, or (file, field))."""
    if not ok:
        raise InputError(f"{where(path, field)}: {message}")


def extreme(s, *keys):
    """The key of s (a mapping) whose positive value lies farthest from 1 (by orders of magnitude): the input
    a derived product or quotient that over- or underflows follows."""
    return max(keys, key=lambda k: abs(math.log10(s[k])))


def tank_field(tank, field):
    """(tank file, field) of a tank field, for a refusal that blames the tank."""
    return (tank.path, field)


def width_field(tank):
    """The tank field that gives its first vessel's width: its vessels, or its walls if it names none."""
    return tank_field(tank, "vessels" if tank.spec.get("vessels") else "walls")


def lattice_field(tank, nx, ny, resolution):
    """What a liquid lattice of nx x ny particles is short of across: the tank's liquid.depth if only its depth
    holds fewer than 2, its first vessel's width if only the width does, else the resolution's field."""
    if nx >= 2 > ny:
        return tank_field(tank, "liquid.depth")
    return width_field(tank) if ny >= 2 > nx else resolution


def liquid_field(tank, nx, ny, resolution):
    """What a liquid lattice of nx x ny particles owes its size to: the tank's longer side (liquid.depth, or the
    first vessel's width) when the liquid's shape, max / min of nx and ny, gives more of nx ny than the spacing
    does (min^2), else the resolution's field."""
    lo, hi = min(nx, ny), max(nx, ny)
    if hi <= lo ** 3:
        return resolution
    return tank_field(tank, "liquid.depth") if ny > nx else width_field(tank)


def finite(path, field, value, what):
    """Refuse a derived number that over- or underflowed (not finite, or not positive); field: the input it
    follows."""
    require(math.isfinite(value) and value > 0, path, field,
            f"the derived {what} {value!r} is not a finite positive number; choose less extreme values")


def within(path, field, value, lo, hi, reason, stability=False):
    """Refuse value outside [lo, hi] (None: unbounded) unless the run is a stability case; the message
    cites the reason, e.g. 'cfl 50 exceeds 0.4 (WCSPH codes run at 0.1-0.4 ...)'."""
    if stability:
        return
    if lo is not None and not value >= lo:
        raise InputError(f"{path}: field '{field}': {_fmt(value)} is below {_fmt(lo)} ({reason}); a stability case "
                         f"may go outside this range (stability: true)")
    if hi is not None and not value <= hi:
        raise InputError(f"{path}: field '{field}': {_fmt(value)} exceeds {_fmt(hi)} ({reason}); a stability case "
                         f"may go outside this range (stability: true)")
