"""Report section: the paper's method on the flows (applications 3-6, Figures 9-10, Table 1 steps)."""

import pandas as pd
from ....report import md_table, write
from ....inputs import read_yaml
from ....settings import plain
from ....figures.animation import report_line

RUN_IDS = ("run ids: `flow_incomplete` (application 3: from `single_coarse`'s state to step 100,000), "
           "`flow_complete` (application 4: continues it), `_capped` the named variant that reaches f_tol, "
           "`flow_complete_du005` / `_du02` the whole flow with du halved / doubled, `flow_samefloor_*` the rejected "
           "reading with both floors level, `flow_refined_*` Table 1 rows 5-6 (never run by the paper). Steps count "
           "from the start of application 1 (or 2).")


def flow_section(metrics, config, outputs):
    """results/report/20_flow.md: every flow run's outcome, what is left behind and the second vessel's surface."""
    cfg = plain(read_yaml(config)[1])  # the values of the sourced file
    runs = [r for chain in cfg["flow"]["chains"].values() for r in chain[1:]] + list(cfg["flow"]["sensitivity"])
    m = pd.read_csv(metrics).set_index("run")
    t = m.loc[[r for r in dict.fromkeys(runs) if r in m.index]]
    show = pd.DataFrame({
        "run": t.index, "outcome": t["status"].values, "steps": t["steps"].astype(int).values,
        "max abs F (N)": t["residual"].map("{:.3g}".format).values,
        "left in vessel 1": t["particles_left"].astype(int).values,
        "vessel 2 level (cm)": t["depth"].round(1).values, "slope (deg)": t["slope_deg"].round(1).values,
        "surface range (cm)": t["surface_range_cm"].round(1).values,
        "floor err": t["floor_err"].map("{:+.3f}".format).values, "side err": t["side_err"].map("{:+.2f}".format).values,
        "K": t["stress_ratio"].round(2).values})
    text = ["## The paper's method: flow into the second vessel (applications 3-6, Figures 9-10)", "", RUN_IDS, "",
            md_table(show), "",
            "Vessel 2 columns describe the receiving vessel: level = mean top particle per strip above its floor; "
            "slope and range of that profile (a liquid at rest: about 0); K = sigma_xx / sigma_yy of its interior "
            "(a fluid: 1; above 1 the inflow's lateral stress is locked in). Table 1 with our step counts and "
            "times: `results/isa/table1.md`, made by the workflow and not tracked (its times change from run to "
            "run; they are in [`docs/timing.md`](timing.md)).", "",
            report_line("figures/isa_flow_animation.gif", "the paper's coarse flow (applications 3-4), particles "
                        "coloured by |F|"), ""]
    write(text, outputs[0])
