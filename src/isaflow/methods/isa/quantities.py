"""Quantities of ISA run files the claims registry reads (config/claims/papadopoulos2016.yaml ``checks``).

Each is entered with :func:`isaflow.quantities.quantity` (name, units, what it reads); the registry row states the
runs, the reduction and the comparison (isaflow.judge).  The level definition (claims input ``level_definition``)
reaches the level quantities as the reading parameter ``level``: the project's one surface (top centres + half the
layer pitch, isaflow.metrics.surface_of) by default.  Units: cm, N.
"""

import math

import numpy as np

from ... import metrics as M, theory as T
from ...core import fixed_order as FO
from ...quantities import Value, quantity
from . import metrics as IM

SURFACE = "top centres + a/4"  # the kept level definition: the project's one surface
OFFSETS = ("top centres + 0", "top centres + a/4", "top centres + 5 cm")


def _offset(ds, level):
    """What a level definition adds to the top-centre mean [cm]."""
    return {"top centres + 0": 0.0, "top centres + a/4": M.layer_pitch(ds) / 2, "top centres + 5 cm": 5.0}[level]


def _vessel(ds, vessel):
    names = M.vessels(ds)
    return None if vessel is None else names[{"first": 0, "second": -1}.get(vessel, vessel)]


def level_above_floor(ds, vessel=None, level=SURFACE):
    v = _vessel(ds, vessel)
    return M.level_of(ds, v) + _offset(ds, level) - M.vessel_view(ds, v)["floor_y"]


# ------------------------------------------------------------------------------------------ the update
@quantity("largest step component over du, minus 1", fmt=".3g")
def step_excess(ds):
    """max over steps and particles of max(|u_x|, |u_y|) / du - 1 (the solver records the largest increment)."""
    return float(ds.attrs["max_step_move"]) / float(ds.attrs["solver.du"]) - 1.0


@quantity("largest initial overlap into a law's range", "cm", fmt=".3g")
def initial_overlap(ds):
    """max(l_bu - l_b, l_pu - l_p) over the initial particles and pairs: <= 0 means every force starts at zero."""
    pos0 = ds["pos0"].values
    gb = float(wall_distance(pos0, ds["wall_segment"].values).min()) - float(ds.attrs["forces.wall.l_u"])
    gp = _min_pair_distance(pos0, 2 * float(ds.attrs["forces.pair.l_u"])) - float(ds.attrs["forces.pair.l_u"])
    return Value(-min(gb, gp), f"l_b - l_bu {gb:+.3g} cm, l_p - l_pu {gp:+.3g} cm")


def _within(ds, n_u, paper_steps):
    """The run's outcome under a step limit of n_u x paper_steps (claims input step_limit, a reading parameter): a run
    converged later than that limit had not converged by it (the same run, stopped earlier)."""
    st = str(ds.attrs["status"])
    if st == "converged" and n_u is not None and paper_steps is not None and int(ds["steps"]) > n_u * paper_steps:
        return "step_limit"
    return st


@quantity("step of the first max|F| < f_tol")
def converged_step(ds, paper_steps=None, n_u=None):
    """The step at which the run first meets max|F| < f_tol (its end, counted from the chain's start); NaN for a run
    that ends otherwise (a cycle, the step limit, or past n_u x paper_steps), with its max|F| band."""
    if _within(ds, n_u, paper_steps) == "converged":
        return int(ds["steps"])
    return Value(float("nan"), f"never: {outcome_text(ds)}")


def outcome_text(ds):
    lo, hi = band(ds)
    cyc = f" period {int(ds.attrs['cycle_period'])}" if ds.attrs["status"] == "cycle" else ""
    return f"{ds.attrs['status']}{cyc} at step {int(ds['steps']):,}, max|F| {lo:.3g}-{hi:.3g} N over the last records"


@quantity("outcome")
def outcome(ds, paper_steps=None, n_u=None):
    """The run's outcome (under a step limit of n_u x paper_steps when both are given), with its max|F| band over the
    last records (a cycle's width) as text."""
    return Value(_within(ds, n_u, paper_steps), outcome_text(ds))


def band(ds):
    """(lo, hi) [N] of max|F| over the last ten records, or the residual twice."""
    if "hist_fmax_lo" in ds:
        return float(ds["hist_fmax_lo"].values[-10:].min()), float(ds["hist_fmax_hi"].values[-10:].max())
    r = float(ds["residual"])
    return r, r


@quantity("paper-update runs of the study at du factor 1 that do not converge")
def study_unconverged(group):
    """Of the error-against-run-time study's paper-update runs at the paper's du (a group {run id: Dataset}), how
    many end otherwise than converged."""
    runs = {r: ds for r, ds in sorted(group.items()) if ds.attrs["variant"] == "paper" and r.endswith("_du1")}
    bad = [f"{r} {ds.attrs['status']}" for r, ds in runs.items() if ds.attrs["status"] != "converged"]
    return Value(len(bad), f"of {len(runs)}: {', '.join(bad)}" if bad else f"of {len(runs)}")


@quantity("largest pair-reaction change in one step over w, per (1 + typing precision)", fmt=".9f", over="runs")
def pair_increment(runs, typed_precision):
    """[run, its step-by-step replay]: the largest |R_p(n+1) - R_p(n)| over steps and pairs, over the particle
    weight, divided by 1 + the precision R_pu and l_pu are typed with."""
    ds, replay = runs
    w = float(ds["weight"].values.max())
    x = replay["max_pair_increment"].item() / w
    kp = float(ds.attrs["forces.pair.r_u"]) / float(ds.attrs["forces.pair.l_u"])
    return Value(x / (1 + typed_precision), f"{x:.9f} w at step {replay['at_step'].item():,}; 2 k_p du = "
                                            f"{2 * kp * float(ds.attrs['solver.du']):.3g} N, w = {w:g} N")


# ------------------------------------------------------------------------------------------ the laws
def wall_distance(pos, walls):
    """(N,) distance [cm] of each position to its nearest wall segment."""
    pos = np.asarray(pos, float)
    out = np.full(len(pos), np.inf)
    for x0, y0, x1, y1 in np.asarray(walls, float):
        e = np.array([x1 - x0, y1 - y0])
        t = np.clip(FO.dot2(pos - [x0, y0], e) / FO.dot2(e, e), 0.0, 1.0)
        d = pos - (np.array([x0, y0]) + t[:, None] * e)
        out = np.minimum(out, np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2))
    return out


def _min_pair_distance(pos, cutoff):
    pi, pj = M.pairs(np.asarray(pos, float), cutoff)
    d = pos[pi] - pos[pj]
    return float(np.sqrt((d ** 2).sum(1)).min()) if len(pi) else float("inf")


@quantity("|l_bu - nearest initial wall distance|", "cm", fmt=".3g")
def lbu_rule(ds):
    lb = float(wall_distance(ds["pos0"].values, ds["wall_segment"].values).min())
    return Value(abs(float(ds.attrs["forces.wall.l_u"]) - lb), f"l_bu {float(ds.attrs['forces.wall.l_u']):g} cm, nearest {lb:.7g} cm")


@quantity("|l_pu - a / sqrt(2)|", "cm", fmt=".3g")
def lpu_rule(ds):
    side = float(ds.attrs["spacing"]) / math.sqrt(2)
    return Value(abs(float(ds.attrs["forces.pair.l_u"]) - side), f"l_pu {float(ds.attrs['forces.pair.l_u']):.7f} cm, a/sqrt(2) {side:.7f}")


@quantity("largest wall reaction", "kN", fmt=".3f")
def max_wall_reaction(ds):
    return IM.wall_law_usage(ds)["max_wall_reaction_N"] / 1000


@quantity("largest reduction of a wall distance below l_bu", "of l_bu", fmt=".4%")
def wall_gap_reduction(ds):
    return IM.wall_law_usage(ds)["wall_gap_reduction"]


@quantity("k_p / k_b", fmt=".6g")
def stiffness_ratio(ds):
    a = ds.attrs
    return (float(a["forces.pair.r_u"]) / float(a["forces.pair.l_u"])) / (float(a["forces.wall.r_u"]) / float(a["forces.wall.l_u"]))


@quantity("largest departure of a refined input from its section 6.1 rule", "relative", fmt=".3g")
def refined_rules(ds, rbu_factor, kp_over_kb, increment_over_w):
    """max over the rules (R_bu vs rbu_factor max R_b; l_bu vs the initial wall gap; k_p / k_b vs kp_over_kb; the
    reaction increment of a pair one of whose particles moves du along it, k_p du, vs increment_over_w w, as the
    coarse application reads the du rule: k_p du = 1000 N/cm x 0.01 cm = w/5) of |value / rule - 1|."""
    a = ds.attrs
    kb, kp = float(a["forces.wall.r_u"]) / float(a["forces.wall.l_u"]), float(a["forces.pair.r_u"]) / float(a["forces.pair.l_u"])
    w = float(ds["weight"].values.max())
    rules = {"R_bu / 10 max R_b": (float(a["forces.wall.r_u"]), rbu_factor * IM.wall_law_usage(ds)["max_wall_reaction_N"]),
             "l_bu / initial gap": (float(a["forces.wall.l_u"]), float(wall_distance(ds["pos0"].values, ds["wall_segment"].values).min())),
             "k_p / k_b / (1/2)": (kp / kb, kp_over_kb),
             "k_p du / (w/5)": (kp * float(a["solver.du"]), w * increment_over_w)}
    off = {k: x / y - 1 for k, (x, y) in rules.items()}
    return Value(max(abs(v) for v in off.values()), ", ".join(f"{k} {v:+.1%}" for k, v in off.items()))


# ------------------------------------------------------------------------------------------ levels and loads
@quantity("free-surface level above the floor", "cm", fmt=".2f")
def surface(ds, vessel=None, level=SURFACE):
    """The free surface of a vessel (first or second; None the whole scene) above its floor, under a level definition
    (claims input level_definition; default the project's one surface)."""
    return Value(level_above_floor(ds, vessel, level), level)


@quantity("area loss against the initial lattice", "of A_0", fmt=".1%")
def area_loss(ds, level=SURFACE):
    """1 - (level - floor) / (initial level - floor) of a single vessel, both under the same level definition."""
    v = M.vessel_view(ds)
    init = T.free_surface_level(ds["pos0"].values, float(ds.attrs["spacing"]), v["x_range"]) + _offset(ds, level)
    now = level_above_floor(ds, None, level) + v["floor_y"]
    return Value(1 - (now - v["floor_y"]) / (init - v["floor_y"]), f"{now:.2f} cm from {init:.2f} cm")


@quantity("second vessel's area per particle lost against the initial lattice", "of A_0", fmt=".1%", over="runs")
def area_loss_second(runs, level=SURFACE):
    """[flow run, its chain's single-vessel run]: 1 - (area per particle in the second vessel) / (the initial
    lattice's), both under the same level definition."""
    fc, sc = runs
    v2, v1 = M.vessel_view(fc, M.vessels(fc)[-1]), M.vessel_view(sc)
    per2 = v2["width"] * level_above_floor(fc, "second", level) / int(v2["inside"].sum())
    top0 = T.free_surface_level(sc["pos0"].values, float(sc.attrs["spacing"]), v1["x_range"]) + _offset(sc, level)
    per0 = v1["width"] * (top0 - v1["floor_y"]) / sc.sizes["particle"]
    return Value(1 - per2 / per0, f"{per2:.1f} against {per0:.1f} cm^2")


def loads(ds, vessel=None, level=SURFACE):
    """Wall-load errors of a vessel against a hydrostatic liquid of its own weight whose surface is the level:
    {side wall: relative error of its total}, contact_rms (per-contact error in gamma h a), floor_err, depth."""
    vname = _vessel(ds, vessel)
    v = M.vessel_view(ds, vname)
    lev = level_above_floor(ds, vessel, level) + v["floor_y"]
    walls = ds["wall_segment"].values
    weight = float(ds["weight"].values[v["inside"]].sum())
    h = lev - v["floor_y"]
    gamma = weight / (v["width"] * h)
    cw = np.where(M.contact_in_vessel(ds, v["x_range"]), ds["contact_wall"].values, -1)
    f = ds["contact_force"].values
    mag = np.sqrt(f[:, 0] ** 2 + f[:, 1] ** 2)
    th = T.contact_theory(walls, cw, ds["contact_point"].values, gamma, lev, v["wall_in"])
    sides, floor = {}, float("nan")
    for w, name in enumerate(str(n) for n in ds["wall"].values):
        if not v["wall_in"][w]:
            continue
        total, ttot = float(mag[cw == w].sum()), T.wall_total(walls[w], gamma, lev)
        if v["horizontal"][w] and np.isclose(walls[w, 1], v["floor_y"]):
            floor = (total - ttot) / ttot
        elif not v["horizontal"][w] and ttot > 0:
            sides[name] = (total - ttot) / ttot
    wet = np.isfinite(th)
    rms = float(np.sqrt(np.mean(((mag[wet] - th[wet]) / (gamma * h * M.panel_length(ds))) ** 2)))
    return sides, rms, floor, h


@quantity("worst of the side-wall errors and the per-contact RMS (gamma h a)", fmt=".3f")
def wall_worst(ds, vessel=None, level=SURFACE):
    """max(|side-wall total error| of each wetted side wall, RMS per-contact error in units of gamma h a)."""
    sides, rms, floor, h = loads(ds, vessel, level)
    return Value(max([abs(x) for x in sides.values()] + [rms]),
                 ", ".join(f"{w} {x:+.1%}" for w, x in sides.items()) + f", RMS {rms:.3f}, floor {floor:+.2%}, "
                                                                      f"depth {h:.2f} cm")


@quantity("largest side-wall error", fmt=".3f")
def side_worst(ds, level=SURFACE):
    sides, _, _, _ = loads(ds, None, level)
    return Value(max(abs(x) for x in sides.values()), ", ".join(f"{w} {x:+.1%}" for w, x in sides.items()))


@quantity("per-contact RMS error (gamma h a)", fmt=".3f")
def contact_rms(ds, level=SURFACE):
    return loads(ds, None, level)[1]


@quantity("rhombic lattice's advantage: square's worst error minus rhombic's", fmt=".3f", over="runs")
def rhomb_advantage(runs, level=SURFACE):
    """[rhombic run, alternative run]: the alternative's worst wall error minus the rhombic one's."""
    rh, sq = (wall_worst(ds, None, level) for ds in runs)
    return Value(sq.value - rh.value, f"rhombic {rh.value:.3f} ({rh.text}); alternative {sq.value:.3f} ({sq.text})")


@quantity("largest interior rhomb area loss", "of A_0", fmt=".1%")
def rhomb_loss(ds):
    c = IM.compressibility(ds)
    return Value(c["rhomb_loss_max"], f"mean {c['rhomb_loss_mean']:.1%}")


# ------------------------------------------------------------------------------------------ the flows
@quantity("largest |pos0 - the start run's final positions|", "cm", fmt=".3g", over="runs")
def start_offset(runs):
    """[run, the run it starts from]: how far its initial state is from the other's final one."""
    run, start = runs
    return float(np.abs(run["pos0"].values - start["pos"].values).max())


@quantity("opening height above the first floor", "cm", fmt=".4g")
def opening(ds):
    walls = ds["wall_segment"].values
    v1 = M.vessel_view(ds, M.vessels(ds)[0])
    x1 = v1["x_range"][1]
    vert = [w for w in walls if np.isclose(w[0], x1) and np.isclose(w[2], x1)]
    lows = sorted(min(w[1], w[3]) for w in vert if max(w[1], w[3]) > v1["floor_y"])
    return (lows[0] - v1["floor_y"]) if lows else float("nan")


@quantity("vessel width", "cm", fmt=".4g")
def vessel_width(ds, vessel):
    return M.vessel_view(ds, _vessel(ds, vessel))["width"]


@quantity("fraction in the second vessel", fmt=".1%")
def transferred(ds):
    n2 = M.flow_measures(ds)[f"particles_{M.vessels(ds)[-1]}"]
    return Value(n2 / ds.sizes["particle"], f"{n2} of {ds.sizes['particle']} at step {int(ds['steps']):,}")


@quantity("particles left in the first vessel")
def particles_left(ds):
    return int(M.flow_measures(ds)["particles_left"])


@quantity("largest |F| on a particle left in the first vessel", "N", fmt=".3g")
def left_force(ds):
    """max(|F_x|, |F_y|) over the particles the flow leaves in the first vessel (per-particle force field)."""
    x0, x1 = M.vessel_view(ds, M.vessels(ds)[0])["x_range"]
    inside = (ds["pos"].values[:, 0] >= x0) & (ds["pos"].values[:, 0] < x1)
    f = np.abs(ds["force"].values[inside])
    return Value(float(f.max()) if inside.any() else 0.0, f"{int(inside.sum())} particles")


@quantity("largest move from the end state to the continued equilibrium", "du", fmt=".3g", over="runs")
def settle_move(runs):
    """[run, its capped continuation]: max |pos_settled - pos_end| / du."""
    end, settled = runs
    return Value(float(np.abs(settled["pos"].values - end["pos"].values).max()) / float(end.attrs["solver.du"]),
                 f"continuation {settled.attrs['status']} at step {int(settled['steps']):,}")


@quantity("second-vessel level minus ((N - left) / N) x first level x (B_1 / B_2)", "cm", fmt="+.2f", over="runs")
def level_consistency(runs, level=SURFACE):
    """[flow run, the single-vessel run it continues]: the paper's section 6.4 expectation applied to our numbers."""
    fc, sc = runs
    y2 = level_above_floor(fc, "second", level)
    n, left = fc.sizes["particle"], M.flow_measures(fc)["particles_left"]
    ratio = M.vessel_view(fc, M.vessels(fc)[0])["width"] / M.vessel_view(fc, M.vessels(fc)[-1])["width"]
    expect = (n - left) / n * level_above_floor(sc, None, level) * ratio
    return Value(y2 - expect, f"{y2:.2f} against {expect:.2f} cm")


@quantity("second vessel's surface range", "cm", fmt=".1f")
def surface_range(ds):
    s = M.surface_measures(ds, M.vessels(ds)[-1])
    return Value(s["surface_range_cm"], f"slope {s['slope_deg']:+.1f} deg")


@quantity("mean pair-list entries per particle-step", fmt=".3f")
def pairs_per_particle(ds):
    """Mean pair-list entries per particle (pairs within l_pu + skin, what the compiled loop evaluates per step) over
    the run's recorded states: initial, snapshots, final."""
    states = [ds["pos0"].values, *(list(ds["snap_pos"].values) if "snap_pos" in ds else []), ds["pos"].values]
    rc = float(ds.attrs["forces.pair.l_u"]) + float(ds.attrs["solver.skin"])
    return float(np.mean([len(M.pairs(np.asarray(p, float), rc)[0]) / len(p) for p in states]))


@quantity("refined / coarse particle-steps to max|F| < f_tol", fmt=".3g", over="runs")
def particle_steps_ratio(runs):
    """[refined, coarse]: (N x converged step) ratio; NaN when the coarse run never converges (it saves nothing),
    inf when only the refined one never does."""
    ref, co = runs
    a, b = (float(getattr(v, "value", v)) for v in (converged_step(ref), converged_step(co)))
    if not np.isfinite(b):
        return Value(float("nan"), "the coarse run never converges")
    if not np.isfinite(a):
        return Value(float("inf"), "the refined run never converges")
    return (ref.sizes["particle"] * a) / (co.sizes["particle"] * b)


TAU = np.linspace(0.0, 5.0, 501)


@quantity("largest return flow (fall of the transferred fraction below its running maximum)", "of N", fmt=".4f", over="runs")
def return_flow(runs):
    """A flow chain's runs in order: the largest fall of the second vessel's share below its running maximum."""
    _, f = IM.transfer_curve(list(runs))
    f = np.asarray(f, float)
    return float((np.maximum.accumulate(f) - f).max()) if len(f) else 0.0


# ------------------------------------------------------------------------------------------ printed numbers
@quantity("area loss the paper's levels imply, lower bound", "of A_0", over="numbers", fmt=".1%")
def implied_loss(numbers, y_eq, y_in, a, level=SURFACE):
    """1 - (y_eq + s) / y_in with the paper's reading given its uncertainty in its favour: s = a/4 (the half layer
    pitch), or 5 cm under the paper's own y_in reading (top centres + 5 cm)."""
    s = 5.0 if level == "top centres + 5 cm" else numbers[a] / 4
    return Value(1 - (numbers[y_eq] + s) / numbers[y_in], f"1 - ({numbers[y_eq]:g} + {s:g}) / {numbers[y_in]:g}")


@quantity("area loss of the second vessel against the initial lattice, paper's numbers", "of A_0", over="numbers",
          fmt=".1%")
def implied_loss_second(numbers, level=SURFACE):
    """1 - ((y_2 + s) B_2) / (((N - left) / N) y_in B_1): s = a/4 = 2.5 cm, or 5 cm under the paper's y_in reading."""
    s = 5.0 if level == "top centres + 5 cm" else 2.5
    n, left = numbers["particles"], numbers["particles_left"]
    return 1 - (numbers["level_second_cm"] + s) * numbers["width_second_cm"] / (
        (n - left) / n * numbers["y_in_cm"] * numbers["width_first_cm"])


@quantity("flow steps after application 1", over="runs")
def flow_steps(runs):
    """[flow run, the single-vessel run its chain starts from]: the steps of the flow chain after application 1 (the
    paper counts 'from beginning of first application', of which application 1 took its own steps)."""
    flow, app1 = runs
    return Value(int(flow["steps"]) - int(app1["steps"]), f"chain step {int(flow['steps']):,}, application 1 "
                                                             f"{int(app1['steps']):,}")


@quantity("step of the first max|F| < f_tol, counted as the paper counts", over="runs")
def chain_converged_step(runs, app1_steps, paper_steps=None, n_u=None):
    """[flow run, the single-vessel run its chain starts from]: the converged step of the flow chain with application
    1 counted at the paper's own step count (app1_steps) instead of its steps here; NaN if it never converges (or
    only past n_u x paper_steps, a step-limit reading)."""
    flow, app1 = runs
    if _within(flow, n_u, paper_steps) != "converged":
        return Value(float("nan"), f"never: {outcome_text(flow)}")
    return Value(int(flow["steps"]) - int(app1["steps"]) + app1_steps,
                 f"{int(flow['steps']) - int(app1['steps']):,} flow steps after application 1")


@quantity("max|F| over the last records", "N", fmt=".3g")
def fmax_window(ds, last, stat="min"):
    """max|F| read over the last ``last`` steps of the run's records (stat: min, mean or max), with its extremes."""
    steps, f = ds["hist_step"].values, ds["hist_fmax"].values
    w = f[steps >= steps[-1] - last]
    return Value(float({"min": np.min, "mean": np.mean, "max": np.max}[stat](w)),
                 f"{w.min():.3g}-{w.max():.3g} N over the last {last:,} steps ({len(w)} records)")
