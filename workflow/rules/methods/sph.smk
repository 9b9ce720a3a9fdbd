# Weakly compressible SPH on the shared tank (single vessel, then the flow), figures, summary, claims,
# report fragment 50.  Package: src/isaflow/methods/sph/.  Every rule calls one package function
# through scripts/call.py.

SPH_CFG = "config/methods/sph.yaml"
_SPH = _inputs.read_yaml(SPH_CFG)[1]

SPH_VARIANTS = list(_SPH["variants"])
# resolution ids as isaflow.methods.sph.outputs.res_id names them: n<particles> or dx<spacing>
SPH_SINGLE, SPH_FLOW = (
    [f"n{r['particles']}" if "particles" in r else f"dx{r['spacing']:g}" for r in _SPH["runs"][case]]
    for case in ("single", "flow")
)
SPH_STAB = list(_SPH["runs"]["stability"])
SPH_CODE = code("methods/sph/__init__", "methods/sph/kernels", "methods/sph/eos", "methods/sph/repulsion",
                "methods/sph/particles", "methods/sph/settings", "methods/sph/solver", "methods/sph/outputs")
SPH_SINGLE_RUNS = [f"results/sph/single_wcsph_{r}.nc" for r in SPH_SINGLE]
SPH_FLOW_RUNS = [f"results/sph/flow_wcsph_{r}.nc" for r in SPH_FLOW]
SPH_RUNS = (
    SPH_SINGLE_RUNS
    # the delta-SPH variant costs about twice as much per step: all but the finest resolution
    + [f"results/sph/single_{v}_{r}.nc" for v in SPH_VARIANTS if v != "wcsph" for r in SPH_SINGLE[:-1]]
    + SPH_FLOW_RUNS
    + [f"results/sph/stab_{c}.nc" for c in SPH_STAB]
)
SPH_FIGURES = [f for name in ("sph_single", "sph_flow", "sph_flow_snapshots") for f in figure(name)]
SPH_REPORT_FIGURES = [f for name in ("sph_single", "sph_flow", "sph_flow_snapshots")
                      for f in report_figure(name, "sph_figure", "Methods compared")]

register(SPH_RUNS + ["results/sph/summary.csv"] + SPH_FIGURES, ["results/report/50_sph.md"], ["results/claims/sph.csv"],
         ["results/timing/50_sph.md"])


rule sph_single:
    input:
        cfg=SPH_CFG,
        tank="config/tanks/single.yaml",
        code=SPH_CODE,
    output:
        "results/sph/single_{variant}_{res}.nc",
    wildcard_constraints:
        variant="|".join(SPH_VARIANTS),
    params:
        func="methods.sph.outputs.run_case",
        kw=lambda wc: dict(case="single", variant=wc.variant, rid=wc.res),
    resources:
        runtime=30,
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/sph/single_{variant}_{res}.log",
    script:
        "../../scripts/call.py"


rule sph_flow:
    input:
        cfg=SPH_CFG,
        tank="config/tanks/flow_step50.yaml",
        start="results/sph/single_{variant}_{res}.nc",
        code=SPH_CODE,
    output:
        "results/sph/flow_{variant}_{res}.nc",
    wildcard_constraints:
        variant="|".join(SPH_VARIANTS),
    params:
        func="methods.sph.outputs.run_case",
        kw=lambda wc: dict(case="flow", variant=wc.variant, rid=wc.res),
    resources:
        runtime=30,
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/sph/flow_{variant}_{res}.log",
    script:
        "../../scripts/call.py"


rule sph_stability:
    input:
        cfg=SPH_CFG,
        tank="config/tanks/single.yaml",
        code=SPH_CODE,
    output:
        "results/sph/stab_{case}.nc",
    wildcard_constraints:
        case="|".join(SPH_STAB),
    params:
        func="methods.sph.outputs.run_case",
        kw=lambda wc: dict(case="stab", variant="wcsph", rid=wc.case),
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/sph/stab_{case}.log",
    script:
        "../../scripts/call.py"


rule sph_summary:
    input:
        runs=SPH_RUNS,
        code=SPH_CODE + code("metrics", "theory"),
    output:
        "results/sph/summary.csv",
    params:
        func="methods.sph.outputs.summary",
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/sph/summary.log",
    script:
        "../../scripts/call.py"


rule sph_figures:
    input:
        single_runs=SPH_SINGLE_RUNS,
        flow_runs=SPH_FLOW_RUNS,
        code=code("methods/sph/figures"),
    output:
        SPH_REPORT_FIGURES,
    params:
        func="methods.sph.figures.all_figures",
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/sph/figures.log",
    script:
        "../../scripts/call.py"


rule sph_report:
    input:
        summary="results/sph/summary.csv",
        code=code("methods/sph/report"),
    output:
        "results/claims/sph.csv",
        "results/report/50_sph.md",
        "results/timing/50_sph.md",
    params:
        func="methods.sph.report.write",
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/sph/report.log",
    script:
        "../../scripts/call.py"
