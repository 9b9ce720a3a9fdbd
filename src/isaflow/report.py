"""docs/replication.md, assembled from fragments the workflow generates.

Each part of the workflow writes a Markdown fragment under results/report/;
:func:`assemble` joins them in name order under a generated header.  Nothing
in docs/replication.md is typed by hand.
"""

import datetime as dt
import subprocess
from pathlib import Path

import pandas as pd
import yaml

from .metrics import tolerances


def md_table(df):
    """Markdown table of a DataFrame (no index)."""
    cols = list(df.columns)
    out = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for _, r in df.iterrows():
        out.append("| " + " | ".join(_fmt(r[c]) for c in cols) + " |")
    return "\n".join(out)


def _fmt(v):
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def verdict(diff, tol, note=""):
    """'agrees' when |diff| <= tol, else 'differs' (with the note's reason)."""
    if diff is None or tol is None:
        return note or "n/a"
    ok = abs(diff) <= tol
    return ("agrees" if ok else "differs") + f" (tol {tol:.3g})" + (f"; {note}" if note and not ok else "")


def comparison(quantity, paper, ours, diff, tol=None, note=""):
    return {"quantity": quantity, "paper": paper, "ours": ours, "difference": diff if diff is not None else "",
            "verdict": verdict(diff, tol, note)}


def single_section(metrics, calibration, config, out):
    """Fragment for applications 1-2 (levels, steps, times, loads, calibration)."""
    cfg = yaml.safe_load(Path(config).read_text())
    m = pd.read_csv(metrics).set_index("run")
    rows = []
    tol_rows = []
    for base, paper in cfg["paper"].items():
        if base not in m.index:
            continue
        a = 10.0 if "coarse" in base else 5.0
        for run in [r for r in (base, f"{base}_capped") if r in m.index]:
            r = m.loc[run].to_dict()
            tol = tolerances(r, a, r["particles"], 0.1)
            tag = f"{base} [{r['variant']}]"
            rows.append(comparison(f"{tag} free-surface level (cm)", paper["level"], round(r["level"], 2),
                                   round(r["level"] - paper["level"], 2), tol["level"][0],
                                   "see calibration"))
            stop = "converged" if r["converged"] else f"{r['status']} (never < 0.1 N)"
            rows.append(comparison(f"{tag} steps to max|F| < 0.1 N", f"about {paper['steps']:,.0f}",
                                   f"{int(r['steps']):,} ({stop})", None,
                                   note="differs: literal update cannot converge, see Convergence" if not r["converged"]
                                   else f"{r['steps'] / paper['steps']:.1f}x the paper's steps"))
            rows.append(comparison(f"{tag} computing time (s)", paper["time_s"], f"{r['wall_time_s']:.3g}", None,
                                   note=f"{paper['time_s'] / max(r['wall_time_s'], 1e-9):.0f}x faster"))
            rows.append(comparison(f"{tag} final max|F| (N)", "< 0.1", f"{r['max_force_N']:.3g}",
                                   round(max(r["max_force_N"] - 0.1, 0.0), 3), 0.0, "literal update stalls in a cycle"))
            for key, label in (("floor", "floor total / W - 1"), ("side", "side walls total / (W h/2B) - 1")):
                val = r[f"{key}_err"]
                rows.append(comparison(f"{tag} {label}", "satisfactory (figure)", f"{val:+.3f}", round(val, 4),
                                       tol[key][0], "lattice is not a fluid: see Wall loads"))
            val = r["side_height_err"]
            rows.append(comparison(f"{tag} side resultant height - h/3 (cm)", "h/3 (theory)", f"{val:+.2f}",
                                   round(val, 2), tol["side_height"][0], "see Wall loads"))
            tol_rows += [{"run": run, "check": k, "tolerance": v[0], "derivation": v[1]} for k, v in tol.items()]
    cal = pd.read_csv(calibration)
    text = ["## Applications 1-2: single vessel (Figures 5-8)", "",
            "Paper value | ours | difference | verdict, for every number the paper states about the single "
            "vessel. `[paper]` rows run section 3.3 literally; `[capped]` rows run the named capped-step variant.", "",
            md_table(pd.DataFrame(rows)), "", "### Tolerances", "",
            "Derived from the discretisation before looking at results (`isaflow.metrics.tolerances`):", "",
            md_table(pd.DataFrame(tol_rows)), "", "### Calibration of the free-surface level", "",
            "Level of every calibration run (capped variant, `figures/calibration_free_surface.png`); "
            "`consistent` marks runs within a/4 of the paper's level:", ""]
    levels = {k: v["level"] for k, v in cfg["paper"].items()}
    cal["paper_level"] = [levels.get(s.removesuffix("_lbu25")) for s in cal["run"]]
    cal["consistent"] = [abs(l - p) <= (2.5 if "coarse" in s else 1.25) for s, l, p in
                         zip(cal["run"], cal["level"], cal["paper_level"])]
    text += [md_table(cal[["run", "k_wall", "ratio", "level", "level_max", "paper_level", "consistent", "status", "steps"]]), ""]
    both = _consistent_pairs(cal)
    text += ["(k_b, k_p/k_b) consistent with **both** reported levels (coarse 72.5 cm and refined 75 cm, "
             "same reading of the refined walls): " + (", ".join(both) if both else "none"), ""]
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    Path(out).write_text("\n".join(text) + "\n")


def _consistent_pairs(cal):
    out = []
    for ref in sorted({r for r in cal["run"] if "refined" in r}):
        c = cal[cal["run"] == "single_coarse"].set_index(["k_wall", "ratio"])["consistent"]
        f = cal[cal["run"] == ref].set_index(["k_wall", "ratio"])["consistent"]
        for key in c.index.intersection(f.index):
            if c[key] and f[key]:
                out.append(f"k_b = {key[0]:g} N/cm, k_p/k_b = {key[1]:g} (k_p = {key[0] * key[1]:g} N/cm) with {ref}")
    return out


def inferred_section(inferred_path, scene_paths, out):
    """Fragment listing every inferred input, checked against the scenes."""
    items = yaml.safe_load(Path(inferred_path).read_text())
    scenes = {Path(p).stem: yaml.safe_load(Path(p).read_text()) for p in scene_paths}
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
    Path(out).write_text("\n".join(text) + "\n")


def assemble(fragments, out):
    """Join fragments (name order) under a generated header into out."""
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    head = ["# Replication report: Papadopoulos, Koutitas & Lazaridis (2016)", "",
            f"Generated by the workflow (`snakemake -c2`) on {dt.date.today().isoformat()} at commit "
            f"{commit or 'unknown'}; do not edit by hand. Units: cm, N, s.", ""]
    body = [Path(f).read_text() for f in sorted(fragments, key=lambda p: Path(p).name)]
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    Path(out).write_text("\n".join(head + body))
