"""Sweeps: one scene varied over a design of experiments, on all cores or a Dask cluster, results in Parquet.

>>> from apexseal.runtime.studies.sweep import load_study, run_sweep
>>> study = load_study("preload-map.toml")
>>> report = run_sweep(study, "apexseal-out/preload-map")      # LocalCluster on every core
>>> report.table                                                 # one row per point (pandas)

``docs/sweeps.md`` describes the study file, the output folder and running on a cluster.
"""

from .execute import SweepReport, run_sweep
from .store import read_results
from .study import Study, StudyError, load_study, study_from_toml

__all__ = ["Study", "StudyError", "SweepReport", "load_study", "read_results", "run_sweep", "study_from_toml"]
