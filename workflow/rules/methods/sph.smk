# Issue 10: weakly compressible SPH on the shared tank (single vessel, then the flow), figures,
# summary, claims, report fragment 50.  Package: src/isaflow/methods/sph/.
import yaml as _sph_yaml

SPH_CFG = "config/methods/sph.yaml"
with open(SPH_CFG) as _fh:
    _SPH = _sph_yaml.safe_load(_fh)


def _sph_res(r):
    return f"n{r['particles']}" if "particles" in r else f"dx{r['spacing']:g}"


SPH_VARIANTS = list(_SPH["variants"])
SPH_SINGLE = [_sph_res(r) for r in _SPH["runs"]["single"]]
SPH_FLOW = [_sph_res(r) for r in _SPH["runs"]["flow"]]
SPH_STAB = list(_SPH["runs"]["stability"])
SPH_CODE = [f"src/isaflow/methods/sph/{m}.py" for m in ("__init__", "kernels", "particles", "settings", "solver", "outputs")]
SPH_RUNS = (
    [f"results/sph/single_wcsph_{r}.nc" for r in SPH_SINGLE]
    # the delta-SPH variant costs about twice as much per step: all but the finest resolution
    + [f"results/sph/single_{v}_{r}.nc" for v in SPH_VARIANTS if v != "wcsph" for r in SPH_SINGLE[:-1]]
    + [f"results/sph/flow_wcsph_{r}.nc" for r in SPH_FLOW]
    + [f"results/sph/stab_{c}.nc" for c in SPH_STAB]
)
SPH_FLOW_RUNS = [f"results/sph/flow_wcsph_{r}.nc" for r in SPH_FLOW]

register(
    SPH_RUNS + ["results/sph/summary.csv"] + figure("sph_single") + figure("sph_flow") + figure("sph_flow_snapshots"),
    ["results/report/50_sph.md"],
    ["results/claims/sph.csv"],
)


rule sph_single:
    input:
        cfg=SPH_CFG,
        tank="config/tanks/single.yaml",
        code=SPH_CODE,
    output:
        "results/sph/single_{variant}_{res}.nc",
    wildcard_constraints:
        variant="|".join(SPH_VARIANTS),
    log:
        "logs/sph/single_{variant}_{res}.log",
    run:
        from isaflow.methods.sph.outputs import write_run

        write_run(input.cfg, "single", wildcards.variant, wildcards.res, output[0], log[0])


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
    log:
        "logs/sph/flow_{variant}_{res}.log",
    run:
        from isaflow.methods.sph.outputs import write_run

        write_run(input.cfg, "flow", wildcards.variant, wildcards.res, output[0], log[0], start=input.start)


rule sph_stability:
    input:
        cfg=SPH_CFG,
        tank="config/tanks/single.yaml",
        code=SPH_CODE,
    output:
        "results/sph/stab_{case}.nc",
    wildcard_constraints:
        case="|".join(SPH_STAB),
    log:
        "logs/sph/stab_{case}.log",
    run:
        from isaflow.methods.sph.outputs import write_run

        write_run(input.cfg, "stab", "wcsph", wildcards.case, output[0], log[0])


rule sph_summary:
    input:
        runs=SPH_RUNS,
        code=SPH_CODE + code("metrics", "theory"),
    output:
        "results/sph/summary.csv",
    log:
        "logs/sph/summary.log",
    run:
        from isaflow.methods.sph.outputs import summary

        summary(input.runs, output[0])


rule sph_figures:
    input:
        runs=SPH_RUNS,
        code="src/isaflow/methods/sph/figures.py",
    output:
        single=figure("sph_single"),
        flow=figure("sph_flow"),
        snaps=figure("sph_flow_snapshots"),
    log:
        "logs/sph/figures.log",
    run:
        from isaflow.methods.sph import figures

        figures.single([f"results/sph/single_wcsph_{r}.nc" for r in SPH_SINGLE], output.single)
        figures.flow(SPH_FLOW_RUNS, output.flow)
        figures.snapshots(SPH_FLOW_RUNS[-1], output.snaps)


rule sph_report:
    input:
        summary="results/sph/summary.csv",
        code="src/isaflow/methods/sph/report.py",
    output:
        claims="results/claims/sph.csv",
        report="results/report/50_sph.md",
    log:
        "logs/sph/report.log",
    run:
        from isaflow.methods.sph.report import write

        write(input.summary, output.claims, output.report)
