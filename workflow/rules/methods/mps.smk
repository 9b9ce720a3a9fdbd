# Issue 11: MPS with three pressure source terms on the shared tank (single vessel, then the flow),
# stiff and extreme cases.  Package: src/isaflow/methods/mps/.  Runs -> summary -> figures, claims,
# report fragment 55.  Every rule calls one package function through scripts/call.py.

MPS_CFG = "config/methods/mps.yaml"
_MPS = _inputs.read_yaml(MPS_CFG)[1]
MPS_VARIANTS = list(REGISTRY["mps"].variants)
MPS_STIFF = ["large_dt", "small_re", "no_relaxation", "on_wall"]
MPS_DX = {case: [f"{l0:.3g}" for l0 in _MPS["runs"][f"{case}_spacings"]["value"]] for case in ("single", "flow")}
MPS_CODE = code("methods/mps/model", "methods/mps/operators", "methods/mps/boundary", "methods/mps/pressure", "methods/mps/solver",
                "methods/mps/settings", "methods/mps/outputs")
MPS_SINGLE = [f"results/mps/single_{v}_dx{dx}.nc" for v in MPS_VARIANTS for dx in MPS_DX["single"]]
MPS_FLOW = [f"results/mps/flow_{v}_dx{dx}.nc" for v in MPS_VARIANTS for dx in MPS_DX["flow"]]
MPS_STIFF_RUNS = [f"results/mps/stiff_{c}.nc" for c in MPS_STIFF]
MPS_COURANTS = [f"{c:g}" for c in _MPS["dt_study"]["courants"]["value"]]
MPS_DT_RUNS = [f"results/mps/dt_standard_c{c}.nc" for c in MPS_COURANTS]
MPS_RUNS = MPS_SINGLE + MPS_FLOW + MPS_STIFF_RUNS + MPS_DT_RUNS

register(MPS_RUNS + ["results/mps/summary.csv"] + figure("mps_wall_loads") + figure("mps_flow") + figure("mps_rest"),
         ["results/report/55_mps.md"], ["results/claims/mps.csv"], ["results/timing/55_mps.md"])


rule mps_single:
    input:
        cfg=MPS_CFG,
        tank="config/tanks/single.yaml",
        code=MPS_CODE,
    output:
        "results/mps/single_{variant}_dx{dx}.nc",
    wildcard_constraints:
        variant="|".join(MPS_VARIANTS),
    params:
        func="methods.mps.outputs.run_case",
        kw=lambda wc: dict(case="single", variant=wc.variant, label=wc.dx),
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/mps/single_{variant}_dx{dx}.log",
    script:
        "../../scripts/call.py"


rule mps_flow:
    input:
        cfg=MPS_CFG,
        tank="config/tanks/flow_step50.yaml",
        code=MPS_CODE,
    output:
        "results/mps/flow_{variant}_dx{dx}.nc",
    wildcard_constraints:
        variant="|".join(MPS_VARIANTS),
    params:
        func="methods.mps.outputs.run_case",
        kw=lambda wc: dict(case="flow", variant=wc.variant, label=wc.dx),
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/mps/flow_{variant}_dx{dx}.log",
    script:
        "../../scripts/call.py"


rule mps_stiff:
    input:
        cfg=MPS_CFG,
        tank="config/tanks/single.yaml",
        code=MPS_CODE,
    output:
        "results/mps/stiff_{case}.nc",
    wildcard_constraints:
        case="|".join(MPS_STIFF),
    params:
        func="methods.mps.outputs.run_stiff",
        kw=lambda wc: dict(case=wc.case),
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/mps/stiff_{case}.log",
    script:
        "../../scripts/call.py"


rule mps_dt:
    input:
        cfg=MPS_CFG,
        tank="config/tanks/single.yaml",
        code=MPS_CODE,
    output:
        "results/mps/dt_standard_c{courant}.nc",
    wildcard_constraints:
        courant="|".join(MPS_COURANTS),
    params:
        func="methods.mps.outputs.run_dt",
        kw=lambda wc: dict(courant=wc.courant),
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/mps/dt_standard_c{courant}.log",
    script:
        "../../scripts/call.py"


rule mps_summary:
    input:
        runs=MPS_RUNS,
        code=MPS_CODE + code("metrics", "theory"),
    output:
        "results/mps/summary.csv",
    params:
        func="methods.mps.outputs.summary",
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/mps/summary.log",
    script:
        "../../scripts/call.py"


rule mps_figure_loads:
    input:
        runs=MPS_SINGLE,
        code=code("methods/mps/figures"),
    output:
        report_figure("mps_wall_loads", "mps_figure", "Methods compared"),
    params:
        func="methods.mps.figures.wall_loads",
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/mps/figure_loads.log",
    script:
        "../../scripts/call.py"


rule mps_figure_rest:
    input:
        runs=MPS_SINGLE,
        code=code("methods/mps/figures"),
    output:
        report_figure("mps_rest", "mps_figure", "Methods compared"),
    params:
        func="methods.mps.figures.rest",
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/mps/figure_rest.log",
    script:
        "../../scripts/call.py"


rule mps_figure_flow:
    input:
        runs=[f"results/mps/flow_{v}_dx{MPS_DX['flow'][-1]}.nc" for v in MPS_VARIANTS],
        code=code("methods/mps/figures"),
    output:
        report_figure("mps_flow", "mps_figure", "Methods compared"),
    params:
        func="methods.mps.figures.flow",
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/mps/figure_flow.log",
    script:
        "../../scripts/call.py"


rule mps_report:
    input:
        summary="results/mps/summary.csv",
        cfg=MPS_CFG,
        bench="benchmarks/results/mps_step_cost.csv",
        code=code("methods/mps/report"),
    output:
        claims="results/claims/mps.csv",
        report="results/report/55_mps.md",
        timing="results/timing/55_mps.md",
        table="docs/tables/mps_single.csv",
    params:
        func="methods.mps.report.write",
    conda:
        "../../envs/isaflow.yaml"
    log:
        "logs/mps/report.log",
    script:
        "../../scripts/call.py"
