"""Settings of the 1D truncated-SPH study (config/methods/sph1d.yaml): JSON schema and loader.

Every entry is {value, source}; unknown keys are rejected; a bad file raises
isaflow.inputs.InputError with one line naming the file and the field.
"""

from pathlib import Path

import numpy as np

from isaflow.core.smoothing import NAMES
from isaflow import inputs
from isaflow.inputs import InputError as SceneError

from .system import FLOORS, GRADIENT_FORMS


def _entry(value_schema):
    return {"type": "object", "additionalProperties": False, "required": ["value", "source"],
            "properties": {"value": value_schema, "source": {"type": "string", "minLength": 8}}}


_POS = {"type": "number", "exclusiveMinimum": 0}
SCHEMA = {
    "type": "object", "additionalProperties": False,
    "required": ["column", "kernels", "ratio", "n", "variants", "classify"],
    "properties": {
        "column": {"type": "object", "additionalProperties": False, "required": ["height", "rho_g"],
                   "properties": {"height": _entry(_POS), "rho_g": _entry(_POS)}},
        "kernels": _entry({"type": "array", "minItems": 1, "uniqueItems": True,
                           "items": {"enum": list(NAMES)}}),
        "ratio": _entry({"type": "object", "additionalProperties": False, "required": ["start", "stop", "step"],
                         "properties": {"start": {"type": "number", "exclusiveMinimum": 0.5},
                                        "stop": _POS, "step": _POS}}),
        "n": _entry({"type": "array", "minItems": 2, "items": {"type": "integer", "minimum": 8}}),
        "variants": _entry({"type": "object", "minProperties": 1, "additionalProperties": {
            "type": "object", "additionalProperties": False, "required": ["gradient", "floor"],
            "properties": {"gradient": {"enum": list(GRADIENT_FORMS)}, "floor": {"enum": list(FLOORS)}}}}),
        "classify": {"type": "object", "additionalProperties": False,
                     "required": ["window", "settle_factor", "ill_conditioned", "small_error"],
                     "properties": {"window": _entry({"type": "integer", "minimum": 2}),
                                    "settle_factor": _entry({"type": "number", "exclusiveMinimum": 1}),
                                    "ill_conditioned": _entry(_POS), "small_error": _entry(_POS)}},
    },
}


def _values(node):
    """Strip {value, source} wrappers."""
    if isinstance(node, dict) and set(node) == {"value", "source"}:
        return node["value"]
    return {k: _values(v) for k, v in node.items()} if isinstance(node, dict) else node


def load(path):
    """{name: value} of a settings file; adds 'ratios' (array of h/dx) and 'path'."""
    path = Path(path)
    spec = inputs.load(path, SCHEMA, "1D SPH settings")[1]
    s = _values(spec)
    r = s["ratio"]
    if r["stop"] < r["start"]:
        raise SceneError(f"{path}: ratio.value.stop: must be >= start")
    if len(s["n"]) < s["classify"]["window"]:
        raise SceneError(f"{path}: n.value: needs at least classify.window = {s['classify']['window']} values")
    s["ratios"] = np.round(np.arange(r["start"], r["stop"] + 0.5 * r["step"], r["step"]), 10)
    s["n"] = sorted(s["n"])
    s["path"] = str(path)
    return s
