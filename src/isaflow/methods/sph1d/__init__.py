"""The truncated SPH hydrostatic problem in 1D as a linear system (issue 12).

Merino-Alonso, Macia & Souto-Iglesias (2020), abstract only: a liquid column
at rest, the SPH momentum balance grad p = -rho g at every particle, the kernel
truncated at the free surface; A p = b is solved directly (no time stepping).
Modules: ``system`` (assembly, banded), ``column`` (one solve), ``band`` (its LU, solves and
condition number, deterministically), ``closed_form`` (one neighbour per side), ``sweep``
(N x h/dx x kernel, the classification), ``settings`` and ``checks`` (the values of
config/methods/sph1d.yaml, plausibility and cost), ``pipeline`` (what the rules call),
``figures``, ``report``, ``quantities`` (what the rows of config/claims/merino_alonso2020.yaml read from
the sweep).  A 1D static study: it writes its own tables, not the 2D contract.
"""

from isaflow.methods import Method, Variant

METHOD = Method(
    name="sph1d", order=60, marker="v",
    label="truncated SPH hydrostatic column (1D, static linear system)",
    paper="merino_alonso2020", paper_label="Merino-Alonso et al. (2020), truncated SPH hydrostatics (abstract only)",
    variants=(
        Variant("symmetric_hydrostatic", "symmetric gradient (p_i + p_j), mirror floor ghosts with hydrostatic "
                "pressure (our reading; not stated)", "tab:blue", "o"),
        Variant("plain_hydrostatic", "plain gradient (p_j), mirror floor ghosts with hydrostatic pressure "
                "(alternative reading)", "tab:green", "s"),
        Variant("symmetric_equal", "symmetric gradient (p_i + p_j), mirror floor ghosts with equal pressure "
                "(alternative reading)", "tab:purple", "^"),
    ),
)
