"""Elastic floor on the project's 100 cm tank: a plate of solid particles loaded by the liquid.

The plate (settings section 'floor'): nx = span / dx + 1 columns, 'layers' rows of cubic particles,
top face at y = 0 (the tank's floor line).  Simply supported at the two ends of its middle row
(pin at x = 0: x and y held; roller at x = span: y held), so the span between supports is the
tank's floor length and the supports sit on the neutral axis.  2D plane strain, per unit thickness.

Variants: 'uniform_load' (the hydrostatic W / span as nodal loads, the beam-theory check) and
'oneway' (one-way coupling: the floor contacts of a rigid-floor run of another method, applied as
nodal loads on the plate's top particles; the liquid does not see the plate move, justified when
the deflection is small against the depth).  Units cm, N, s.
"""

import numpy as np

from isaflow import runfile

from . import lattice as L
from . import solve as S
from . import theory as T
from .settings import material_units


def plate(cfg):
    """(state, top (N,) bool, mid (N,) bool) of the unloaded, supported plate."""
    f = cfg["floor"]
    dx, ny = f["dx_cm"], f["layers"]
    nx = int(round(f["span_cm"] / dx)) + 1
    blk = L.block(nx, ny, 1, dx, (0.0, -(ny - 0.5) * dx, 0.0))
    mat = S.Material(*material_units(cfg["material"]))
    st = S.State(blk, mat, f["solid_model"], np.ones((blk.n, 3)))
    i, j = blk.index[:, 0], blk.index[:, 1]
    mid = j == ny // 2
    mask = np.zeros((blk.n, 3), bool)
    mask[:, 2] = True
    mask[mid & (i == 0), :2] = True  # pin
    mask[mid & (i == nx - 1), 1] = True  # roller
    S.prescribe(st, mask, np.zeros(3))
    return st, j == ny - 1, mid


def stiffness(cfg):
    """Plane-strain bending stiffness E' I [N cm^2 per cm], E' = E / (1 - nu^2), I = t^3 / 12, t = layers dx."""
    f = cfg["floor"]
    E, nu, _ = material_units(cfg["material"])
    t = f["layers"] * f["dx_cm"]
    return E / (1.0 - nu**2) * t**3 / 12.0


def floor_contacts(ds):
    """(x (C,) cm, load (C,) N downward on the floor) of a run file's floor-wall contacts: the liquid pushes
    on the wall with minus the wall's force on it."""
    names = [str(w) for w in ds["wall"].values]
    if "floor" not in names:
        raise KeyError(f"run file has no wall named 'floor' (walls: {', '.join(names)})")
    on = ds["contact_wall"].values == names.index("floor")
    seg = ds["wall_segment"].values[names.index("floor")]
    x0 = min(seg[0], seg[2])
    return ds["contact_point"].values[on, 0] - x0, ds["contact_force"].values[on, 1], float(abs(seg[2] - seg[0]))


def nodal(x, load, dx, nx):
    """Loads at points x [cm] shared between the two nearest top particles (hat functions: force and
    moment kept); (nx,) N.  Points outside [0, span] go to the end particles."""
    s = np.clip(np.asarray(x, float) / dx, 0.0, nx - 1 - 1e-12)
    k = np.floor(s).astype(int)
    w = s - k
    out = np.zeros(nx)
    np.add.at(out, k, (1.0 - w) * load)
    np.add.at(out, np.minimum(k + 1, nx - 1), w * load)
    return out


def run_floor(cfg, variant, loads=None, case=None):
    """Settle the plate under its nodal loads; deflection of the middle row against beam theory under
    (a) the uniform W / span and (b) the same nodal loads.  loads: a rigid-floor run file ('oneway')."""

    f = cfg["floor"]
    st, top, mid = plate(cfg)
    dx, span = f["dx_cm"], f["span_cm"]
    nx = st.block.shape[0]
    src = {}
    if variant == "uniform_load":
        W = f["weight_N"]
        P = nodal(np.arange(nx) * dx, np.full(nx, W / nx), dx, nx)
    elif variant == "oneway":
        ds = runfile.read(loads)
        x, fy, length = floor_contacts(ds)
        if abs(length - span) > 1e-6 * span:
            raise ValueError(f"{loads}: floor length {length:g} cm, the plate spans {span:g} cm")
        P = nodal(x, fy, dx, nx)
        W = float(ds["weight"].values.sum())
        try:  # the liquid's depth above the floor (its one surface), for deflection / depth (the one-way premise)
            from isaflow.metrics import surface_of

            depth = float(surface_of(ds)) - float(ds["wall_segment"].values[[str(w) for w in ds["wall"].values].index(
                "floor"), 1])
        except (KeyError, ValueError):
            depth = float("nan")
        src = {"depth_cm": depth, "load_source": str(loads), "load_method": ds.attrs.get("method", ""),
               "load_variant": ds.attrs.get("variant", ""), "load_wall_time_s": float(ds["wall_time"])}
    else:
        raise KeyError(f"floor variant '{variant}' is not implemented (choose from uniform_load, oneway)")
    order = np.argsort(st.block.index[top, 0])
    st.fext[np.flatnonzero(top)[order], 1] = -P
    status, msg, resid, _ = S.relax(st, cfg["solver"]["tol"], f["max_steps"], label=f"floor {variant}")
    EI = stiffness(cfg)
    xm = st.block.ref[mid, 0]
    o = np.argsort(xm)
    xm = xm[o]
    w = -(st.pos[mid, 1] - st.block.ref[mid, 1])[o]
    w_uni = T.beam_uniform_deflection(xm, W / span, span, EI)
    w_act = T.beam_point_deflection(xm, np.arange(nx) * dx, P, span, EI)
    c = nx // 2
    hist = {
        "x_mid": (("node",), xm, "cm", "x of the middle-row particles"),
        "w_mid": (("node",), w, "cm", "plate deflection (downward) of the middle row"),
        "w_theory_uniform": (("node",), w_uni, "cm", "Euler-Bernoulli deflection under the uniform W / span"),
        "w_theory_actual": (("node",), w_act, "cm", "Euler-Bernoulli deflection under the applied nodal loads"),
        "nodal_load": (("node",), P, "N", "downward load on each top particle, by x"),
        "w_centre": (("record",), [w[c]], "cm", "mid-span deflection"),
        "w_centre_uniform": (("record",), [w_uni[c]], "cm", "mid-span beam theory, uniform W / span"),
        "w_centre_actual": (("record",), [w_act[c]], "cm", "mid-span beam theory, applied loads"),
        "load_total": (("record",), [P.sum()], "N", "total applied load"),
        "liquid_weight": (("record",), [W], "N", "liquid weight W of the load case"),
    }
    case = case or ("floor_uniform" if variant == "uniform_load" else f"floor_{src['load_method']}")
    r = S.result(st, case, status, msg, resid, hist,
                {"span_cm": span, "thickness_cm": f["layers"] * dx, "supports": f["supports"],
                 "solid_model": f["solid_model"], "EI_N_cm2": EI, **src})
    r.variant = variant
    return r
