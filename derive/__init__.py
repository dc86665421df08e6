"""Symbolic derivation of the apex-seal model (Phung, Sultan, Appuhamillage 2018, Eqs. 1-80).

Entry points: :func:`derive_model` (always derives) and :func:`cached_model`
(content-hash cached). Both take the :class:`Effects` and :class:`Assumptions`
of a scene and return a :class:`DerivedModel`. The model is assembled from the
submodels of :mod:`.submodels` (one class per contact or load, each declaring its
parameters, options, guards and laws).

Names are imported lazily: reading the declarations (a scene does) never imports sympy.
"""

_EXPORTS = {
    "Assumptions": ".assumptions", "Effects": ".effects", "EFFECTS": ".effects", "Options": ".options",
    "DerivedModel": ".model", "derive_model": ".model", "cached_model": ".cache",
}


def __getattr__(name: str):
    if name in _EXPORTS:
        import importlib

        return getattr(importlib.import_module(_EXPORTS[name], __name__), name)
    raise AttributeError(name)


def __dir__():
    return sorted(_EXPORTS)


__all__ = sorted(_EXPORTS)
