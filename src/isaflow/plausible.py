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

Every refusal is one line naming the file and the setting (InputError).
Pure Python.
"""

import math

from .inputs import InputError


def _fmt(x):
    return f"{x:.4g}" if isinstance(x, float) else str(x)


def require(ok, path, field, message):
    """Refuse unless ok: '<path>: field '<field>': <message>'."""
    if not ok:
        raise InputError(f"{path}: field '{field}': {message}")


def finite(path, field, value, what):
    """Refuse a derived number that over- or underflowed (not finite, or not positive)."""
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
