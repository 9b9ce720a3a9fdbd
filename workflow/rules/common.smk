# Shared by every rules file: the project's source on the path (the workflow parses with only
# Snakemake installed), every configuration file read through the project's hardened reader and
# checked against its schema before any job starts, the method registry, register(), the run
# declarations of every tank method, and the source files each rule depends on.
import csv
import functools
import glob
import os
import re
import sys
import time

sys.path.insert(0, os.path.join(workflow.basedir, "src"))

from isaflow import deps as _deps  # noqa: E402
from isaflow import derived as _derived  # noqa: E402
from isaflow import inputs as _inputs  # noqa: E402
from isaflow import methods as _methods  # noqa: E402
from isaflow import timing as _timing  # noqa: E402


def refuse(message):
    """Stop the workflow while it is parsed: one line naming the file and the field, exit status 2."""
    print(f"error: {message}", file=sys.stderr)
    raise SystemExit(2)


# Resources of the rules, documented in docs/cluster.md.  `threads` where a job uses more than one core; `resources:`
# mem_mb and runtime (minutes).  Runs (runs.smk): per run from its cost estimate (run_resources below,
# isaflow.budget.job_resources).  Every other rule: one of these classes, from measured job times (the
# start and end times Snakemake records, full runs on the shared 2-core machine) and peaks (the run jobs'
# benchmarks: 195-347 MB resident for the same interpreter, numpy, xarray and matplotlib):
#   SMALL  tables, figures, summaries, report fragments: at most 17 s measured
#   SOLID  the solid and 1D SPH computations (one core, numba): at most 48 s measured
#   CLAIMS the claims rule: opens every run file of every method (a few hundred small files)
#   BENCH  the step benchmark (2 threads, up to 1e6 particles at 253 B each: benchmarks/results/memory.csv;
#          80-109 s measured)
SMALL = {"mem_mb": 1000, "runtime": 5}
SOLID = {"mem_mb": 1000, "runtime": 10}
CLAIMS = {"mem_mb": 2000, "runtime": 15}
BENCH = {"mem_mb": 2000, "runtime": 15}
# the line each job prints when it starts (its rule and first output, so the wildcards)
JOB = "{rule}: {output[0]}"
RUN_RESOURCES = {}  # {(method, run id): {'mem_mb', 'runtime'}}, filled by check_inputs() from the estimates


def run_resources(members):
    """mem_mb and runtime of a job running members [(method, run id)] one after another, from their cost
    estimates (isaflow.budget.job_resources): the largest memory, the sum of the times."""
    res = [RUN_RESOURCES[m] for m in members if declaration(*m)]
    return {"mem_mb": max(r["mem_mb"] for r in res), "runtime": sum(r["runtime"] for r in res)}


def workflow_schema(schema):
    """A schema of workflow/schemas/ (a mapping), read by the hardened reader."""
    return _inputs.read_yaml(os.path.join(workflow.basedir, "workflow", "schemas", schema), "schema")[1]


def read_config(path, schema):
    """A configuration file read by the hardened reader and checked against a schema (workflow/schemas/)."""
    try:
        return _inputs.load(path, workflow_schema(schema), "workflow configuration")[1]
    except _inputs.InputError as err:
        refuse(err)


def read_sourced(path, schema, leaves):
    """The plain values of a workflow settings file in the settings dialect (every value {value, source}; the
    one loader, isaflow.settings): the schema (workflow/schemas/) gives the values at the dotted paths leaves."""
    from isaflow import settings as _settings

    try:
        return _settings.read_values(path, _settings.values_of(workflow_schema(schema), leaves), "workflow settings")
    except _inputs.InputError as err:
        refuse(err)


config.update(read_config("config/config.yaml", "config.schema.yaml"))
REGISTRY = _methods.registry()
TANK_METHODS = [name for name, m in REGISTRY.items() if m.tank]

# What each rules file contributes, read lazily by `rule all` and the report (input functions run
# after every file is included, so include order does not matter): targets; report fragments
# results/report/NN_name.md (assembled in NN order); timing fragments
# results/timing/NN_name.md (everything that changes from run to run goes there, never into
# docs/replication.md).
TARGETS = {"targets": [], "report": [], "timing": [], "bench": []}


def register(targets=(), report=(), timing=(), bench=()):
    """targets: outputs of the full run; report / timing: fragments of docs/replication.md / docs/timing.md;
    bench: outputs of the benchmarks (target `benchmarks`, docs/benchmarks.md from its .md fragments), which
    take the whole machine for minutes and are not part of the full run."""
    TARGETS["targets"].extend(targets)
    TARGETS["report"].extend(report)
    TARGETS["timing"].extend(timing)
    TARGETS["bench"].extend(bench)


def code(*modules):
    """Source files (src/isaflow/...) of the given modules and everything they import (isaflow.deps), so
    editing any of them reruns the rule.  A module is a dotted name ('isaflow.run', 'methods.isa.tables')
    or a path glob under src/isaflow without '.py' ('methods/sph/*')."""
    return list(_code(modules))


@functools.cache
def _code(modules):
    names = []
    for m in modules:
        if os.path.sep in m or "*" in m:
            names += [os.path.relpath(f, "src")[:-3].replace(os.sep, ".")
                      for f in sorted(glob.glob(f"src/isaflow/{m}.py"))]
        else:
            names.append(m)
    return tuple(_deps.closure(*names))


def func_code(func):
    """code() of the module of an isaflow function named as call.py names it ('module.function')."""
    return code(func.rsplit(".", 1)[0])


def settings_runs(method):
    """The runs section of a tank method's settings file (read by the one loader, refused on any error)."""
    from isaflow import settings as _settings

    m = REGISTRY[method]
    try:
        return _settings.read(m.settings, m.values_schema(), f"{method} settings").get("runs", {})
    except _inputs.InputError as err:
        refuse(err)


# Run declarations of every tank method: {method: {run id: {tank, variant, resolution, set, accept,
# start, threads, compare, label, meta}}} (isaflow.settings.RUN_SCHEMA): the runs section of each tank method's
# settings file, from the registry (a method needs no rules file to have its runs made); a rules file adds
# the runs it generates (e.g. ISA's study plan) with declare_runs(); the one rule `run` (runs.smk) makes them.
RUNS = {name: dict(settings_runs(name)) for name in TANK_METHODS}


def declare_runs(method, runs):
    for run_id, decl in runs.items():
        if run_id in RUNS[method]:
            refuse(f"{REGISTRY[method].settings}: field 'runs.{run_id}': run declared twice")
        RUNS[method][run_id] = decl


def run_file(method, run):
    return f"results/runs/{method}/{run}.nc"


def declaration(method, run):
    """The declaration of a run; a run no settings file declares (a target such as results/runs/<method>/<id>.nc
    asked for on the command line) is refused with one line while the jobs are planned, before any starts."""
    if run not in RUNS[method]:
        refuse(f"{REGISTRY[method].settings}: field 'runs': no {method} run '{_inputs.printable(run)}' is declared, "
               f"so nothing makes {_inputs.printable(run_file(method, run))}")
    return RUNS[method][run]


def run_job(method, run):
    """(method, run id, declaration + the paths isaflow.run reads: tank_file, settings_file, start_file)."""
    decl = dict(declaration(method, run), tank_file=f"config/tanks/{RUNS[method][run]['tank']}.yaml",
                settings_file=REGISTRY[method].settings)
    if decl.get("start"):
        decl["start_file"] = run_file(method, decl["start"])
    return method, run, decl


def runs_inputs(members):
    """Inputs of a job running members [(method, run id)]: tanks, settings, start files made by other jobs,
    the code, and each method's compiled kernels (the compile rule's stamp; ancient: a later compile reruns
    nothing)."""
    inside = set(members)
    out = {"tank": [], "settings": [], "start": [], "compiled": [],
           "code": code("isaflow.run", "isaflow.timing") + ["workflow/scripts/run.py"]}
    for method, run in members:
        decl = declaration(method, run)
        out["tank"].append(f"config/tanks/{decl['tank']}.yaml")
        out["settings"].append(REGISTRY[method].settings)
        out["code"] += code(REGISTRY[method].entry)
        out["compiled"].append(ancient(f"results/compiled/{method}.txt"))
        if decl.get("start") and (method, decl["start"]) not in inside:
            out["start"].append(run_file(method, decl["start"]))
    return {k: sorted(set(v), key=str) for k, v in out.items()}


def run_blocks():
    """{block id '<method>_<block>': [(method, run id)]} of every declared run with a `block`, each run after the
    run it continues; a block may not be both a run id's block and another method's unblocked run id."""
    blocks = {}
    for method in TANK_METHODS:
        for run, decl in RUNS[method].items():
            if decl.get("block"):
                blocks.setdefault(f"{method}_{decl['block']}", []).append((method, run))
    for bid, members in blocks.items():
        done, order = set(), []
        pending = list(members)
        while pending:
            ready = [mr for mr in pending
                     if not RUNS[mr[0]][mr[1]].get("start") or (mr[0], RUNS[mr[0]][mr[1]]["start"]) not in pending]
            if not ready:
                refuse(f"{REGISTRY[pending[0][0]].settings}: field 'runs.{pending[0][1]}.start': the runs of block "
                       f"'{bid}' continue each other in a circle")
            order += ready
            pending = [mr for mr in pending if mr not in ready]
        blocks[bid] = order
    unblocked = {run for m in TANK_METHODS for run, d in RUNS[m].items() if not d.get("block")}
    for bid, members in blocks.items():
        for method, run in members:
            if run in unblocked:
                refuse(f"{REGISTRY[method].settings}: field 'runs.{run}': in block '{bid}', and another method "
                       f"declares a run '{run}' outside any block (run ids must tell the rules apart)")
    return blocks


def runtime_runs():
    """Run files of the single-vessel runs a method adds to the error-against-run-time figure ('runtime: true')."""
    return [run_file(m, r) for m in TANK_METHODS for r, d in RUNS[m].items() if d.get("runtime")]


def first_run(method, tank):
    """Run file of a method's first declared compared run on a tank (declaration order)."""
    for run, d in RUNS[method].items():
        if d.get("compare") and d["tank"] == tank:
            return run_file(method, run)
    raise KeyError(f"method {method} declares no compared run on tank {tank}")


def compare_runs():
    """Run files of every run a tank method marks 'compare: true' on the comparison's tanks (config.yaml)."""
    tanks = set(config["compare"]["tanks"])
    return [run_file(m, r) for m in TANK_METHODS for r, d in RUNS[m].items() if d.get("compare") and d["tank"] in tanks]


# the runs the target `vtk` exports for ParaView (export.smk)
@functools.cache
def _vessel_count(tank):
    """Vessels of a tank of config/tanks/ (its file read by the project's reader; refused with one line)."""
    from isaflow import tank as _tank

    try:
        return len(_tank.load(_tank.path_of(tank)).spec.get("vessels", []))
    except _inputs.InputError as err:
        refuse(err)


def flow_runs():
    """(method, run id) of every compared run of a tank method on a tank of two or more vessels."""
    return [(m, r) for m in TANK_METHODS for r, d in RUNS[m].items() if d.get("compare") and _vessel_count(d["tank"]) > 1]


def vtk_file(method, run):
    return f"results/vtk/{method}/{run}/{run}.pvd"


def figure(name):
    """PNG and PDF paths of a figure."""
    return [f"figures/{name}.png", f"figures/{name}.pdf"]


def report_file(path, caption, category, subcategory=None):
    """path marked for the Snakemake report with the caption workflow/report/<caption>.rst."""
    # Snakemake resolves a caption against the directory of the rule file that calls this (rules/ or
    # rules/methods/), so give it the path from there
    rst = os.path.join(workflow.basedir, "workflow", "report", f"{caption}.rst")
    kw = {"subcategory": subcategory} if subcategory else {}
    return report(path, caption=os.path.relpath(rst, str(workflow.current_basedir)), category=category, **kw)


# The Snakemake report's figures: one caption per figure (workflow/report/figures.yaml) with the verdicts of the
# claims it bears on.  The report holds copies results/report/figures/<name>.png (rule report_figure_copy),
# made only by a run of this checkout, never the committed figures/<name>.png.
REPORT_FIGURES = read_config("workflow/report/figures.yaml", "report_figures.schema.yaml")


def with_report_copies(paths):
    """paths, then results/report/figures/<name>.<png|gif> of every figures/<name>.<png|gif> (a figure, an
    animation) among them that has a caption."""
    names = [os.path.basename(p) for p in paths if p.startswith("figures/") and p.endswith((".png", ".gif"))]
    return list(paths) + [f"results/report/figures/{n}" for n in names if n[:-4] in REPORT_FIGURES]


def _rst(text, limit=None):
    """text as plain reStructuredText (markup characters escaped), cut to limit characters."""
    text = " ".join(str(text).split())
    if limit and len(text) > limit:
        text = f"{text[: limit - 3].rstrip()}..."
    return "".join(f"\\{c}" if c in "\\`*_|[]<>:" else c for c in text)


@functools.cache
def _judged_claims(path):
    """{claim id: row} of a claims registry CSV, None if this checkout's run has not made it."""
    if not os.path.exists(path):
        return None
    with open(path, newline="") as f:
        return {r["id"]: r for r in csv.DictReader(f)}


def report_captions():
    """{figure: caption (reStructuredText)}: its text in figures.yaml, then the verdict of every claim it names,
    read from the claims registry this checkout's run made (results/claims/registry/<paper>.csv; read while
    the workflow is parsed, so `snakemake --report` after the run shows the run's verdicts)."""
    out = {}
    for name, spec in REPORT_FIGURES.items():
        lines = [" ".join(spec["caption"].split()), ""]
        for paper, ids in spec["claims"].items():
            path = f"results/claims/registry/{paper}.csv"
            rows = _judged_claims(path)
            if rows is None:
                lines += [f"Verdicts ({paper}): not made by this run ({path} comes from the claims rule).", ""]
                continue
            lines += [f"Verdicts ({paper}, {path}):", ""]
            for cid in ids:
                r = rows.get(cid)
                rob = f", {r['robustness']}" + (f" (flips at {r['flips']})" if r.get("flips") else "") if r else ""
                what = (f"{_rst(r['verdict'] + rob)}: {_rst(r['claim'], 160) or 'project check'}" if r
                        else "not in the registry")
                lines.append(f"- ``{cid}``: {what}")
            lines.append("")
        out[name] = "\n".join(lines)
    return out


config["report_captions"] = report_captions()


# the claims (claims.smk)
CLAIM_PAPERS = list(_methods.papers())
CLAIM_LABELS = _methods.papers()  # {paper id: label}
# run files outside the tank methods' runs, by '<method>:<run id>' (the solid and 1D methods register theirs)
OTHER_RUN_FILES = {}
# groups of runs, by '<method>:<group>' (ISA's study groups, calibration)
RUN_GROUPS = {}


# numbers the claims read that no solver writes (the registry files' `derived` entries, isaflow.derived; rule
# derived in claims.smk): each computed from the run file its entry names, read by the claims as a run file
def _derived_entries():
    from isaflow import claims_registry  # noqa: E402

    try:
        return claims_registry.derived()
    except _inputs.InputError as err:
        refuse(err)


DERIVED = _derived_entries()  # {'<method>:<name>': entry}


def _paper_run_keys():
    from isaflow import claims_registry  # noqa: E402

    try:
        return claims_registry.paper_runs()
    except _inputs.InputError as err:
        refuse(err)


PAPER_RUN_KEYS = _paper_run_keys()  # {paper: set of '<method>:<run>' its rows may read}
OTHER_RUN_FILES.update({k: _derived.path(k) for k in DERIVED})


def derived_inputs(wc):
    """The run file a derived number is computed from, the code, and (a tank method's) the kernels' compile stamp."""
    key = f"{wc.method}:{wc.name}"
    if key not in DERIVED:
        refuse(f"config/claims: field 'derived': no entry '{key}' (declared: {', '.join(DERIVED)})")
    entry = DERIVED[key]
    out = {"run": claim_runs()[entry["from"]], "code": func_code(entry["compute"]) + code("derived")}
    if wc.method in TANK_METHODS:
        out["compiled"] = ancient(f"results/compiled/{wc.method}.txt")
    return out


def claim_runs(wc=None):
    """{'<method>:<run>': path or [paths]} of every run any claim may read."""
    out = {f"{m}:{r}": run_file(m, r) for m in TANK_METHODS for r in RUNS[m]}
    out.update(OTHER_RUN_FILES)
    out.update(RUN_GROUPS)
    return out


def paper_claim_runs(wc):
    """The run files one paper's rows read (isaflow.claims_registry.paper_runs: their runs, checks, inputs' runs and
    the paper's version of each), as the claims job's inputs and its run mapping."""
    runs = claim_runs()
    keys = PAPER_RUN_KEYS[wc.paper]
    return {k: v for k, v in runs.items() if k in keys}


def paper_claim_files(wc):
    files = []
    for v in paper_claim_runs(wc).values():
        files += v if isinstance(v, list) else [v]
    return sorted(set(files))


def claim_inputs(wc):
    files = []
    for v in claim_runs().values():
        files += v if isinstance(v, list) else [v]
    return sorted(set(files))


def check_inputs():
    """Every input checked before any job starts (the Snakefile calls this after every rules file declared
    its runs): the comparison's tanks; every declared run of every tank method (tank, variant, resolution,
    overrides, start run, outcomes, plausibility, cost: isaflow.preflight); the settings of the methods
    without tanks (preflight.check_file); the run each derived number of the claims is computed from.  The first error stops the workflow with one line.  Each run's
    estimate then gives its job's mem_mb and runtime (RUN_RESOURCES, isaflow.budget.job_resources)."""
    from isaflow import budget as _budget
    from isaflow import preflight as _preflight

    d = _preflight.Declarations()
    try:
        check_cores(_budget)
        for name in config["compare"]["tanks"]:
            try:
                d.tank(name)
            except _inputs.InputError as err:
                raise _inputs.InputError(f"config/config.yaml: field 'compare.tanks': {err}") from None
        for method in TANK_METHODS:
            d.check(method, RUNS[method])
            # the comparison, the integration target and the solid floor under its liquid read its first one
            if not any(r.get("compare") and r["tank"] == "single" for r in RUNS[method].values()):
                raise _inputs.InputError(f"{REGISTRY[method].settings}: field 'runs': a tank method needs a run on "
                                         f"tank 'single' with compare: true (none declared)")
        for name, m in REGISTRY.items():
            if not m.tank:
                _preflight.check_file(name)
        runs = claim_runs()
        for key, entry in DERIVED.items():  # a derived number is computed from a run the workflow makes
            if entry["from"] not in runs:
                raise _inputs.InputError(f"{entry['_path']}: field '{entry['_where']}.from': '{entry['from']}' is no run "
                                         "of the workflow (a declared run '<method>:<run id>' or a product such as "
                                         "'sph1d:sweep')")
    except _inputs.InputError as err:
        refuse(err)
    RUN_RESOURCES.update({key: _budget.job_resources(cost) for key, cost in d.costs.items()})


def check_cores(budget):
    """Snakemake's --cores: a whole number, at least 1 (a job's threads are at most the cores, and each sets
    NUMBA_NUM_THREADS to its threads).  More than this machine has only oversubscribes it, so it is allowed (the
    integration profile asks for 2 on any machine)."""
    try:
        cores = workflow.cores
    except Exception:  # a cluster run given no --cores: each job's threads are its rule's
        return
    budget.check_threads("snakemake command line: field '--cores'", cores,
                         max(cores, budget.machine_cores()) if isinstance(cores, int) else None)


def workflow_timing(cores):
    """Where this Snakemake run's time went (isaflow.timing), from this process's start to now."""
    start, end = _timing.process_start(), time.time()
    jobs = _timing.read(start)
    if not jobs:
        return
    text = _timing.markdown(_timing.summary(jobs, start, end, cores))
    print(text, file=sys.stderr)
    os.makedirs("results/timing", exist_ok=True)
    with open("results/timing/workflow_run.md", "w") as f:
        f.write(text)
    if os.path.exists("docs/timing.md") and os.path.getmtime("docs/timing.md") >= start:
        with open("docs/timing.md", "a") as f:
            f.write(f"\n{text}")
