# ISA, the paper's method (Papadopoulos, Koutitas & Lazaridis 2016): its runs (config/methods/isa.yaml),
# the free-surface calibration, the error-against-run-time and stability study
# (config/methods/isa_study.yaml), Figures 5-10, Table 1, its claims, report fragments 10-30 and its
# timing fragment (config/methods/isa_workflow.yaml).  Package: src/isaflow/methods/isa/.  Runs go
# through the shared rule `run`; every other rule calls one package function through scripts/call.py.
from isaflow import settings as _isa_settings  # noqa: E402
from isaflow.methods.isa import plan as _isa_plan  # noqa: E402
from isaflow.methods.isa.settings import VALUES as _ISA_VALUES  # noqa: E402

ISA_SETTINGS = REGISTRY["isa"].settings
ISA_WORKFLOW_CFG = "config/methods/isa_workflow.yaml"
ISA_STUDY_CFG = "config/methods/isa_study.yaml"
try:
    _ISA_SPEC = _isa_settings.read(ISA_SETTINGS, _ISA_VALUES, "isa settings")
except _inputs.InputError as _err:
    refuse(_err)  # noqa: F821 (common.smk)
# every value of these two files is sourced ({value, source}, the settings dialect); the schemas give the values
ISA = read_sourced(ISA_WORKFLOW_CFG, "isa_workflow.schema.yaml", ["figures", "inferred", "overdamped", "fig10_sweeps",
                   "calibration", "paper", "flow", "table1", "speed_targets.*"])
STUDY = read_sourced(ISA_STUDY_CFG, "isa_study.schema.yaml", ["study.*"])["study"]
for _v in [ISA["calibration"]["variant"],
           *(v for b in STUDY["error_runtime"]["blocks"] for v in b["variants"]), *STUDY["stability_map"]["variants"]]:
    if _v not in REGISTRY["isa"].variants:
        refuse(f"{ISA_STUDY_CFG}: variant '{_v}': not a variant of method isa ({', '.join(REGISTRY['isa'].variants)})")
try:
    ISA_RUNS = _ISA_SPEC.get("runs", {})
    STUDY_RUNS = _isa_plan.plan(STUDY, _ISA_SPEC)
    CAL_RUNS = _isa_plan.calibration(ISA["calibration"], ISA_RUNS, _ISA_SPEC)
except (_inputs.InputError, KeyError) as _err:
    refuse(f"{ISA_STUDY_CFG}: {_err}")
for _sid in STUDY_RUNS:
    if STUDY_RUNS[_sid]["meta"]["group"] == "error_runtime":
        STUDY_RUNS[_sid]["runtime"] = True  # single-vessel points of the methods' error-against-run-time figure
declare_runs("isa", {**STUDY_RUNS, **CAL_RUNS})  # its settings file's runs are declared already (common.smk)
STUDY_META = _isa_plan.meta(STUDY_RUNS)
# groups of runs the claims read (claims.smk)
RUN_GROUPS.update({"isa:error_vs_runtime": _isa_plan.run_files(STUDY_RUNS, "error_runtime"),
                   "isa:stability_map": _isa_plan.run_files(STUDY_RUNS, "stability_map"),
                   "isa:cases": _isa_plan.run_files(STUDY_RUNS, "cases"),
                   "isa:fire_tuning": _isa_plan.run_files(STUDY_RUNS, "fire_tuning"),
                   "isa:calibration": [run_file("isa", r) for r in CAL_RUNS]})
CAL_FILES = [run_file("isa", r) for r in CAL_RUNS]
FIGS = ISA["figures"]
FLOW = ISA["flow"]
TABLE1_RUNS = sorted({run for row in ISA["table1"] for run in row["chain"]})


isa_file = lambda run: run_file("isa", run)  # noqa: E731
study_files = lambda group, **match: _isa_plan.run_files(STUDY_RUNS, group, **match)  # noqa: E731


use rule call as isa_metrics with:
    input:
        runs=[isa_file(r) for r in ISA_RUNS],
        code=code("methods.isa.tables"),
    output:
        "results/isa/metrics.csv",
    params:
        func="methods.isa.tables.metrics_table",
    log:
        "logs/isa/metrics.log",


use rule call as isa_calibration_table with:
    input:
        runs=CAL_FILES,
        code=code("methods.isa.tables"),
    output:
        "results/isa/calibration.csv",
    params:
        func="methods.isa.tables.calibration_table",
    log:
        "logs/isa/calibration_table.log",


use rule call as isa_fig_inputs with:
    input:
        inputs=lambda wc: [isa_file(FIGS[wc.name])],
        code=code("methods.isa.figures.single"),
    output:
        figure("{name}"),
    params:
        func="methods.isa.figures.single.inputs_figure",
        kw=lambda wc: {"inferred": ISA.get("inferred", {}).get(wc.name)},
    log:
        "logs/isa/figures/{name}.log",
    wildcard_constraints:
        name="fig05_inputs_coarse|fig07_inputs_refined",


use rule call as isa_fig_single with:
    input:
        inputs=lambda wc: [isa_file(FIGS[wc.name])],
        code=code("methods.isa.figures.single"),
    output:
        figure("{name}"),
    params:
        func="methods.isa.figures.single.single_vessel_figure",
        kw=lambda wc: {"paper_level": ISA["paper"][FIGS[wc.name].removesuffix("_capped")]["level"],
                       "inferred": ISA.get("inferred", {}).get(wc.name)},
    log:
        "logs/isa/figures/{name}.log",
    wildcard_constraints:
        name="fig06_single_coarse|fig08_single_refined",


use rule call as isa_fig_calibration with:
    input:
        inputs=CAL_FILES,
        code=code("methods.isa.figures.single"),
    output:
        figure("calibration_free_surface"),
    params:
        func="methods.isa.figures.single.calibration_figure",
        kw={"paper_levels": {k: v["level"] for k, v in ISA["paper"].items()}, "adopted": ISA["calibration"]["adopted"]},
    log:
        "logs/isa/figures/calibration_free_surface.log",


use rule call as isa_fig_convergence with:
    input:
        inputs=[isa_file(r) for r in ["single_coarse", "single_coarse_capped", "single_coarse_paper", "single_refined",
                                      "single_refined_capped", "single_refined_paper"]],
        code=code("methods.isa.figures.single"),
    output:
        figure("convergence_single"),
    params:
        func="methods.isa.figures.single.convergence_figure",
    log:
        "logs/isa/figures/convergence_single.log",


use rule call as isa_fig_flow with:
    input:
        inputs=lambda wc: [isa_file(FIGS[wc.name])],
        code=code("methods.isa.figures.flow"),
    output:
        figure("{name}"),
    params:
        func=lambda wc: {
            "fig09_flow_incomplete": "methods.isa.figures.flow.flow_incomplete_figure",
            "fig10_flow_complete": "methods.isa.figures.flow.flow_complete_figure",
        }[wc.name],
        kw=lambda wc: {"paper": FLOW["paper"], "inferred": ISA.get("inferred", {}).get(wc.name)},
    log:
        "logs/isa/figures/{name}.log",
    wildcard_constraints:
        name="fig09_flow_incomplete|fig10_flow_complete",


_FIG10_SWEEPS = ISA.get("fig10_sweeps", {})  # Figure 10 across an inferred input: fig10_<name>


for _name, _sweep in _FIG10_SWEEPS.items():

    rule:
        name:
            f"isa_fig10_{_name}"
        input:
            inputs=[isa_file(r[k]) for r in _sweep["runs"] for k in ("complete", "incomplete")],
            registry=sorted(glob.glob("config/claims/*.yaml")),
            code=code("methods.isa.figures.flow"),
        output:
            figure(f"fig10_{_name}"),
        params:
            func="methods.isa.figures.flow.fig10_sweep_figure",
            kw={"sweep": _sweep, "inferred": ISA.get("inferred", {}).get(f"fig10_{_name}")},
        message:
            JOB
        resources:
            **SMALL,
        log:
            f"logs/isa/figures/fig10_{_name}.log",
        conda:
            "../../envs/isaflow.yaml"
        script:
            "../../scripts/call.py"


_OD = ISA.get("overdamped", {})
OD_RUNS = [*_OD.get("isa_chain", []), _OD.get("single"), *_OD.get("flows", []), *_OD.get("singles", [])] if _OD else []


use rule call as isa_fig_overdamped with:
    input:
        inputs=[isa_file(r) for r in OD_RUNS],
        code=code("methods.isa.figures.damping"),
    output:
        figure("isa_overdamped"),
    params:
        func="methods.isa.figures.damping.overdamped_figure",
        kw={**_OD, "inferred": ISA.get("inferred", {}).get("isa_overdamped")},
    log:
        "logs/isa/figures/isa_overdamped.log",


use rule call as isa_fig_flow_history with:
    input:
        inputs=sorted({isa_file(r) for chain in FLOW["chains"].values() for r in chain}),
        code=code("methods.isa.figures.flow"),
    output:
        figure("flow_history"),
    params:
        func="methods.isa.figures.flow.flow_history_figure",
        kw={"chains": FLOW["chains"]},
    log:
        "logs/isa/figures/flow_history.log",


# the paper's coarse flow as an animation: the stored states of its flow runs (the chain without its single vessel)
use rule call as isa_flow_animation with:
    input:
        runs=[isa_file(r) for r in FLOW["chains"]["coarse"][1:]],
        code=code("figures.animation"),
    output:
        "figures/isa_flow_animation.gif",
    params:
        func="figures.animation.flow_animation",
    log:
        "logs/isa/figures/flow_animation.log",


use rule call as isa_table1 with:
    input:
        runs=[isa_file(r) for r in TABLE1_RUNS],
        benchmarks=[f"results/benchmarks/runs/isa/{r}.tsv" for r in TABLE1_RUNS],
        code=code("methods.isa.tables"),
    output:
        "results/isa/table1.csv",
        "results/isa/table1.md",
    params:
        func="methods.isa.tables.write_table1",
        kw={"rows": ISA["table1"]},
    log:
        "logs/isa/table1.log",


use rule call as isa_study_error_table with:
    input:
        runs=study_files("error_runtime"),
        code=code("methods.isa.tables"),
    output:
        "results/isa/study/error_vs_runtime.csv",
    params:
        func="methods.isa.tables.error_table",
        kw={"meta": STUDY_META, "paper": ISA["paper"]},
    log:
        "logs/isa/study/error_table.log",


use rule call as isa_study_fire_tables with:
    input:
        tuning=study_files("fire_tuning"),
        references=[f for lat in STUDY["fire_tuning"]["lattices"] for var in ("capped", "paper")
                    for f in study_files("error_runtime", lattice=lat, variant=var, du_factor=1)],
        code=code("methods.isa.tables"),
    output:
        "results/isa/study/fire_tuning.csv",
        "results/isa/study/fire_ratio.csv",
    params:
        func="methods.isa.tables.fire_tables",
        kw={"meta": STUDY_META, "paper": ISA["paper"], "required_ratio": STUDY["fire_tuning"]["required_ratio"]},
    log:
        "logs/isa/study/fire_tables.log",


use rule call as isa_study_map_table with:
    input:
        runs=study_files("stability_map"),
        code=code("methods.isa.tables"),
    output:
        "results/isa/study/stability_map.csv",
    params:
        func="methods.isa.tables.map_table",
        kw={"meta": STUDY_META},
    log:
        "logs/isa/study/map_table.log",


use rule call as isa_study_cases_table with:
    input:
        runs=study_files("cases"),
        code=code("methods.isa.tables"),
    output:
        "results/isa/study/stability_cases.csv",
    params:
        func="methods.isa.tables.cases_table",
        kw={"meta": STUDY_META},
    log:
        "logs/isa/study/cases_table.log",


use rule call as isa_fig_error_vs_runtime with:
    input:
        inputs=["results/isa/study/error_vs_runtime.csv"],
        code=code("methods.isa.figures.study"),
    output:
        figure("{name}"),
    params:
        func="methods.isa.figures.study.error_vs_runtime_figure",
        kw=lambda wc: {"x": {"error_vs_runtime": "wall_time_s", "error_vs_work": "particle_steps"}[wc.name]},
    log:
        "logs/isa/figures/{name}.log",
    wildcard_constraints:
        name="error_vs_runtime|error_vs_work",


use rule call as isa_fig_stability_map with:
    input:
        inputs=["results/isa/study/stability_map.csv", "results/isa/study/stability_cases.csv"],
        code=code("methods.isa.figures.study"),
    output:
        figure("stability_map"),
    params:
        func="methods.isa.figures.study.stability_map_figure",
    log:
        "logs/isa/figures/stability_map.log",


use rule call as isa_report_findings with:
    input:
        metrics="results/isa/metrics.csv",
        calibration="results/isa/calibration.csv",
        code=code("methods.isa.report.findings"),
    output:
        "results/report/findings.md",
    params:
        func="methods.isa.report.findings.findings_file",
    log:
        "logs/isa/report/findings.log",


use rule call as isa_report_single with:
    input:
        metrics="results/isa/metrics.csv",
        calibration="results/isa/calibration.csv",
        config=ISA_WORKFLOW_CFG,
        code=code("methods.isa.report.single"),
    output:
        "results/report/10_single.md",
        "docs/tables/single_tolerances.csv",
        "docs/tables/calibration.csv",
    params:
        func="methods.isa.report.single.single_section",
    log:
        "logs/isa/report/single.log",


use rule call as isa_report_flow with:
    input:
        metrics="results/isa/metrics.csv",
        config=ISA_WORKFLOW_CFG,
        code=code("methods.isa.report.flow"),
    output:
        "results/report/20_flow.md",
    params:
        func="methods.isa.report.flow.flow_section",
    log:
        "logs/isa/report/flow.log",


use rule call as isa_report_study with:
    input:
        errors="results/isa/study/error_vs_runtime.csv",
        fire_ratio="results/isa/study/fire_ratio.csv",
        fire_grid="results/isa/study/fire_tuning.csv",
        stability_map="results/isa/study/stability_map.csv",
        cases="results/isa/study/stability_cases.csv",
        study_config=ISA_STUDY_CFG,
        code=code("methods.isa.report.study"),
    output:
        "results/report/30_study.md",
        "docs/tables/study_recommendation.csv",
        "docs/tables/study_cases.csv",
    params:
        func="methods.isa.report.study.report_section",
    log:
        "logs/isa/report/study.log",


rule isa_bench_step:
    input:
        script="benchmarks/bench_step.py",
        reference="benchmarks/numpy_reference.py",
        floor="benchmarks/isa_floor.py",
        code=code("methods.isa.method"),
    output:
        "benchmarks/results/step_cost.csv",
        "benchmarks/results/compile.csv",
        "benchmarks/results/memory.csv",
        "benchmarks/results/summary.txt",
        "benchmarks/results/machine.txt",
        "benchmarks/results/step_cost.png",
        "benchmarks/results/step_threads.csv",
        "benchmarks/results/newton_evals.csv",
        "benchmarks/results/step_floor.csv",
    threads: 2  # the benchmark takes the whole 2-core machine so other jobs do not perturb it
    message:
        JOB
    resources:
        **BENCH,
    log:
        "logs/isa/bench_step.log",
    conda:
        "../../envs/isaflow.yaml"
    params:
        src=os.path.join(workflow.basedir, "src"),  # this checkout's source (no install needed)
    shell:
        "PYTHONPATH={params.src} python {input.script} > {log} 2>&1"


rule isa_bench_output:
    input:
        script="benchmarks/bench_output.py",
        code=code("methods.isa.method"),
    output:
        "benchmarks/results/output_cost.csv",
    threads: 2  # the benchmark takes the whole 2-core machine so other jobs do not perturb it
    message:
        JOB
    resources:
        **SMALL,
    log:
        "logs/isa/bench_output.log",
    conda:
        "../../envs/isaflow.yaml"
    params:
        src=os.path.join(workflow.basedir, "src"),  # this checkout's source (no install needed)
    shell:
        "PYTHONPATH={params.src} python {input.script} > {log} 2>&1"


use rule call as isa_timing with:
    input:
        step_cost="benchmarks/results/step_cost.csv",
        compile="benchmarks/results/compile.csv",
        memory="benchmarks/results/memory.csv",
        machine="benchmarks/results/machine.txt",
        output_cost="benchmarks/results/output_cost.csv",
        table1="results/isa/table1.csv",
        table1_md="results/isa/table1.md",
        code=code("methods.isa.report.speed"),
    output:
        "results/bench/10_isa.md",
    params:
        func="methods.isa.report.speed.timing_fragment",
        kw={"targets": ISA["speed_targets"]},
    log:
        "logs/isa/report/timing.log",


# the paper's own outputs, Figures 5-10 and Table 1, and only what they need (quick start: snakemake -c2
# paper); the report's sections and the claims need the full run
PAPER_TARGETS = [f for name in ("fig05_inputs_coarse", "fig06_single_coarse", "fig07_inputs_refined",
                                "fig08_single_refined", "fig09_flow_incomplete", "fig10_flow_complete")
                 for f in figure(name)] + ["results/isa/table1.csv", "results/isa/table1.md"]


rule paper:
    input:
        with_report_copies(PAPER_TARGETS),
        # the paper's claims, judged from the runs its rows read (claims.smk, one job per paper)
        "results/claims/registry/papadopoulos2016.csv",


# the smallest target set CI runs (.tests/integration/config.yaml): the paper's coarse Figures 5, 6, 9 and 10
# from their three coarse runs, and a coarse single-vessel run of every other ISA update rule and of the first
# compared SPH and MPS runs, in parallel from an empty kernel cache (each method compiled once, rule compile)
INTEGRATION_TARGETS = [f for name in ("fig05_inputs_coarse", "fig06_single_coarse", "fig09_flow_incomplete",
                                      "fig10_flow_complete") for f in figure(name)] + [
    isa_file(f"single_coarse_{v}") for v in REGISTRY["isa"].variants if v != "paper"]


rule integration:
    input:
        lambda wc: with_report_copies(INTEGRATION_TARGETS + [first_run(m, "single") for m in TANK_METHODS if m != "isa"]),


register(targets=PAPER_TARGETS + figure("calibration_free_surface") + figure("convergence_single")
         + figure("flow_history") + figure("error_vs_runtime") + figure("error_vs_work") + figure("stability_map")
         + figure("isa_overdamped") + [f for n in _FIG10_SWEEPS for f in figure(f"fig10_{n}")]
         + ["results/isa/study/fire_ratio.csv", "results/isa/metrics.csv"])
register(targets=["figures/isa_flow_animation.gif"])
register(report=["results/report/10_single.md", "results/report/20_flow.md", "results/report/30_study.md"])
# the paper's claims are judged by the shared claims rule (claims.smk) from config/claims/papadopoulos2016.yaml
# and the quantities of methods.isa.quantities: results/claims/registry/papadopoulos2016.csv
register(bench=["results/bench/10_isa.md"])
