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
    name="isa", order=10, marker="o", tank=True,
    label="incremental static analysis of point particles",
    paper="papadopoulos2016", paper_label="Papadopoulos, Koutitas & Lazaridis (2016), the paper replicated",
    variants=(
        Variant("paper", "paper: x += du F / max|F| (section 3.3, literal)", "tab:blue", "o", paper=True),
        Variant("capped", "capped: x += du F / max(max|F|, f_ref) (variant, not in paper)", "tab:green", "s"),
        Variant("fire", "fire: FIRE relaxation, Bitzek et al. 2006 (variant, not in paper)", "tab:purple", "^"),
        Variant("overdamped", "overdamped: m x'' = F - c x', m = w/g, same laws (variant, not in paper)",
                "tab:olive", "v"),
        Variant("newton_lm", "newton_lm: energy minimisation, Newton-type (Levenberg-Marquardt) with "
                "the contacts' Hessian (equilibrium solver, not in paper)", "tab:brown", "X"),
    ),
)
