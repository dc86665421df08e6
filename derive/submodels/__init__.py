"""Submodels: each contact and load of the seal is one class in one file that declares everything about itself.

* :mod:`.base` - the :class:`~.base.Submodel` contract, guards, loads and the derivation context;
* :mod:`.laws` - the contact laws written once (penalty, one-sided damping, regularised Coulomb friction);
* :mod:`.registry` - the ordered registry; the parameter vector, options, guards and modes are built from it;
* the built-in submodels: :mod:`.seal` (the seal body, its geometry and the rotor's inertial loads),
  :mod:`.housing`, :mod:`.spring`, :mod:`.groove`, :mod:`.pressure`.

A user adds a contact by subclassing :class:`~.base.Submodel` and calling :func:`~.registry.register`
(docs/extending.md walks through an example).
"""
