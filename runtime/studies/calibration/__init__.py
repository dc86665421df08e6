"""The calibration study: the unknown contact parameters fitted to the paper's reported features (Figs. 12-14)."""

from .features import Features, features
from .fit import PLAUSIBLE, Calibration, CalibrationError, calibrate

__all__ = ["PLAUSIBLE", "Calibration", "CalibrationError", "Features", "calibrate", "features"]
