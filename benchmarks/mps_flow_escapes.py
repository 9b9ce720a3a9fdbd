"""The 12 MPS flows (3 source terms x l0 = 5.56, 3.45 cm x flow_step50, flow_samefloor), each continuing its
3 s single-vessel run, for 8 s: status (escaped or not), time reached, wall-line reflections of the
penetration guard (walls.reflect), cost per step; and the single runs' side loads (mean of the left and right
wall loads over 0.1-0.3 s and over the last 0.5 s, against rho g h^2 / 2 = 3262.5 N).  The full check behind
tests/test_mps.py::test_every_flow_runs_without_an_escape (which runs the first escape's flow for 1 s); too
slow for the test suite (about 10 minutes on one core).

Writes benchmarks/results/mps_flow_escapes.csv (or --out=PATH).  Run: python benchmarks/mps_flow_escapes.py
[--out=PATH] [setting=value ...] (settings overrides, e.g. walls.reflect=false).
"""

import sys
import time
from pathlib import Path

import numba
import numpy as np
import pandas as pd

from isaflow.methods.mps import settings, solver
from isaflow.tank import load as load_tank

ROOT = Path(__file__).resolve().parents[1]
CFG = ROOT / "config" / "methods" / "mps.yaml"
FLOW_TIME = 8.0  # s


def side_loads(r):
    h = r.history
    t = h["sample_time"][1]
    F = np.hypot(*np.moveaxis(h["sample_panel_force"][1], -1, 0))
    on = (t >= 0.1) & (t <= 0.3)
    early = np.mean([F[on][:, r.contact_wall == w].sum(1).mean() for w in (0, 2)])
    late = np.mean([np.hypot(*r.contact_force[r.contact_wall == w].T).sum() for w in (0, 2)])
    return early / 3262.5 - 1, late / 3262.5 - 1


def main(args):
    out = ROOT / "benchmarks" / "results" / "mps_flow_escapes.csv"
    overrides = []
    for arg in args:
        if arg.startswith("--out="):
            out = Path(arg.removeprefix("--out="))
        else:
            overrides.append(arg)
    numba.set_num_threads(1)
    quiet = lambda *a: None  # noqa: E731
    rows = []
    for res in ("dx5.56", "dx3.45"):
        for variant in ("standard", "hattori", "mixed"):
            cfg = settings.resolved(CFG, variant=variant, resolution=res, overrides=overrides)
            l0 = cfg["resolution.spacing"]
            w0 = time.perf_counter()
            single = solver.solve(load_tank(ROOT / "config" / "tanks" / "single.yaml"), cfg, variant, l0,
                                  cfg["time.single_time"], cfg["probes.single"], threads=1, log=quiet)
            early, late = side_loads(single)
            rows.append(dict(run=f"single_{variant}_{res}", status=single.status, t_end_s=single.sim_time,
                             time_to_rest_s=float(single.measures["time_to_rest"][1]),
                             side_err_early=early, side_err_late=late, reflected=single.params["reflected_particles"],
                             ms_per_step=1e3 * (time.perf_counter() - w0) / single.steps))
            print(rows[-1], flush=True)
            start = dict(pos=single.pos, vel=single.fields["velocity"][1], steps=single.steps,
                         sim_time=single.sim_time, initial_depth=single.params["initial_depth"])
            for tank, name in (("flow_step50", "flow"), ("flow_samefloor", "samefloor")):
                w0 = time.perf_counter()
                r = solver.solve(load_tank(ROOT / "config" / "tanks" / f"{tank}.yaml"), cfg, variant, l0, FLOW_TIME,
                                 cfg["probes.flow"], start=start, threads=1, log=quiet)
                steps = r.steps - r.start_step
                rows.append(dict(run=f"{name}_{variant}_{res}", status=r.status, t_end_s=r.sim_time - single.sim_time,
                                 reflected=r.params["reflected_particles"], reflect_steps=r.params["reflect_steps"],
                                 graze_steps=r.params["graze_steps"], deepest_graze_cm=r.params["deepest_graze_cm"],
                                 max_speed_cm_s=float(np.max(r.history["sample_max_speed"][1])),
                                 ms_per_step=1e3 * (time.perf_counter() - w0) / max(1, steps),
                                 message=r.message))
                print(rows[-1], flush=True)
    out.parent.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(rows).to_csv(out, index=False, float_format="%.6g")
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv[1:])
