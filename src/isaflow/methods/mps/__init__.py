"""MPS (moving particle semi-implicit, Koshizuka & Oka 1996, as the public MPS-Basic code implements it)
on the shared tank, with three source terms of its pressure Poisson equation (variants)."""

from isaflow.methods import Method, Variant

METHOD = Method(
    name="mps", order=55, marker="^", tank=True,
    label="MPS (Koshizuka & Oka 1996; variational pressure gradient, Suzuki et al. 2007), semi-implicit",
    paper="hattori", paper_label="Hattori et al., MPS pressure Poisson source term",
    variants=(
        Variant("standard", "MPS, standard source gamma rho0/dt^2 (n0 - n*)/n0, relaxation gamma as MPS-Basic (Koshizuka & Oka 1996; not the paper's method)",
                "tab:blue", "s"),
        Variant("hattori", "MPS, Hattori et al. eq. (6) source, Rho* = rho0 n*/n0, its density term (rho0 - Rho*)/dt^2 relaxed by gamma as the standard source (not the paper's method)",
                "tab:red", "D"),
        Variant("mixed", "MPS, mixed source rho0/dt div V* + gamma_m rho0/dt^2 (n0 - n*)/n0 as Tanaka & Masunaga 2010 state it (divergence unrelaxed; not the paper's method)",
                "tab:green", "^"),
    ),
)
