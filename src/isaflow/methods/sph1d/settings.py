"""Settings of the 1D truncated-SPH study (config/methods/sph1d.yaml), read by the one loader (isaflow.settings).

Every entry is {value, source}; unknown keys are rejected; a bad file raises
isaflow.inputs.InputError with one line naming the file and the field.
"""

from isaflow import preflight
from isaflow import settings as S

KERNELS = ("cubic_spline", "wendland_c2", "wendland_c4", "wendland_c6", "wendland_c2_1d", "wendland_c4_1d",
           "wendland_c6_1d")  # core.smoothing.NAMES (tested equal): the Wendland functions in their 3D and 1D forms
GRADIENT_FORMS = ("symmetric", "plain")  # system.GRADIENT_FORMS (tested equal)
FLOORS = ("mirror_hydrostatic", "mirror_equal", "truncated")  # system.FLOORS (tested equal)


_POS = {"type": "number", "exclusiveMinimum": 0}
# {dotted key: JSON schema of the value} of config/methods/sph1d.yaml (isaflow.settings); the sweep solves
# every variant of its 'variants' section
VALUES = {
    "column.height": _POS, "column.rho_g": _POS,
    "kernels": {"type": "array", "minItems": 1, "uniqueItems": True, "items": {"enum": list(KERNELS)}},
    "ratio": {"type": "object", "additionalProperties": False, "required": ["start", "stop", "step"],
              "properties": {"start": {"type": "number", "exclusiveMinimum": 0.5}, "stop": _POS, "step": _POS}},
    "n": {"type": "array", "minItems": 2, "items": {"type": "integer", "minimum": 8}},
    "gradient": {"enum": list(GRADIENT_FORMS)}, "floor": {"enum": list(FLOORS)},
    "surface": {"type": "number", "minimum": 0, "maximum": 0.5},  # the top particle's gap below the surface [dx]
    "classify.window": {"type": "integer", "minimum": 2},
}


def checked_values(path, resolution=None):
    """{name: value} of a settings file (with its ``resolutions`` entry ``resolution`` applied, e.g. the longer
    N range of the sweep to N = 8192), checked (isaflow.preflight: the defaults and every resolution); adds
    'variants' ({name: {gradient, floor}}), 'ratios' (array of h/dx), 'path' and 'resolution'."""
    import numpy as np

    spec = preflight.check_file("sph1d", path)
    s = S.load(path, VALUES, resolution=resolution, spec=spec).tree()
    s["variants"] = {}
    for name in spec["variants"]:
        v = S.load(path, VALUES, variant=name, resolution=resolution, spec=spec)
        s["variants"][name] = {"gradient": v["gradient"], "floor": v["floor"]}
    del s["gradient"], s["floor"]
    r = s["ratio"]
    s["ratios"] = np.round(np.arange(r["start"], r["stop"] + 0.5 * r["step"], r["step"]), 10)
    s["n"] = sorted(s["n"])
    s["path"] = str(path)
    s["resolution"] = resolution or ""
    return s
