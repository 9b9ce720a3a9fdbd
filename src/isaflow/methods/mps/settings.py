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


# {dotted key: JSON schema of the value} of config/methods/mps.yaml
VALUES = {
    'model.re_density': {"type": "number", "exclusiveMinimum": 1},
    'model.re_laplacian': {"type": "number", "exclusiveMinimum": 1},
    'model.beta': {"type": "number", "exclusiveMinimum": 0, "maximum": 1},
    'model.kinematic_viscosity': {"type": "number", "minimum": 0},
    'model.gamma_mixed': {"type": "number", "minimum": 0},
    'model.clip_negative': {"type": "boolean"},
    'model.collision_distance': {"type": "number", "minimum": 0, "maximum": 1},
    'model.restitution': {"type": "number", "minimum": 0, "maximum": 1},
    'model.re_gradient': {"type": "number", "exclusiveMinimum": 1},
    'model.relaxation': {"type": "number", "exclusiveMinimum": 0, "maximum": 1},
    'model.sound_speed': {"type": "number", "minimum": 0},
    'model.pressure_layers': {"type": "integer", "minimum": 1, "maximum": 6},
    'model.dummy_layers': {"type": "integer", "minimum": 0, "maximum": 6},
    'model.surface_distribution': {"type": "number", "minimum": 0},
    'model.re_surface': {"type": "number", "exclusiveMinimum": 1},
    'model.surface_pressure': {"enum": ["zero", "hydrostatic", "extrapolated"]},
    'model.gradient': {"enum": ["min", "corrected", "symmetric", "cmps", "variational", "variational_dummies"]},
    'model.pressure_laplacian': {"enum": ["mps", "hl"]},
    'model.divergence': {"enum": ["mps", "hs"]},
    'model.ecs': {"type": "boolean"},
    'model.shifting': {"type": "number", "minimum": 0, "maximum": 0.5},
    'model.list_skin': {"type": "number", "minimum": 0},
    'model.relaxation_scope': {"enum": ["density", "source", "standard"]},
    'time.courant': {"type": "number", "exclusiveMinimum": 0},
    'time.velocity_courant': {"type": "number", "minimum": 0},
    'time.sample_interval': {"type": "number", "exclusiveMinimum": 0},
    'time.single_time': {"type": "number", "exclusiveMinimum": 0},
    'time.flow_time': {"type": "number", "exclusiveMinimum": 0},
    'time.average_window': {"type": "number", "exclusiveMinimum": 0},
    'time.snapshot_single': {"type": "number", "exclusiveMinimum": 0},
    'time.snapshot_flow': {"type": "number", "exclusiveMinimum": 0},
    'time.snapshot_megabytes': {"type": "number", "exclusiveMinimum": 0},
    'pressure.solver': {"enum": ["cg_jacobi", "scipy_cg", "amg", "direct"]},
    'pressure.rtol': {"type": "number", "exclusiveMinimum": 0},
    'pressure.maxiter': {"type": "integer", "minimum": 1},
    'pressure.fail_factor': {"type": "number", "minimum": 1},
    'walls.panel_length': {"type": "number", "exclusiveMinimum": 0},
    'walls.graze_depth': {"type": "number", "minimum": 0},
    'walls.reflect': {"type": "boolean"},
    'walls.thin_line_of_sight': {"type": "boolean"},
    'resolution.spacing': {"type": ["number", "null"], "exclusiveMinimum": 0},
    'start.on_wall_point': {"type": ["array", "null"], "items": {"type": "number"}, "minItems": 2, "maxItems": 2},
    'probes.single': {"type": "array", "items": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}},
    'probes.flow': {"type": "array", "items": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}},
}


def resolved(path=DEFAULT_PATH, variant=None, resolution=None, overrides=()):
    """Resolved settings (isaflow.settings.Settings, 'group.key' -> value); InputError naming file and field."""
    return S.load(path, VALUES, variant, resolution, overrides, what="MPS settings")
