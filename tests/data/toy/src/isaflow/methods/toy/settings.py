"""The toy's settings values (config/methods/toy.yaml)."""

VALUES = {
    "lattice.spacing": {"type": "number", "exclusiveMinimum": 0},  # cm
    "springs.strain": {"type": "number", "exclusiveMinimum": 0, "maximum": 0.1},  # floor spring's static strain
    "springs.damping_ratio": {"type": "number", "exclusiveMinimum": 0},  # of the column's first mode
    "time.courant": {"type": "number", "exclusiveMinimum": 0, "maximum": 0.5},  # dt / sqrt(m / k)
    "time.chunk": {"type": "number", "exclusiveMinimum": 0},  # s of one compiled chunk (one rest sample)
    "time.t_max": {"type": "number", "exclusiveMinimum": 0},  # s
    "time.snapshot_every": {"type": "number", "exclusiveMinimum": 0},  # s
    "time.snapshot_megabytes": {"type": "number", "exclusiveMinimum": 0},
}
