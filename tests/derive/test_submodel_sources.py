"""A submodel's helper modules are part of the derivation's cache key (derive/submodels/sources.py): editing the
laws a submodel imports, at the top of its file or inside ``contacts()``, gives a new key, and editing what it
does not import does not."""

from __future__ import annotations

import importlib
import sys

import pytest

from apexseal.derive.submodels.base import Submodel
from apexseal.derive.submodels.housing import HousingContact
from apexseal.derive.submodels.sources import source_files, source_key, source_text

CLASS = '''
import math

import numpy as np

from apexseal.derive.submodels.base import Submodel

from .shared import constants


class Pad(Submodel):
    name = "pad_{tag}"

    def contacts(self, ctx):
        from . import laws
        from .deep.inner import shape

        return []
'''


def _package(root, tag: str):
    """A package ``pads_<tag>`` below ``root``: the class, two helpers it imports (one inside a method), a helper
    of a helper's subpackage, and a module it never imports; returns the class."""
    pkg = root / f"pads_{tag}"
    (pkg / "deep").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "pad.py").write_text(CLASS.format(tag=tag))
    (pkg / "shared.py").write_text("constants = 1\n")
    (pkg / "laws.py").write_text("from .deep import inner\n\ndef force(k, d):\n    return k * d\n")
    (pkg / "deep" / "__init__.py").write_text("")
    (pkg / "deep" / "inner.py").write_text("shape = 'flat'\n")
    (pkg / "unused.py").write_text("x = 1\n")
    sys.path.insert(0, str(root))
    try:
        return importlib.import_module(f"pads_{tag}.pad").Pad
    finally:
        sys.path.remove(str(root))


@pytest.fixture(autouse=True)
def remembered_at_once(monkeypatch):
    """No racy window: every key and import graph is remembered at once, so the tests exercise the remembered
    path (files written a moment ago are otherwise never remembered)."""
    import apexseal.derive.submodels.sources as sources
    import apexseal.files as files

    monkeypatch.setattr(files, "RACY_NS", -1)
    sources._FOUND.clear()


@pytest.fixture
def pad(tmp_path):
    cls = _package(tmp_path, "a")
    sys.path.insert(0, str(tmp_path))
    yield cls, tmp_path / "pads_a"
    sys.path.remove(str(tmp_path))
    for name in [m for m in sys.modules if m.startswith("pads_a")]:
        del sys.modules[name]


def test_the_key_covers_the_helpers_a_submodel_imports_and_nothing_else(pad):
    cls, pkg = pad
    root, own, helpers = source_files(cls)
    assert root == pkg.resolve() and own == pkg.resolve() / "pad.py"
    assert [f.relative_to(root).as_posix() for f in helpers] == [  # the package's __init__ runs on import too
        "__init__.py", "deep/__init__.py", "deep/inner.py", "laws.py", "shared.py"]
    assert source_text(cls).startswith((pkg / "pad.py").read_text())


@pytest.mark.parametrize("helper", ["laws.py", "shared.py", "deep/inner.py"])
def test_editing_an_imported_helper_changes_the_key(pad, helper):
    cls, pkg = pad
    before = source_text(cls)
    (pkg / helper).write_text((pkg / helper).read_text() + "\n# a changed law\n")
    assert source_text(cls) != before


def test_the_key_of_a_registered_class_follows_an_edit_in_the_same_process(pad):
    cls, pkg = pad
    before = source_key(cls)
    assert source_key(cls) == before
    (pkg / "deep" / "inner.py").write_text("shape = 'round'\n")
    assert source_key(cls) != before
    (pkg / "extra.py").write_text("k = 3\n")
    (pkg / "laws.py").write_text((pkg / "laws.py").read_text() + "from . import extra\n")  # a new helper
    after = source_key(cls)
    (pkg / "extra.py").write_text("k = 4\n")
    assert source_key(cls) != after


def test_a_helper_created_after_the_first_key_enters_it(tmp_path):
    """A helper imported (inside contacts()) before it existed: creating it changes its folder, and the key."""
    cls = _package(tmp_path, "late")
    pkg = tmp_path / "pads_late"
    (pkg / "laws.py").unlink()
    before = source_key(cls)
    (pkg / "laws.py").write_text("def force(k, d):\n    return k * d\n")
    assert source_key(cls) != before and "\nlaws.py\n" in source_text(cls)
    for name in [m for m in sys.modules if m.startswith("pads_late")]:
        del sys.modules[name]


def test_editing_a_module_it_does_not_import_keeps_the_key(pad):
    cls, pkg = pad
    before = source_text(cls)
    (pkg / "unused.py").write_text("x = 2\n")
    assert source_text(cls) == before


def test_a_module_outside_any_package_takes_the_modules_of_its_folder_only(tmp_path):
    """Not a library in a virtual environment below its folder (it imported sympy: 596 files, 6 s a process)."""
    venv = tmp_path / ".venv" / "lib" / "site-packages" / "padlib"
    venv.mkdir(parents=True)
    (venv / "__init__.py").write_text("x = 1\n")
    (tmp_path / "flat_pad_lib.py").write_text(
        "from apexseal.derive.submodels.base import Submodel\n\n\nclass LibPad(Submodel):\n    name = 'lib_pad'\n\n"
        "    def contacts(self, ctx):\n        import padlib\n\n        return []\n")
    sys.path[:0] = [str(tmp_path), str(venv.parent)]
    try:
        cls = importlib.import_module("flat_pad_lib").LibPad
        assert source_files(cls)[2] == []
    finally:
        sys.path.remove(str(tmp_path))
        sys.path.remove(str(venv.parent))
        sys.modules.pop("flat_pad_lib", None)


def test_a_module_outside_any_package_takes_its_folder_s_helpers(tmp_path):
    (tmp_path / "flat_pad_laws.py").write_text("def force(k, d):\n    return k * d\n")
    (tmp_path / "flat_pad.py").write_text(
        "from apexseal.derive.submodels.base import Submodel\n\n\nclass FlatPad(Submodel):\n    name = 'flat_pad'\n\n"
        "    def contacts(self, ctx):\n        import flat_pad_laws\n\n        return []\n")
    sys.path.insert(0, str(tmp_path))
    try:
        cls = importlib.import_module("flat_pad").FlatPad
        before = source_text(cls)
        assert "\nflat_pad_laws.py\n" in before
        (tmp_path / "flat_pad_laws.py").write_text("def force(k, d):\n    return 2 * k * d\n")
        assert source_text(cls) != before
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("flat_pad", None)


def test_a_built_in_submodel_gives_its_file_and_a_class_without_a_file_its_declarations():
    path = sys.modules[HousingContact.__module__].__file__
    assert source_text(HousingContact) == open(path, encoding="utf-8").read()
    cls = type("Made", (Submodel,), {"name": "made", "__module__": "nowhere"})
    assert "()" in source_text(cls)


def test_a_broken_helper_is_hashed_not_run(tmp_path):
    """The helpers are found on the file system: nothing of the submodel's package is imported to hash it. A helper
    with a syntax error, imported inside contacts() (``from .helpers import scale``), crashed every command that
    loads a model, the default scene's too, because looking up ``helpers.scale`` imported ``helpers``; one with
    side effects ran them."""
    pkg = tmp_path / "pads_broken"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "pad.py").write_text(CLASS.format(tag="broken").replace("from . import laws", "from .helpers import scale"))
    (pkg / "shared.py").write_text("constants = 1\n")
    (pkg / "helpers.py").write_text(f"open({str(tmp_path / 'ran')!r}, 'w').close()\ndef scale(:\n")
    sys.path.insert(0, str(tmp_path))
    try:
        cls = importlib.import_module("pads_broken.pad").Pad
        root, _, helpers = source_files(cls)
        assert [h.name for h in helpers] == ["helpers.py", "shared.py"]
        first = source_key(cls)
        assert not (tmp_path / "ran").exists()
        (pkg / "helpers.py").write_text("def scale(x):\n    return x\n")  # repaired: another key
        assert source_key(cls) != first
    finally:
        sys.path.remove(str(tmp_path))
        for name in [m for m in sys.modules if m.startswith("pads_broken")]:
            del sys.modules[name]


def test_a_package_in_a_folder_of_another_name_takes_its_helpers(tmp_path):
    """A package imported as ``pads_renamed`` from a folder ``code`` (setuptools' package-dir, as apexseal's own
    layout): its helpers were looked for under the folder's name and none was found, so editing one kept the key."""
    import importlib.util

    folder = tmp_path / "code"
    folder.mkdir()
    (folder / "__init__.py").write_text("")
    (folder / "pad.py").write_text("from apexseal.derive.submodels.base import Submodel\n\nfrom . import laws\n\n\n"
                                   "class Pad(Submodel):\n    name = 'pad_renamed'\n")
    (folder / "laws.py").write_text("k = 1\n")
    spec = importlib.util.spec_from_file_location("pads_renamed", folder / "__init__.py",
                                                  submodule_search_locations=[str(folder)])
    package = importlib.util.module_from_spec(spec)
    sys.modules["pads_renamed"] = package
    try:
        spec.loader.exec_module(package)
        cls = importlib.import_module("pads_renamed.pad").Pad
        root, _, helpers = source_files(cls)
        assert root == folder.resolve() and [h.name for h in helpers] == ["__init__.py", "laws.py"]
        first = source_key(cls)
        (folder / "laws.py").write_text("k = 2\n")
        assert source_key(cls) != first
    finally:
        for name in [m for m in sys.modules if m.startswith("pads_renamed")]:
            del sys.modules[name]
