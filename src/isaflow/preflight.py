"""The checks of a run that need no numerics, made before any work and while the workflow is parsed.

:func:`check` takes a run's tank (None for the methods without tanks), resolved
settings and outcomes: unstable outcomes (escaped, non-finite, solver failure)
may be accepted only by a declared stability case; the method's ``checks``
module refuses implausible settings and estimates the cost that
isaflow.budget holds against the machine and the CPU-hour budget.  Every
method's ``checks`` module has the same two functions::

    plausible(tank, settings, stability=False)   # InputError naming the file and the setting
    cost(tank, settings, particles=None)         # -> [budget.Cost], one per run the settings make

:func:`check_file` checks the settings file of a method without tanks (every
resolution).  :class:`Declarations` checks every run a method's settings file
(or a study plan) declares: its tank, variant, resolution, overrides, start run
and the same checks, each error one line naming the file, the run and the
setting.  Pure Python (yaml, jsonschema).
"""

from . import budget, inputs, methods, rest, settings
from . import tank as tanks
from .inputs import InputError

UNSTABLE = ("escaped", "nonfinite", "solver_failed")  # outcomes only a stability case may accept
UNSTABLE_RULE = ("may be accepted only by a declared stability case (stability: true / --stability-case); any other "
                 "run that ends so fails")


def unstable_accepted(accept, stability):
    """The first outcome of ``accept`` that only a stability case may accept, if this run is none; else None."""
    return None if stability else next((a for a in accept if a in UNSTABLE), None)
WORKFLOW_KEYS = ("meta", "runtime")  # keys the workflow adds to a declaration (not part of RUN_SCHEMA)


def check(method, tank, s, accept=("converged",), stability=False, max_hours=None, particles=None, field="accept"):
    """Refuse (InputError) a run whose outcomes, settings, cost or threads are not allowed.  tank: tank.Tank or
    None; s: resolved settings.Settings; particles: a start file's count (None: the resolution's).  Returns the
    largest of its costs (budget.Cost).  field: how a refusal of ``accept`` names it."""
    budget.check_environment()
    rest.load()  # the rest criterion every dynamic run reads (config/rest.yaml): refused here, not in the job
    bad = unstable_accepted(accept, stability)
    if bad:
        raise InputError(f"{field}: outcome '{bad}' {UNSTABLE_RULE}")
    checks = methods.get(method).checks_module()
    checks.plausible(tank, s, stability)  # first: it refuses derived numbers that over- or underflow
    costs = [budget.check(s.path, c, max_hours) for c in checks.cost(tank, s, particles)]
    return max(costs, key=lambda c: (c.bytes, c.hours))


def check_file(method, path=None):
    """Check the settings file of a method without tanks, its defaults and every resolution (InputError naming
    the file and the setting); returns the validated file as written."""
    m = methods.get(method)
    path, schema = str(path or m.settings), m.values_schema()
    spec = settings.read(path, schema, f"{method} settings")
    for resolution in (None, *spec.get("resolutions", {})):
        check(method, None, settings.load(path, schema, resolution=resolution, spec=spec))
    return spec


class Declarations:
    """Checks the declared runs of the tank methods, reading each tank and settings file once."""

    def __init__(self):
        self._tanks, self._specs = {}, {}
        self.costs = {}  # {(method, run id): budget.Cost} of every checked run

    def tank(self, name):
        """The tank config/tanks/<name>.yaml, whose ``name`` must be <name>: the run files record the file's name
        and the comparison reads it (a single.yaml named 'other' dropped its runs from the figures)."""
        if name not in self._tanks:
            path = tanks.path_of(name)
            t = tanks.load(path)
            if t.name != name:
                raise InputError(f"{path}: field 'name': '{inputs.printable(t.name)}', but the file is tank '{name}' "
                                 f"(a tank's name is its file's)")
            self._tanks[name] = t
        return self._tanks[name]

    def spec(self, method):
        if method not in self._specs:
            m = methods.get(method)
            self._specs[method] = settings.read(m.settings, m.values_schema(), f"{method} settings")
        return self._specs[method]

    def check(self, method, runs):
        """Check {run id: declaration} of one method (InputError naming the file, the run and the field)."""
        m = methods.get(method)
        path, spec = m.settings, self.spec(method)
        for run_id, decl in runs.items():
            try:
                self.costs[method, run_id] = self._check_run(method, m, path, spec, runs, run_id, decl)
            except InputError as err:
                raise InputError(err if f"runs.{run_id}" in str(err) else f"{err} (run '{run_id}')") from None

    def _check_run(self, method, m, path, spec, runs, run_id, decl):
        where = f"{path}: field 'runs.{run_id}"
        plain = {k: v for k, v in decl.items() if k not in WORKFLOW_KEYS}
        inputs.validate(plain, settings.RUN_SCHEMA, f"{path}: run '{run_id}'")
        if decl["variant"] not in m.variants:
            raise InputError(f"{where}.variant': method {method} has no variant "
                             f"'{inputs.printable(decl['variant'])}' (choose from {', '.join(m.variants)})")
        if decl.get("start") and decl["start"] not in runs:
            raise InputError(f"{where}.start': no declared {method} run '{inputs.printable(decl['start'])}'")
        chain, at = [run_id], decl.get("start")
        while at in runs:  # a run that continues itself, through others or directly, was planned without its start
            if at in chain:
                raise InputError(f"{where}.start': the runs continue each other ({' -> '.join([*chain, at])}); a "
                                 f"run cannot start from its own result")
            chain.append(at)
            at = runs[at].get("start")
        try:
            tank = self.tank(decl["tank"])
        except InputError as err:
            raise InputError(f"{where}.tank': {err}") from None
        s = settings.load(path, m.values_schema(), decl["variant"], decl["resolution"], decl.get("set", {}),
                          spec=spec)
        return check(method, tank, s, decl.get("accept", ["converged"]), decl.get("stability", False),
                     decl.get("max_hours"), field=f"{where}.accept'")
