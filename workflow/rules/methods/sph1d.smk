# Issue 12: the truncated SPH hydrostatic problem in 1D as a linear system
# (Merino-Alonso et al. 2020, abstract only).  Sweep -> tables -> figures,
# claims and report fragment 60.  Package: src/isaflow/methods/sph1d/.

SPH1D_SETTINGS = "config/methods/sph1d.yaml"
SPH1D_CODE = [f"src/isaflow/methods/sph1d/{m}.py" for m in
              ("__init__", "system", "column", "closed_form", "sweep", "settings", "pipeline")]
SPH1D_FIGURES = {name: figure(f"sph1d_{name}") for name in ("error_vs_n", "maps", "variants")}


rule sph1d_sweep:
    input:
        settings=SPH1D_SETTINGS,
        code=SPH1D_CODE + code("core/smoothing", "runfile"),
    output:
        sweep="results/sph1d/sweep.nc",
        cases="results/sph1d/cases.csv",
        summary="results/sph1d/summary.csv",
    log:
        "logs/sph1d/sweep.log",
    run:
        from isaflow.methods.sph1d import pipeline

        pipeline.run_sweep(input.settings, output.sweep, output.cases, output.summary, log[0])


rule sph1d_figures:
    input:
        settings=SPH1D_SETTINGS,
        sweep="results/sph1d/sweep.nc",
        cases="results/sph1d/cases.csv",
        code=SPH1D_CODE + ["src/isaflow/methods/sph1d/figures.py", "src/isaflow/figures/style.py"],
    output:
        [f for pair in SPH1D_FIGURES.values() for f in pair],
    log:
        "logs/sph1d/figures.log",
    run:
        from isaflow.methods.sph1d import pipeline

        pipeline.make_figures(input.settings, input.sweep, input.cases, SPH1D_FIGURES, log[0])


rule sph1d_report:
    input:
        settings=SPH1D_SETTINGS,
        sweep="results/sph1d/sweep.nc",
        cases="results/sph1d/cases.csv",
        summary="results/sph1d/summary.csv",
        figures=[f for pair in SPH1D_FIGURES.values() for f in pair],
        code=SPH1D_CODE + ["src/isaflow/methods/sph1d/report.py"],
    output:
        claims="results/claims/sph1d.csv",
        fragment="results/report/60_sph1d.md",
    log:
        "logs/sph1d/report.log",
    run:
        from isaflow.methods.sph1d import pipeline

        pipeline.make_report(input.settings, input.sweep, input.cases, input.summary,
                             output.claims, output.fragment, log[0])


SPH1D_TARGETS = [f for pair in SPH1D_FIGURES.values() for f in pair] + ["results/sph1d/summary.csv"]
register(targets=SPH1D_TARGETS + ["results/claims/sph1d.csv", "results/report/60_sph1d.md"])
register(report=["results/report/60_sph1d.md"], claims=["results/claims/sph1d.csv"])
