# Issue 11: MPS with three pressure source terms on the shared tank (single vessel, then the flow).
# Package: src/isaflow/methods/mps/.  Runs -> summary -> figures, claims, report fragment 55.
import yaml as _mps_yaml

MPS_CFG = "config/methods/mps.yaml"
with open(MPS_CFG) as _fh:
    _MPS = _mps_yaml.safe_load(_fh)
MPS_VARIANTS = ["standard", "hattori", "mixed"]
MPS_DX = {case: [f"{l0:.3g}" for l0 in _MPS["runs"][f"{case}_spacings"]["value"]] for case in ("single", "flow")}
MPS_CODE = [f"src/isaflow/methods/mps/{m}.py" for m in ("model", "boundary", "pressure", "solver", "settings", "outputs")]
MPS_RUNS = [f"results/mps/{case}_{v}_dx{dx}.nc" for case in ("single", "flow") for v in MPS_VARIANTS for dx in MPS_DX[case]]

register(MPS_RUNS + ["results/mps/summary.csv"] + figure("mps_wall_loads") + figure("mps_flow"),
         ["results/report/55_mps.md"], ["results/claims/mps.csv"])


rule mps_single:
    input:
        cfg=MPS_CFG,
        tank="config/tanks/single.yaml",
        code=MPS_CODE,
    output:
        "results/mps/single_{variant}_dx{dx}.nc",
    wildcard_constraints:
        variant="|".join(MPS_VARIANTS),
    log:
        "logs/mps/single_{variant}_dx{dx}.log",
    run:
        from isaflow.methods.mps.outputs import write_run

        write_run(input.cfg, "single", wildcards.variant, wildcards.dx, output[0], log[0])


rule mps_flow:
    input:
        cfg=MPS_CFG,
        tank="config/tanks/flow_step50.yaml",
        start="results/mps/single_{variant}_dx{dx}.nc",
        code=MPS_CODE,
    output:
        "results/mps/flow_{variant}_dx{dx}.nc",
    wildcard_constraints:
        variant="|".join(MPS_VARIANTS),
    log:
        "logs/mps/flow_{variant}_dx{dx}.log",
    run:
        from isaflow.methods.mps.outputs import write_run

        write_run(input.cfg, "flow", wildcards.variant, wildcards.dx, output[0], log[0], start=input.start)


rule mps_summary:
    input:
        runs=MPS_RUNS,
        code=MPS_CODE + code("metrics", "theory"),
    output:
        "results/mps/summary.csv",
    log:
        "logs/mps/summary.log",
    run:
        from isaflow.methods.mps.outputs import summary

        summary(input.runs, output[0])


rule mps_figures:
    input:
        runs=MPS_RUNS,
        code="src/isaflow/methods/mps/figures.py",
    output:
        loads=figure("mps_wall_loads"),
        flow=figure("mps_flow"),
    log:
        "logs/mps/figures.log",
    run:
        from isaflow.methods.mps import figures

        figures.wall_loads([r for r in input.runs if "/single_" in r], output.loads)
        figures.flow([f"results/mps/flow_{v}_dx{MPS_DX['flow'][-1]}.nc" for v in MPS_VARIANTS], output.flow)


rule mps_report:
    input:
        summary="results/mps/summary.csv",
        cfg=MPS_CFG,
        code="src/isaflow/methods/mps/report.py",
    output:
        claims="results/claims/mps.csv",
        report="results/report/55_mps.md",
    log:
        "logs/mps/report.log",
    run:
        from isaflow.methods.mps.report import write

        write(input.summary, input.cfg, output.claims, output.report)
