"""SPH settings: the values of config/methods/sph.yaml, read by the one loader (isaflow.settings).

Every value is ``{value, source}``; the physical settings sit under ``settings.<name>``, the resolution
(a target particle count or a spacing, and the on-wall stability start) under ``resolution.<name>``.
Variants (names and labels in the method registry) and resolutions change the values they list.  Bad
settings raise inputs.InputError naming the file and the field.  Pure Python.
"""

from pathlib import Path

from ... import settings as S
from ...inputs import InputError as SceneError

DEFAULT_PATH = Path(__file__).resolve().parents[4] / "config" / "methods" / "sph.yaml"

_POS = {"type": "number", "exclusiveMinimum": 0}
_NONNEG = {"type": "number", "minimum": 0}
SETTINGS = {
    "kernel": {"enum": ["cubic_spline", "wendland_c2"]},
    "h_factor": _POS,            # h / spacing
    "density": {"enum": ["summation", "continuity"]},
    "eos": {"enum": ["tait", "linear"]},
    "gamma": _POS,               # Tait exponent
    "sound_speed_factor": _POS,  # c0 / sqrt(2 g max_drop)
    "max_drop": _POS,            # cm
    "negative_pressure": {"enum": ["clamp", "keep"]},
    "alpha": _NONNEG,            # artificial viscosity
    "wall_viscosity": {"type": "boolean"},
    "delta": _NONNEG,            # density diffusion coefficient
    "repulsion_radius": _NONNEG,  # Lennard-Jones wall repulsion range / cell spacing (0: off)
    "cfl": _POS,                 # dt = cfl h / c0
    "skin": _NONNEG,             # neighbour-list skin / h
    "t_max_single": _POS,        # s
    "t_max_flow": _POS,          # s
    "chunk_time": _POS,          # s
    "panel_length": _POS,        # cm
    "snapshot_times": {"type": "array", "items": _NONNEG},
    "domain": {"enum": ["tank", "periodic_block"]},  # the tank's walls, or its liquid lattice made periodic (block)
    "stretch": {"type": "number", "exclusiveMinimum": -0.5, "maximum": 1.0},  # block: uniform linear strain
    "perturbation": _NONNEG,     # block: random initial displacement / spacing
    "seed": {"type": "integer", "minimum": 0},  # block: seed of the perturbation
    "t_max_block": _POS,         # s
}
VALUES = {**{f"settings.{k}": v for k, v in SETTINGS.items()},
          "resolution.particles": {"type": ["integer", "null"], "minimum": 4},
          "resolution.spacing": {"type": ["number", "null"], "exclusiveMinimum": 0},
          "resolution.on_wall": {"type": "boolean"}}


def read_file(path=DEFAULT_PATH):
    """The validated settings file as written (InputError naming the file and the field)."""
    return S.read(path, VALUES, "SPH settings")


def resolve(spec, variant, overrides=None, path=DEFAULT_PATH):
    """{name: value} of the physical settings of a variant (then overrides {name: value or {value, source}})."""
    if variant not in spec["variants"]:
        raise SceneError(f"SPH settings: field 'variants': no variant '{variant}' "
                         f"(choose from {', '.join(spec['variants'])})")
    extra = {f"settings.{k}": v for k, v in (overrides or {}).items()}
    for k in extra:
        if k not in VALUES:
            raise SceneError(f"SPH settings: override field '{k[9:]}': unknown (choose from {', '.join(SETTINGS)})")
    return physics(S.load(path, VALUES, variant, overrides=extra, spec=spec))


def physics(settings):
    """{name: value} of the ``settings.*`` values of a resolved isaflow.settings.Settings."""
    return settings.tree("settings")


def resolution(settings):
    """{'particles': N} or {'spacing': cm} of a resolved Settings (InputError if neither or both)."""
    r = settings.tree("resolution")
    given = {k: r[k] for k in ("particles", "spacing") if r.get(k) is not None}
    if len(given) != 1:
        raise SceneError(f"{settings.path}: field 'resolution': give exactly one of particles and spacing "
                         f"(resolution '{settings.resolution}')")
    return given
