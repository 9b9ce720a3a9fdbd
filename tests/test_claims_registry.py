"""The claims registry (config/claims/<paper>.yaml): valid files, unique ids, verbatim quotes, kinds from
the list, a tolerance that can fail on every testable entry, every row of the old 42-row claims table
mapped, run ids that exist (or are flagged new), and the loader's refusals."""

import os
import re
import shutil
from pathlib import Path

import pytest
import yaml

from isaflow import claims_registry as reg
from isaflow.inputs import InputError, load as load_yaml

ROOT = Path(__file__).resolve().parents[1]
CLAIMS_DIR = ROOT / "config" / "claims"
CLAIMS = reg.load(CLAIMS_DIR)
FILES = sorted(CLAIMS_DIR.glob("*.yaml"))


def papers_dir():
    """The shared papers folder: $ISAFLOW_PAPERS, else shared/papers beside any parent of the checkout."""
    env = os.environ.get("ISAFLOW_PAPERS")
    if env:
        return Path(env)
    for parent in ROOT.parents:
        if (parent / "shared" / "papers").is_dir():
            return parent / "shared" / "papers"
    return None


PAPERS = papers_dir()
TEXT = {p: spec["text"] for p, spec in reg.load_files(CLAIMS_DIR).items()}


def test_counts_per_paper_and_kind():
    """The tally printed for the report and the audit note (pytest -s shows it)."""
    table = reg.counts(CLAIMS)
    print("\n" + reg.format_counts(table))
    assert set(table) == set(reg.PAPERS)
    assert sum(sum(r[k] for k in reg.KINDS) for r in table.values()) == len(CLAIMS)
    for p, r in table.items():
        tally = sum(r[k] for k in reg.PAPER_KINDS)
        assert tally == sum(1 for c in CLAIMS if c["paper"] == p and c["kind"] not in reg.OWN_KINDS)
        assert r["independent"] <= r["testable"] <= tally


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_each_file_is_valid(path):
    _, spec = load_yaml(path, reg.SCHEMA, "claims registry file")
    assert spec["paper"] == path.stem
    assert all(c["paper"] == path.stem for c in spec["claims"])


def test_one_file_per_paper_and_unique_ids():
    assert sorted(p.stem for p in FILES) == sorted(reg.PAPERS)
    ids = [c["id"] for c in CLAIMS]
    assert len(ids) == len(set(ids))


def test_kinds_from_the_list():
    assert {c["kind"] for c in CLAIMS} <= set(reg.KINDS)
    assert all(c["id"].startswith("prj-") == (c["kind"] == "project check") for c in CLAIMS)


def test_deviations_say_what_the_paper_and_the_project_do():
    """A row decided by this project's own choice is a stated deviation (issue 31): what the paper says, what the
    project does, why, and the paper's version (its runs when it was run)."""
    devs = [c for c in CLAIMS if c["kind"] == "project deviation"]
    assert {"pap-3.5-stop-rule", "pap-6.1-rpu-half", "pap-6.2-same-way", "mar-3-coupling", "hat-eq4-rho-star",
            "hat-eq5-implicit"} <= {c["id"] for c in devs}
    for c in devs:
        d = c["deviation"]
        assert all(d[k].strip() for k in ("paper", "project", "why", "paper_version")), c["id"]
        listed = reg.declared_runs(c, {})
        assert {r["id"] for r in d.get("runs", [])} <= listed, c["id"]
        assert d.get("runs") or "not run" in d["paper_version"].lower(), c["id"]


def test_no_row_asks_for_what_exists_nowhere_in_the_code():
    """A test that asks for a coupling no source file has can never pass: such a row is a deviation, not a paper
    failure (the stop-at-the-boundary coupling of marko2017 section 3)."""
    src = "\n".join(p.read_text() for p in (ROOT / "src" / "isaflow").rglob("*.py") if p.name != "claims.py")
    for c in CLAIMS:
        if c["kind"] in reg.PAPER_KINDS and c.get("testable") and "stop_at_boundary" in c["tolerance"].get("test", ""):
            assert "stop_at_boundary" in src, c["id"]


def test_shared_root_causes_are_grouped():
    """The paper update's period-2 cycle and the missing Poisson and shear coupling of Marko's printed equations are
    each one root cause (depends_on), counted once on the first screen."""
    roots = reg.roots(CLAIMS)
    by = {c["id"]: c for c in CLAIMS}
    cycle = [k for k, r in roots.items() if "pap-7-isa-oscillations" in r and k != "pap-7-isa-oscillations"]
    assert len([k for k in cycle if by[k]["kind"] == "method result"]) >= 9
    coupling = [k for k, r in roots.items() if {"mar-3-no-poisson", "mar-3-shear-mechanism"} & set(r)]
    assert len([k for k in coupling if by[k]["kind"] == "method result"]) >= 9


def test_post_hoc_marks_name_a_commit_and_what_was_seen():
    marked = [c for c in CLAIMS if c.get("testable") and "post_hoc" in c["tolerance"]]
    assert {"pap-6.3-sum-fx", "pap-6.1-max-rb", "pap-6.1-satisfactory-coarse", "mer-abs-one-nb-residue",
            "mer-abs-one-nb-explicit"} <= {c["id"] for c in marked}
    for c in marked:
        assert re.fullmatch(r"[0-9a-f]{7,40}", c["tolerance"]["post_hoc"]["commit"]) and c["tolerance"]["post_hoc"]["seen"]


def test_findings_name_claims_of_their_file_and_a_figure_of_the_report():
    figures = yaml.safe_load((ROOT / "workflow" / "report" / "figures.yaml").read_text())
    for paper, spec in reg.load_files(CLAIMS_DIR).items():
        assert len(spec.get("findings", [])) <= 5
        for f in spec.get("findings", []):
            assert Path(f["figure"]).stem in figures, f["figure"]


@pytest.mark.skipif(PAPERS is None, reason="shared papers folder not found (set ISAFLOW_PAPERS)")
@pytest.mark.parametrize("claim", [c for c in CLAIMS if "quote" in c], ids=lambda c: c["id"])
def test_quote_is_verbatim(claim):
    """Every fragment of the quote ('...' separates them) occurs in the paper's text, in order, after
    whitespace normalisation."""
    text = (PAPERS / TEXT[claim["paper"]]).read_text(encoding="utf-8")
    body, at = reg.normalise(text), 0
    for frag in reg.fragments(claim["quote"]):
        k = body.find(frag, at)
        assert k >= 0, f"fragment not found (in order): {frag!r}"
        at = k + len(frag)


def test_every_paper_claim_has_a_quote():
    assert all(c.get("quote") for c in CLAIMS if c["kind"] != "project check")


@pytest.mark.parametrize("claim", [c for c in CLAIMS if c["testable"]], ids=lambda c: c["id"])
def test_testable_entries_have_a_tolerance_that_can_fail(claim):
    from isaflow import claims

    t = dict(claim["tolerance"], test=claims.test_text(claim))  # an executable row's test: its checks' comparisons
    assert t["derivation"].strip() and t["source"].strip() and t["test"].strip()
    assert re.match(r"^(page text|paper wording|printed precision|discretisation|physics|statistics|round-off)",
                    t["source"])
    if t["kind"] in ("absolute", "relative", "ratio", "range", "order"):
        assert "value" in t
    if t["kind"] == "range":
        lo, hi = t["value"]
        assert lo < hi
    # a test that cannot fail is no test: it names a comparison or a condition
    assert re.search(r"[<>=]|\b(inconsistent|every|all|each|no|without|more than|monotone|strictly|smaller|"
                     r"exceed|passes|reaches|stays|computes)\b", t["test"]), t["test"]
    if claim["kind"] == "method result":
        assert claim.get("runs") or any(c.get("runs") for c in claim.get("checks", [])), "a method result is judged on runs"


def test_untestable_entries_say_why():
    for c in CLAIMS:
        if not c["testable"]:
            assert c["why_not"].strip() and "tolerance" not in c, c["id"]


def test_references_resolve():
    inputs = reg.inputs(CLAIMS_DIR)
    ids = {c["id"] for c in CLAIMS}
    for c in CLAIMS:
        names = {i["id"] for i in inputs[c["paper"]]}
        assert set(c["inferred_inputs"]) <= names, c["id"]
        assert set(c.get("depends_on", [])) <= ids - {c["id"]}, c["id"]
    for p, lst in inputs.items():
        for i in lst:
            assert set(i.get("calibrated_against", [])) <= ids


def test_every_inferred_input_is_used_by_a_verdict():
    used = {(c["paper"], name) for c in CLAIMS for name in c["inferred_inputs"]}
    for p, lst in reg.inputs(CLAIMS_DIR).items():
        for i in lst:
            assert (p, i["id"]) in used, f"{p}: input {i['id']} rests no verdict"


def test_the_calibrated_level_rows_name_their_calibration():
    k_pair = next(i for i in reg.inputs(CLAIMS_DIR)["papadopoulos2016"] if i["id"] == "k_pair")
    assert set(k_pair["calibrated_against"]) == {"pap-6.1-level-coarse", "pap-6.2-level-refined"}


def test_two_sided_sentences_are_split():
    """Sentences with an ISA half and an SPH or MPS half are two rows (issue 23)."""
    halves = {(c["section"], c["half"]) for c in CLAIMS if "half" in c}
    assert {h for _, h in halves} >= {"isa", "sph", "mps"}
    by_id = {c["id"]: c for c in CLAIMS}
    assert by_id["pap-7-isa-oscillations"]["half"] == "isa" and by_id["pap-7-sph-needs-technique"]["half"] == "sph"
    assert by_id["mar-abs-tensile-solid"]["half"] == "solid" and by_id["mar-1-spam-tensile"]["half"] == "sph"


# --- the 42 rows of docs/replication.md before issue 23: each maps to an entry ('was.row') -------------
OLD_ROWS = [
    "papadopoulos2016 1, 7 | \"approximates dynamic behavior with strong damping\"",
    "papadopoulos2016 1 (introduction) | in the MPS method",
    "papadopoulos2016 6.1, 6.2 | \"in about 2.000 steps",
    "papadopoulos2016 6.4, 7 | \"In about 300,000 steps",
    "papadopoulos2016 6.1 | \"free surface level ... y_eq ~ 72.5 cm\"",
    "papadopoulos2016 6.2 | \"free surface level ... y_eq ~ 75 cm\"",
    "papadopoulos2016 6.1 | \"The approximation between computational and theoretical results",
    "papadopoulos2016 6.2 | \"A slightly improved approximation",
    "papadopoulos2016 5 | \"For small deformations u < 0.293a",
    "papadopoulos2016 5 | \"the area of elementary rhomb has been reduced by only 8.6%\"",
    "papadopoulos2016 6.1 | \"approximate maximum external repulsive reaction",
    "papadopoulos2016 6.1 | \"distance, from boundary to adjacent particle",
    "papadopoulos2016 6.3 | \"In 100,000 steps",
    "papadopoulos2016 6.4 | \"except of few, fourteen",
    "papadopoulos2016 6.4 | \"y_eq ~ 32.0 cm ~ 33.4 cm",
    "papadopoulos2016 Table 1 | \"Steps number ... Computing Time\"",
    "papadopoulos2016 7 | artificial high frequency oscillations are suppressed",
    "marko2017 4.1 | The peak tensile stress of 1.4758 MPa",
    "marko2017 4.1 | the width in the X and Z direction decreased",
    "marko2017 4.1 | yielding an equivalent Poisson's ratio of 0.34125",
    "marko2017 4.1 | the magnitude of the stress was identical to the tension case",
    "marko2017 4.1 | the width in the X and Z direction increased",
    "marko2017 4.2 | shear modulus of G_Y = 79.6154 GPa",
    "marko2017 4.2 | gamma = 18.3429e-6 / 9.3619e-2 = 1.9593e-4",
    "marko2017 4.2 | tau = (79.6154e9) x (1.9593e-4) = 15.5992e6",
    "marko2017 4.2 | The numerical maximum shear stress was observed to be 15.8993 MPa",
    "marko2017 4.3 | E'_Y = 207 / (1 - 0.3^2) = 227.4725",
    "marko2017 4.3 | the peak stress ranging from 7.3 to 10 GPa",
    "marko2017 4.3 | the analytical load to accomplish this would be 2.66 to 5.98 kN",
    "marko2017 4.3 | the error percentages for the peak stress were even lower",
    "marko2017 4.3 | The error percentages for the load varied from 2% to 10.4%",
    "marko2017 4.3 | the simulation under discussion uses time steps ranging from 15 to 56 nanoseconds",
    "marko2017 4.4 | The simulation was ran for 400 time steps",
    "marko2017 4.4 | It was observed that the steel particles are all pushed outwards",
    "marko2017 4.4 | as the liquid pressure stabilizes within the pressure vessel",
    "marko2017 floor | (not in the papers) an elastic floor",
    "hattori eqs. (1)-(5) | By adding the equation (3) and the equation (5)",
    "hattori eq. (6) | Considering the temporal compressibility",
    "merino_alonso2020 abstract | the problem in which each particle has one single neighbor",
    "merino_alonso2020 abstract | When two and three neighbors are involved",
    "merino_alonso2020 abstract | divergent solutions are also found",
    "merino_alonso2020 abstract | In general, the Wendland Kernel C 2 turns out to be the worst choice",
]


def test_every_old_row_maps_to_an_entry():
    assert len(OLD_ROWS) == 42
    was = [c["was"]["row"] for c in CLAIMS if "was" in c]
    for row in OLD_ROWS:
        assert any(w.startswith(row) for w in was), f"old row not mapped: {row}"
    for w in was:  # and every 'was' names one of them
        assert any(w.startswith(row) for row in OLD_ROWS), f"'was' names no old row: {w}"


# --- run ids: the workflow's names, or flagged new_run ------------------------------------------------
def _smk_list(path, name):
    m = re.search(rf"^{name} = \[(.*?)\]", (ROOT / path).read_text(), re.M | re.S)
    return re.findall(r'"([^"]+)"', m.group(1))


def existing_runs():
    """Every run id the workflow defines today, as <method>:<id>: the runs declared in every tank method's
    settings file, ISA's planned groups, the solid runs (its rule file) and the 1D sweep."""
    from isaflow import methods, settings as S

    runs = set()
    for name, m in methods.tank_methods().items():
        runs |= {f"{name}:{r}" for r in S.read(ROOT / m.settings, m.values_schema()).get("runs", {})}
    runs |= {"isa:calibration", "isa:error_vs_runtime", "isa:stability_map"}
    cases = _smk_list("workflow/rules/methods/solid.smk", "SOLID_CASES")
    runs |= {f"solid:{c}_{v}" for c in cases for v in ("paper", "hooke")}
    runs |= {"solid:vessel_pressure_load", "solid:vessel_water_particles", "solid:floor_uniform_uniform_load"}
    runs |= {f"solid:floor_{m}_oneway" for m in methods.tank_methods()}
    runs |= {f"solid:{r}" for r in _smk_list("workflow/rules/methods/solid.smk", "SOLID_CLAIM_RUN_IDS")}
    sweeps = S.read(ROOT / methods.registry()["sph1d"].settings, methods.registry()["sph1d"].values_schema()).get(
        "resolutions", {})  # sph1d.smk: one sweep per resolution
    runs |= set(reg.derived(CLAIMS_DIR))  # claims.smk: the registry's derived numbers
    return runs | {"sph1d:sweep"} | {f"sph1d:sweep_{r}" for r in sweeps}


def test_runs_exist_or_are_flagged_new():
    known = existing_runs()
    listed = [r for c in CLAIMS for r in c.get("runs", [])]
    listed += [{"id": r} for c in CLAIMS for chk in c.get("checks", []) for r in chk.get("runs", [])]
    listed += [{"id": r} for v in reg.paper_versions(CLAIMS_DIR).values() for r in v.values()]
    listed += [r for lst in reg.inputs(CLAIMS_DIR).values() for i in lst for r in i.get("runs", [])]
    for r in listed:
        if r.get("new_run"):
            assert r["id"] not in known, f"{r['id']} exists already: drop new_run"
            assert r["what"].strip()
        else:
            assert r["id"] in known, f"{r['id']} is no run of the workflow: flag it new_run with 'what'"


# --- the loader refuses -------------------------------------------------------------------------------
@pytest.fixture
def registry_copy(tmp_path):
    d = tmp_path / "claims"
    shutil.copytree(CLAIMS_DIR, d)
    return d


def _edit(path, old, new):
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))


def test_copy_loads(registry_copy):
    assert len(reg.load(registry_copy)) == len(CLAIMS)


@pytest.mark.parametrize("case, file, old, new, message", [
    ("duplicate key", "hattori.yaml", "    kind: paper arithmetic\n", "    kind: paper arithmetic\n    kind: input rule\n",
     "duplicate key"),
    ("alias", "hattori.yaml", "    inferred_inputs: []\n", "    inferred_inputs: &x []\n    note: *x\n", "aliases"),
    ("unknown field", "hattori.yaml", "    kind: paper arithmetic\n", "    kind: paper arithmetic\n    verdict: reproduced\n",
     "Additional properties"),
    ("unknown kind", "hattori.yaml", "    kind: paper arithmetic\n", "    kind: result\n", "kind"),
    ("testable without tolerance", "merino_alonso2020.yaml", "    testable: true\n", "    testable: false\n",
     "claims"),
    ("unknown input", "hattori.yaml", "inferred_inputs: [rho_star_reading]", "inferred_inputs: [nowhere]",
     "inferred input 'nowhere'"),
    ("unknown dependency", "papadopoulos2016.yaml", "depends_on: [pap-6.1-steps-coarse, pap-6.2-steps-refined]",
     "depends_on: [pap-9-nothing]", "depends_on"),
    ("wrong prefix", "hattori.yaml", "id: hat-eq1-5-algebra", "id: mer-eq1-5-algebra", "prefix"),
    ("NaN", "hattori.yaml", "value: 1.5\n", "value: .nan\n", "finite"),
    ("unregistered method", "marko2017.yaml", '"solid:floor_uniform_uniform_load"', '"dem:floor"',
     "'dem:floor' names no registered method"),
    ("sweep value outside the range", "papadopoulos2016.yaml", '- {value: 2000, label: "2000 N/cm"',
     '- {value: 3000, label: "2000 N/cm"', "sweep: its values"),
    ("undeclared stand-in run", "papadopoulos2016.yaml", '"isa:single_coarse": "isa:single_coarse_kp1000"',
     '"isa:single_coarse": "isa:single_coarse_kp1500"', "stands in run 'isa:single_coarse_kp1500'"),
    ("two kept sweep values", "papadopoulos2016.yaml", 'label: "250 N/cm", runs', 'label: "250 N/cm", kept: true, runs',
     "more than one value is kept"),
    ("a check's target that is no printed number", "papadopoulos2016.yaml", "op: within, target: level_cm}",
     "op: within, target: level_xx}", "'level_xx' is no printed number of the row"),
    ("derived number no row reads", "hattori.yaml", '- id: "mps:dilation_single_hattori_dx3.45"\n',
     '- id: "mps:dilation_other"\n', "derived.2 ('mps:dilation_other'): no row or input of its file reads it"),
    ("derived from an unregistered method", "merino_alonso2020.yaml", 'from: "sph1d:sweep"', 'from: "dem:sweep"',
     "field 'from' names no registered method"),
    ("derived number defined twice", "hattori.yaml", '- id: "mps:step_check_single_standard_dx3.45"\n',
     '- id: "mps:step_check_single_hattori_dx3.45"\n', "defined twice"),
    ("derived without a function", "hattori.yaml", "compute: methods.mps.derived.dilation",
     "compute: dilation()", "compute"),
])
def test_loader_refuses(registry_copy, case, file, old, new, message):
    _edit(registry_copy / file, old, new)
    with pytest.raises(InputError, match=re.escape(message) if case != "unknown field" else message):
        reg.load(registry_copy)


def test_every_derived_number_names_a_function_and_a_run_of_the_workflow():
    """A derived entry's compute is an isaflow function and its 'from' a run the workflow makes."""
    from isaflow import derived

    known = existing_runs()
    for key, d in reg.derived(CLAIMS_DIR).items():
        assert callable(derived.function(d["compute"])), key
        assert d["from"] in known, f"{key}: from '{d['from']}' is no run of the workflow"
        assert derived.path(key) == f"results/derived/{key.replace(':', '/')}.nc"


def test_a_tank_method_run_is_one_entry_per_tank_method():
    """'{tank_method}' in a run id: the floor under every tank method's liquid, from the registry, in its order
    (a new tank method's floor is judged without editing config/claims/marko2017.yaml)."""
    from isaflow import methods

    floor = next(c for c in CLAIMS if c["id"] == "prj-floor-beam")
    assert "floor_{tank_method}_oneway" in (CLAIMS_DIR / "marko2017.yaml").read_text()
    assert floor["checks"][0]["runs"] == ["solid:floor_uniform_uniform_load"] + [
        f"solid:floor_{m}_oneway" for m in methods.tank_methods()]


def test_loader_refuses_duplicate_ids_across_files(registry_copy):
    text = (registry_copy / "merino_alonso2020.yaml").read_text()
    (registry_copy / "merino_alonso2020.yaml").write_text(text.replace("id: mer-abs-setup", "id: prj-hat-mps-step", 1)
                                                          .replace("    kind: input rule\n    checks: [{q: sph1d.unsolved",
                                                                   "    kind: project check\n    checks: [{q: sph1d.unsolved", 1))
    with pytest.raises(InputError, match="occurs 2 times"):
        reg.load(registry_copy)


def test_loader_refuses_a_file_named_after_another_paper(registry_copy):
    (registry_copy / "hattori.yaml").rename(registry_copy / "hattori2.yaml")
    with pytest.raises(InputError, match="does not match the file name"):
        reg.load(registry_copy)


def test_loader_refuses_a_paper_no_method_names(registry_copy):
    """The schema names no paper: a registry file is one of the method registry's papers (methods.papers())."""
    text = (registry_copy / "hattori.yaml").read_text().replace("paper: hattori\n", "paper: nobody\n", 1)
    (registry_copy / "nobody.yaml").write_text(text)
    with pytest.raises(InputError, match="'nobody' is no registered method's paper"):
        reg.load(registry_copy)


def test_loader_refuses_a_missing_paper(registry_copy):
    (registry_copy / "hattori.yaml").unlink()
    with pytest.raises(InputError, match="no registry file for hattori"):
        reg.load(registry_copy)


def test_quote_matching_is_ordered_and_whitespace_blind():
    text = "Alpha  beta\n gamma. Delta epsilon."
    assert reg.quote_found("Alpha beta gamma ... Delta", text)
    assert not reg.quote_found("Delta ... Alpha", text)
    assert not reg.quote_found("beta gamma delta", text)


def test_every_figure_that_carries_a_claim_is_tracked_and_viewed():
    """A claim-carrying figure is never git-ignored (a reader of the repository sees it) and was looked at (issue 31);
    timing figures, which change from run to run and are ignored, carry no claim."""
    figures = yaml.safe_load((ROOT / "workflow" / "report" / "figures.yaml").read_text())
    ignored = [ln.strip().lstrip("/").removeprefix("figures/").split(".")[0].rstrip("*")
               for ln in (ROOT / ".gitignore").read_text().splitlines() if ln.strip().lstrip("/").startswith("figures/")]
    for name, spec in figures.items():
        if spec["claims"]:
            assert not any(name.startswith(i) for i in ignored), f"{name} carries claims but is git-ignored"
            assert "viewed" in spec, f"{name} carries claims but was never viewed"


def test_a_row_reads_only_the_runs_it_declares(tmp_path):
    """judge hands each row a view of its declared runs (its checks' runs, their paper's version, its inputs'
    stand-ins: claims_registry.declared_runs): a declared run reads; any other key, present or not, stops the job
    (claims.Undeclared names the claim and the key) instead of becoming a verdict."""
    from isaflow import claims

    row = {"id": "x-1", "paper": "p", "section": "1", "kind": "method result", "testable": True,
           "checks": [{"q": "core.status", "runs": ["isa:a"], "op": "==", "target": "converged"}],
           "inferred_inputs": ["i"], "tolerance": {"source": "s", "derivation": "d", "units": "1", "kind": "boolean"}}
    inputs = {"i": {"id": "i", "runs": [{"id": "isa:b"}]}}
    assert reg.declared_runs(row, inputs, versions={"isa:a": "isa:a_paper"}) == {"isa:a", "isa:a_paper", "isa:b"}
    ctx = claims.Context({"isa:a": "a.nc", "isa:b": "b.nc", "isa:z": "z.nc"})
    view = ctx.only(reg.declared_runs(row, inputs), "x-1")
    assert sorted(view.paths) == ["isa:a", "isa:b"]
    for key in ("isa:z", "isa:nowhere"):
        with pytest.raises(claims.Undeclared, match=f"claim 'x-1' reads '{key}'"):
            view.has(key)


def test_sweep_affects_patterns_name_runs_the_rows_read():
    """Each sweep value's affects globs match some role a row of its file reads (a pattern matching nothing would
    leave a value's runs silently unchanged), and every input's paper's version and judged value are values of its
    sweep."""
    import fnmatch

    from isaflow import judge as J

    files = reg.load_files()
    for paper, spec in files.items():
        roles = {r for c in spec["claims"] for chk in c.get("checks", []) for r in chk.get("runs", [])}
        roles |= {r["id"] for c in spec["claims"] for r in c.get("runs", [])}
        for i in spec.get("inputs", []):
            values = [str(v["value"]) for v in i.get("sweep", [])]
            if "paper_version" in i and values:
                assert str(i["paper_version"]) in values, i["id"]
            assert sum(bool(v.get("judged")) for v in i.get("sweep", [])) <= 1, i["id"]
            for v in i.get("sweep", []):
                pats = v.get("affects")
                if pats:
                    fn = J.affects(pats)
                    assert any(fn(r) for r in roles), (paper, i["id"], v["value"], pats)
                    assert not isinstance(pats, str) or not fnmatch.fnmatchcase("", pats)


def test_no_row_has_two_root_causes():
    """One cause counted once: every row's depends_on leads to one root at most (the report groups a row under its
    root and counts the root once)."""
    two = {k: r for k, r in reg.roots(CLAIMS).items() if len(r) > 1}
    assert not two, two


@pytest.mark.skipif(not (ROOT / ".git").exists(), reason="the registry's git history is not here")
def test_every_change_of_a_tolerance_in_the_registrys_history_is_marked():
    """The git history decides what was set after the fact: every commit that changed a testable row's tolerance
    (value or parameters) to one it never had is named by the row, as post_hoc (set after its value was seen) or as
    rewritten (the same test in another form, with why)."""
    import json
    import subprocess

    def git(*args):
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True).stdout

    unmarked = []
    for path in sorted(CLAIMS_DIR.glob("*.yaml")):
        rel = str(path.relative_to(ROOT))
        changed, last = {}, {}
        for commit in git("log", "--format=%H", "--reverse", "--", rel).split():
            spec = yaml.safe_load(git("show", f"{commit}:{rel}")) or {}
            for c in spec.get("claims", []):
                if not c.get("testable"):
                    continue
                t = c.get("tolerance") or {}
                v = json.dumps([t.get("value"), t.get("parameters")], sort_keys=True)
                if c["id"] in last and v not in last[c["id"]]:  # a value met before is a merge's order, no change
                    changed.setdefault(c["id"], []).append(commit)
                last.setdefault(c["id"], set()).add(v)
        for c in yaml.safe_load(path.read_text())["claims"]:
            t = c.get("tolerance") or {}
            named = [m["commit"] for m in t.get("rewritten", [])] + ([t["post_hoc"]["commit"]] if "post_hoc" in t else [])
            for commit in changed.get(c["id"], []):
                if not any(commit.startswith(n) for n in named):
                    unmarked.append((c["id"], commit[:7]))
    assert not unmarked, unmarked
