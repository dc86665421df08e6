"""Sweeps: one scene varied over a design of experiments, on all cores or a Dask cluster, results in Parquet.

>>> from apexseal.runtime.studies.sweep import load_study, run_sweep
>>> study = load_study("preload-map.toml")
>>> report = run_sweep(study, "apexseal-out/preload-map")      # LocalCluster on every core
>>> report.table                                                 # one row per point (pandas)
>>> apexseal.simulate(point_scene(study, 3))                       # one point alone, with every output of a run

``docs/sweeps.md`` describes the study file, the output folder and running on a cluster.
"""

from .execute import SweepReport, point_scene, run_sweep
from .store import read_results
from .study import Study, StudyError, load_study, study_from_toml

__all__ = ["Study", "StudyError", "SweepReport", "load_study", "point_scene", "read_results", "run_sweep",
           "study_from_toml"]
