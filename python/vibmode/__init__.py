"""vibmode: vibration modes of vehicle suspensions from in-service accelerations.

scipy-compatible spectra (:func:`welch`, :func:`periodogram`, :func:`csd`, :func:`coherence`),
the ideal DFT anti-alias resampling (:func:`resample_ideal`), AR / ARMA prediction-error models
(:func:`fit_ar`, :func:`fit_arma`) and order sweeps (:func:`sweep`), multichannel SSI-cov with mode shapes (:func:`ssi_cov`), reading recordings
(:func:`read`), the whole analysis (:func:`analyze`), the full-car model (:func:`fullcar`,
:func:`simulate`) and fleet monitoring (:mod:`vibmode.fleet`), computed by vibmode's Rust core.

Units: frequencies in Hz, sampling rates in Hz, times in s, damping ratios dimensionless,
densities in signal units**2/Hz. Bad arguments raise ValueError, unreadable files OSError, with
the library's one-line messages. Long calls release the GIL.
"""

from . import fleet
from ._analysis import Simulation, SimRecord, analysis_config, analyze, fullcar, simulate
from ._io import Recording, info, read, resample_ideal, write
from ._models import ArmaModel, SweepResult, fit_ar, fit_arma, sweep
from ._native import __version__
from ._spectral import coherence, csd, get_window, periodogram, welch
from ._ssi import SsiResult, ssi_cov

fleet_check = fleet.check

__all__ = [
    "ArmaModel",
    "Recording",
    "SimRecord",
    "SsiResult",
    "Simulation",
    "SweepResult",
    "__version__",
    "analysis_config",
    "analyze",
    "coherence",
    "csd",
    "fit_ar",
    "fit_arma",
    "fleet",
    "fleet_check",
    "fullcar",
    "get_window",
    "info",
    "periodogram",
    "read",
    "resample_ideal",
    "simulate",
    "ssi_cov",
    "sweep",
    "welch",
    "write",
]
