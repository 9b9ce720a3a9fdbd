"""Shared numerical core of every method: units, wall geometry, neighbour lists, smoothing kernels, wall panels.

Everything here is method-agnostic.  Kernels are ``numba.njit`` functions over
plain arrays (no config, no I/O, no globals beyond constants); ``jit`` is that
``njit`` with the on-disk cache many processes share.
"""
