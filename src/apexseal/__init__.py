"""apexseal: derive, generate and run the equations of motion of the apex seal of limaçon machines.

The model is that of Phung, Sultan and Appuhamillage, "On the apex seal analysis of
limaçon positive displacement machines", Mech. Mach. Theory 127 (2018).

Public API::

    scene = apexseal.load_scene()            # the embedded default (the paper's case study)
    result = apexseal.simulate(scene)        # a SimulationResult
    help(apexseal.RunSettings)               # the run settings simulate takes (rtol=..., method=...), their ranges
    apexseal.resume("apexseal-out/default")  # continue a stopped run (or a finished one, for more revolutions)
    apexseal.Model(scene).rhs(theta, state)  # the state derivative, numpy
    result.plot("fig12"); result.to_xarray(); result.to_pandas(); result.summary()
    apexseal.plot_comparison([result_a, result_b], ["x", "Pf_total"])  # several results in one Figure
    apexseal.compare(["out/a", "out/b"])    # the scene keys that differ and the runs' numbers, side by side
    with apexseal.reusing_engines(): ...     # many runs of one model and settings share one integrator
    apexseal.optimise_preload(scene, min_force=5.0)  # the spring-preload study (a PreloadResult)
    apexseal.preload_functions(scene)        # that study's compiled CasADi Functions, every input/output slot named
    apexseal.save_preload_report("out", constant, schedule)  # its report, as the command writes it
    apexseal.PreloadResult.load("out")     # a saved study's constant optimum, e.g. to start a schedule from
    apexseal.run_sweep("my-study.toml", "out")  # a design study (a SweepReport); under if __name__ == "__main__"
    apexseal.load_study("my-study.toml"); apexseal.read_results("out")  # a study file; a sweep's table (pandas)

Exceptions to catch: SceneError (a scene), SettingsError (run settings), PreloadStudyError (the preload study's
options), StudyError (a sweep's study file), SchedulerError (a sweep's Dask scheduler), ResultFolderError (a
result folder that cannot be read or resumed), ResultStorageError (one that cannot be written).
"""

__version__ = "0.1.0"


#: public name -> (module, attribute); imported on first use, so that importing apexseal stays cheap
_LAZY = {
    "load_scene": ("runtime.scenes.scene", "load_scene"),
    "embedded_scene_path": ("runtime.scenes.scene", "embedded_scene_path"),
    "Scene": ("runtime.scenes.scene", "Scene"),
    "SceneError": ("runtime.scenes.errors", "SceneError"),
    "simulate": ("runtime.api", "simulate"),
    "resume": ("runtime.api", "resume"),
    "Model": ("runtime.api", "Model"),
    "SimulationResult": ("runtime.results.result", "SimulationResult"),
    "plot_comparison": ("runtime.results.plots", "plot_comparison"),
    "compare": ("runtime.results.compare", "compare"),
    "optimise_preload": ("runtime.studies.preload.study", "optimise_preload"),
    "reusing_engines": ("runtime.solving.engine_pool", "reusing"),
    "RunInterrupted": ("signals", "RunInterrupted"),
    "RunInterruptedWarning": ("runtime.api", "RunInterruptedWarning"),
    "preload_functions": ("runtime.studies.preload.functions", "preload_functions"),
    "save_preload_report": ("runtime.studies.preload.report", "save_report"),
    "PreloadResult": ("runtime.studies.preload.result", "PreloadResult"),
    "load_study": ("runtime.studies.sweep.study", "load_study"),
    "run_sweep": ("runtime.studies.sweep.execute", "run_sweep"),
    "read_results": ("runtime.studies.sweep.store", "read_results"),
    # the exceptions a user of the API catches (each a ValueError or an OSError, so older handlers still catch it)
    "RunSettings": ("runtime.solving.settings", "RunSettings"),
    "SettingsError": ("runtime.solving.settings", "SettingsError"),
    "PreloadStudyError": ("runtime.studies.preload.problem", "PreloadStudyError"),
    "StudyError": ("runtime.studies.sweep.study", "StudyError"),
    "SchedulerError": ("runtime.studies.sweep.execute", "SchedulerError"),
    "ResultFolderError": ("runtime.results.reading", "ResultFolderError"),
    "ResultStorageError": ("runtime.results.folder", "ResultStorageError"),
}


def __getattr__(name):  # lazy: importing apexseal stays cheap
    if name in _LAZY:
        import importlib

        module, attr = _LAZY[name]
        return getattr(importlib.import_module(f".{module}", __name__), attr)
    raise AttributeError(f"module 'apexseal' has no attribute {name!r}")


def __dir__():
    return sorted({*globals(), *_LAZY})


__all__ = sorted(["__version__", *_LAZY])
