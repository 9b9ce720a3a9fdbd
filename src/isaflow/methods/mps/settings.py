"""MPS settings: config/methods/mps.yaml, validated by settings.schema.json.

Every value is stored as {value, source}; :func:`load` returns the values
flattened to ``group.key`` -> value and keeps the sources for the report.
"""

import copy
import json
from importlib import resources


from isaflow import inputs
from isaflow.inputs import InputError
from isaflow.inputs import InputError as SceneError

SCHEMA = json.loads(resources.files("isaflow.methods.mps").joinpath("settings.schema.json").read_text())
DEFAULT_PATH = "config/methods/mps.yaml"


class Settings(dict):
    """{'group.key': value}; ``sources`` {'group.key': source}; ``path`` the file."""

    def __init__(self, values, sources, path):
        super().__init__(values)
        self.sources = sources
        self.path = path

    def with_overrides(self, **kw):
        """Copy with values replaced (keys 'group.key'); KeyError for unknown keys."""
        new = Settings(copy.deepcopy(dict(self)), dict(self.sources), self.path)
        for k, v in kw.items():
            if k not in new:
                raise KeyError(f"unknown MPS setting '{k}'")
            new[k] = v
        return new


def load(path=DEFAULT_PATH, overrides=()):
    """Read and validate the settings; overrides 'group.key=value' (YAML value).

    Raises SceneError with one line naming the file and the field.
    """
    path = str(path)
    _, spec = inputs.read_yaml(path, "MPS settings")
    for item in overrides:
        key, sep, value = item.partition("=")
        group, _, name = key.strip().partition(".")
        if not sep or name not in spec.get(group, {}):
            raise SceneError(f"{path}: override '{inputs.printable(item)}': no field '{inputs.printable(key.strip())}'")
        try:
            spec[group][name]["value"] = inputs.parse_yaml(value)
        except InputError as err:
            raise SceneError(f"{path}: override '{inputs.printable(item)}': {err}") from None
    inputs.validate(spec, SCHEMA, path)
    values = {f"{g}.{k}": v["value"] for g, grp in spec.items() for k, v in grp.items()}
    sources = {f"{g}.{k}": v["source"] for g, grp in spec.items() for k, v in grp.items()}
    return Settings(values, sources, path)
