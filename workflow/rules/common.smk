# Config validation and input functions shared by all rules.
import glob

from snakemake.utils import validate

validate(config, "../schemas/config.schema.yaml")

RUNS = config["runs"]

# What each rules file contributes, read lazily by `rule all` and the report
# (input functions run after every file is included, so include order does
# not matter).  register(targets=[...]) adds files to the full target;
# register(report=[...]) adds report fragments results/report/NN_name.md
# (assembled in NN order); register(claims=[...]) adds claims-table CSVs
# (columns: paper, section, claim, measured, verdict, evidence).
TARGETS = {"targets": [], "report": [], "claims": []}


def register(targets=(), report=(), claims=()):
    TARGETS["targets"].extend(targets)
    TARGETS["report"].extend(report)
    TARGETS["claims"].extend(claims)


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


def run_file(run):
    return f"results/runs/{run}.nc"


def run_overrides(wildcards):
    return " ".join(f"--set '{s}'" for s in RUNS[wildcards.run].get("set", []))


def start_file(run):
    """The run file a run continues from (particles.from_run, after overrides), if any."""
    import yaml

    for item in RUNS[run].get("set", []):
        if item.startswith("particles.from_run="):
            return [item.split("=", 1)[1]]
    with open(RUNS[run]["scene"]) as fh:
        src = yaml.safe_load(fh).get("particles", {}).get("from_run")
    return [src] if src else []


def scene_law(scene_path, which):
    """(l_u cm, r_u N) of a scene's 'wall' or 'pair' force law."""
    import yaml

    with open(scene_path) as fh:
        law = yaml.safe_load(fh)["forces"][which]
    return law["l_u"], law["r_u"]


# runs whose metrics go into results/metrics.csv
METRIC_RUNS = list(RUNS)


CAL = config["calibration"]


def calibration_overrides(wc):
    """Scene overrides of one calibration point: k_b = kb, k_p = ratio kb."""
    scene = RUNS[wc.run]["scene"]
    wl_u, _ = scene_law(scene, "wall")
    pl_u, _ = scene_law(scene, "pair")
    kb, ratio = float(wc.kb), float(wc.ratio)
    sets = [
        f"forces.wall.r_u={kb * wl_u}",
        f"forces.pair.r_u={kb * ratio * pl_u}",
        f"solver.variant={CAL['variant']}",
        f"solver.max_steps={CAL['max_steps']}",
        "solver.accept=[converged,cycle,step_limit]",
        "solver.history={}",
    ]
    return " ".join(f"--set '{s}'" for s in sets)
