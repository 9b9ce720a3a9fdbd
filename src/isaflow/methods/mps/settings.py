"""MPS settings: the values of config/methods/mps.yaml, read by the one loader (isaflow.settings).

Every value is ``{value, source}`` under its group (``model``, ``time``, ``pressure``, ``walls``; the
run's ``resolution.spacing`` l0, the on-wall stiff case's ``start.on_wall_point``, the pressure
``probes``).  The variant is the source term of the pressure equation.  isaflow.settings.Settings maps
'group.key' -> value, as the solver reads it.  Pure Python.
"""

from pathlib import Path

from ... import settings as S

DEFAULT_PATH = Path(__file__).resolve().parents[4] / "config" / "methods" / "mps.yaml"


def own_tank(tank, settings):
    """The overrides ('key=value') of a run on a tank no settings file was written for (isaflow compare): the
    pressure probes' points are in the project's tanks (x = 10-250 cm), so none is read in another (set them on a
    run of its own)."""
    return ("probes.single=[]", "probes.flow=[]")


# {dotted key: JSON schema of the value, with its units (multiples of l0 are '1')} of config/methods/mps.yaml
_in = S.with_units
_POINT = {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}  # (x, y)
VALUES = {
    'model.re_density': _in("1", {"type": "number", "exclusiveMinimum": 1}),
    'model.re_laplacian': _in("1", {"type": "number", "exclusiveMinimum": 1}),
    'model.beta': _in("1", {"type": "number", "exclusiveMinimum": 0, "maximum": 1}),
    'model.kinematic_viscosity': _in("cm2 s-1", {"type": "number", "minimum": 0}),
    'model.gamma_mixed': _in("1", {"type": "number", "minimum": 0}),
    'model.clip_negative': {"type": "boolean"},
    'model.collision_distance': _in("1", {"type": "number", "minimum": 0, "maximum": 1}),
    'model.restitution': _in("1", {"type": "number", "minimum": 0, "maximum": 1}),
    'model.re_gradient': _in("1", {"type": "number", "exclusiveMinimum": 1}),
    'model.relaxation': _in("1", {"type": "number", "exclusiveMinimum": 0, "maximum": 1}),
    'model.sound_speed': _in("cm s-1", {"type": "number", "minimum": 0}),
    'model.pressure_layers': {"type": "integer", "minimum": 1, "maximum": 6},
    'model.dummy_layers': {"type": "integer", "minimum": 0, "maximum": 6},
    'model.surface_distribution': _in("1", {"type": "number", "minimum": 0}),
    'model.re_surface': _in("1", {"type": "number", "exclusiveMinimum": 1}),
    'model.surface_pressure': {"enum": ["zero", "hydrostatic", "extrapolated"]},
    'model.gradient': {"enum": ["min", "corrected", "symmetric", "cmps", "variational", "variational_dummies"]},
    'model.pressure_laplacian': {"enum": ["mps", "hl"]},
    'model.divergence': {"enum": ["mps", "hs"]},
    'model.ecs': {"type": "boolean"},
    'model.shifting': _in("1", {"type": "number", "minimum": 0, "maximum": 0.5}),
    'model.list_skin': _in("1", {"type": "number", "minimum": 0}),
    'model.relaxation_scope': {"enum": ["density", "source", "standard"]},
    'time.courant': _in("1", {"type": "number", "exclusiveMinimum": 0}),
    'time.velocity_courant': _in("1", {"type": "number", "minimum": 0}),
    'time.sample_interval': _in("s", {"type": "number", "exclusiveMinimum": 0}),
    'time.single_time': _in("s", {"type": "number", "exclusiveMinimum": 0}),
    'time.flow_time': _in("s", {"type": "number", "exclusiveMinimum": 0}),
    'time.average_window': _in("s", {"type": "number", "exclusiveMinimum": 0}),
    'time.snapshot_single': _in("s", {"type": "number", "exclusiveMinimum": 0}),
    'time.snapshot_flow': _in("s", {"type": "number", "exclusiveMinimum": 0}),
    'time.snapshot_megabytes': _in("1e6 byte", {"type": "number", "exclusiveMinimum": 0}),
    'pressure.solver': {"enum": ["cg_jacobi", "scipy_cg", "amg", "direct"]},
    'pressure.rtol': _in("1", {"type": "number", "exclusiveMinimum": 0}),
    'pressure.maxiter': {"type": "integer", "minimum": 1},
    'pressure.fail_factor': _in("1", {"type": "number", "minimum": 1}),
    'walls.panel_length': _in("cm", {"type": "number", "exclusiveMinimum": 0}),
    'walls.graze_depth': _in("1", {"type": "number", "minimum": 0}),
    'walls.reflect': {"type": "boolean"},
    'walls.thin_line_of_sight': {"type": "boolean"},
    'resolution.spacing': _in("cm", {"type": ["number", "null"], "exclusiveMinimum": 0}),
    'start.on_wall_point': _in("cm", {**_POINT, "type": ["array", "null"]}),
    'probes.single': _in("cm", {"type": "array", "items": _POINT}),
    'probes.flow': _in("cm", {"type": "array", "items": _POINT}),
}


def resolved(path=DEFAULT_PATH, variant=None, resolution=None, overrides=()):
    """Resolved settings (isaflow.settings.Settings, 'group.key' -> value); InputError naming file and field."""
    return S.load(path, VALUES, variant, resolution, overrides, what="MPS settings")
