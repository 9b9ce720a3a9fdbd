"""Settings of the solid method (config/methods/solid.yaml), read by the one loader (isaflow.settings).

Every value is ``{value: ..., source: "..."}``; unknown keys are rejected and
a bad file raises isaflow.inputs.InputError naming the file and field.
"""

from isaflow import preflight
from isaflow import settings as S
from isaflow.core.units import KG, PA


POS = {"type": "number", "exclusiveMinimum": 0}
COUNT = {"type": "integer", "minimum": 1}


SECTIONS = {
    "material": dict(E_GPa=POS, nu={"type": "number", "minimum": 0, "exclusiveMaximum": 0.5}, rho_kg_m3=POS),
    "solver": dict(tol=POS, max_steps=COUNT, max_steps_mechanism=COUNT),
    "bar": dict(particles={"type": "array", "items": COUNT, "minItems": 3, "maxItems": 3}, dx_mm=POS,
                        pull_um=POS, grips={"enum": ["clamped", "sliding"]}, exaggeration=POS),
    "shear": dict(particles={"type": "array", "items": COUNT, "minItems": 3, "maxItems": 3},
                          grip_layers={"type": "integer", "minimum": 0}, deflection_um=POS, height_cm=POS),
    "hertz": dict(plate={"type": "array", "items": COUNT, "minItems": 2, "maxItems": 2}, dx_um=POS,
                          radius_mm=POS, depths_um={"type": "array", "items": POS, "minItems": 1},
                          plane={"enum": ["strain"]}, paper_dt_ns={"type": "array", "items": POS},
                          dt_check_steps=COUNT, scale_radii_mm={"type": "array", "items": POS, "minItems": 1},
                          eq27_vfloor_m_s=POS, eq27_record_every=COUNT,
                          depths_alt_um={"type": "array", "items": POS, "minItems": 1}),
    "bar_long": dict(strain=POS, strain_sweep={"type": "array", "items": POS, "minItems": 1}, dt_over_dx_c=POS,
                     dt_sweep={"type": "array", "items": POS, "minItems": 1}, steps=COUNT,
                     perturbation_dx={"type": "number", "minimum": 0}, seed={"type": "integer", "minimum": 0},
                     record_every=COUNT),
    "vessel": dict(dx_mm=POS, ring_particles=COUNT, water_radius_particles=COUNT, pressure_Pa=POS,
                           K_GPa=POS, rho_water_kg_m3=POS, steps=COUNT, dt_ns=POS,
                           solid_model={"enum": ["paper", "hooke", "objective"]}, history_us=POS, record_every=COUNT,
                           water_kernel={"enum": ["cubic_spline", "wendland_c2", "wendland_c4", "wendland_c6"]},
                           water_h_over_dx=POS, water_alpha={"type": "number", "minimum": 0},
                           coupling={"enum": ["mirror_pressure", "stop_at_boundary"]},
                           water_h_sweep={"type": "array", "items": {"type": "number", "minimum": 1.0}},
                           water_alpha_sweep={"type": "array", "items": {"type": "number", "minimum": 0}}),
    "floor": dict(span_cm=POS, dx_cm=POS, layers=COUNT, supports={"enum": ["simply_supported"]},
                          solid_model={"enum": ["paper", "hooke", "objective"]}, weight_N=POS, max_steps=COUNT),
}
# {dotted key: JSON schema of the value} of config/methods/solid.yaml
VALUES = {f"{sec}.{k}": v for sec, fields in SECTIONS.items() for k, v in fields.items()}


def checked_values(path):
    """{section: {key: value}} of a settings file, values as written (sources dropped); plausibility and the
    cost of every case checked (isaflow.preflight)."""
    s = S.load(path, VALUES, what="solid settings")
    preflight.check("solid", None, s)
    return s.tree()


def material_units(mat):
    """(E N/cm^2, nu, rho N s^2/cm^4) from the file's GPa and kg/m^3."""
    return mat["E_GPa"] * 1e9 * PA, mat["nu"], mat["rho_kg_m3"] * KG / 1e6


def claim_run_ids(config_path):
    """The run ids '<case>_<variant>' the claims registry asks for, from the settings file: the Hertz plate under
    every hertz.scale_radii_mm disk, eqs. 26-27 stepping (paper, hooke) and eq. 27 alone, the bar in sustained
    tension at every bar_long strain x step (the kept pair named bar_tension_long), the vessel with water under
    the printed solid model, with the project's coupling and with the paper's (stop at the boundary; and with the
    paper's at every vessel.water_h_sweep and water_alpha_sweep value), the printed bar held by axial-only grips and
    the printed plate pressed to hertz.depths_alt_um."""
    c = checked_values(config_path)
    radii = [f"{r:g}mm" if r < 1000 else f"{r / 1000:g}m" for r in c["hertz"]["scale_radii_mm"]]
    lg = c["bar_long"]
    sweep = [f"bar_tension_long_e{100 * e:g}_dt{d:g}_paper" for e in lg["strain_sweep"] for d in lg["dt_sweep"]
             if (e, d) != (lg["strain"], lg["dt_over_dx_c"])]
    return ([f"hertz_R{r}_paper" for r in radii] + ["hertz_eq27_paper", "hertz_eq27_hooke", "hertz_eq27_uncapped_paper",
            "bar_tension_long_paper"] + sweep + ["vessel_water_particles_paper", "vessel_water_stop_paper"]
            + [f"vessel_water_stop_h{h:g}_paper" for h in c["vessel"]["water_h_sweep"]]
            + [f"vessel_water_stop_a{a:g}_paper" for a in c["vessel"]["water_alpha_sweep"]]
            + ["bar_tension_sliding_paper", "bar_compression_sliding_paper", "hertz_loadsteps_paper"])
