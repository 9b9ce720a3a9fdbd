"""Quantities of the solid runs and of marko2017's printed numbers (config/claims/marko2017.yaml ``checks``).

Each is entered with :func:`isaflow.quantities.quantity`; the registry row states the runs, the reduction and the
comparison (isaflow.judge).  The readings of the row's inferred inputs reach them as keyword parameters (the
inputs' sweep ``params``), their defaults the kept readings: ``length`` (bar_length), ``necking`` (necking_reading),
``height_dx`` (shear_height), ``plane`` (hertz_plane), ``load_reading`` (hertz_load_reading), ``speed``
(sound_speed), ``scale`` (hertz_scale_reading).  A run quantity naming ``numbers`` is given the row's printed
numbers (the input-rule rows compare a run's settings with the page).  No tolerance, paper number or run id lives
here.  Run files in cm, N, s (stresses N/cm^2); printed numbers in the units of their ``units``; theory.py in SI.
"""

import math

import numpy as np

from ...core.units import PA
from ...judge import NoRun
from ...quantities import Value, quantity
from . import theory as T
from .cases import UM

BROKEN = ("escaped", "nonfinite")


def _first(ds, name):
    return float(np.asarray(ds[name].values, float).ravel()[0])


def _shape(ds):
    """Particles along each lattice axis of a run."""
    idx = ds["lattice_index"].values
    return [int(idx[:, k].max()) + 1 for k in range(idx.shape[1])]


def _mpa(x):
    return float(x) / PA / 1e6


# ------------------------------------------------------------------------------------------- any solid run
@quantity("largest particle move in one step", "dx", fmt=".3g")
def step_move(ds):
    """The largest move of any particle (ring and water particles alike) in one step over dx, the paper's stability
    standard (eq. 27: no particle moves more than 10 % of its width in a step); infinite when the run escaped (a
    particle left its width) or went non-finite, whatever it moved before."""
    move = float(ds.attrs["max_step_move_over_dx"])
    if "water_max_step_move_over_dx" in ds:
        move = max(move, _first(ds, "water_max_step_move_over_dx"))
    st = str(ds.attrs["status"])
    return Value(math.inf if st in BROKEN else move, st + (f" at step {int(ds['steps']):,} ({move:.3g} dx before)"
                                                           if st in BROKEN else ""))


@quantity("largest step over eq. 26's dx / (4 C_s), minus 1", fmt=".3g")
def dt_over_eq26(ds):
    """The largest step a run took over eq. 26's dt_max (C_s = sqrt(E / rho), the run's), minus 1: <= 0 when eq. 26
    capped every step."""
    a = ds.attrs
    return Value(float(a["dt_max_s"]) / float(a["dt_rule_s"]) - 1,
                 f"steps {float(a['dt_min_s']):.3g}-{float(a['dt_max_s']):.3g} s, eq. 26 {float(a['dt_rule_s']):.3g} s")


@quantity("a run's first record of a variable", fmt=".4g")
def record(ds, name):
    """The first value of a run-file variable (a record the case wrote, in its units)."""
    return _first(ds, name)


DERIVED = {  # settings a run holds in its lattice and history rather than in an attribute
    "shape": lambda ds: _shape(ds),
    "shape_2d": lambda ds: _shape(ds)[:2],
    "free_shape": lambda ds: [s - 2 * int(ds.attrs["grip_layers"]) * (k == 1) for k, s in enumerate(_shape(ds))],
    "depth_first": lambda ds: float(ds["depth"].values[0]),
    "depth_last": lambda ds: float(ds["depth"].values[-1]),
    "increments": lambda ds: len(ds["depth"].values),
    "bottom_held_rest_free": lambda ds: float(_bottom_held(ds)),
    "water_radius_particles": lambda ds: float(ds.attrs["a_cm"]) / float(ds.attrs["dx_cm"]),
    "ring_particles": lambda ds: (float(ds.attrs["b_cm"]) - float(ds.attrs["a_cm"])) / float(ds.attrs["dx_cm"]),
}


def _bottom_held(ds):
    bottom = ds["lattice_index"].values[:, 1] == 0
    pos, pos0 = ds["pos"].values, ds["pos0"].values
    return bool(np.all(pos[bottom] == pos0[bottom]) and np.any(pos[~bottom] != pos0[~bottom]))


@quantity("largest relative difference of a run's settings from the page", fmt=".3g")
def settings_vs_page(ds, numbers, pairs):
    """max over pairs {printed number: [setting, factor]} of |setting x factor / number - 1| (factor: the run's units
    to the number's; a setting is a run attribute or one of DERIVED; lists compare element by element), with the
    settings that differ."""
    devs = {}
    for name, (setting, factor) in pairs.items():
        if setting not in DERIVED and setting not in ds.attrs:
            devs[name] = (math.inf, f"the run has no {setting}")
            continue
        ours = DERIVED[setting](ds) if setting in DERIVED else ds.attrs[setting]
        ours, page = np.atleast_1d(np.asarray(ours, float)) * factor, np.atleast_1d(np.asarray(numbers[name], float))
        devs[name] = (float(np.max(np.abs(ours / page - 1))) if ours.shape == page.shape else math.inf,
                      f"{', '.join(f'{x:.7g}' for x in ours)} against {', '.join(f'{x:g}' for x in page)}")
    name = max(devs, key=lambda k: devs[k][0])
    return Value(devs[name][0], f"{len(devs)} settings, the farthest {name}: {devs[name][1]}")


# ------------------------------------------------------------------------------------- 4.1 the bar
def _length(ds, length):
    ny, dx = _shape(ds)[1], float(ds.attrs["dx_cm"])
    return {"held": (ny - 1) * dx, "extent": ny * dx}[length] if isinstance(length, str) else float(length)


@quantity("peak stress over E delta / L", fmt=".7f")
def hooke_ratio(ds, length="held"):
    """sigma_peak (the largest |sigma_yy| of the mid-length layer, with the load's sign) over Hooke's E delta / L, L
    by the reading of input bar_length: 'held' (the held end layers' distance, (ny - 1) dx; kept), 'extent' (ny dx)
    or a length in cm (the stated one)."""
    L = _length(ds, length)
    hooke = float(ds.attrs["E_N_cm2"]) * float(ds.attrs["pull_cm"]) / L
    s = _first(ds, "sigma_peak")
    return Value(s / hooke, f"{_mpa(s):.5f} against {_mpa(hooke):.5f} MPa at L = {L:.4g} cm")


@quantity("peak stress magnitude", "MPa", fmt=".6f")
def peak_stress(ds):
    return abs(_mpa(_first(ds, "sigma_peak")))


KEPT_NECKING = "per side, half-width"


def _necking(reading, nx, ny):
    """(factor from the run's per-side change to the paper's quantity, width d in dx, length L in dx) of a reading of
    input necking_reading: the printed 0.1329 um per side over the half-width (kept) or over the outer particle
    centre's half-width (strain over the held layers), or the total change over the full width."""
    return {"per side, half-width": (1.0, nx / 2, ny), "per side, outer centres": (1.0, (nx - 1) / 2, ny - 1),
            "total, full width": (2.0, nx, ny)}[reading]


def _contraction_um(ds):
    """Per-side contraction at mid-length [um] (the mean of x and z; narrowing positive)."""
    return -0.5 * (_first(ds, "width_change_x") + _first(ds, "width_change_z")) / UM


@quantity("lateral contraction at mid-length", "um", fmt=".4f")
def contraction(ds, necking=KEPT_NECKING):
    """The mid-length contraction as the paper's 0.1329 um is read (input necking_reading): per side, or the total."""
    return _necking(necking, *_shape(ds)[:2])[0] * _contraction_um(ds)


@quantity("equivalent Poisson ratio (eq. 17 inverted)", fmt=".4f")
def poisson(ds, necking=KEPT_NECKING):
    """nu from eq. 17 with the run's own contraction, read as the paper's number is (input necking_reading)."""
    (nx, ny), dx = _shape(ds)[:2], float(ds.attrs["dx_cm"])
    f, d, L = _necking(necking, nx, ny)
    return T.poisson_from_necking(f * _contraction_um(ds) * UM, d * dx, abs(float(ds.attrs["pull_cm"])) / (L * dx))


@quantity("the page's equivalent Poisson ratio (eq. 17 inverted)", over="numbers", fmt=".5f")
def page_poisson(numbers, necking=KEPT_NECKING):
    """nu from eq. 17 with the printed necking, width and pull under a reading of input necking_reading."""
    nx, ny, _ = numbers["particles"]
    _, d, L = _necking(necking, nx, ny)
    dx = numbers["dx_mm"] * 1e-3
    return T.poisson_from_necking(numbers["necking_um"] * 1e-6, d * dx, numbers["pull_um"] * 1e-6 / (L * dx))


@quantity("lateral change against the load over the Poisson value nu |strain| d", fmt=".3g")
def neck(ds):
    """The per-side contraction with the load's sign (narrowing in tension and widening in compression count
    positive) over nu |delta| / (ny dx) x (nx / 2) dx, the change a Poisson ratio nu would give."""
    (nx, ny), dx, pull = _shape(ds)[:2], float(ds.attrs["dx_cm"]), float(ds.attrs["pull_cm"])
    ref = float(ds.attrs["nu"]) * abs(pull) / (ny * dx) * nx / 2 * dx / UM
    return Value(math.copysign(1.0, pull) * _contraction_um(ds) / ref,
                 f"{_contraction_um(ds):+.4f} um, Poisson value {ref:.4f} um")


@quantity("compression's lateral contraction over tension's", fmt=".6f", over="runs")
def bulge_ratio(runs):
    """[compression run, tension run]: the ratio of their mid-length contractions (-1: the same distance, the other
    way); NaN when the tension run does not change its width."""
    comp, tens = (_contraction_um(ds) for ds in runs)
    return Value(comp / tens if tens else math.nan, f"tension {tens:+.4f} um, compression {comp:+.4f} um")


@quantity("the page's peak stress over E delta / L", over="numbers", fmt=".5f")
def page_hooke_ratio(numbers, length="held"):
    """The printed 1.4758 MPa over E delta / L with the printed E and pull, L by the reading of input bar_length."""
    dx = numbers["dx_mm"] / 10
    L = {"held": (numbers["particles_y"] - 1) * dx, "extent": numbers["particles_y"] * dx}.get(length, length)
    return Value(numbers["sigma_MPa"] / (numbers["E_GPa"] * 1e3 * numbers["pull_um"] * 1e-4 / float(L)),
                 f"L = {float(L):.4g} cm")


# ------------------------------------------------------------------------------------- 4.2 shear
@quantity("peak shear stress over G delta / H", fmt=".4g")
def shear_ratio(ds, height_dx=None):
    """tau_peak (the largest tau_yx of the free layers) over G delta / H (eqs. 18-20), H the run's distance between
    its held and moved layers or, under a reading of input shear_height, height_dx particle widths."""
    H = _first(ds, "height") if height_dx is None else float(height_dx) * float(ds.attrs["dx_cm"])
    th = T.shear_stress(T.shear_modulus(float(ds.attrs["E_N_cm2"]), float(ds.attrs["nu"])),
                        float(ds.attrs["deflection_cm"]), H)
    tau = _first(ds, "tau_peak")
    return Value(tau / th, f"{_mpa(tau):.4g} against {_mpa(th):.4f} MPa at H = {H:.3f} cm, {ds.attrs['status']}")


# ------------------------------------------------------------------------------------- 4.3 Hertz contact
def _hertz(ds, increments, plane):
    """(depths m, eq. 25's p_max Pa, E' Pa, R m) of a Hertz run's increments, NaN-padded to the page's increments;
    plane (input hertz_plane): 'strain' E' = E / (1 - nu^2), 'stress' E' = E."""
    E = float(ds.attrs["E_N_cm2"]) / PA
    Er = T.reduced_modulus(E, float(ds.attrs["nu"])) if plane == "strain" else E
    R = float(ds.attrs["radius_cm"]) / 100
    d = np.full(increments, np.nan)
    got = ds["depth"].values[:increments] / 100
    d[:len(got)] = got
    return d, T.hertz_pmax(R, d, Er), Er, R


def _worst(ds, err, depths):
    """Largest |error| over the increments (a depth not reached counts as infinite); an undamped run that did not
    break has only single samples of an oscillation at its increments' ends: NaN (no settled value to read)."""
    if str(ds.attrs["status"]) not in BROKEN and int(ds.attrs.get("damped", 1)) == 0:
        return Value(math.nan, "undamped: no settled value (one sample of an oscillation per increment)")
    worst = math.inf if np.isnan(err).any() else float(np.abs(err).max())
    return Value(worst, ", ".join("none" if np.isnan(e) else f"{e:+.1%}" for e in err) + " at "
                 + ", ".join(f"{x * 1e6:g}" for x in depths if np.isfinite(x)) + f" um, {ds.attrs['status']}")


@quantity("worst peak-pressure error against eq. 25", fmt=".1%")
def pmax_error(ds, increments, plane="strain"):
    """max over the increments of |p_max / eq. 25 - 1|, p_max the largest contact force on a top particle / dx."""
    d, p_th, _, _ = _hertz(ds, increments, plane)
    p = np.full(increments, np.nan)
    got = ds["pmax"].values[:increments] / PA
    p[:len(got)] = got
    return _worst(ds, p / p_th - 1, d)


LOADS = {"line x particle": "line_times_thickness", "line per metre": "line_per_m", "sphere x particle": "sphere"}


@quantity("worst load error against the Hertz load", fmt=".1%")
def load_error(ds, increments, plane="strain", load_reading="line x particle"):
    """max over the increments of |load / Hertz load - 1|, the load the plate's force on the disk (per unit
    thickness; times one plate particle where the reading of input hertz_load_reading names a thickness) against
    theory.load_candidates."""
    d, _, Er, R = _hertz(ds, increments, plane)
    t = float(ds.attrs["dx_cm"]) / 100
    load = np.full(increments, np.nan)
    got = ds["load"].values[:increments] * 100
    load[:len(got)] = got
    ref = T.load_candidates(R, d, Er, t)[LOADS[load_reading]]
    return _worst(ds, load * (1 if load_reading == "line per metre" else t) / ref - 1, d)


@quantity("increments at rest")
def increments_at_rest(ds):
    """How many load increments came to rest (the solver's rest test); 0 for a run that broke down before any did,
    NaN for an undamped run (no rest test)."""
    if "increment_converged" in ds:
        return int(ds["increment_converged"].values.sum())
    return Value(0 if str(ds.attrs["status"]) in BROKEN else math.nan, f"{ds.attrs['status']}, no rest test")


def _speeds(E, nu, rho):
    """{reading of input sound_speed: m/s} of steel (SI in): shear, bar, P-wave."""
    return {"shear": math.sqrt(E / (2 * (1 + nu)) / rho), "bar": math.sqrt(E / rho),
            "P-wave": math.sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho)}


def _speed(numbers, speed):
    return _speeds(numbers["E_GPa"] * 1e9, numbers["nu"], numbers["rho_kg_m3"])[speed]


@quantity("printed step over eq. 26's dx / (4 C_s)", over="numbers", fmt=".3g")
def eq26_ratio(numbers, dt, speed="bar"):
    """The printed step named dt [ns] over eq. 26's longest permitted step dx / (4 C_s) for the printed particle
    size dx_um, C_s by the reading of input sound_speed."""
    cap = numbers["dx_um"] * 1e-6 / (4 * _speed(numbers, speed)) * 1e9
    return Value(numbers[dt] / cap, f"eq. 26: {cap:.3g} ns at C_s = {_speed(numbers, speed) / 1e3:.3g} km/s")


@quantity("speed eq. 27 needs for the printed average step, over C_s", over="numbers", fmt=".3g")
def eq27_speed_ratio(numbers, speed="bar"):
    """0.1 dx / dt (the largest particle speed V_max at which eq. 27 gives the printed step dt_ns) over C_s (input
    sound_speed), for the printed particle size dx_mm."""
    v = 0.1 * numbers["dx_mm"] * 1e-3 / (numbers["dt_ns"] * 1e-9)
    c = _speed(numbers, speed)
    return Value(v / c, f"V_max {v / 1e3:.3g} km/s against C_s {c / 1e3:.3g} km/s")


@quantity("exponent of the Hertz load in delta between the printed depths", over="numbers", fmt=".3f")
def load_exponent(numbers, load_reading="line x particle"):
    """n of P ~ delta^n between the two printed depths for the Hertz load of a reading of input hertz_load_reading
    (the line contact, P' ~ a^2 with eq. 24's chord, whatever thickness multiplies it; a rigid sphere 1.5)."""
    d = np.asarray(numbers["depths_um"], float) * 1e-6
    P = T.load_candidates(numbers["radius_mm"] * 1e-3, d, 1.0, 1.0)[LOADS[load_reading]]
    return float(np.log(P[1] / P[0]) / np.log(d[1] / d[0]))


@quantity("contact half-width sqrt(2 R delta) over the plate's half-width", over="numbers", fmt=".3g")
def contact_over_plate(numbers, scale="same plate"):
    """sqrt(2 R delta) at the smallest stated large radius and the first depth over the plate's half-width (plate_x
    particles of dx_um), the plate as printed ('same plate') or scaled with the radius from radius_mm ('scaled')."""
    R, d = numbers["radius_m"][0], numbers["depth_um"] * 1e-6
    half = numbers["plate_x"] * numbers["dx_um"] * 1e-6 / 2 * (R / (numbers["radius_mm"] * 1e-3) if scale == "scaled"
                                                                else 1)
    return Value(math.sqrt(2 * R * d) / half, f"{math.sqrt(2 * R * d) * 1e3:.1f} mm against {half * 1e3:.3g} mm")


# ------------------------------------------------------------------------------------- 4.4 pressure vessel
def breathing_period(t, u):
    """(period [s], how): the mean time between upward crossings of the history's mean; with fewer than two
    crossings, twice the time of the first maximum (an undamped step response from rest peaks at T / 2; NaN if the
    history ends rising)."""
    dev = u - u.mean()
    cross = t[1:][(dev[:-1] < 0) & (dev[1:] >= 0)]
    if cross.size > 1:
        return float(np.diff(cross).mean()), "between upward crossings"
    k = int(np.argmax(u))
    return (2.0 * float(t[k]) if 0 < k < len(u) - 1 else math.nan), "twice the first maximum"


@quantity("the paper's run over a quarter of the ring's breathing period", fmt=".3f")
def settle_fraction(ds):
    """t_paper (400 steps of 146.8 ns) over T / 4, T the ring's breathing period in the run's own history (its
    recorded period where it has one), with the inner wall's displacement at t_paper over its settled value."""
    tp = _first(ds, "t_paper")
    T_b, how = ((_first(ds, "breathing_period"), "recorded") if "breathing_period" in ds
                else breathing_period(ds["time"].values, ds["u_inner_t"].values))
    settled = _first(ds, "u_inner_settled" if "u_inner_settled" in ds else "u_inner_mean_cycles")
    period = f"T {T_b * 1e6:.0f} us ({how})" if math.isfinite(T_b) else "no period (no oscillation about a radius)"
    return Value(tp / (T_b / 4), f"t_paper {tp * 1e6:.1f} us, {period}, u(t_paper) / settled "
                                 f"{_first(ds, 'u_paper_end') / settled:.2f}")


@quantity("ring's settled inner displacement over Lame's", fmt=".3g")
def expansion_over_lame(ds):
    """The inner wall's settled radial displacement (the mean over whole breathing cycles, or the damped settled
    value) over the elastic one: Lame's thick ring at the pressure the water keeps (at p0 without water)."""
    settled = _first(ds, "u_inner_settled" if "u_inner_settled" in ds else "u_inner_mean_cycles")
    lame = _first(ds, "u_lame_compressible" if "u_lame_compressible" in ds else "u_lame_inner")
    return Value(settled / lame, f"{settled / UM:.3g} um against {lame / UM:.3g} um")


@quantity("smallest radial displacement of a ring particle", "um", fmt=".3g")
def radial_min(ds, window):
    """The smallest u_r of any ring particle: over the records of the paper's run after window x t_paper (window a
    number in [0, 1]) or, window 'cycles', in the mean over whole breathing cycles (the settled state where the run
    was settled)."""
    if window == "cycles":
        u = ds["u_radial_mean_cycles" if "u_radial_mean_cycles" in ds else "u_radial_settled"].values
        return float(np.nanmin(u)) / UM
    t, tp = ds["time"].values, _first(ds, "t_paper")
    keep = (t >= float(window) * tp - 1e-12) & (t <= tp + 1e-12)
    return Value(float(np.nanmin(ds["u_radial_min_t"].values[keep])) / UM, f"{int(keep.sum())} records")


@quantity("water pressure's half-range, last over first quarter of the paper's run", fmt=".3g")
def pressure_swing(ds):
    """The half-range of the mean water pressure in the last quarter of [0, t_paper] over that in the first (NaN for a
    run without water)."""
    if "p_water_t" not in ds:
        raise NoRun("a run with water particles")
    t, p, tp = ds["time"].values, ds["p_water_t"].values, _first(ds, "t_paper")
    edges = np.linspace(0.0, tp, 5)
    q = [0.5 * np.ptp(p[(t >= a - 1e-12) & (t <= b + 1e-12)]) for a, b in zip(edges[:-1], edges[1:])]
    return Value(q[-1] / q[0], "quarters " + ", ".join(f"{x / PA / 1e3:.2f}" for x in q) + " kPa")


# ------------------------------------------------------------------------------------- the elastic floor
@quantity("mid-span deflection over beam theory under the same loads, minus 1", fmt="+.2%")
def floor_error(ds):
    return Value(_first(ds, "w_centre") / _first(ds, "w_centre_actual") - 1, f"{_first(ds, 'w_centre') * 10:.3f} mm")
