# Every claim of every paper judged from the run outputs (isaflow.claims): the registry
# (config/claims/<paper>.yaml) says what each claim measures, with its tolerance and the runs it needs;
# the methods' claims modules measure; results/claims/registry/<paper>.csv and the counts by kind feed the report.
# Its replays are the replicated paper's runs: the kernels of that method (the registry's first) are loaded
# from its generation instead of compiled in the job (85 -> 68 s); the other methods' kernels its measures
# call are read from their own generations, sealed by then (their runs are its inputs; isaflow.core.jit.read_also).
CLAIMS_KERNELS = next(iter(REGISTRY))


# numbers the claims read that no solver writes (the registry files' `derived` entries, isaflow.derived; DERIVED in
# common.smk): each computed from the run file its entry names by its own job, with that method's kernels
use rule call as derived with:
    input:
        unpack(derived_inputs),
    output:
        "results/derived/{method}/{name}.nc",
    params:
        func="derived.write",
        kernels=lambda wc: wc.method,
        kw=lambda wc: {"key": f"{wc.method}:{wc.name}", "compute": DERIVED[f"{wc.method}:{wc.name}"]["compute"]},
    wildcard_constraints:
        method="|".join(sorted({k.split(":", 1)[0] for k in DERIVED})) or "(?!)",
        name="|".join(re.escape(k.split(":", 1)[1]) for k in DERIVED) or "(?!)",
    log:
        "logs/derived/{method}/{name}.log",


# one paper's claims judged from the union of its rows' runs (so `snakemake paper` can yield the paper's table)
use rule call as claims with:
    input:
        run_files=paper_claim_files,
        registry_files=sorted(glob.glob("config/claims/*.yaml")),
        compiled=ancient(f"results/compiled/{CLAIMS_KERNELS}.txt"),
        code=code("claims", "judge", "quantities", *[f"methods.{m}.{k}" for m in _methods.PACKAGES for k in ("claims", "quantities")
                                                     if os.path.exists(f"src/isaflow/methods/{m}/{k}.py")]),
    output:
        "results/claims/registry/{paper}.csv",
        report_file("results/claims/registry/{paper}.html", "claims", "Claims", "{paper}"),
    params:
        func="claims.write_paper",
        kernels=[CLAIMS_KERNELS] + [m for m in REGISTRY if m != CLAIMS_KERNELS],
        kw=lambda wc: {"registry": "config/claims", "paper": wc.paper, "runs": paper_claim_runs(wc)},
    wildcard_constraints:
        paper="|".join(CLAIM_PAPERS),
    resources:
        **CLAIMS,
    log:
        "logs/claims/{paper}.log",


# the counts by paper and kind, from the judged tables
use rule call as claims_counts with:
    input:
        tables=[f"results/claims/registry/{p}.csv" for p in CLAIM_PAPERS],
        code=code("claims"),
    output:
        "results/claims/registry/counts.csv",
    params:
        func="claims.write_counts",
    log:
        "logs/claims/counts.log",


# where each fragile method result flips (isaflow.figures.robustness): from the claims tables alone
use rule call as claims_robustness_figure with:
    input:
        tables=[f"results/claims/registry/{p}.csv" for p in CLAIM_PAPERS],
        registry=sorted(glob.glob("config/claims/*.yaml")),
        code=code("figures.robustness", "figures.style"),
    output:
        figure("claims_robustness"),
    params:
        func="figures.robustness.robustness_figure",
    log:
        "logs/claims/robustness_figure.log",


register(targets=figure("claims_robustness"))
