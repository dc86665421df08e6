"""A process whose imported model code was edited on disk since does not derive or generate (apexseal.loaded_code).

The model's keys follow the files on disk, the derivation and the generation run the code the process imported: a
notebook that ran a model, then had a submodel's file edited and ran again, derived and generated the old model and
kept it in the cache under the edited file's key, where every later process found it as the new model's (the C it
served differed from a fresh generation of the edited source)."""

from __future__ import annotations

import importlib
import sys

import pytest

from apexseal.derive.assumptions import Assumptions
from apexseal.derive.cache import cache_dir, cached_model, derivation_key
from apexseal.derive.effects import Effects
from apexseal.derive.submodels import registry
from apexseal.generated.generate import generate
from apexseal.generated.manifest import input_hash
from apexseal.loaded_code import EditedSinceImportError, edited_since_import

CLASS = '''
from apexseal.derive.options import NONE, ON, Option
from apexseal.derive.parameters import Parameter
from apexseal.derive.submodels.base import ContactModel, Load, Submodel


class Nudge(Submodel):
    name = "nudge"
    summary = "a constant force on the seal along its Ys axis"
    switch = "nudge"
    parameters = (Parameter("Fn", "N", "the force", key="contacts.Fn", default=1.0, ge=0),)
    options = (Option("nudge", (NONE, ON), "the force on the seal"),)

    def contacts(self, ctx):
        from sympy.physics.vector import Vector

        return [ContactModel("nudge", [Load("nu", Vector(0), {factor} * ctx.P["Fn"] * ctx.k.S.y)])]
'''


@pytest.fixture
def nudge(tmp_path, monkeypatch):
    """A submodel in a package of its own, imported and registered; its file and module."""
    pkg = tmp_path / "nudges"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "nudge.py").write_text(CLASS.format(factor=1))
    monkeypatch.syspath_prepend(str(tmp_path))
    module = importlib.import_module("nudges.nudge")
    with registry.registered(module.Nudge):
        yield pkg / "nudge.py", module
    for name in [m for m in sys.modules if m == "nudges" or m.startswith("nudges.")]:
        del sys.modules[name]


def test_a_submodel_edited_since_import_is_neither_derived_nor_generated(nudge, tmp_path):
    path, module = nudge
    effects, assumptions = Effects.from_mapping({"nudge": True}), Assumptions()
    before = input_hash(effects, assumptions)  # what a run computes first
    path.write_text(CLASS.format(factor=2))  # the model changed on disk; the process still has the old class
    assert input_hash(effects, assumptions) != before  # the key follows the file, as before
    edited = rf"{path.name} \(module nudges\.nudge\) changed on disk after this process imported it"
    with pytest.raises(EditedSinceImportError, match=edited + ".*would derive the model"):
        cached_model(effects, assumptions)
    assert not (cache_dir() / "derive" / f"{derivation_key(effects, assumptions)}.pkl").exists()
    with pytest.raises(EditedSinceImportError, match=edited + ".*would generate the model's C.*new Python process"):
        generate(effects, assumptions, tmp_path / "out", compile=False, echo=None)
    assert not (tmp_path / "out").exists()
    importlib.reload(module)  # the process has the edited code now
    assert edited_since_import([path]) == []


def test_a_file_edited_before_its_module_is_imported_is_not_refused(tmp_path, monkeypatch):
    """Only a module the process imported can be older than its file: one imported after the edit is the edit."""
    pkg = tmp_path / "later"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "laws.py").write_text("k = 1\n")
    assert edited_since_import([pkg / "laws.py"]) == []  # not imported: nothing noted
    (pkg / "laws.py").write_text("k = 2\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        importlib.import_module("later.laws")
        assert edited_since_import([pkg / "laws.py"]) == []
        (pkg / "laws.py").write_text("k = 3\n")
        assert edited_since_import([pkg / "laws.py"]) == [(pkg / "laws.py", "later.laws")]
    finally:
        for name in [m for m in sys.modules if m == "later" or m.startswith("later.")]:
            del sys.modules[name]
