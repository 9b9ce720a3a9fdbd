"""SPH settings: config/methods/sph.yaml, validated by SCHEMA (unknown keys rejected).

Every physical setting is ``{value: ..., source: "page text: ..." | "inferred: ..."
| "literature: ..."}``.  A variant is a named set of overrides with its own
label; runs may override further (stability cases).  Bad settings raise
inputs.InputError naming the file and the field.
"""

from pathlib import Path


from ... import inputs
from ...inputs import InputError as SceneError

DEFAULT_PATH = Path(__file__).resolve().parents[4] / "config" / "methods" / "sph.yaml"


def _setting(value_schema):
    return {"type": "object", "additionalProperties": False, "required": ["value", "source"],
            "properties": {"value": value_schema,
                           "source": {"type": "string", "pattern": "^(page text|inferred|literature|issue text): .+"}}}


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
}
_OVERRIDES = {"type": "object", "additionalProperties": False,
              "properties": {k: _setting(v) for k, v in SETTINGS.items()}}
_RESOLUTION = {"type": "object", "additionalProperties": False,
               "properties": {"particles": {"type": "integer", "minimum": 4}, "spacing": _POS,
                              "source": {"type": "string"}},
               "oneOf": [{"required": ["particles"]}, {"required": ["spacing"]}]}
SCHEMA = {
    "type": "object", "additionalProperties": False, "required": ["settings", "variants", "runs"],
    "properties": {
        "settings": {**_OVERRIDES, "required": list(SETTINGS)},
        "variants": {"type": "object", "minProperties": 1, "additionalProperties": {
            "type": "object", "additionalProperties": False, "required": ["label", "set"],
            "properties": {"label": {"type": "string"}, "set": _OVERRIDES}}},
        "runs": {"type": "object", "additionalProperties": False, "required": ["single", "flow", "stability"],
                 "properties": {
                     "single": {"type": "array", "items": _RESOLUTION},
                     "flow": {"type": "array", "items": _RESOLUTION},
                     "stability": {"type": "object", "additionalProperties": {
                         "type": "object", "additionalProperties": False, "required": ["label", "resolution"],
                         "properties": {"label": {"type": "string"}, "resolution": _RESOLUTION,
                                        "set": _OVERRIDES, "on_wall": {"type": "boolean"}}}},
                 }},
    },
}


def load(path=DEFAULT_PATH):
    """The validated settings file as a dict (SceneError naming file and field)."""
    return inputs.load(path, SCHEMA, "SPH settings")[1]


def resolve(spec, variant, overrides=None):
    """{name: value} of a variant's settings (defaults, then the variant's, then overrides).

    overrides: {name: value} (plain values) or {name: {value, source}}.
    """
    if variant not in spec["variants"]:
        raise SceneError(f"SPH settings: field 'variants': no variant '{variant}' "
                         f"(choose from {', '.join(spec['variants'])})")
    out = {k: v["value"] for k, v in spec["settings"].items()}
    out.update({k: v["value"] for k, v in spec["variants"][variant]["set"].items()})
    for k, v in (overrides or {}).items():
        if k not in SETTINGS:
            raise SceneError(f"SPH settings: override field '{k}': unknown (choose from {', '.join(SETTINGS)})")
        out[k] = v["value"] if isinstance(v, dict) else v
    return out
