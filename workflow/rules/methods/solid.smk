# Hooke's-law solid particles (marko2017 section 4): bar, shear, Hertz runs, figures, claims, report
# fragment 65.  Package: src/isaflow/methods/solid/.  Every rule calls one package function through
# scripts/call.py.
SOLID_CFG = "config/methods/solid.yaml"
SOLID_CASES = ["bar_tension", "bar_compression", "shear", "hertz", "hertz_dt15ns", "hertz_dt56ns"]
SOLID_RUNS = expand("results/solid/{case}_{variant}.nc", case=SOLID_CASES, variant=["paper", "hooke"])
SOLID_CODE = code("methods/solid/kernels", "methods/solid/rotation", "methods/solid/lattice", "methods/solid/solve",
                  "methods/solid/cases", "methods/solid/settings", "methods/solid/outputs")
SOLID_FIGURES = figure("solid_bar") + figure("solid_hertz")
SOLID_REPORT_FIGURES = [f for name in ("solid_bar", "solid_hertz") for f in report_figure(name, "solid_figure", "Methods compared")]

# section 4.4 pressure vessel and the elastic floor of the single tank (one-way: loads from the first
# compared rigid-floor run of every tank method on the single tank, first_run in common.smk)
SOLID_FLOOR_LOADS = TANK_METHODS
SOLID_VESSEL_RUNS = ["results/solid/vessel_pressure_load.nc", "results/solid/vessel_water_particles.nc"]
SOLID_FLOOR_RUNS = ["results/solid/floor_uniform_uniform_load.nc"] + [
    f"results/solid/floor_{src}_oneway.nc" for src in SOLID_FLOOR_LOADS]
SOLID_NEW_RUNS = SOLID_VESSEL_RUNS + SOLID_FLOOR_RUNS
SOLID_NEW_CODE = SOLID_CODE + code("methods/solid/vessel", "methods/solid/water", "methods/solid/floor",
                                    "methods/solid/theory", "core/smoothing", "core/neighbours")
SOLID_FIGURES += figure("solid_vessel") + figure("solid_floor")
SOLID_REPORT_FIGURES_44 = [f for name in ("solid_vessel", "solid_floor")
                           for f in report_figure(name, "solid_figure", "Methods compared")]

register(SOLID_RUNS + SOLID_NEW_RUNS + SOLID_FIGURES, ["results/report/65_solid.md"], ["results/claims/solid.csv"],
         ["results/timing/65_solid.md"])


rule solid_run:
    input:
        cfg=SOLID_CFG,
        code=SOLID_CODE,
    output:
        "results/solid/{case}_{variant}.nc",
    wildcard_constraints:
        case="|".join(SOLID_CASES),
        variant="paper|hooke",
    params:
        func="methods.solid.outputs.run_case",
        kw=lambda wc: dict(case=wc.case, variant=wc.variant),
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/solid/{case}_{variant}.log",
    script:
        "../../scripts/call.py"


rule solid_vessel:
    input:
        cfg=SOLID_CFG,
        code=SOLID_NEW_CODE,
    output:
        "results/solid/vessel_{variant}.nc",
    wildcard_constraints:
        variant="pressure_load|water_particles",
    params:
        func="methods.solid.outputs.run_case",
        kw=lambda wc: dict(case="vessel", variant=wc.variant),
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/solid/vessel_{variant}.log",
    script:
        "../../scripts/call.py"


rule solid_floor_uniform:
    input:
        cfg=SOLID_CFG,
        code=SOLID_NEW_CODE,
    output:
        "results/solid/floor_uniform_uniform_load.nc",
    params:
        func="methods.solid.outputs.run_case",
        kw=dict(case="floor_uniform", variant="uniform_load"),
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/solid/floor_uniform_uniform_load.log",
    script:
        "../../scripts/call.py"


rule solid_floor_oneway:
    input:
        cfg=SOLID_CFG,
        loads=lambda wc: first_run(wc.src, "single"),
        code=SOLID_NEW_CODE,
    output:
        "results/solid/floor_{src}_oneway.nc",
    wildcard_constraints:
        src="|".join(SOLID_FLOOR_LOADS),
    params:
        func="methods.solid.outputs.run_case",
        kw=lambda wc: dict(case=f"floor_{wc.src}", variant="oneway"),
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/solid/floor_{src}_oneway.log",
    script:
        "../../scripts/call.py"


rule solid_figures_44:
    input:
        cfg=SOLID_CFG,
        runs=SOLID_NEW_RUNS,
        code=code("methods/solid/figures", "methods/solid/theory", "figures/style", "methods/__init__",
                  "methods/solid/__init__"),
    output:
        SOLID_REPORT_FIGURES_44,
    params:
        func="methods.solid.figures.vessel_and_floor",
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/solid/figures_44.log",
    script:
        "../../scripts/call.py"


rule solid_figures:
    input:
        cfg=SOLID_CFG,
        runs=SOLID_RUNS,
        code=code("methods/solid/figures", "methods/solid/theory", "figures/style"),
    output:
        SOLID_REPORT_FIGURES,
    params:
        func="methods.solid.figures.bar_and_hertz",
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/solid/figures.log",
    script:
        "../../scripts/call.py"


rule solid_claims:
    input:
        cfg=SOLID_CFG,
        runs=SOLID_RUNS + SOLID_NEW_RUNS,
        code=code("methods/solid/claims", "methods/solid/theory", "methods/solid/figures"),
    output:
        "results/claims/solid.csv",
        "results/report/65_solid.md",
        "results/timing/65_solid.md",
    params:
        func="methods.solid.claims.claims_and_report",
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/solid/claims.log",
    script:
        "../../scripts/call.py"


# the solid runs the claims read (claims.smk): 'solid:<case>_<variant>'
OTHER_RUN_FILES.update({f"solid:{os.path.splitext(os.path.basename(f))[0]}": f for f in SOLID_RUNS + SOLID_NEW_RUNS})
