# Hooke's-law solid particles (marko2017 section 4): bar, shear, Hertz runs, figures, claims, report
# fragment 65.  Package: src/isaflow/methods/solid/.  Every rule calls one package function through
# scripts/call.py.
import re

from isaflow.methods.solid import settings as _solid_settings

SOLID_CFG = "config/methods/solid.yaml"
SOLID_CASES = ["bar_tension", "bar_compression", "shear", "hertz", "hertz_dt15ns", "hertz_dt56ns"]
SOLID_RUNS = expand("results/solid/{case}_{variant}.nc", case=SOLID_CASES, variant=["paper", "hooke"])
SOLID_CODE = code("methods/solid/kernels", "methods/solid/rotation", "methods/solid/lattice", "methods/solid/solve",
                  "methods/solid/cases", "methods/solid/settings", "methods/solid/outputs")
SOLID_FIGURES_41_43 = figure("solid_bar") + figure("solid_hertz")

# section 4.4 pressure vessel and the elastic floor of the single tank (one-way: loads from the first
# compared rigid-floor run of every tank method on the single tank, first_run in common.smk)
SOLID_FLOOR_LOADS = TANK_METHODS
SOLID_VESSEL_RUNS = ["results/solid/vessel_pressure_load.nc", "results/solid/vessel_water_particles.nc"]
SOLID_FLOOR_RUNS = ["results/solid/floor_uniform_uniform_load.nc"] + [
    f"results/solid/floor_{src}_oneway.nc" for src in SOLID_FLOOR_LOADS]
SOLID_NEW_RUNS = SOLID_VESSEL_RUNS + SOLID_FLOOR_RUNS
SOLID_NEW_CODE = SOLID_CODE + code("methods/solid/vessel", "methods/solid/water", "methods/solid/floor",
                                    "methods/solid/theory", "core/smoothing", "core/neighbours")
SOLID_FIGURES_44 = figure("solid_vessel") + figure("solid_floor")
SOLID_FIGURES = SOLID_FIGURES_41_43 + SOLID_FIGURES_44

# runs the claims registry asks for (config/claims/marko2017.yaml): the 4.3 plate under disks of the other
# stated radii, stepped by eq. 27 undamped (capped by eq. 26 and not), the 4.1 bar held in sustained tension
# (the strain x step sweep of input tension_test_setup), the 4.4 vessel with water under the printed solid model
# (the project's mirror-pressure coupling, and the paper's stop-at-the-boundary coupling: vessel_water_stop_paper, also
# with the other waters of input vessel_water), the printed bar with axial-only grips, the printed plate at the other
# depths
SOLID_CLAIM_RUN_IDS = ["hertz_R50.8mm_paper", "hertz_R127mm_paper", "hertz_R20m_paper", "hertz_R50m_paper",
                       "hertz_eq27_paper", "hertz_eq27_hooke", "hertz_eq27_uncapped_paper", "bar_tension_long_paper",
                       "bar_tension_long_e0.1_dt0.1_paper", "bar_tension_long_e0.1_dt0.25_paper",
                       "bar_tension_long_e0.1_dt0.5_paper", "bar_tension_long_e1_dt0.1_paper",
                       "bar_tension_long_e1_dt0.5_paper", "bar_tension_long_e5_dt0.1_paper",
                       "bar_tension_long_e5_dt0.25_paper", "bar_tension_long_e5_dt0.5_paper",
                       "vessel_water_particles_paper", "vessel_water_stop_paper", "vessel_water_stop_h1_paper",
                       "vessel_water_stop_h1.5_paper", "vessel_water_stop_a0_paper", "vessel_water_stop_a0.1_paper",
                       "bar_tension_sliding_paper", "bar_compression_sliding_paper", "hertz_loadsteps_paper"]


# the list above is what the settings give (hertz.scale_radii_mm, the bar_long sweep): refuse the rule file otherwise
try:
    _claim_ids = _solid_settings.claim_run_ids(SOLID_CFG)
except _inputs.InputError as _err:
    refuse(_err)
if sorted(_claim_ids) != sorted(SOLID_CLAIM_RUN_IDS):
    refuse(f"{SOLID_CFG}: the runs of hertz.scale_radii_mm and the bar_long sweep are "
           f"{sorted(_claim_ids)}, workflow/rules/methods/solid.smk lists "
           f"{sorted(SOLID_CLAIM_RUN_IDS)}")
SOLID_CLAIM_RUNS = [f"results/solid/{r}.nc" for r in SOLID_CLAIM_RUN_IDS]
SOLID_CLAIM_CASES = sorted({r.rsplit("_", 1)[0] for r in SOLID_CLAIM_RUN_IDS})

register(SOLID_RUNS + SOLID_NEW_RUNS + SOLID_CLAIM_RUNS + SOLID_FIGURES, ["results/report/65_solid.md"],
         timing=["results/timing/65_solid.md"])


# every solid run without a liquid's loads (the bar, shear and Hertz cases, the pressure vessel, the uniformly
# loaded floor) solves in seconds: one job, one process, one compile of the solid's kernels
SOLID_BLOCK = [(os.path.basename(f)[:-3].rsplit("_", 1), f) for f in SOLID_RUNS + SOLID_CLAIM_RUNS] + [
    (["vessel", v], f"results/solid/vessel_{v}.nc") for v in ("pressure_load", "water_particles")] + [
    (["floor_uniform", "uniform_load"], "results/solid/floor_uniform_uniform_load.nc")]


use rule call as solid_cases with:
    input:
        cfg=SOLID_CFG,
        code=SOLID_NEW_CODE,
    output:
        [f for _, f in SOLID_BLOCK],
    params:
        func="methods.solid.outputs.run_cases",
        kw={"cases": [c for c, _ in SOLID_BLOCK]},
    message:
        f"solid_cases: {len(SOLID_BLOCK)} runs in one process"
    resources:
        mem_mb=SOLID["mem_mb"],
        runtime=SOLID["runtime"] * 4,
    log:
        "logs/solid/cases.log",


# the elastic floor under each tank method's liquid (its first compared single-vessel run): one job, after the
# solid cases' job has filled the solid's kernel cache (ancient: their dates do not matter)
use rule call as solid_floors_oneway with:
    input:
        cfg=SOLID_CFG,
        loads=lambda wc: [first_run(m, "single") for m in SOLID_FLOOR_LOADS],
        kernels=ancient(SOLID_BLOCK[0][1]),
        code=SOLID_NEW_CODE,
    output:
        [f"results/solid/floor_{src}_oneway.nc" for src in SOLID_FLOOR_LOADS],
    params:
        func="methods.solid.outputs.run_cases",
        kw={"cases": [[f"floor_{src}", "oneway"] for src in SOLID_FLOOR_LOADS]},
    message:
        f"solid_floors_oneway: {len(SOLID_FLOOR_LOADS)} runs in one process"
    resources:
        **SOLID,
    log:
        "logs/solid/floors_oneway.log",


use rule call as solid_figures_44 with:
    input:
        cfg=SOLID_CFG,
        runs=SOLID_NEW_RUNS,
        code=code("methods/solid/figures", "methods/solid/theory", "figures/style", "methods/__init__",
                  "methods/solid/__init__"),
    output:
        SOLID_FIGURES_44,
    params:
        func="methods.solid.figures.vessel_and_floor",
    log:
        "logs/solid/figures_44.log",


use rule call as solid_figures with:
    input:
        cfg=SOLID_CFG,
        runs=SOLID_RUNS,
        code=code("methods/solid/figures", "methods/solid/theory", "figures/style"),
    output:
        SOLID_FIGURES_41_43,
    params:
        func="methods.solid.figures.bar_and_hertz",
    log:
        "logs/solid/figures.log",


use rule call as solid_report with:
    input:
        runs=SOLID_RUNS + SOLID_NEW_RUNS + SOLID_CLAIM_RUNS,
        claims="results/claims/registry/marko2017.csv",
        registry=sorted(glob.glob("config/claims/*.yaml")),
        code=code("methods/solid/report"),
    output:
        "results/report/65_solid.md",
        "results/timing/65_solid.md",
    params:
        func="methods.solid.report.report",
    log:
        "logs/solid/report.log",


# the solid's step cost against its floor (the same per-link arithmetic fused in one loop) and the coupled
# vessel's step cost: target `benchmarks`, not the full run
rule solid_bench:
    input:
        script="benchmarks/bench_solid.py",
        cfg=SOLID_CFG,
        code=code("methods/solid/*"),
    output:
        "benchmarks/results/solid_step_cost.csv",
    message:
        JOB
    resources:
        **BENCH,
    log:
        "logs/solid/bench.log",
    conda:
        "../../envs/isaflow.yaml"
    params:
        src=os.path.join(workflow.basedir, "src"),  # this checkout's source (no install needed)
    shell:
        "PYTHONPATH={params.src} python {input.script} > {log} 2>&1"


register(bench=["benchmarks/results/solid_step_cost.csv"])


# the solid runs the claims read (claims.smk): 'solid:<case>_<variant>'
OTHER_RUN_FILES.update({f"solid:{os.path.splitext(os.path.basename(f))[0]}": f
                        for f in SOLID_RUNS + SOLID_NEW_RUNS + SOLID_CLAIM_RUNS})
