"""Report section: every inferred input, checked against the scenes."""

from pathlib import Path

import yaml

from . import write


def inferred_section(inferred, scenes, outputs):
    """Fragment listing every inferred input, checked against the scenes."""
    items = yaml.safe_load(Path(inferred).read_text())
    scenes = {Path(p).stem: yaml.safe_load(Path(p).read_text()) for p in scenes}
    text = ["## Inferred inputs", "", "Everything the paper leaves out, the reading we take and why "
            "(from `config/inferred.yaml`; scene values quoted from the scene files):", ""]
    for it in items:
        held = []
        for scene, fields in (it.get("where") or {}).items():
            for f in fields:
                node = scenes[scene]
                for k in f.split("."):
                    node = node[k]
                held.append(f"`{scene}.{f}` = {node}")
        text += [f"- **{it['name']}**: {it['value']}. {it['source'].strip()}" + (f" Scene values: {'; '.join(held)}." if held else "")]
    write(text, outputs[0])
