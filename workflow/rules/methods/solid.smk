# Hooke's-law solid particles (marko2017 section 4): bar, shear, Hertz runs, figures, claims, report
# fragment 65.  Package: src/isaflow/methods/solid/.  Every rule calls one package function through
# scripts/call.py.
SOLID_CFG = "config/methods/solid.yaml"
SOLID_CASES = ["bar_tension", "bar_compression", "shear", "hertz", "hertz_dt15ns", "hertz_dt56ns"]
SOLID_RUNS = expand("results/solid/{case}_{variant}.nc", case=SOLID_CASES, variant=["paper", "hooke"])
SOLID_CODE = code("methods/solid/kernels", "methods/solid/lattice", "methods/solid/solve", "methods/solid/cases",
                  "methods/solid/settings", "methods/solid/outputs")
SOLID_FIGURES = figure("solid_bar") + figure("solid_hertz")
SOLID_REPORT_FIGURES = [f for name in ("solid_bar", "solid_hertz") for f in report_figure(name, "solid_figure", "Methods compared")]

register(SOLID_RUNS + SOLID_FIGURES, ["results/report/65_solid.md"], ["results/claims/solid.csv"],
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
        runs=SOLID_RUNS,
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
