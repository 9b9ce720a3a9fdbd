"""Command line: ``isaflow run SCENE -o RUN.nc [--set key=value ...]``.

Exit codes: 0 success; 1 the run ended in an outcome the scene does not
accept (no output written); 2 bad input (scene or start file).
"""

import argparse
import sys

from . import runfile, scene as scenes
from .methods.isa import solver
from .methods.isa.settings import settings


def run(scene_path, out, overrides=(), config=None, quiet=False):
    """Load, solve and write one run; returns the exit code."""
    try:
        scene = scenes.load(scene_path, overrides)
        pos0, weight, start, spacing = scenes.initial_state(scene)
    except scenes.SceneError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    started = runfile.now()

    def progress(step, fmax):
        if not quiet:
            print(f"{scene.name}: step {step:>9d}  max|F| = {fmax:.4g} N", file=sys.stderr, flush=True)

    result = solver.solve(scene, pos0, weight, start_step=start, progress=progress)
    accepted = settings(scene)["accept"]
    print(f"{scene.name}: {result.status}: {result.message} ({result.wall_time:.3f} s)", file=sys.stderr)
    if result.status not in accepted:
        print(f"error: {scene.path}: field 'solver.accept': outcome '{result.status}' is not accepted "
              f"({', '.join(accepted)}); no output written", file=sys.stderr)
        return 1
    inputs = {"scene": scene.path, "config": config, "start": scene.spec["particles"].get("from_run")}
    prov = runfile.provenance(inputs)
    prov.update(scene_yaml=scene.text, scene_overrides="; ".join(scene.overrides) or "none",
                scene_resolved_sha256=scene.digest)
    ds = runfile.to_dataset(result, scene, prov, started, runfile.now(), spacing)
    runfile.write(ds, out)
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
    return run(args.scene, args.out, args.set, args.config, args.quiet)


if __name__ == "__main__":
    sys.exit(main())
