"""Every tank method on a tank of your own: ``isaflow compare TANK.yaml -o DIR``, and the workflow's target
``compare`` (``snakemake -c2 compare --config tank=TANK.yaml``: the same into results/compare/<tank name>/).

Each tank method of the registry (:func:`isaflow.methods.tank_methods`) runs on the tank as ``isaflow run``
runs it, one process per method (each binds its own kernel cache, isaflow.core.jit), with the variant and the
resolution of its first compared run on tank ``single`` (the run every tank method declares: its variant; the
level ``coarse`` takes that variant's first compared resolution there, ``refined`` its second, ``METHOD=NAME``
names one) and the overrides its settings module declares for a tank no settings file was written for
(``own_tank(tank, settings)`` beside its ``VALUES``: ISA's lattice then fills the tank's first vessel, SPH's
assumed largest fall fits the tank, MPS reads no pressure probes).  DIR then holds

- ``runs/<method>.nc``: each method's run file (isaflow.runfile);
- ``compare.csv``: the comparison table (tables.tank_table: a row per method and run, metrics.comparison_row with
  every wall's load against the tank's theory, and a row per method that could not run, with its reason);
- ``methods.png``, ``methods.pdf``: the methods figure (figures.methods.tanks_figure);
- ``report.md``: the tank and its theory, each method's command, outcome and times, the table and the figure.

A method that cannot run the tank (refused by its checks, or ending in an outcome no comparison accepts) says
why in one line and the others still run.  Bad input (a tank that does not load, an output directory that
cannot be written, an unknown resolution) is one line naming the file and the field, exit status 2, nothing
written.  Exit status 0 when at least one method ran, 1 when none did (the table and report say why), 130 / 143
when interrupted.  Units cm, N, s.
"""

import importlib
import os
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from . import inputs, methods, settings
from . import tank as tanks
from .inputs import InputError

LEVELS = ("coarse", "refined")  # the first and second compared resolution of a method on tank 'single'
ACCEPT = ("converged", "cycle", "step_limit")  # the outcomes a compared run may end in (the table shows which)
REFERENCE_TANK = "single"  # the tank on which every tank method declares a compared run (docs/architecture.md)


@dataclass
class Plan:
    """One method's run on the tank: its variant, resolution and overrides, or why it cannot run."""

    method: str
    variant: str = ""
    resolution: str = ""
    overrides: tuple = ()
    reason: str = ""  # non-empty: the method does not run (one line)
    out: str = ""
    command: list = field(default_factory=list)
    elapsed: float = float("nan")  # s, the method's process from start to exit (start-up, compile, solve, write)
    status: str = ""


def parse_resolution(values):
    """(level, {method: resolution}) of --resolution values: 'coarse' or 'refined' (every method), 'METHOD=NAME'
    (one method; the others at the level given, coarse by default).  InputError naming the argument."""
    level, picks = LEVELS[0], {}
    known = methods.tank_methods()
    for v in values or ():
        bad = inputs.bad_string(v)
        if bad:
            raise InputError(f"argument --resolution '{inputs.printable(v)}': {bad}")
        if "=" in v:
            name, res = (s.strip() for s in v.split("=", 1))
            if name not in known:
                raise InputError(f"argument --resolution '{inputs.printable(v)}': no tank method "
                                 f"'{inputs.printable(name)}' (choose from {', '.join(known)})")
            picks[name] = res
        elif v in LEVELS:
            level = v
        else:
            raise InputError(f"argument --resolution '{inputs.printable(v)}': choose {' or '.join(LEVELS)}, or "
                             f"METHOD=RESOLUTION")
    return level, picks


def own_tank_overrides(m, tank, variant, resolution):
    """The overrides ('key=value') a method's settings module declares for a tank no settings file was written for:
    its ``own_tank(tank, settings)`` beside its VALUES, given the run's resolved settings (none if it has none)."""
    module = importlib.import_module(m.values.split(":")[0])
    if not hasattr(module, "own_tank"):
        return ()
    s = settings.load(m.settings, m.values_schema(), variant, resolution, what=f"{m.name} settings")
    return tuple(module.own_tank(tank, s))


def plans(tank, level="coarse", picks=None):
    """[Plan] of every tank method (registry order) at a level, or the resolutions picks names
    ({method: resolution}); a method without a compared run on tank 'single' at that level gets its reason.
    InputError (naming the settings file) for a picked resolution the method does not declare."""
    picks = picks or {}
    out = []
    for name, m in methods.tank_methods().items():
        spec = settings.read(m.settings, m.values_schema(), f"{name} settings")
        ref = [d for d in spec.get("runs", {}).values() if d.get("compare") and d["tank"] == REFERENCE_TANK]
        if not ref:
            out.append(Plan(name, reason=f"{m.settings} declares no compared run on tank '{REFERENCE_TANK}' "
                                         f"(the run whose variant and resolutions a tank of yours takes)"))
            continue
        variant = ref[0]["variant"]
        levels = list(dict.fromkeys(d["resolution"] for d in ref if d["variant"] == variant))
        if name in picks:
            res = picks[name]
            if res not in spec.get("resolutions", {}):
                raise InputError(f"{m.settings}: field 'resolutions': no resolution '{inputs.printable(res)}' "
                                 f"(argument --resolution {name}={inputs.printable(res)}; choose from "
                                 f"{', '.join(spec.get('resolutions', {}))})")
        elif LEVELS.index(level) < len(levels):
            res = levels[LEVELS.index(level)]
        else:
            out.append(Plan(name, variant, reason=f"no {level} resolution: its compared runs of variant '{variant}' "
                                                  f"on tank '{REFERENCE_TANK}' use {', '.join(levels)} only"))
            continue
        out.append(Plan(name, variant, res, own_tank_overrides(m, tank, variant, res)))
    return out


def check_output_dir(out):
    """Refuse, before anything is written, an output directory that cannot be made or written (InputError)."""
    path = Path(out)
    if inputs.bad_string(str(out)):
        raise InputError(f"argument -o '{inputs.printable(str(out))}': {inputs.bad_string(str(out))}")
    if os.path.lexists(path) and not path.is_dir():
        raise InputError(f"{out}: field '-o': the output path exists and is not a directory")
    for anc in (path, *path.parents):
        if os.path.lexists(anc):
            if not anc.is_dir():
                raise InputError(f"{out}: field '-o': cannot create the output directory: '{anc}' is not a directory")
            if not os.access(anc, os.W_OK | os.X_OK):
                raise InputError(f"{out}: field '-o': cannot write the output directory: '{anc}' is not writable")
            return
    raise InputError(f"{out}: field '-o': cannot create the output directory")


def _child_env():
    """The environment of a method's process: this package's sources first on its path (the workflow's rules run
    the checkout's src/ without an install), the same numba cache folder."""
    env = dict(os.environ)
    src = str(Path(__file__).resolve().parents[1])
    env["PYTHONPATH"] = src + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    return env


def command(p, tank_path):
    """The ``isaflow run`` command line of a plan (the report shows it: each run can be made again alone)."""
    sets = [a for o in p.overrides for a in ("--set", o)]
    return ["isaflow", "run", "--method", p.method, "--tank", str(tank_path), "--variant", p.variant, "--resolution",
            p.resolution, *sets, "--accept", ",".join(ACCEPT), "--threads", "1", "-o", p.out]


def _run(p, tank_path, log):
    """Run one plan in its own process (python -m isaflow.cli run ...), its lines passed to log; sets p.status,
    p.reason (one line if it made no run file), p.elapsed.  Returns the child's exit status."""
    p.command = command(p, tank_path)
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "isaflow.cli", *p.command[1:]], stdin=subprocess.DEVNULL,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=_child_env())
    last_error, finished = "", ""
    try:
        for line in proc.stderr:
            line = line.rstrip("\n")
            log(f"  {line}")
            if line.startswith("error: "):
                last_error = line[len("error: "):]
            elif ": finished: " in line:
                finished = line.split(": finished: ", 1)[1]
                p.status = finished.split(":", 1)[0]
        code = proc.wait()
    except BaseException:
        proc.send_signal(signal.SIGTERM)
        proc.wait()
        raise
    p.elapsed = time.perf_counter() - t0
    if code != 0:
        p.reason = (f"its run ended '{p.status}' ({finished.split(':', 1)[1].strip()}), an outcome no comparison "
                    f"accepts" if code == 1 and finished else last_error or f"isaflow run exited with status {code}")
        p.status = p.status or ("refused" if code == 2 else "failed")
    return code


def compare(tank_path, out, resolution=("coarse",), log=None):
    """Run every tank method on the tank and write DIR (module docstring); returns the exit status."""
    log = log or (lambda msg: print(msg, file=sys.stderr, flush=True))
    try:
        tank = tanks.load(tank_path)
        check_output_dir(out)
        level, picks = parse_resolution(resolution)
        todo = plans(tank, level, picks)
    except InputError as err:
        log(f"error: {err}")
        return 2
    except OSError as err:
        log(f"error: {getattr(err, 'filename', None) or tank_path}: {err.strerror or err}")
        return 2
    out = Path(out)
    (out / "runs").mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    for p in todo:
        if p.reason:
            log(f"{p.method}: cannot run tank '{tank.name}': {p.reason}")
            continue
        p.out = str(out / "runs" / f"{p.method}.nc")
        Path(p.out).unlink(missing_ok=True)  # a run file of an earlier comparison in DIR never stands for this one
        log(f"{p.method}: variant {p.variant}, resolution {p.resolution}{' (' + ', '.join(p.overrides) + ')' if p.overrides else ''}")
        code = _run(p, tank_path, log)
        if code in (130, 143):
            log(f"error: {p.method}: interrupted; stopping")
            return code
        if code != 0:
            log(f"{p.method}: cannot run tank '{tank.name}': {p.reason}")
    total = time.perf_counter() - t0
    write_outputs(tank, todo, out, total)
    ran = [p for p in todo if not p.reason]
    log(f"compare: {len(ran)} of {len(todo)} methods ran on tank '{tank.name}' in {total:.1f} s; wrote "
        f"{out / 'compare.csv'}, {out / 'methods.png'}, {out / 'report.md'}")
    return 0 if ran else 1


def write_outputs(tank, todo, out, total):
    """compare.csv, methods.png / .pdf and report.md of the plans run (module docstring)."""
    from . import tables
    from .figures import methods as figure

    ran = [p for p in todo if not p.reason]
    csv = out / "compare.csv"
    df = tables.tank_table([p.out for p in ran], [csv], skipped={p.method: (p.status or "not run", p.reason)
                                                                  for p in todo if p.reason})
    pictures = [out / "methods.png", out / "methods.pdf"]
    for f in pictures:
        f.unlink(missing_ok=True)
    if ran:
        figure.tanks_figure(csv, pictures, tanks=[tank.name])
    report_page(tank, todo, df, out / "report.md", total, bool(ran))


def report_page(tank, todo, df, path, total, figure):
    """report.md: the tank and its theory, every wall's loads, the runs (command, outcome, times), the table, the
    figure."""
    import numpy as np
    import pandas as pd

    from .report import md_table, write
    from .report.methods import tank_table

    lines = [f"# Every method on tank `{tank.name}`", "",
             f"Tank file `{tank.path}`: {tank.spec.get('description', '').strip() or '(no description)'}", "",
             f"Liquid: W = {tank.weight:g} N per unit thickness, depth h = {tank.depth:g} cm above the first "
             f"vessel's floor (y = {tank.floor_y(0):g} cm), filling A = {tank.liquid_area:.6g} cm^2 of its polygon: "
             f"rho g = W / A = {tank.rho_g:.6g} N/cm^2.  Vessels: "
             + "; ".join(f"`{n}` x = [{a:g}, {b:g}] cm, floor y = {tank.floor_y(k):g} cm"
                         for k, (n, (a, b)) in enumerate(tank.vessels)) + ".", ""]
    runs = df[df["compare"].astype(bool)].reset_index(drop=True) if len(df) else df
    if len(runs):
        first, rows = runs.iloc[0], []
        for (x0, y0, x1, y1), w in zip(tank.walls_list(), tank.wall_names):
            for col in [c for c in df.columns if c.endswith(f"theory_{w}_N") and not c.endswith(f"_fx_{w}_N")
                        and not c.endswith(f"_fy_{w}_N")]:
                pre = col[: -len(f"theory_{w}_N")]
                if not first[col] > 0:
                    continue
                rows.append({"wall": w + (f" ({pre.rstrip('_')})" if pre else ""),
                             "from, to (cm)": f"({x0:g}, {y0:g}), ({x1:g}, {y1:g})",
                             "slope (deg)": float(np.degrees(np.arctan2(abs(y1 - y0), abs(x1 - x0)))),
                             "theory normal (N)": first[col], "Fx (N)": first[f"{pre}theory_fx_{w}_N"],
                             "Fy (N)": first[f"{pre}theory_fy_{w}_N"],
                             **{f"{r['method']} normal, magnitude (N)": f"{r[f'{pre}normal_{w}_N']:.4g}, "
                                                                         f"{r[f'{pre}load_{w}_N']:.4g}"
                                for _, r in runs.iterrows()}})
        lines += ["## The tank's theory and every method's wall loads", "",
                  "The hydrostatic theory of the tank's liquid at rest over the vessels' polygons (theory.rest_level, "
                  "theory.wall_total: a plane wall of slope theta wetted to depth h carries gamma h^2 / (2 sin theta) "
                  "normal to it; Fx, Fy: the liquid's force on the wall, theory.wall_force), against each method's "
                  "run: its contacts on the wall resolved on the wall's normal (metrics.normal_loads) and "
                  "their magnitudes (metrics.load_errors, which the errors below read; a discrete wall "
                  "may carry a tangential part). Wetted walls only.", "", md_table(pd.DataFrame(rows)), ""]
        t, levels, recv = tank_table(runs)
        lines += ["## Every method against the tank's theory", "",
                  f"The tank's liquid at rest: {levels}. The errors of the methods' comparison "
                  f"(metrics.comparison_row{', the ' + recv + ' vessel' if recv else ''}); every column, the weight the "
                  f"walls carry (`walls_weight_err`) and each wall's normal load (`wall_err_<wall>`) in `compare.csv`.",
                  "", md_table(t), ""]
    lines += ["## Runs", "",
              f"Each method in its own process (`isaflow run`, one thread): {total:.1f} s for all of them on this "
              f"machine (start-up, compilation where the kernel cache was empty, solving, writing); solver time "
              f"excludes compilation.", ""]
    for p in todo:
        if p.reason:
            lines += [f"- **{p.method}**: did not run: {p.reason}" + (f" (`{' '.join(p.command)}`)" if p.command else ""),
                      ""]
            continue
        r = runs[runs["method"] == p.method].iloc[0]
        ttr = r.get("time_to_rest_s", np.nan)
        lines += [f"- **{p.method}** ({p.variant}, {p.resolution}): {r['status']}, {int(r['particles'])} particles, "
                  f"solver {r['wall_time_s']:.3g} s, process {p.elapsed:.1f} s"
                  + (f", at rest from t = {ttr:.3g} s" if np.isfinite(ttr) else "")
                  + f"; `{' '.join(p.command)}`", ""]
    if figure:
        lines += ["## Figure", "", "![every method on this tank](methods.png)", ""]
    write(lines, path)


def workflow_tank(path):
    """(tank file, tank name) of the workflow's ``--config tank=TANK.yaml`` (None without one); InputError naming
    the file and the field if the tank does not load (the workflow refuses it while it is parsed)."""
    if not path:
        return None
    return str(path), tanks.load(str(path)).name


def run_tank(tank, outputs, resolution="coarse"):
    """The workflow's rule compare_tank: compare(tank, outputs[0]); InputError for bad input, RuntimeError if no
    method ran."""
    lines = []

    def log(msg):
        lines.append(msg)
        print(msg, file=sys.stderr, flush=True)

    code = compare(tank, outputs[0], [resolution] if isinstance(resolution, str) else list(resolution), log)
    if code == 2:
        raise InputError(next((m[len("error: "):] for m in lines if m.startswith("error: ")), "bad input"))
    if code != 0:
        raise RuntimeError(f"no method ran on tank {tank} (see {outputs[0]}/report.md)")
