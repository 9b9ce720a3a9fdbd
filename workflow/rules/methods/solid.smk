# Hooke's-law solid particles (marko2017 section 4): bar, shear, Hertz runs, figures, claims, report.
SOLID_CFG = "config/methods/solid.yaml"
SOLID_CASES = ["bar_tension", "bar_compression", "shear", "hertz", "hertz_dt15ns", "hertz_dt56ns"]
SOLID_RUNS = expand("results/solid/{case}_{variant}.nc", case=SOLID_CASES, variant=["paper", "hooke"])
SOLID_CODE = [f"src/isaflow/methods/solid/{m}.py" for m in ("kernels", "lattice", "solve", "cases", "settings", "outputs")]

SOLID_TARGETS = SOLID_RUNS + figure("solid_bar") + figure("solid_hertz")
register(SOLID_TARGETS, ["results/report/65_solid.md"], ["results/claims/solid.csv"])


rule solid_run:
    input:
        cfg=SOLID_CFG,
        code=SOLID_CODE,
    output:
        "results/solid/{case}_{variant}.nc",
    wildcard_constraints:
        case="|".join(SOLID_CASES),
        variant="paper|hooke",
    log:
        "logs/solid/{case}_{variant}.log",
    run:
        from isaflow.methods.solid.outputs import write_run

        write_run(input.cfg, wildcards.case, wildcards.variant, output[0], log[0])


rule solid_figures:
    input:
        cfg=SOLID_CFG,
        runs=SOLID_RUNS,
        code="src/isaflow/methods/solid/figures.py",
    output:
        bar=figure("solid_bar"),
        hertz=figure("solid_hertz"),
    log:
        "logs/solid/figures.log",
    run:
        from isaflow.methods.solid.figures import bar_and_hertz

        bar_and_hertz(input.cfg, "results/solid", output.bar, output.hertz, log[0])


rule solid_claims:
    input:
        cfg=SOLID_CFG,
        runs=SOLID_RUNS,
        code="src/isaflow/methods/solid/claims.py",
    output:
        claims="results/claims/solid.csv",
        report="results/report/65_solid.md",
    log:
        "logs/solid/claims.log",
    run:
        from isaflow.methods.solid.claims import claims_and_report

        claims_and_report(input.cfg, "results/solid", output.claims, output.report, log[0])
