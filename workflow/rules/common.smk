# Config validation and input functions shared by all rules.
import glob
import os

from snakemake.utils import validate

from isaflow.plan import set_args
from isaflow.scene import load as load_scene

validate(config, "../schemas/config.schema.yaml")

RUNS = config["runs"]

# What each rules file contributes, read lazily by `rule all` and the report
# (input functions run after every file is included, so include order does
# not matter).  register(targets=[...]) adds files to the full target;
# register(report=[...]) adds report fragments results/report/NN_name.md
# (assembled in NN order); register(claims=[...]) adds claims-table CSVs
# (columns: paper, section, claim, measured, verdict, evidence); register(timing=[...])
# adds timing fragments results/timing/<part>.md, appended to docs/timing.md (everything
# that changes from run to run goes there, never into docs/replication.md).
TARGETS = {"targets": [], "report": [], "claims": [], "timing": []}


def register(targets=(), report=(), claims=(), timing=()):
    TARGETS["targets"].extend(targets)
    TARGETS["report"].extend(report)
    TARGETS["claims"].extend(claims)
    TARGETS["timing"].extend(timing)


def code(*patterns):
    """Package source files a rule depends on (globs under src/isaflow, without .py),
    so editing them reruns the rule."""
    return sorted({f for p in patterns for f in glob.glob(f"src/isaflow/{p}.py")})


# what an ISA run executes
SOLVER_CODE = code("core/*", "methods/__init__", "methods/isa/*", "contract", "scene", "runfile", "cli")
FIGURE_CODE = code("figures/*", "metrics", "theory", "methods/__init__", "methods/isa/__init__")


def figure(name):
    """PNG and PDF paths of a figure."""
    return [f"figures/{name}.png", f"figures/{name}.pdf"]


def report_file(path, caption, category):
    """path marked for the Snakemake report with the caption workflow/report/<caption>.rst."""
    # Snakemake resolves a caption against the directory of the rule file that calls this (rules/ or
    # rules/methods/), so give it the path from there
    rst = os.path.join(workflow.basedir, "workflow", "report", f"{caption}.rst")
    return report(path, caption=os.path.relpath(rst, str(workflow.current_basedir)), category=category)


def report_figure(name, caption, category):
    """figure(name) with the PNG marked for the Snakemake report."""
    png, pdf = figure(name)
    return [report_file(png, caption, category), pdf]


def run_file(run):
    return f"results/runs/{run}.nc"


def run_overrides(wildcards):
    return set_args(RUNS[wildcards.run].get("set", []))


def start_file(run):
    """The run file a run continues from (particles.from_run, after overrides), if any."""
    spec = load_scene(RUNS[run]["scene"], RUNS[run].get("set", [])).spec
    src = spec["particles"].get("from_run")
    return [src] if src else []


# runs whose metrics go into results/metrics.csv
METRIC_RUNS = list(RUNS)


CAL = config["calibration"]


def calibration_overrides(wc):
    """Scene overrides of one calibration point: k_b = kb, k_p = ratio kb."""
    scene = load_scene(RUNS[wc.run]["scene"])
    wall_l_u, _ = scene.law("wall")
    pair_l_u, _ = scene.law("pair")
    kb, ratio = float(wc.kb), float(wc.ratio)
    sets = [
        f"forces.wall.r_u={kb * wall_l_u}",
        f"forces.pair.r_u={kb * ratio * pair_l_u}",
        f"solver.variant={CAL['variant']}",
        f"solver.max_steps={CAL['max_steps']}",
        "solver.accept=[converged,cycle,step_limit]",
        "solver.history={}",
    ]
    return set_args(sets)
