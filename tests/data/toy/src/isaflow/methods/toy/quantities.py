"""The toy's quantities (isaflow.quantities): what its claims read from its run files."""

from ...quantities import quantity


@quantity("share of the weight the floor carries over the last rest window", fmt=".5f")
def floor_share(ds, wall="floor"):
    """The wall's load over the run's last rest window (wall_load_mean, written by the driver) / the weight held."""
    names = [str(n) for n in ds["wall"].values]
    return float(ds["wall_load_mean"].values[names.index(wall)]) / float(ds["weight"].values.sum())
