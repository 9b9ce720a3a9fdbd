"""Command line: ``isaflow run SCENE -o RUN.nc [--set key=value ...]``.

Exit codes: 0 success; 1 the run ended in an outcome the scene does not
accept (no output written); 2 bad input: scene, override, start file,
configuration file, output path or a run that cannot fit in memory, refused
before any work with one line naming the file and the field; 3 the output
could not be written after the solve; 130/143 interrupted (SIGINT/SIGTERM;
the temporary file is removed).  No traceback is printed unless
ISAFLOW_DEBUG=1.
"""

import argparse
import os
import signal
import sys
from pathlib import Path

from . import inputs, runfile
from . import scene as scenes


def _interrupted(signum, frame):
    raise SystemExit(128 + signum)  # unwinds through runfile.write's cleanup


def _error(msg):
    print(f"error: {msg}", file=sys.stderr)


def prepare(scene_path, out, overrides=(), config=None):
    """Every check that can refuse a run, before any work: (scene, start, settings) or SceneError/RunFileError."""
    from .methods.isa.settings import settings

    scene = scenes.load(scene_path, overrides)
    start = scenes.start_file(scene) if "from_run" in scene.spec["particles"] else None
    if config is not None:
        p = Path(config)
        if not p.is_file():
            raise scenes.SceneError(f"{config}: --config: not a readable regular file")
        try:
            with open(p, "rb"):
                pass
        except OSError as err:
            raise scenes.SceneError(f"{config}: --config: {err.strerror or err}") from None
    runfile.check_output(out)
    inputs_read = {"the scene": scene_path, "--config": config, "particles.from_run": start and start["path"]}
    for what, src in inputs_read.items():
        if src and _same_file(src, out):
            raise runfile.RunFileError(f"{out}: the output would overwrite {what} ('{src}'); choose another path")
    return scene, start, settings(scene)


def _same_file(a, b):
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def run(scene_path, out, overrides=(), config=None, quiet=False):
    """Check, solve and write one run; returns the exit code (see the module docstring)."""
    from .methods.isa import solver

    try:
        scene, start, s = prepare(scene_path, out, overrides, config)
        if start is None:
            pos0, weight, start_step, spacing = scenes.initial_state(scene)
            state = None
        else:
            pos0, weight, start_step, spacing = start["pos"], start["weight"], start["steps"], start["spacing"]
            state = start["state"]
        files = {"scene": scene.path, "config": config, "start": start and start["path"]}
        prov = runfile.provenance(files)
    except (scenes.SceneError, runfile.RunFileError) as err:
        _error(err)
        return 2
    except OSError as err:
        _error(f"{getattr(err, 'filename', None) or scene_path}: {err.strerror or err}")
        return 2
    prov.update(scene_yaml=scene.text, scene_overrides="; ".join(scene.overrides) or "none",
                scene_resolved_sha256=scene.digest, restart=start["restart"] if start else "none (fresh start)")
    if start:
        prov.update(start_sha256=start["sha256"], start_step=start["steps"])
    started = runfile.now()

    def progress(step, fmax):
        if not quiet:
            print(f"{scene.name}: step {step:>9d}  max|F| = {fmax:.4g} N", file=sys.stderr, flush=True)

    result = solver.solve(scene, pos0, weight, start_step=start_step, progress=progress, state=state)
    finished = runfile.now()
    print(f"{scene.name}: {result.status}: {result.message} ({result.wall_time:.3f} s)", file=sys.stderr)
    if result.status not in s["accept"]:
        _error(f"{scene.path}: field 'solver.accept': outcome '{result.status}' is not accepted "
               f"({', '.join(s['accept'])}); no output written")
        return 1
    try:
        runfile.write(runfile.to_dataset(result, scene, prov, started, finished, spacing), out)
    except (OSError, runfile.RunFileError) as err:
        _error(f"{out}: the run finished but its file could not be written: {getattr(err, 'strerror', None) or err}")
        return 3
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(prog="isaflow", description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="relax one scene and write its netCDF run file")
    r.add_argument("scene")
    r.add_argument("-o", "--out", required=True)
    r.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override a scene field")
    r.add_argument("--config", help="workflow config file to hash into the provenance")
    r.add_argument("-q", "--quiet", action="store_true")
    args = ap.parse_args(argv)
    for name in ("scene", "out", "config"):
        bad = getattr(args, name) is not None and inputs.bad_string(getattr(args, name))
        if bad:
            _error(f"argument {name} '{inputs.printable(getattr(args, name))}': {bad}")
            return 2
    signal.signal(signal.SIGTERM, _interrupted)
    try:
        return run(args.scene, args.out, args.set, args.config, args.quiet)
    except KeyboardInterrupt:
        _error("interrupted (SIGINT); no output written")
        return 130
    except SystemExit as err:
        if err.code in (128 + signal.SIGTERM,):
            _error("terminated (SIGTERM); no output written")
        raise
    except MemoryError:
        _error("out of memory (the estimate in methods.isa.budget was too low: please report); no output written")
        return 2
    except Exception as err:
        if os.environ.get("ISAFLOW_DEBUG") == "1":
            raise
        _error(f"internal error {type(err).__name__}: {inputs.printable(str(err), 300)} (ISAFLOW_DEBUG=1 shows the "
               f"traceback); no output written")
        return 70


if __name__ == "__main__":
    sys.exit(main())
