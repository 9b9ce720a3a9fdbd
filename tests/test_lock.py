"""Pinned environment: the lock pins everything pyproject.toml asks for, within its
ranges; the rules' conda environment holds exactly the lock's versions; the
installed environment is the lock (a hard check once ISAFLOW_REQUIRE_LOCK=1)."""

import importlib.util
import os
import tomllib
from importlib import metadata

import pytest
import yaml
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
from packaging.version import Version

from conftest import ROOT

LOCK = ROOT / "requirements" / "lock-py311.txt"
EXTRAS_IN = ROOT / "requirements" / "extras.in"
ENV = ROOT / "workflow" / "envs" / "isaflow.yaml"
LOCKED_EXTRAS = ("test",)  # the extras requirements/compile.sh passes to uv


def conda_env_module():
    spec = importlib.util.spec_from_file_location("conda_env", ROOT / "requirements" / "conda_env.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def locked():
    """{canonical name: Version} of the lock file."""
    return {canonicalize_name(n): Version(v) for n, v in conda_env_module().pins(LOCK.read_text())}


def requested():
    """Requirements the lock is compiled from: pyproject dependencies, locked extras, extras.in."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    lines = list(project["dependencies"])
    for extra in LOCKED_EXTRAS:
        lines += project.get("optional-dependencies", {}).get(extra, [])
    lines += [ln.split("#")[0].strip() for ln in EXTRAS_IN.read_text().splitlines() if ln.split("#")[0].strip()]
    return [Requirement(line) for line in lines]


def test_lock_is_exact_pins_for_python_311():
    header = LOCK.read_text().splitlines()[:2]
    assert "uv pip compile pyproject.toml" in header[1] and "--python-version 3.11" in header[1]
    pins = conda_env_module().pins(LOCK.read_text())  # raises on anything but name==version
    names = [canonicalize_name(n) for n, _ in pins]
    assert len(names) == len(set(names)), "a package is pinned twice (platform markers?)"


def test_every_requested_package_is_pinned_within_its_range():
    pins = locked()
    missing = [str(r) for r in requested() if canonicalize_name(r.name) not in pins]
    assert not missing, f"not in the lock (run requirements/compile.sh): {missing}"
    outside = [f"{r} but {pins[canonicalize_name(r.name)]}" for r in requested()
               if not r.specifier.contains(pins[canonicalize_name(r.name)], prereleases=True)]
    assert not outside, f"lock outside pyproject's range (run requirements/compile.sh): {outside}"


def test_conda_environment_is_the_lock():
    env = yaml.safe_load(ENV.read_text())
    assert env["channels"] == ["conda-forge", "nodefaults"]
    assert "python=3.11" in env["dependencies"]
    pip_section = next(d["pip"] for d in env["dependencies"] if isinstance(d, dict))
    from_env = {canonicalize_name(p.split("==")[0]): Version(p.split("==")[1]) for p in pip_section}
    assert from_env == locked()
    # and the file is exactly what requirements/conda_env.py writes (so it is regenerated, not edited)
    body = "".join(f"      - {n}=={v}\n" for n, v in conda_env_module().pins(LOCK.read_text()))
    assert ENV.read_text() == conda_env_module().HEADER.format(lock="requirements/lock-py311.txt") + body
    # no post-deploy install of the project: an environment is not tied to one checkout (the scripts read src/)
    assert not (ENV.parent / "isaflow.post-deploy.sh").exists()


def test_installed_environment_is_the_lock():
    differ = []
    for name, version in locked().items():
        try:
            have = Version(metadata.version(name))
        except metadata.PackageNotFoundError:
            have = None
        if have != version:
            differ.append(f"{name} {have} (lock {version})")
    if differ and os.environ.get("ISAFLOW_REQUIRE_LOCK") != "1":
        pytest.skip(f"installed environment is not the lock ({len(differ)}: {', '.join(differ[:5])}); "
                    "install with `pip install -r requirements/lock-py311.txt`")
    assert not differ


def test_run_files_record_the_lock_file_and_its_hash():
    """Provenance names the lock relative to the project (equal across clones) and its sha256."""
    from isaflow import runfile

    prov = runfile.provenance({})
    assert prov["lock_file"] == "requirements/lock-py311.txt"
    assert prov["lock_sha256"] == runfile.sha256(ROOT / "requirements" / "lock-py311.txt")
