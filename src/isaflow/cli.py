"""Command line: ``isaflow run --method NAME --tank TANK --variant V --resolution R -o RUN.nc``; ``isaflow export
RUN.nc --vtk DIR`` (a run's stored states as VTK files for ParaView: isaflow.export); ``isaflow compare TANK.yaml -o
DIR`` (every tank method on one tank: isaflow.compare).

Runs any tank method of the registry on any tank (isaflow.run), or a run
declared in the method's settings file (``--run ID``: its tank, variant,
resolution, overrides and start).  Exit codes: 0 success; 1 the run ended in
an outcome it does not accept (no output written); 2 bad input (tank,
settings, override, start file, output path, a run that cannot fit), refused
before any work with one line naming the file and the field; 3 the output
could not be written after the solve; 130/143 interrupted (SIGINT/SIGTERM; the
temporary file is removed); 70 internal error.  No traceback is printed
unless ISAFLOW_DEBUG=1.
"""

import argparse
import math
import os
import signal
import sys

from . import inputs, methods, preflight
from .settings import OUTCOMES
from . import run as runs



def _interrupted(signum, frame):
    raise SystemExit(128 + signum)  # unwinds through runfile.write's cleanup


def _error(msg):
    print(f"error: {msg}", file=sys.stderr)


def _internal(err, written=""):
    """Exit code 70 of an internal error, in one line (the traceback only with ISAFLOW_DEBUG=1)."""
    if os.environ.get("ISAFLOW_DEBUG") == "1":
        raise err
    _error(f"internal error {type(err).__name__}: {inputs.printable(str(err), 300)} (ISAFLOW_DEBUG=1 shows the "
           f"traceback)" + (f"; {written}" if written else ""))
    return 70


def declared(method, run_id, settings_path=None):
    """(tank path, variant, resolution, overrides, start path, accept, stability, max_hours) of a run declared
    in a settings file."""
    from . import settings as S
    from . import tank as T

    m = runs.tank_method(method)
    spec = S.read(settings_path or m.settings, m.values_schema(), f"{method} settings")
    decl = spec.get("runs", {}).get(run_id)
    if decl is None:
        raise inputs.InputError(f"{settings_path or m.settings}: field 'runs': no run '{inputs.printable(run_id)}' "
                                f"(choose from {', '.join(spec.get('runs', {}))})")
    start = f"results/runs/{method}/{decl['start']}.nc" if decl.get("start") else None
    return (T.path_of(decl["tank"]), decl["variant"], decl["resolution"], decl.get("set", {}), start,
            tuple(decl.get("accept", ["converged"])), decl.get("stability", False), decl.get("max_hours"))


class _Parser(argparse.ArgumentParser):
    """argparse with the one-line refusal of every bad input (usage and message were several lines)."""

    def error(self, message):
        _error(f"{message} ({self.prog} --help lists the options)")
        raise SystemExit(2)


def export(args):
    """``isaflow export RUN.nc --vtk DIR`` -> exit code: 0 written, 2 bad input (one line; nothing written)."""
    from . import export as X

    for name, value in (("run", args.run), ("--vtk", args.vtk)):
        bad = inputs.bad_string(value)
        if bad:
            _error(f"argument {name} '{inputs.printable(value)}': {bad}")
            return 2
    try:
        pvd = X.export_vtk(args.run, args.vtk)
    except inputs.InputError as err:
        _error(err)
        return 2
    except OSError as err:
        _error(f"{args.vtk}: --vtk: cannot write the export: {err.strerror or err}; nothing written")
        return 2
    except Exception as err:
        return _internal(err, "nothing written")
    print(f"wrote {pvd}", file=sys.stderr)
    return 0


def parser():
    """The command line's parser (isaflow run / export / compare)."""
    ap = _Parser(prog="isaflow", description="Run a method on a tank, export a run for ParaView, or compare every "
                                             "tank method on one tank (exit codes: the module docstring of isaflow.cli).")
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run one method on one tank and write its netCDF run file")
    r.add_argument("--method", required=True, help=f"a tank method: one of {', '.join(methods.tank_methods())}")
    r.add_argument("--run", help="a run declared in the method's settings file (runs: section)")
    r.add_argument("--tank", help="tank file, e.g. config/tanks/single.yaml")
    r.add_argument("--variant")
    r.add_argument("--resolution")
    r.add_argument("--settings", help="settings file (default: the method's config/methods/<name>.yaml)")
    r.add_argument("--start", help="run file of the same method to continue")
    r.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override a setting")
    r.add_argument("--accept", help=f"comma-separated outcomes that count as success (default converged; "
                                    f"{', '.join(OUTCOMES)})")
    r.add_argument("--stability-case", action="store_true",
                   help="a stability case: settings outside the method's literature ranges are run, and it may "
                        "accept escaped / nonfinite / solver_failed outcomes")
    r.add_argument("--max-hours", type=float, help="this run's CPU-hour budget, for a deliberate long run "
                                                   "(default: config/limits.yaml cpu_hours)")
    r.add_argument("--threads", type=int, help="threads of the compiled loops (default: numba's)")
    r.add_argument("-o", "--out", required=True)
    e = sub.add_parser("export", help="write a run file's stored states as VTK files for ParaView (isaflow.export)")
    e.add_argument("run", help="a run file (netCDF) of a tank method")
    e.add_argument("--vtk", required=True, metavar="DIR",
                   help="directory for <run>.pvd, its .vtu particle files and the walls' .vtp (created if missing)")
    compare_parser(sub)
    return ap


def main(argv=None):
    args = parser().parse_args(argv)
    if args.cmd == "export":
        return export(args)
    if args.cmd == "compare":
        return compare(args)
    for name in ("method", "run", "tank", "variant", "resolution", "settings", "start", "out", "accept"):
        value = getattr(args, name)
        bad = value is not None and inputs.bad_string(value)
        if bad:
            _error(f"argument --{name} '{inputs.printable(value)}': {bad}")
            return 2
    for name in ("tank", "settings"):  # a file the user named on the command line: refused under its option
        value = getattr(args, name)
        kind = value is not None and inputs.not_a_file(value)
        if kind:
            _error(f"argument --{name}: '{value}': {kind}")  # a text bad_string passed above
            return 2
    signal.signal(signal.SIGTERM, _interrupted)
    try:
        overrides, accept = list(args.set), ("converged",)
        stability, max_hours = args.stability_case, args.max_hours
        if args.run:
            given = [f"--{n}" for n in ("tank", "variant", "resolution") if getattr(args, n) is not None]
            if given:  # they were ignored: the declaration names its own
                _error(f"{', '.join(given)}: not with --run (the declared run names its tank, variant and resolution; "
                       f"--set changes its settings)")
                return 2
            tank, variant, resolution, decl_set, start, accept, decl_stab, decl_hours = declared(
                args.method, args.run, args.settings)
            stability = stability or decl_stab
            max_hours = max_hours if max_hours is not None else decl_hours
            overrides = {**decl_set, **runs.settings.parse_overrides(overrides, "--set")}
            start = args.start or start
        else:
            missing = [f"--{n}" for n in ("tank", "variant", "resolution") if getattr(args, n) is None]
            if missing:
                _error(f"{', '.join(missing)} required (or --run ID of a declared run)")
                return 2
            tank, variant, resolution, start = args.tank, args.variant, args.resolution, args.start
        if args.accept is not None:  # '--accept ""' names no outcome: refused below, not the default
            accept = tuple(a.strip() for a in args.accept.split(","))
            bad = [a for a in accept if a not in OUTCOMES]
            if bad:
                _error(f"argument --accept: unknown outcome '{inputs.printable(bad[0])}' (choose from {', '.join(OUTCOMES)})")
                return 2
        bad = preflight.unstable_accepted(accept, stability)
        if bad:
            _error(f"argument --accept: outcome '{bad}' {preflight.UNSTABLE_RULE}")
            return 2
        if max_hours is not None and not (math.isfinite(max_hours) and max_hours > 0):
            _error("argument --max-hours: must be a finite positive number of hours")
            return 2
        return runs.run(args.method, tank, variant, resolution, args.out, args.settings, overrides, start, accept,
                        args.threads, args.run, stability=stability, max_hours=max_hours)
    except inputs.InputError as err:
        _error(err)
        return 2
    except KeyboardInterrupt:
        _error("interrupted (SIGINT); no output written")
        return 130
    except SystemExit as err:
        if err.code in (128 + signal.SIGTERM,):
            _error("terminated (SIGTERM); no output written")
        raise
    except MemoryError:
        _error("out of memory (the method's memory estimate was too low: please report); no output written")
        return 2
    except Exception as err:
        return _internal(err, "no output written")


def compare_parser(sub):
    """``isaflow compare TANK.yaml -o DIR [--resolution coarse|refined|METHOD=NAME ...]`` (isaflow.compare)."""
    c = sub.add_parser("compare", help="run every tank method on one tank and write the comparison table, the "
                                       "methods figure and a report page into a directory")
    c.add_argument("tank", help="tank file (config/tanks/*.yaml's format; docs/architecture.md, 'Adding a tank')")
    c.add_argument("-o", "--out", required=True, help="output directory (created; its files are replaced)")
    c.add_argument("--resolution", action="append", default=[], metavar="LEVEL|METHOD=NAME",
                   help="coarse (default: each method's first compared resolution on tank single) or refined "
                        "(its second); METHOD=NAME picks one method's resolution; may be repeated")


def compare(args):
    """Exit status of ``isaflow compare`` (isaflow.compare.compare: 0 written, 1 no method ran, 2 bad input)."""
    from . import compare as C

    for name in ("tank", "out"):
        bad = inputs.bad_string(getattr(args, name))
        if bad:
            _error(f"argument {'-o' if name == 'out' else name} '{inputs.printable(getattr(args, name))}': {bad}")
            return 2
    signal.signal(signal.SIGTERM, _interrupted)
    try:
        return C.compare(args.tank, args.out, args.resolution or ["coarse"])
    except KeyboardInterrupt:
        _error("interrupted (SIGINT)")
        return 130
    except Exception as err:
        return _internal(err)


if __name__ == "__main__":
    sys.exit(main())
