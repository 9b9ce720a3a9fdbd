"""Report fragment and timing of the 1D study, generated from the case table (sweep.classify).

The abstract's claims are judged by isaflow.claims from the registry (config/claims/merino_alonso2020.yaml,
quantities in methods/sph1d/quantities.py); this fragment describes the sweep and states the classification rule
with the registry's numbers.  Units: errors relative to ||p_exact||_2 (1), h/dx (1).
"""


def fragment(cases, summary, variants, labels, nmax, window_ns, band, round_off):
    """Markdown of the report section (results/report/60_sph1d.md); window_ns: the N of the classification
    window; band, round_off: the rule's numbers (config/claims/merino_alonso2020.yaml)."""
    d = variants[0]
    s = summary[summary.variant == d]
    lines = [
        "## 1D truncated SPH hydrostatic column (Merino-Alonso et al. 2020, abstract only)", "",
        "The SPH momentum balance at rest, grad p = -rho g, at every particle of a liquid column, with the "
        "kernel truncated at the free surface, solved as a banded linear system A p = b (no time stepping). "
        "The abstract states neither the gradient form nor the floor; the discrete equations we chose are "
        "in `docs/sph1d.md`.  Variants: " + "; ".join(f"`{v}`: {labels[v]}" for v in variants) + ".", "",
        f"Sweep: h/dx {cases.ratio.min():.2f} to {cases.ratio.max():.2f}, N up to {nmax}, "
        f"{len(cases)} (variant, kernel, h/dx) cases (solve time in `docs/timing.md`).  Error: relative quadratic "
        f"error at the largest N.  Behaviour over N = {', '.join(map(str, window_ns))} from the doubling ratios "
        f"r = E(2N)/E(N) (the rule of `config/claims/merino_alonso2020.yaml`): settled if every r is in "
        f"[{band:g}, {1 / band:.4g}], decreasing if every r < {band:g}, divergent if some r > {1 / band:.4g} with no net "
        f"decrease (or a non-finite error), exact if every error is below {round_off:g}, undetermined otherwise; "
        f"ill-conditioned if cond_1(A) grows faster than N by the same margin.", "",
        f"Per kernel and neighbours per side (`{d}`):", "",
        "| kernel | nb | median error | min | max | settled | decreasing | undetermined | divergent ratios | "
        "ill-conditioned | max cond_1/N |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for _, r in s.iterrows():
        lines.append(f"| {r.kernel} | {r.neighbours} | {r.median_error:.3g} | {r.min_error:.3g} | "
                     f"{r.max_error:.3g} | {r.settled} | {r.decreasing} | {r.undetermined} | "
                     f"{r.divergent_ratios if r.divergent else '-'} | {r.ill_conditioned} | {r.max_cond_over_n:.3g} |")
    lines += ["", "The abstract's claims are judged in the claims table (`config/claims/merino_alonso2020.yaml`).", "",
              "![error against N](../figures/sph1d_error_vs_n.png)",
              "![error and conditioning maps](../figures/sph1d_maps.png)",
              "![variants](../figures/sph1d_variants.png)", ""]
    return "\n".join(lines)


def timing(cases, nmax, solve_seconds):
    """Markdown for docs/timing.md: the sweep's solve time."""
    return (f"## 1D truncated SPH sweep: solve time\n\n{len(cases)} (variant, kernel, h/dx) cases, N up to {nmax}, "
            f"every N of each case: {solve_seconds:.1f} s of banded solves and condition estimates (one process).\n")
