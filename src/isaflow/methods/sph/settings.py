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


def own_tank(tank, settings):
    """The overrides ('key=value') of a run on a tank no settings file was written for (isaflow compare), given the
    run's resolved settings: settings.max_drop, the largest free fall in the project's tanks (72.5 cm of liquid over
    a 50 cm step), at least the tank's own (the liquid's top above its lowest wall point: the sound speed keeps the
    Mach number at 0.1) and at most what the tank allows (the checks' bound, its escape box's height); a longer
    assumed fall only raises the sound speed, and with it the artificial viscosity's damping."""
    low = min(min(w["from"][1], w["to"][1]) for w in tank.spec["walls"])
    box = tank.escape_box()
    drop = max(tank.floor_y(0) + tank.depth - low, min(settings["settings.max_drop"], box[3] - box[1]))
    return () if drop == settings["settings.max_drop"] else (f"settings.max_drop={drop!r}",)


_in = S.with_units  # a value's schema with the units its run-file attribute carries (settings_units)
SETTINGS = {
    "kernel": {"enum": ["cubic_spline", "wendland_c2"]},
    "h_factor": _in("1", _POS),  # h / spacing
    "density": {"enum": ["summation", "continuity"]},
    "eos": {"enum": ["tait", "linear"]},
    "gamma": _in("1", _POS),  # Tait exponent
    "sound_speed_factor": _in("1", _POS),  # c0 / sqrt(2 g max_drop)
    "max_drop": _in("cm", _POS),
    "negative_pressure": {"enum": ["clamp", "keep"]},
    "alpha": _in("1", _NONNEG),  # artificial viscosity
    "wall_viscosity": {"type": "boolean"},
    "delta": _in("1", _NONNEG),  # density diffusion coefficient
    "repulsion_radius": _in("1", _NONNEG),  # Lennard-Jones wall repulsion range / cell spacing (0: off)
    "cfl": _in("1", _POS),  # dt = cfl h / c0
    "skin": _in("1", _NONNEG),  # neighbour-list skin / h
    "t_max_single": _in("s", _POS),
    "t_max_flow": _in("s", _POS),
    "chunk_time": _in("s", _POS),
    "panel_length": _in("cm", _POS),
    "snapshot_every_single": _in("s", _POS),  # between snapshots (driver.Recording), single vessel
    "snapshot_every_flow": _in("s", _POS),  # between snapshots, a tank of vessels
    "snapshot_megabytes": _in("1e6 byte", _POS),  # what the kept snapshots may take before they are thinned
    "domain": {"enum": ["tank", "periodic_block"]},  # the tank's walls, or its liquid lattice made periodic (block)
    "stretch": _in("1", {"type": "number", "exclusiveMinimum": -0.5, "maximum": 1.0}),  # block: uniform linear strain
    "perturbation": _in("1", _NONNEG),  # block: random initial displacement / spacing
    "seed": {"type": "integer", "minimum": 0},  # block: seed of the perturbation
    "t_max_block": _in("s", _POS),
}
VALUES = {**{f"settings.{k}": v for k, v in SETTINGS.items()},
          "resolution.particles": {"type": ["integer", "null"], "minimum": 4},
          "resolution.spacing": _in("cm", {"type": ["number", "null"], "exclusiveMinimum": 0}),
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
