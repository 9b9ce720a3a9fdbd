"""isaflow: incremental static analysis of 2D flow by inter-colliding point particles, and its neighbours.

Replication of Papadopoulos, Koutitas & Lazaridis (2016), Open J. Civil Eng. 6,
397-409.  Units throughout: length cm, force N, stiffness N/cm, time s.

Importing the package points numba's cache (``cache=True`` kernels) at a folder
named after a hash of the package's sources, unless NUMBA_CACHE_DIR is set:
numba checks only the timestamp of the file that holds a compiled function, so
a cached kernel that calls a changed function of another module would be used
stale (seen: a segfault).  A new source tree compiles afresh.
"""

import hashlib
import os
from pathlib import Path

__version__ = "0.1.0"


def _source_hash():
    """sha256 (16 hex digits) of every .py file of the package, in path order."""
    h = hashlib.sha256()
    root = Path(__file__).resolve().parent
    for p in sorted(root.rglob("*.py")):
        h.update(str(p.relative_to(root)).encode())
        h.update(p.read_bytes())
    return h.hexdigest()[:16]


if "NUMBA_CACHE_DIR" not in os.environ:
    os.environ["NUMBA_CACHE_DIR"] = str(Path(__file__).resolve().parents[2] / ".numba-cache" / _source_hash())
