"""Report section: every inferred input of every method, with its source, checked against the files.

config/inferred.yaml explains the paper's missing inputs (name, value, why) and names where each one
lives (``where: {method: [dotted keys]}`` in config/methods/<method>.yaml, ``resolutions.<name>.<key>``
inside a resolution, or ``tank:<name>: [field]`` in a tank file); the values quoted are read from those
files.  Then every ``{value, source}`` setting whose source starts with "inferred:" or "calibrated:" in
every method's settings file is listed, per method.
"""

from pathlib import Path

from ..inputs import read_yaml
from . import write


def leaves(node, prefix=""):
    """[(dotted path, value, source)] of every {value, source} entry under node."""
    out = []
    if isinstance(node, dict) and set(node) == {"value", "source"}:
        return [(prefix, node["value"], node["source"])]
    if isinstance(node, dict):
        for k, v in node.items():
            out += leaves(v, f"{prefix}.{k}" if prefix else k)
    return out


def _lookup(spec, key):
    """Value of a dotted key in a settings file (through resolutions.<name>.set for resolution keys)."""
    if key.startswith("resolutions."):
        _, name, rest = key.split(".", 2)
        return spec["resolutions"][name]["set"][rest]["value"]
    node = spec
    for k in key.split("."):
        node = node[k]
    return node["value"] if isinstance(node, dict) and "value" in node else node


def inferred_section(inferred, settings, outputs):
    """Fragment listing every inferred input: the paper's (config/inferred.yaml, values quoted from the files
    that hold them) and every method's inferred settings."""
    items = _items(inferred)
    files = {Path(p).stem: read_yaml(p)[1] for p in settings}
    text = ["## Inferred inputs", "",
            "Everything the papers leave out, the reading we take and why (`config/inferred.yaml`; values quoted "
            "from the files that hold them):", ""]
    for it in items:
        held = []
        for where, keys in (it.get("where") or {}).items():
            spec = read_yaml(f"config/tanks/{where[5:]}.yaml")[1] if where.startswith("tank:") else files[where]
            for key in keys:
                value = spec[key] if where.startswith("tank:") else _lookup(spec, key)
                held.append(f"`{where}: {key}` = {value}")
        text += [f"- **{it['name']}**: {it['value']}. {it['source'].strip()}" + (f" Values: {'; '.join(held)}." if held else "")]
    text += ["", "Every setting of every method whose source is an inference or a calibration "
             "(`config/methods/<method>.yaml`; `resolutions.<r>` / `variants.<v>` entries apply to that resolution "
             "or variant only):", ""]
    for name, spec in files.items():
        rows = [(k, v, s) for k, v, s in leaves(spec) if s.startswith(("inferred:", "calibrated:"))]
        if rows:
            text += [f"**{name}** ({len(rows)}):", ""]
            text += [f"- `{k}` = {v}: {s.split(':', 1)[1].strip()}" for k, v, s in rows]
            text.append("")
    write(text, outputs[0])


def _items(path):
    """The list of config/inferred.yaml (a YAML list, read by the hardened reader's parser)."""
    from ..inputs import parse_yaml

    return parse_yaml(Path(path).read_text())
