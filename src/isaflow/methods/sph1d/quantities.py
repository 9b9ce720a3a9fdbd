"""Quantities of the 1D sweep (results/sph1d/sweep*.nc) the claims registry reads (config/claims/merino_alonso2020.yaml).

Each reads one sweep file; the row states the comparison (isaflow.judge).  Reading parameters of the registry's inputs
reach them by name: ``variant`` (gradient_form, floor_treatment: a variant of the file; default its first, the kept
readings), ``norm`` (error_norm: 'l2' or 'max').  The classification rule's numbers ``settle_band``, ``round_off``
are the rows' tolerance.parameters (sweep.behaviour, the file header).  Kernels are named by family: 'wendland_c2'
is the file's Wendland C2 in either form (input kernel_form: the 3D or the 1D Wendland function).  Errors relative to
||p_exact||; h/dx [1].
"""

import numpy as np
from scipy import stats

from ...quantities import Value, quantity
from . import closed_form, sweep

SHORT = {"cubic_spline": "cubic", "wendland_c2": "C2", "wendland_c4": "C4", "wendland_c6": "C6"}


def _family(kernel):
    return str(kernel).removesuffix("_1d")


def _view(ds, variant=None, norm="l2"):
    """The sweep of one variant (default the first) with the error of the norm read as 'error'."""
    ds = ds.sel(variant=[variant or str(ds.variant.values[0])])
    return ds.assign(error=ds.error_max) if norm == "max" else ds


def _cases(ds, settle_band, round_off, variant=None, norm="l2"):
    """sweep.classify of one variant over the file's own window, kernels by family."""
    c = sweep.classify(_view(ds, variant, norm), int(ds.attrs["classify_window"]), settle_band, round_off)
    return c.assign(kernel=c.kernel.map(_family))


def _window(ds):
    w = int(ds.attrs["classify_window"])
    return f"N {int(ds.n.values[-w])}-{int(ds.n.values[-1])}"


# ------------------------------------------------------------------------------------------ the sweep and its system
@quantity("cases not solved at every N, plus 1 if N is not refined")
def unsolved(ds):
    """(case, N) pairs without a finite solve, plus 1 unless N strictly increases: 0 when every case refines N at a
    fixed h/dx."""
    n = ds.n.values
    bad = int(np.isnan(ds.error.values).sum()) + int(not (len(n) >= 2 and np.all(np.diff(n) > 0)))
    return Value(bad, f"N = {', '.join(str(int(x)) for x in n)} at each of {ds.sizes['ratio']} h/dx in "
                      f"[{ds.ratio.values.min():.2f}, {ds.ratio.values.max():.2f}] x {ds.sizes['kernel']} kernels x "
                      f"{ds.sizes['variant']} variants, H = {float(ds.attrs['height_cm']):g} cm")


@quantity("neighbours per side")
def neighbours(ds, stat):
    """The fewest ('min') or most ('max') neighbours per side inside the support 2 h over the file's h/dx (the count
    ceil(2 h/dx) - 1 of system.neighbours_per_side, the same at every N)."""
    nb = ds.neighbours.values
    i = int(np.argmin(nb) if stat == "min" else np.argmax(nb))
    return Value(int(nb[i]), f"at h/dx {float(ds.ratio.values[i]):.2f}; h/dx {ds.ratio.values.min():.2f}-"
                             f"{ds.ratio.values.max():.2f} give {int(nb.min())}-{int(nb.max())}")


@quantity("Wendland kernels")
def wendland_kernels(ds):
    names = [str(k) for k in ds.kernel.values if str(k).startswith("wendland")]
    return Value(len(names), ", ".join(names))


@quantity("max |p(2 rho g) - 2 p(rho g)| / max |2 p(rho g)|", fmt=".3g")
def linearity(ds):
    """The derived linearity product of a sweep (sweep.linearity): the largest relative difference over the kernels."""
    parts = [f"{SHORT[_family(k)]} h/dx {float(ds.ratio.sel(kernel=k)):.2f}: {float(ds.rel_diff.sel(kernel=k)):.3g}"
             for k in ds.kernel.values]
    return Value(float(ds.rel_diff.max()), f"N = {int(ds.attrs['n'])}; " + "; ".join(parts))


@quantity("max |E_solver - E_closed| / (1 + E_closed), one neighbour", fmt=".3g")
def closed_form_gap(ds):
    """The closed-form one-neighbour error (closed_form.error, at the file's gradient forms, floors and top gap) against
    the solver's, over every kernel, one-neighbour h/dx, N and variant with a mirrored floor."""
    one = ds.neighbours.values == 1
    ratios, gap = ds.ratio.values[one], float(ds.attrs["top_gap_dx"])
    worst, where, largest = -1.0, "no variant with a mirrored floor", 0.0
    for var, (grad, floor) in sweep.variant_forms(ds).items():
        if floor not in ("mirror_hydrostatic", "mirror_equal"):
            continue
        for kern in ds.kernel.values:
            for k, n in enumerate(ds.n.values):
                closed = closed_form.error(int(n), ratios, str(kern), floor, gap, grad)
                d = np.abs(ds.error.sel(variant=var, kernel=kern).values[one, k] - closed) / (1.0 + closed)
                largest = max(largest, float(closed.max()))
                if d.max() > worst:
                    i = int(np.argmax(d))
                    worst, where = float(d.max()), f"at {var}, {kern}, h/dx {ratios[i]:.2f}, N {int(n)}"
    return Value(worst if worst >= 0 else float("nan"), f"{where}; E_closed up to {largest:.3g}")


# ------------------------------------------------------------------------------------------ one neighbour per side
def _limit(ds, variant=None, norm="l2"):
    """{kernel family: (ratios,) error at the largest N} of the one-neighbour ratios."""
    d = _view(ds, variant, norm)
    one = ds.neighbours.values == 1
    return {_family(k): d.error.sel(kernel=k).values[0, one, -1] for k in ds.kernel.values}


@quantity("smallest share over the kernels of one-neighbour ratios not converging", fmt=".3f")
def nonconvergent_share(ds, settle_band, round_off, variant=None, norm="l2"):
    """Per kernel, the share of one-neighbour h/dx whose error limit (at the largest N) exceeds round_off and whose
    error is not decreasing over the window (sweep.behaviour); the smallest share."""
    c = _cases(ds, settle_band, round_off, variant, norm)
    one = c[c.neighbours == 1]
    bad = (one.error_limit > round_off) & (one.behaviour != "decreasing")
    count, size = bad.groupby(one.kernel, sort=False).sum(), one.groupby(one.kernel, sort=False).size()
    return Value(float((count / size).min()), f"{_window(ds)}: " + ", ".join(
        f"{SHORT[k]} {int(count[k])} of {int(size[k])}" for k in count.index))


@quantity("smallest share over the kernels of one-neighbour error limits >= large", fmt=".3f")
def residue_share(ds, large, variant=None, norm="l2"):
    """Per kernel, the share of one-neighbour h/dx whose error at the largest N (the residue |kappa - 1| plus O(dx),
    closed_form) is at least ``large``; the smallest share, with each kernel's median limit."""
    lim = _limit(ds, variant, norm)
    share = {k: float(np.mean(v >= large)) for k, v in lim.items()}
    return Value(min(share.values()), f"N {int(ds.n.values[-1])}: " + "; ".join(
        f"{SHORT[k]} median {np.median(v):.3g}, {100 * share[k]:.0f} % >= {large:g}" for k, v in lim.items()))


# ------------------------------------------------------------------------------------------ two and more neighbours
@quantity("one-sided sign-test p that the kernels' cond_1/N ranks their errors, two neighbours", fmt=".2g")
def cond_sign_test(ds, variant=None, norm="l2"):
    """At each two-neighbour h/dx, Spearman over the kernels of (cond_1/N, error) at the largest N; p of a one-sided
    sign test that it is positive at more ratios than negative (1 when it is not); the pooled Spearman over every
    (kernel, h/dx), which h/dx alone can drive, is reported."""
    d = _view(ds, variant, norm)
    two = ds.neighbours.values == 2
    cond = d.cond.values[0][:, two, -1] / int(ds.n.values[-1])  # (kernel, ratio)
    err = d.error.values[0][:, two, -1]
    per = [stats.spearmanr(cond[:, i], err[:, i])[0] for i in range(cond.shape[1])
           if np.isfinite(cond[:, i]).all() and np.isfinite(err[:, i]).all() and np.ptp(cond[:, i]) > 0
           and np.ptp(err[:, i]) > 0]
    up, down = sum(r > 0 for r in per), sum(r < 0 for r in per)
    p = float(stats.binomtest(up, up + down, 0.5, alternative="greater").pvalue) if up > down else 1.0
    ok = np.isfinite(cond) & np.isfinite(err)
    rho, p_pool = stats.spearmanr(cond[ok], err[ok], alternative="greater")
    return Value(p, f"{_window(ds)}: kernels agree at {up}, disagree at {down} of {len(per)} two-neighbour h/dx; "
                    f"pooled Spearman {rho:.3f} (p {p_pool:.2g}, reported)")


@quantity("share of two- and three-neighbour cases settling to a limit in [round_off, small)", fmt=".3f")
def small_limit_share(ds, settle_band, round_off, small, variant=None, norm="l2"):
    c = _cases(ds, settle_band, round_off, variant, norm)
    t = c[c.neighbours.isin([2, 3])]
    good = (t.behaviour == "settled") & (t.error_limit >= round_off) & (t.error_limit < small)
    counts = t.behaviour.value_counts()
    return Value(float(good.mean()), f"{_window(ds)}: {int(good.sum())} of {len(t)}; behaviour " + ", ".join(
        f"{k} {int(v)}" for k, v in counts.items()))


def _divergent(c, kernel, neighbours=None):
    k = c[(c.kernel == kernel) & ((c.neighbours == neighbours) if neighbours else True)]
    return k, k[k.behaviour == "divergent"]


def _elsewhere(c):
    div = c[c.behaviour == "divergent"]
    return "; divergent: " + (", ".join(f"{SHORT[k]} {nb} nb h/dx {g.ratio.min():.2f}-{g.ratio.max():.2f} ({len(g)})"
                                        for (k, nb), g in div.groupby(["kernel", "neighbours"], sort=False)) or "none")


@quantity("divergent h/dx")
def divergent_count(ds, kernel, settle_band, round_off, neighbours=None, variant=None, norm="l2"):
    """How many h/dx of a kernel (with that many neighbours per side, if given) diverge (sweep.behaviour)."""
    c = _cases(ds, settle_band, round_off, variant, norm)
    k, div = _divergent(c, kernel, neighbours)
    return Value(len(div), f"of {len(k)}, {_window(ds)}, max cond_1/N {k.cond_over_n.max():.3g}{_elsewhere(c)}")


@quantity("divergent h/dx of the kernel minus the most of its rivals")
def divergent_lead(ds, kernel, rivals, settle_band, round_off, variant=None, norm="l2"):
    c = _cases(ds, settle_band, round_off, variant, norm)
    n = {k: len(_divergent(c, k)[1]) for k in [kernel, *rivals]}
    return Value(n[kernel] - max(n[k] for k in rivals), f"{_window(ds)}: " + ", ".join(
        f"{SHORT[k]} {v}" for k, v in n.items()))


@quantity("share of the kernel's divergent h/dx that are ill-conditioned", fmt=".3f")
def illcond_share(ds, kernel, settle_band, round_off, variant=None, norm="l2"):
    """Of the kernel's divergent h/dx, the share whose cond_1 grows faster than N (sweep.ill_conditioned); none when
    none diverges."""
    c = _cases(ds, settle_band, round_off, variant, norm)
    k, div = _divergent(c, kernel)
    ill = int(div.ill_conditioned.sum())
    return Value(ill / len(div) if len(div) else float("nan"),
                 f"{ill} of {len(div)} divergent; ill-conditioned in all {int(k.ill_conditioned.sum())}")
