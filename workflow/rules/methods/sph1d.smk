# The truncated SPH hydrostatic problem in 1D as a linear system (Merino-Alonso et al. 2020, abstract
# only).  Sweep -> tables (classified by the claims registry's rule) -> figures and report fragment 60; the
# claims are judged by the claims rule (claims.smk) from the sweep.  Package: src/isaflow/methods/sph1d/.
# Every rule calls one package function through scripts/call.py.

SPH1D_SETTINGS = "config/methods/sph1d.yaml"
SPH1D_CODE = code("methods/sph1d/*", "core/smoothing", "runfile")
SPH1D_REGISTRY = "config/claims/merino_alonso2020.yaml"  # the classification rule's numbers
SPH1D_FIGURES = [f for name in ("error_vs_n", "maps", "variants") for f in figure(f"sph1d_{name}")]

register(SPH1D_FIGURES + ["results/sph1d/summary.csv"], ["results/report/60_sph1d.md"],
         timing=["results/timing/60_sph1d.md"])


use rule call as sph1d_sweep with:
    input:
        settings_path=SPH1D_SETTINGS,
        code=SPH1D_CODE,
    output:
        "results/sph1d/sweep.nc",
    params:
        func="methods.sph1d.pipeline.run_sweep",
    resources:
        **SOLID,
    log:
        "logs/sph1d/sweep.log",


# the sweep at other values of two registry inputs (config/methods/sph1d.yaml resolutions; sensitivity only):
# n_window (to N = 8192), surface_placement (the top particle on the surface) and kernel_form (the 1D Wendland functions)
for _res in ("n8192", "surface_top", "wendland_1d"):

    rule:
        name:
            f"sph1d_sweep_{_res}"
        input:
            settings_path=SPH1D_SETTINGS,
            code=SPH1D_CODE,
        output:
            f"results/sph1d/sweep_{_res}.nc",
        params:
            func="methods.sph1d.pipeline.run_sweep",
            kw={"resolution": _res},
        conda:
            "../../envs/isaflow.yaml"
        message:
            JOB
        resources:
            mem_mb=1000,
            runtime=20,
        log:
            f"logs/sph1d/sweep_{_res}.log",
        script:
            "../../scripts/call.py"

    OTHER_RUN_FILES[f"sph1d:sweep_{_res}"] = f"results/sph1d/sweep_{_res}.nc"


use rule call as sph1d_cases with:
    input:
        sweep_nc="results/sph1d/sweep.nc",
        registry=SPH1D_REGISTRY,
        code=SPH1D_CODE,
    output:
        "results/sph1d/cases.csv",
        "results/sph1d/summary.csv",
    params:
        func="methods.sph1d.pipeline.make_cases",
    log:
        "logs/sph1d/cases.log",


use rule call as sph1d_figures with:
    input:
        settings_path=SPH1D_SETTINGS,
        sweep_nc="results/sph1d/sweep.nc",
        cases_csv="results/sph1d/cases.csv",
        surface_nc="results/sph1d/sweep_surface_top.nc",  # input surface_placement's other value (variants figure)
        registry=SPH1D_REGISTRY,
        code=SPH1D_CODE + code("figures/style"),
    output:
        SPH1D_FIGURES,
    params:
        func="methods.sph1d.pipeline.make_figures",
    log:
        "logs/sph1d/figures.log",


use rule call as sph1d_report with:
    input:
        settings_path=SPH1D_SETTINGS,
        sweep_nc="results/sph1d/sweep.nc",
        cases_csv="results/sph1d/cases.csv",
        summary_csv="results/sph1d/summary.csv",
        registry=SPH1D_REGISTRY,
        figure_files=SPH1D_FIGURES,
        code=SPH1D_CODE,
    output:
        "results/report/60_sph1d.md",
        "results/timing/60_sph1d.md",
    params:
        func="methods.sph1d.pipeline.make_report",
    log:
        "logs/sph1d/report.log",


# the sweep, read by the claims (claims.smk)
OTHER_RUN_FILES["sph1d:sweep"] = "results/sph1d/sweep.nc"
