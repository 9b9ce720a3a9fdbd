"""Every input file (tanks, method settings, the workflow's and the claims' files) is read and validated here, once.

:func:`read_yaml` refuses, with one line naming the file (and field where there
is one), anything that is not a small, plain YAML mapping: unreadable or
non-UTF-8 files, files over MAX_BYTES, empty or non-mapping documents,
several documents, anchors and aliases (no alias bombs), explicit tags,
duplicate keys, keys that are not plain names, nesting deeper than
MAX_DEPTH.  :func:`validate` checks a mapping against a JSON schema whose
``integer`` means a YAML integer (19.0 is refused, not truncated) and refuses
anywhere: NaN and infinite numbers, integers beyond 64 bits, strings with
control characters or lone surrogates or longer than MAX_STRING.
"""

import copy
import functools
import math
import re
from pathlib import Path

import jsonschema
import yaml

MAX_BYTES = 1_000_000
MAX_DEPTH = 32
MAX_STRING = 100_000  # characters of any one string value


class InputError(ValueError):
    """Invalid input: the message names the file and the offending field."""


class _Strict:
    """A safe loader that refuses duplicate keys."""

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            if not isinstance(key_node, yaml.ScalarNode):
                raise InputError(f"a mapping key must be a plain name (line {key_node.start_mark.line + 1})")
            key = self.construct_object(key_node, deep=deep)
            if not isinstance(key, str):
                raise InputError(f"mapping key {key!r} is not a name (line {key_node.start_mark.line + 1})")
            if key in seen:
                raise InputError(f"duplicate key '{key}' (line {key_node.start_mark.line + 1})")
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


class _StrictLoader(_Strict, yaml.SafeLoader):
    """The pure-Python reader: the reference, and the messages of every text libyaml refuses."""


# libyaml's parser where PyYAML was built with it (the wheels are): the same events and values 10-20x faster
# (0.44 s -> 0.04 s for config/methods/isa.yaml, which every run job reads); a text it refuses is read again by
# the pure-Python reader, whose message (or value: it reads a "\ud800" escape that libyaml refuses, and validate
# then names the field) is the one the user gets
_FastLoader = type("_FastLoader", (_Strict, yaml.CSafeLoader), {}) if hasattr(yaml, "CSafeLoader") else None

# YAML 1.2 reads 1e-12 and 1E6 as numbers; PyYAML (YAML 1.1) needs a dot ('1.0e-12') and reads them as
# strings, which a user typing `--set time.courant=1e-12` would not expect
for _loader in (_StrictLoader, _FastLoader):
    if _loader is not None:
        _loader.add_implicit_resolver(
            "tag:yaml.org,2002:float", re.compile(r"^[-+]?[0-9][0-9_]*[eE][-+]?[0-9]+$"), list("-+0123456789"))


# plain scalars YAML 1.1 (this reader, PyYAML) and YAML 1.2 read as different values: a leading-zero integer
# (octal in 1.1: 010 is 8), a base-60 number (1:30 is 90 in 1.1, a string in 1.2), the 1.1 booleans yes/no/on/off
_OCTAL = re.compile(r"[-+]?0[0-7_]+\Z")
_BASE60 = re.compile(r"[-+]?[0-9][0-9_]*(?::[0-5]?[0-9])+(?:\.[0-9_]*)?\Z")
_BOOL11 = {"yes", "no", "on", "off"}
_SUSPECT = re.compile(r"[-+]?0[0-7_]|[-+]?[0-9][0-9_]*:|(?i:yes|no|on|off)\Z")  # a quick first test of all three


def _ambiguous(value):
    """Why a plain scalar reads differently in YAML 1.1 and 1.2, or None."""
    if not _SUSPECT.match(value):
        return None
    if _OCTAL.match(value) and int(value.replace("_", ""), 8) != int(value.replace("_", ""), 10):
        return (f"'{value}' is the octal number {int(value.replace('_', ''), 8)} in YAML 1.1 (this reader) and "
                f"{int(value.replace('_', ''), 10)} in YAML 1.2; write it without leading zeros")
    if _BASE60.match(value):
        return f"'{value}' is a base-60 number in YAML 1.1 (this reader) and a string in YAML 1.2; quote it or write the number"
    if value.lower() in _BOOL11:
        return f"'{value}' is a boolean in YAML 1.1 (this reader) and a string in YAML 1.2; write true / false, or quote it"
    return None


def _check_events(text, loader):
    """Refuse anchors, aliases, explicit tags, several documents, deep nesting and plain scalars YAML 1.1 and 1.2
    read differently (_ambiguous) before building anything."""
    depth = docs = 0
    for ev in yaml.parse(text, Loader=loader):
        line = f"line {ev.start_mark.line + 1}"
        if ev.__class__ is yaml.ScalarEvent and not ev.style and ev.implicit[0] and _SUSPECT.match(ev.value):
            why = _ambiguous(ev.value)
            if why:
                raise InputError(f"{why} ({line})")
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
    """A YAML value from text under the rules above (InputError without the file name); a text parsed before
    (the settings files, read for every run a process plans) is parsed once and handed out as a fresh copy."""
    return copy.deepcopy(_parse_yaml(text))


@functools.lru_cache(maxsize=64)
def _parse_yaml(text):
    if _FastLoader is not None:
        try:
            _check_events(text, _FastLoader)
            return yaml.load(text, Loader=_FastLoader)
        except (yaml.YAMLError, UnicodeError):
            pass  # read again below
    try:
        _check_events(text, _StrictLoader)
        return yaml.load(text, Loader=_StrictLoader)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        if mark is not None:
            line = mark.line + 1
        elif isinstance(getattr(err, "position", None), int):  # reader errors: special characters
            line = text.count("\n", 0, err.position) + 1
        else:
            line = None
        why = getattr(err, "problem", None) or getattr(err, "reason", None) or str(err)
        if isinstance(err, yaml.reader.ReaderError):
            why = f"character {err.character!r} is not allowed in YAML"
        where = f" (line {line})" if line else ""
        raise InputError(f"not valid YAML: {' '.join(str(why).split())}{where}") from None


def yaml_comment(text):
    """The first YAML comment in text ('# ...' outside every scalar, at a line's start or after a blank), or None.
    A value typed with a comment (an override string, 'key=0.1 # why') would lose the comment silently."""
    if "#" not in text:
        return None
    try:
        spans = [(tok.start_mark.index, tok.end_mark.index) for tok in yaml.scan(text, Loader=yaml.SafeLoader)
                 if isinstance(tok, yaml.ScalarToken)]
    except yaml.YAMLError:
        return None  # not YAML: parse_yaml says so
    for m in re.finditer(r"(?:^|(?<=\s))#", text, re.M):
        if not any(a <= m.start() < b for a, b in spans):
            return text[m.start():].split("\n", 1)[0]
    return None


def not_a_file(path):
    """Why path is no regular file to read ('no such file', 'a directory', 'not a regular file'), or None."""
    p = Path(path)
    if p.is_file():
        return None
    return "a directory" if p.is_dir() else "not a regular file" if p.exists() else "no such file"


def read_text(path, what="file"):
    """The UTF-8 text of a file that may be read (a regular file of at most MAX_BYTES); InputError naming it
    otherwise."""
    path = str(path)
    p = Path(path)
    try:
        kind = not_a_file(p)
        if kind:
            raise InputError(f"{path}: cannot read {what}: {kind}")
        if p.stat().st_size > MAX_BYTES:
            raise InputError(f"{path}: {what} is larger than {MAX_BYTES} bytes")
        return p.read_bytes().decode("utf-8")
    except OSError as err:
        raise InputError(f"{path}: cannot read {what}: {err.strerror or err}") from None
    except UnicodeDecodeError:
        raise InputError(f"{path}: {what} is not UTF-8 text") from None


def _mapping(path, text, what):
    """The YAML mapping of a file's text; InputError naming the file otherwise."""
    try:
        spec = parse_yaml(text)
    except InputError as err:
        raise InputError(f"{path}: {err}") from None
    if not isinstance(spec, dict):
        raise InputError(f"{path}: field '(top level)': the {what} must be a mapping of fields, "
                         f"not {'an empty file' if spec is None else type(spec).__name__}")
    return spec


def read_yaml(path, what="file"):
    """(text, mapping) of a YAML file; InputError naming the file otherwise."""
    text = read_text(path, what)
    return text, _mapping(str(path), text, what)


def bad_string(text):
    """Why a string cannot be accepted (control characters, lone surrogates, over MAX_STRING), or None."""
    if len(text) > MAX_STRING:
        return f"text longer than {MAX_STRING} characters"
    if any((ord(c) < 32 and c not in "\t\n\r") or ord(c) == 127 for c in text):
        return "control characters are not accepted"
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return "text is not valid Unicode (lone surrogates or undecodable bytes)"
    return None


def printable(text, n=60):
    """A short, safe rendering of untrusted text for an error message."""
    r = repr(text)[1:-1]
    return r if len(r) <= n else r[:n] + "..."


def _bad_value(node, where=()):
    """(dotted path, reason) of the first non-finite or out-of-range number or bad string, or None."""
    here = ".".join(map(str, where)) or "(top level)"
    if isinstance(node, float) and not math.isfinite(node):
        return here, "numbers must be finite (NaN and infinity are not accepted)"
    if isinstance(node, int) and not isinstance(node, bool) and abs(node) >= 2**63:
        return here, "integer out of range (|value| >= 2^63)"
    if isinstance(node, str):
        bad = bad_string(node)
        return (here, bad) if bad else None
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for k, v in items:
        if isinstance(k, str) and bad_string(k):
            return here, f"field name '{printable(k)}': {bad_string(k)}"
        found = _bad_value(v, (*where, k))
        if found:
            return found
    return None


_INTEGER = jsonschema.Draft202012Validator.TYPE_CHECKER.redefine(
    "integer", lambda _, x: isinstance(x, int) and not isinstance(x, bool))
Validator = jsonschema.validators.extend(jsonschema.Draft202012Validator, type_checker=_INTEGER)


def validate(spec, schema, path):
    """Check a mapping against a JSON schema; InputError naming the file and the first bad field."""
    bad = _bad_value(spec)
    if bad:
        raise InputError(f"{path}: field '{printable(bad[0])}': {bad[1]}")
    errors = sorted(Validator(schema).iter_errors(spec), key=lambda e: [str(p) for p in e.absolute_path])
    if errors:
        e = errors[0]
        where = ".".join(str(p) for p in e.absolute_path) or "(top level)"
        raise InputError(f"{path}: field '{printable(where)}': {printable(e.message, 200)}")


# (path, text, id(schema)) -> (schema, mapping): each file's text parsed and checked once per process (the
# workflow's parse loads config/rest.yaml and config/limits.yaml once per declared run, ~470 times); the schema is
# kept so its id stays its own
_LOADED = {}


def load(path, schema, what="file"):
    """(text, mapping) of a YAML file valid under schema; InputError naming the file and field otherwise.  The file
    is read every time; text already parsed and checked under this schema object in this process is not parsed or
    checked again (the mapping returned is a copy: callers may change it)."""
    text = read_text(path, what)
    key = (str(path), text, id(schema))
    hit = _LOADED.get(key)
    if hit is None or hit[0] is not schema:
        spec = _mapping(str(path), text, what)
        validate(spec, schema, str(path))
        _LOADED[key] = hit = (schema, spec)
    return text, copy.deepcopy(hit[1])
