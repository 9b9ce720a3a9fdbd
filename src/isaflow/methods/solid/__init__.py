"""Hooke's-law solid particles (Marko 2017, ../shared/papers/marko2017_lagrangian_solid_sph.txt, sections 3-4).

Cubic particles linked to their lattice neighbours (the contact matrix):
linked pairs pull and push by Hooke's law (eqs. 11-16), unlinked ones only
push.  Variants: 'paper' (eqs. 11-16 as printed: normal springs only) and
'hooke' (adds the Poisson contraction of the particle size and shear springs
of modulus G, our reading of how the paper's Poisson and shear numbers arise).
"""

from isaflow.methods import Method, Variant

METHOD = Method(
    name="solid", order=65, marker="D",
    label="Hooke's-law solid particles (Marko 2017)",
    paper="marko2017", paper_label="Marko et al. (2017), SPH liquid and Hooke's-law solid particles",
    variants=(
        Variant("paper", "paper: eqs. 11-16 as printed (normal Hooke springs, no Poisson or shear term)", "tab:red", "s"),
        Variant("hooke", "hooke: eqs. 11-16 + Poisson size coupling + G shear springs (not in the paper)", "tab:blue", "o"),
        Variant("pressure_load", "pressure_load: 4.4 vessel, the water replaced by its pressure on the "
                "ring's wetted faces (what Lame assumes; the paper couples SPH water)", "tab:purple", "D"),
        Variant("water_particles", "water_particles: 4.4 vessel with weakly compressible SPH "
                "water (linear EOS from p0) pushing on the ring, one-step coupled", "tab:cyan", "P"),
        Variant("uniform_load", "uniform_load: elastic floor under the hydrostatic W / span as nodal "
                "loads (beam-theory check; not in either paper)", "0.3", "^"),
        Variant("oneway", "oneway: elastic floor, one-way: loads from the rigid-floor run of another method "
                "(not in either paper)", "tab:green", "v"),
    ),
)
