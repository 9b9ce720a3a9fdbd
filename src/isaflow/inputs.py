"""Every input file (scenes, tanks, method settings) is read and validated here, once.

:func:`read_yaml` refuses, with one line naming the file (and field where there
is one), anything that is not a small, plain YAML mapping: unreadable or
non-UTF-8 files, files over MAX_BYTES, empty or non-mapping documents,
several documents, anchors and aliases (no alias bombs), explicit tags,
duplicate keys, nesting deeper than MAX_DEPTH.  :func:`validate` checks a
mapping against a JSON schema whose ``integer`` means a YAML integer (19.0 is
refused, not truncated) and refuses NaN and infinite numbers anywhere.
"""

import math
from pathlib import Path

import jsonschema
import yaml

MAX_BYTES = 1_000_000
MAX_DEPTH = 32


class InputError(ValueError):
    """Invalid input: the message names the file and the offending field."""


class _StrictLoader(yaml.SafeLoader):
    """SafeLoader that refuses duplicate keys."""

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            if key in seen:
                raise InputError(f"duplicate key '{key}' (line {key_node.start_mark.line + 1})")
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


def _check_events(text):
    """Refuse anchors, aliases, explicit tags, several documents and deep nesting before building anything."""
    depth = docs = 0
    for ev in yaml.parse(text, Loader=yaml.SafeLoader):
        line = f"line {ev.start_mark.line + 1}"
        if isinstance(ev, yaml.AliasEvent) or getattr(ev, "anchor", None):
            raise InputError(f"anchors and aliases are not accepted ({line})")
        tag = getattr(ev, "tag", None)
        if tag is not None:
            implicit = ev.implicit
            if not (any(implicit) if isinstance(implicit, tuple) else implicit):
                raise InputError(f"explicit YAML tags are not accepted: '{tag}' ({line})")
        if isinstance(ev, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            depth += 1
            if depth > MAX_DEPTH:
                raise InputError(f"nesting deeper than {MAX_DEPTH} levels ({line})")
        elif isinstance(ev, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
            depth -= 1
        elif isinstance(ev, yaml.DocumentStartEvent):
            docs += 1
            if docs > 1:
                raise InputError(f"more than one YAML document ({line})")


def parse_yaml(text):
    """A YAML value from text under the rules above (InputError without the file name)."""
    try:
        _check_events(text)
        return yaml.load(text, Loader=_StrictLoader)  # noqa: S506 (a SafeLoader subclass)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" (line {mark.line + 1})" if mark else ""
        raise InputError(f"not valid YAML: {getattr(err, 'problem', None) or err}{where}") from None


def read_yaml(path, what="file"):
    """(text, mapping) of a YAML file; InputError naming the file otherwise."""
    path = str(path)
    p = Path(path)
    try:
        if not p.is_file():
            raise InputError(f"{path}: cannot read {what}: {'a directory' if p.is_dir() else 'no such file'}")
        if p.stat().st_size > MAX_BYTES:
            raise InputError(f"{path}: {what} is larger than {MAX_BYTES} bytes")
        text = p.read_bytes().decode("utf-8")
    except OSError as err:
        raise InputError(f"{path}: cannot read {what}: {err.strerror or err}") from None
    except UnicodeDecodeError:
        raise InputError(f"{path}: {what} is not UTF-8 text") from None
    try:
        spec = parse_yaml(text)
    except InputError as err:
        raise InputError(f"{path}: {err}") from None
    if not isinstance(spec, dict):
        raise InputError(f"{path}: field '(top level)': the {what} must be a mapping of fields, "
                         f"not {'an empty file' if spec is None else type(spec).__name__}")
    return text, spec


def _non_finite(node, where=()):
    """Dotted path of the first NaN or infinite number in a nested structure, or None."""
    if isinstance(node, float) and not math.isfinite(node):
        return ".".join(map(str, where)) or "(top level)"
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for k, v in items:
        found = _non_finite(v, (*where, k))
        if found:
            return found
    return None


_INTEGER = jsonschema.Draft202012Validator.TYPE_CHECKER.redefine(
    "integer", lambda _, x: isinstance(x, int) and not isinstance(x, bool))
Validator = jsonschema.validators.extend(jsonschema.Draft202012Validator, type_checker=_INTEGER)


def validate(spec, schema, path):
    """Check a mapping against a JSON schema; InputError naming the file and the first bad field."""
    bad = _non_finite(spec)
    if bad:
        raise InputError(f"{path}: field '{bad}': numbers must be finite (NaN and infinity are not accepted)")
    errors = sorted(Validator(schema).iter_errors(spec), key=lambda e: [str(p) for p in e.absolute_path])
    if errors:
        e = errors[0]
        where = ".".join(str(p) for p in e.absolute_path) or "(top level)"
        raise InputError(f"{path}: field '{where}': {e.message}")


def load(path, schema, what="file"):
    """(text, mapping) of a YAML file valid under schema; InputError naming the file and field otherwise."""
    text, spec = read_yaml(path, what)
    validate(spec, schema, str(path))
    return text, spec
