"""ccsrm from Python: simulate cable-driven continuum manipulators, read and
write their experiment, run and marker files, and fit their parameters.

Every function calls the same C++ library functions as the ``ccsrm``
command line, so a run or a fit from Python is the command's, to the bit.

    >>> import ccsrm
    >>> model = ccsrm.load_config(ccsrm.bundled_config("paper.yaml"))
    >>> run = ccsrm.simulate(model, case=2, duration=1.0)
    >>> run.joint_angles.shape          # frames x joints x (theta_x, theta_y)
    (101, 12, 2)
"""
import sys as _sys

try:  # every array ccsrm returns is a numpy array: say so at import, not at the first read
    import numpy as _numpy  # noqa: F401
except ImportError as _error:  # pragma: no cover - depends on the interpreter
    raise ImportError(
        "ccsrm needs numpy, which " + _sys.executable + " does not have: use Debian's "
        "/usr/bin/python3 with python3-numpy (scripts/install-deps.sh installs it), or "
        "pip install numpy into this environment") from _error

from ._core import (  # noqa: F401  (the public API)
    Dataset,
    EffectInfo,
    Fit,
    InputError,
    Loop,
    MarkerTable,
    Model,
    ParameterEstimate,
    ParameterInfo,
    Parameters,
    ProcessedRecording,
    Run,
    SimulationSummary,
    SlackInterval,
    __version__,
    bundled_config,
    default_threads,
    effects,
    generate,
    identify,
    load_config,
    loop,
    parameter_table,
    predict,
    Prediction,
    process_markers,
    read_dataset,
    read_markers,
    read_run_file,
    simulate,
    write_c3d,
)

__all__ = [name for name in dir() if not name.startswith("_")] + ["__version__"]
