"""Weakly compressible SPH (issue 10): the liquid of marko2017 section 2 on the project's tanks.

Modules: ``kernels`` (numba pair passes and the compiled leapfrog loop),
``eos`` (equations of state), ``repulsion`` (Lennard-Jones wall safety net),
``particles`` (liquid lattice, wall particles, wall contacts), ``pairs`` (pair
list, thin-wall visibility, the colouring of the parallel passes), ``settings``
(the values of config/methods/sph.yaml), ``checks`` (plausibility and cost, pure
Python), ``method`` (the entry isaflow.run calls), ``solver`` (set-up and the
stepper driver.drive runs -> contract.Result), ``block`` (the periodic block of
the tensile-instability test), ``quantities`` (what the claims read from SPH run files),
``outputs`` (the summary table), ``figures``, ``report`` (report and timing
fragments).
"""

from .. import Method, Variant

METHOD = Method(
    name="sph", order=50, marker="s", tank=True,
    label="weakly compressible SPH",
    paper="marko2017", paper_label="Marko et al. (2017), SPH liquid and Hooke's-law solid particles",
    variants=(
        Variant("wcsph", "WCSPH: marko2017 eqs. 4, 9 with continuity density in place of eq. 6 (free "
                         "surface) + Tait EOS, artificial viscosity, Adami walls (completions from literature)",
                "tab:orange", "D"),
        Variant("wcsph_eq6", "WCSPH with marko2017 eq. 6 literally (summed density, P >= 0; its surface "
                             "band reads low)", "tab:brown", "d"),
        Variant("delta_wc2", "delta-SPH, Wendland C2: continuity density + density diffusion "
                             "(variant, not marko2017)", "tab:red", "v"),
    ),
)
