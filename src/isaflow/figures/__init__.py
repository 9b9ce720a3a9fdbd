"""Figures, drawn only from run files (netCDF) and tables derived from them.

Every public function has the signature ``f(inputs, outputs, **kw)``:
``inputs`` are file paths, ``outputs`` the PNG and PDF paths to write.
"""

from .single import calibration_figure, convergence_figure, inputs_figure, single_vessel_figure  # noqa: F401
from .flow import flow_complete_figure, flow_history_figure, flow_incomplete_figure  # noqa: F401
from .study import error_vs_runtime_figure, stability_map_figure  # noqa: F401
from .methods import methods_error_vs_runtime_figure  # noqa: F401
