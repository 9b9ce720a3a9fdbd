"""Incremental static analysis of point particles (Papadopoulos, Koutitas & Lazaridis 2016).

Modules: ``forces`` (force laws, plain force evaluation, wall contacts),
``relax`` (the compiled step loop of the three update rules), ``dynamics`` (the
compiled loop of the overdamped variant: the same particles with masses w/g),
``newton`` (the equilibrium solver of the variant ``newton_lm``), ``settings``
(solver settings with defaults), ``solver`` (chunks, history, outcome ->
contract.Result).
"""

from .. import Method, Variant

METHOD = Method(
    name="isa",
    label="incremental static analysis of point particles",
    paper="papadopoulos2016",
    variants={
        "paper": Variant("paper", "paper: x += du F / max|F| (section 3.3, literal)", "tab:blue", "o", paper=True),
        "capped": Variant("capped", "capped: x += du F / max(max|F|, f_ref) (variant, not in paper)", "tab:green", "s"),
        "fire": Variant("fire", "fire: FIRE relaxation, Bitzek et al. 2006 (variant, not in paper)", "tab:purple", "^"),
        "overdamped": Variant("overdamped", "overdamped: m x'' = F - c x', m = w/g, same laws (variant, not in paper)",
                              "tab:olive", "v"),
        "newton_lm": Variant("newton_lm", "newton_lm: energy minimisation, Newton-type (Levenberg-Marquardt) with "
                             "the contacts' Hessian (equilibrium solver, not in paper)", "tab:brown", "X"),
    },
    marker="o",
    paper_label="Papadopoulos, Koutitas & Lazaridis (2016), the paper replicated",
    tank=True,
    entry="isaflow.methods.isa.method",
    checks="isaflow.methods.isa.checks",
    values="isaflow.methods.isa.settings:VALUES",
    settings="config/methods/isa.yaml",
    report="results/report/10_isa.md",
    timing="results/timing/10_isa.md",
)
