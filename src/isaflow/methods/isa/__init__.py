"""Incremental static analysis of point particles (Papadopoulos, Koutitas & Lazaridis 2016).

Modules: ``forces`` (force laws, plain force evaluation, wall contacts),
``relax`` (the compiled step loop of the update rules paper, capped and fire),
``dynamics`` (the compiled loop of the overdamped variant: the same particles
with masses w/g), ``newton`` (the equilibrium solver of the variant
``newton_lm``), ``settings`` (the values of config/methods/isa.yaml and the
solver settings with their defaults), ``scene`` (a tank, settings and update rule
as one problem), ``restart`` (start files and the solver's restart state),
``budget`` and ``checks`` (memory and plausibility before any work; ``checks`` pure
Python), ``method`` (the entry isaflow.run calls), ``solver`` (the stepper
driver.drive runs: chunks, history, outcome -> contract.Result), ``plan`` (the
study's and calibration's run declarations), ``theory`` (the rhombic lattice, the
laws' stiffness), ``metrics`` (ISA's own measures), ``replay`` (a run step by
step), ``quantities`` (what the paper's claims read from run files), ``tables``, ``figures``
and ``report`` (Table 1, the study tables, the paper's figures, report fragments).
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
