"""apexseal: derive, generate and run the equations of motion of the apex seal of limaçon machines.

The model is that of Phung, Sultan and Appuhamillage, "On the apex seal analysis of
limaçon positive displacement machines", Mech. Mach. Theory 127 (2018).

Public API::

    scene = apexseal.load_scene()            # the embedded default (the paper's case study)
    result = apexseal.simulate(scene)        # a SimulationResult
    apexseal.Model(scene).rhs(theta, state)  # the state derivative, numpy
"""

__version__ = "0.1.0"


def __getattr__(name):  # lazy: importing apexseal stays cheap
    if name == "load_scene":
        from .runtime.scenes.scene import load_scene

        return load_scene
    if name in ("simulate", "Model"):
        from .runtime import api

        return getattr(api, name)
    if name == "SimulationResult":
        from .runtime.results.result import SimulationResult

        return SimulationResult
    raise AttributeError(name)


__all__ = ["Model", "SimulationResult", "load_scene", "simulate", "__version__"]
