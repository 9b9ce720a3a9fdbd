"""Every method's settings file (config/methods/<name>.yaml), read by this one loader.

The dialect: nested mappings whose leaves are ``{value: ..., source: "..."}``
(the source says where the value comes from: ``page text: ...``,
``literature: ...``, ``inferred: why``, ``issue text: ...``, ``calibrated: ...``
or ``study plan: ...``).  Values are addressed by dotted keys
(``forces.wall.r_u``).  Three top-level sections are reserved:

- ``variants: {name: {set: {dotted.key: leaf}}}``: the settings a variant
  changes (its name, label and colour live in the method registry);
- ``resolutions: {name: {source: str, set: {dotted.key: leaf}}}``: the
  settings one resolution (a lattice, a spacing, a particle count) changes;
- ``runs: {run id: {...}}``: the method's workflow runs (:data:`RUN_SCHEMA`).

A method gives the JSON schema of each value by dotted key (its ``VALUES``);
:func:`file_schema` builds the file's schema from it, so unknown keys are
refused everywhere.  :func:`load` applies a resolution, then a variant, then
overrides (``key=value`` strings parsed as hardened YAML, or ``{key: leaf}``
mappings) and checks every value again.  Every error is one line naming the
file and the field (inputs.InputError).  A run file holds the resolved settings
under their dotted keys (:func:`attributes`, the one naming rule; figures, tables
and claims read those names).  Pure Python (yaml, jsonschema): the workflow reads
settings while it is parsed.
"""

import copy
import json

from . import inputs
from .inputs import InputError

RESERVED = ("variants", "resolutions", "runs")
SOURCE = {"type": "string", "maxLength": 2000,
          "pattern": "^(page text|literature|inferred|issue text|calibrated|study plan)( \\([^)]*\\))?[:;] .+"}
NAME = {"type": "string", "pattern": "^[A-Za-z0-9_.]+\\Z", "maxLength": 64}
# The one list of run outcomes (run-file attribute ``status``; a run declaration's ``accept``), read
# while the workflow is parsed (so here, free of the numerical stack); contract re-exports it.
OUTCOMES = {
    "converged": "stop criterion met: static equilibrium (max|F| < f_tol) or liquid at rest (kinetic-energy criterion)",
    "cycle": "the iteration repeats with a fixed period and can never converge (detected)",
    "step_limit": "step or time limit reached while still out of balance or moving",
    "escaped": "a particle would cross a wall, or left the walls' bounding box",
    "nonfinite": "a position, velocity or force became NaN or infinite",
    "solver_failed": "an implicit (pressure) solve did not reach its tolerance",
}
OUTCOME_NAMES = list(OUTCOMES)


def with_units(units, schema):
    """A value's schema (a method's VALUES entry) with its units, which the run file records (settings_units,
    :func:`attributes`); jsonschema ignores the keyword."""
    return {**schema, "units": units}


def leaf(value_schema):
    """Schema of one ``{value, source}`` entry."""
    return {"type": "object", "additionalProperties": False, "required": ["value", "source"],
            "properties": {"value": value_schema, "source": SOURCE}}


def _tree(values):
    """Nested object schema of the dotted keys of ``values`` (every key required)."""
    root = {}
    for key, schema in values.items():
        node = root
        parts = key.split(".")
        for p in parts[:-1]:
            node = node.setdefault(p, {})
            if not isinstance(node, dict) or "__leaf__" in node:
                raise ValueError(f"settings key '{key}' nests under a value")
        node[parts[-1]] = {"__leaf__": schema}

    def build(node):
        if "__leaf__" in node:
            return leaf(node["__leaf__"])
        return {"type": "object", "additionalProperties": False, "required": sorted(node),
                "properties": {k: build(v) for k, v in node.items()}}

    return build(root)


def overrides_schema(values):
    """Schema of a ``set:`` block: {dotted key: leaf} with the keys of ``values`` only."""
    return {"type": "object", "additionalProperties": False,
            "properties": {k: leaf(v) for k, v in values.items()}}


RUN_SCHEMA = {
    "type": "object", "additionalProperties": False, "required": ["tank", "variant", "resolution"],
    "properties": {
        "tank": NAME,                 # config/tanks/<tank>.yaml
        "variant": NAME,
        "resolution": NAME,
        "start": NAME,                # run id of the same method this run continues
        "set": {"type": "object"},    # overrides, checked against the method's values
        "accept": {"type": "array", "items": {"enum": OUTCOME_NAMES}, "minItems": 1, "uniqueItems": True},
        "label": {"type": "string", "maxLength": 300},
        "compare": {"type": "boolean"},  # the run enters the methods' comparison
        "threads": {"type": "integer", "minimum": 1, "maximum": 64},
        "note": {"type": "string", "maxLength": 2000},
        "stability": {"type": "boolean"},  # a stability case: literature ranges not enforced, may fail
        "max_hours": {"type": "number", "exclusiveMinimum": 0},  # its own CPU-hour budget (a long run)
        "block": NAME,  # runs of one method sharing a block run in one job, one process (short sweep points)
    },
}


_SCHEMAS = {}  # (id(values), id(extra)) -> (values, extra, schema): one schema object per values (inputs.load's key)


def file_schema(values, extra=None):
    """JSON schema of a settings file whose values are ``values`` ({dotted key: value schema}), built once per
    values and extra object (the same object each call: inputs.load checks a file once per schema object).

    extra: {section: schema} of further top-level sections the method's file holds.
    """
    hit = _SCHEMAS.get((id(values), id(extra)))
    if hit is not None and hit[0] is values and hit[1] is extra:
        return hit[2]
    schema = _file_schema(values, extra)
    _SCHEMAS[id(values), id(extra)] = (values, extra, schema)
    return schema


def _file_schema(values, extra):
    sets = overrides_schema(values)
    base = _tree(values)
    props = dict(base["properties"])
    props["variants"] = {"type": "object", "minProperties": 1, "additionalProperties": {
        "type": "object", "additionalProperties": False, "required": ["set"], "properties": {"set": sets}}}
    props["resolutions"] = {"type": "object", "minProperties": 1, "additionalProperties": {
        "type": "object", "additionalProperties": False, "required": ["source", "set"],
        "properties": {"source": SOURCE, "set": sets}}}
    props["runs"] = {"type": "object", "propertyNames": NAME, "additionalProperties": RUN_SCHEMA}
    props.update(extra or {})
    return {"type": "object", "additionalProperties": False, "required": base["required"], "properties": props}


class Settings(dict):
    """{dotted key: value} of one method's settings, resolved for a variant and resolution.

    ``sources`` {dotted key: source}; ``path`` the file; ``variant``,
    ``resolution`` the names applied; ``spec`` the validated file.
    """

    def __init__(self, values, sources, path, spec, variant=None, resolution=None, schema=None):
        super().__init__(values)
        self.sources, self.path, self.spec = sources, path, spec
        self.variant, self.resolution, self.schema = variant, resolution, schema

    def tree(self, prefix=""):
        """Nested {name: value} of the keys under ``prefix`` ('' for all)."""
        out = {}
        for key, value in self.items():
            if prefix and not key.startswith(prefix + "."):
                continue
            node = out
            parts = key[len(prefix) + 1:].split(".") if prefix else key.split(".")
            for p in parts[:-1]:
                node = node.setdefault(p, {})
            node[parts[-1]] = copy.deepcopy(value)
        return out

    def with_overrides(self, overrides=(), what="override", **values):
        """Copy with ``overrides`` applied (see :func:`apply`), then ``values`` ({dotted key: plain value},
        e.g. ``with_overrides(**{"model.beta": 0.9})``)."""
        new = Settings(copy.deepcopy(dict(self)), dict(self.sources), self.path, self.spec, self.variant,
                       self.resolution, self.schema)
        apply(new, overrides, self.schema or {}, self.path, what)
        apply(new, values, self.schema or {}, self.path, what)
        return new

    def runs(self):
        """{run id: declaration} of the file's ``runs`` section."""
        return copy.deepcopy(self.spec.get("runs", {}))


def flatten(node, prefix=""):
    """{dotted key: leaf} of every ``{value, source}`` leaf under node."""
    out = {}
    for k, v in node.items():
        key = f"{prefix}.{k}" if prefix else k
        if isinstance(v, dict) and set(v) == {"value", "source"}:
            out[key] = v
        elif isinstance(v, dict):
            out.update(flatten(v, key))
    return out


def _parse(item, path, what, source=None):
    """(key, leaf) of one override: a 'key=value' string (value as hardened YAML, without a comment: one would be
    dropped silently).  path: what an error names first (a file, '--set', or a file's field); source: the leaf's
    (default: an override on the command line)."""
    if not isinstance(item, str) or "=" not in item:
        raise InputError(f"{path}: {what} '{inputs.printable(str(item))}' is not of the form key=value")
    key, value = item.split("=", 1)
    bad = inputs.bad_string(key) or inputs.bad_string(value)
    if bad:
        raise InputError(f"{path}: {what} '{inputs.printable(item)}': {bad}")
    try:
        parsed = inputs.parse_yaml(value)
    except InputError as err:
        raise InputError(f"{path}: {what} '{inputs.printable(item)}': {err}") from None
    comment = inputs.yaml_comment(value)
    if comment is not None:
        raise InputError(f"{path}: {what} '{inputs.printable(item)}': a comment ('{inputs.printable(comment, 30)}') is "
                         f"not part of a value and would be dropped; give the value alone")
    return key.strip(), {"value": parsed, "source": source or f"inferred: {what} on the command line"}


def parse_overrides(items, path, what="override"):
    """{key: leaf} of 'key=value' strings (:func:`_parse`); a key given twice is refused (which one would win is
    not what the user meant to say)."""
    out = {}
    for item in items:
        key, leaf = _parse(item, path, what)
        if key in out:
            raise InputError(f"{path}: {what} field '{inputs.printable(key)}' is given twice; give it once")
        out[key] = leaf
    return out


def apply(settings, overrides, values, path, what="override"):
    """Set every override in place, checking key and value against ``values``.

    overrides: a list of 'key=value' strings (:func:`parse_overrides`), or a mapping {key: leaf or plain value}.
    """
    items = (overrides if isinstance(overrides, dict) else parse_overrides(overrides, path, what)).items()
    for key, item in items:
        if key not in values:
            raise InputError(f"{path}: {what} field '{inputs.printable(key)}': no such setting")
        entry = item if isinstance(item, dict) and set(item) == {"value", "source"} else \
            {"value": item, "source": f"inferred: {what}"}
        inputs.validate({key: entry}, {"type": "object", "properties": {key: leaf(values[key])}}, path)
        settings[key] = copy.deepcopy(entry["value"])
        settings.sources[key] = entry["source"]


def read(path, values, what="settings", extra=None):
    """The validated settings file as written (InputError naming the file and the field)."""
    return inputs.load(path, file_schema(values, extra), what)[1]


def plain(node):
    """The values of a settings mapping: every ``{value, source}`` leaf replaced by its value."""
    if isinstance(node, dict):
        return node["value"] if set(node) == {"value", "source"} else {k: plain(v) for k, v in node.items()}
    return [plain(v) for v in node] if isinstance(node, list) else node


def values_of(schema, leaves):
    """{dotted key: value schema} of the properties of a JSON schema (a mapping) at the dotted paths ``leaves``
    ('a.*': every property of a), local '$ref's inlined: the VALUES of a settings file whose values that schema
    describes (e.g. the ISA workflow's sections, workflow/schemas/)."""
    defs = schema.get("$defs", {})

    def inline(node):
        if isinstance(node, dict):
            if set(node) == {"$ref"} and node["$ref"].startswith("#/$defs/"):
                return inline(defs[node["$ref"].split("/")[-1]])
            return {k: inline(v) for k, v in node.items()}
        return [inline(v) for v in node] if isinstance(node, list) else node

    def at(path):
        node = schema
        for part in path.split(".") if path else []:
            node = inline(node)["properties"][part]
        return inline(node)

    out = {}
    for leaf in leaves:
        if leaf.endswith("*"):
            base = leaf[:-1].rstrip(".")
            out.update({f"{base}.{k}" if base else k: v for k, v in at(base)["properties"].items()})
        else:
            out[leaf] = at(leaf)
    return out


def read_values(path, values, what="settings"):
    """The plain values (:func:`plain`) of a settings file whose every value is sourced and which holds nothing
    else (no variants, resolutions or runs), read and checked by the one loader."""
    return plain(read(path, values, what))


def load(path, values, variant=None, resolution=None, overrides=(), what="settings", extra=None, spec=None):
    """Settings of a file for one variant and resolution, then overrides (see module docstring).

    values: {dotted key: JSON schema of the value}.  An unknown variant or
    resolution is refused naming the choices.
    """
    path = str(path)
    spec = spec if spec is not None else read(path, values, what, extra)
    leaves = flatten({k: v for k, v in spec.items() if k not in RESERVED and k not in (extra or {})})
    s = Settings({k: v["value"] for k, v in leaves.items()}, {k: v["source"] for k, v in leaves.items()},
                 path, spec, variant, resolution, values)
    for section, name in (("resolutions", resolution), ("variants", variant)):
        if name is None:
            continue
        if name not in spec.get(section, {}):
            raise InputError(f"{path}: field '{section}': no {section[:-1]} '{inputs.printable(str(name))}' "
                             f"(choose from {', '.join(spec[section])})")
        apply(s, spec[section][name]["set"], values, path, f"{section[:-1]} '{name}'")
    if overrides:
        apply(s, overrides, values, path)
    return s


def attribute(value):
    """One setting's value as a netCDF attribute: numbers and strings as they are, booleans as 0 / 1 (a CF
    flag), anything else (null, lists, mappings, an integer netCDF cannot hold) as JSON text."""
    value = value.item() if hasattr(value, "item") and not isinstance(value, (list, dict)) else value  # NumPy scalar
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, int) and -2**63 <= value < 2**63 or isinstance(value, (float, str)):
        return value
    return json.dumps(value, sort_keys=True, separators=(",", ":"))


def attributes(settings, derived=None):
    """The run-file naming rule: {dotted key: attribute} of every resolved setting, one attribute per key
    under the key's own name (``solver.du``, ``forces.wall.l_u``), plus ``settings_sources`` ("key: source"
    lines) and ``settings_units`` ("key: units" lines, the ``units`` of each value's schema in VALUES).

    derived: {dotted key: value} a method computed for a setting its file leaves null (ISA's ``solver.f_ref``);
    a derived value for a setting the file gives is refused unless equal (the method ran with another value).
    """
    derived = derived or {}
    schema = settings.schema or {}
    out, sources, units = {}, [], []
    for key in sorted(settings):
        value, source = settings[key], settings.sources.get(key, "")
        if key in derived:
            if value is not None and derived[key] != value:
                raise ValueError(f"{settings.path}: field '{key}': the method ran with {derived[key]!r}, the settings "
                                 f"say {value!r}")
            if value is None:
                value, source = derived[key], f"derived: computed by the method (the file leaves it null; {source})"
        out[key] = attribute(value)
        sources.append(f"{key}: {source}")
        if schema.get(key, {}).get("units"):
            units.append(f"{key}: {schema[key]['units']}")
    out.update(settings_sources="\n".join(sources), settings_units="\n".join(units))
    return out
