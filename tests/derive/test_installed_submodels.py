"""A submodel an installed package declares as an entry point (group ``apexseal.submodels``) is in every process:
the command line, and so a sweep's worker processes, have it without any import by the user (docs/extending.md).

The package is installed the way pip leaves one: a module and its ``.dist-info`` folder (METADATA and
entry_points.txt) on the path, which is all ``importlib.metadata`` reads.
"""

from __future__ import annotations

import os
import re
import subprocess

import pytest

from apexseal.cli import command
from apexseal.derive.choices import Options
from apexseal.derive.options import ON

PLUGIN = '''
from apexseal.derive.options import NONE, ON, Option
from apexseal.derive.parameters import Parameter
from apexseal.derive.submodels.base import Submodel


class Wiper(Submodel):
    """A declared submodel (never derived here): a parameter and the option that switches it on."""

    name = "wiper"
    switch = "wiper"
    parameters = (Parameter("kwp", "N/m", "wiper stiffness", key="contacts.kwp", default=1e4, gt=0),)
    options = (Option("wiper", (NONE, ON), "a wiper ahead of the seal"),)
'''


def _install(site, module_text: str, package: str = "seal_extras") -> None:
    """``package`` (a new name for each test in this process: an imported module stays imported), version 0.2,
    declaring ``wiper = "<package>.wiper:Wiper"``."""
    (site / package).mkdir(parents=True)
    (site / package / "__init__.py").write_text("")
    (site / package / "wiper.py").write_text(module_text)
    info = site / f"{package}-0.2.dist-info"
    info.mkdir()
    name = package.replace("_", "-")
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 0.2\n")
    (info / "entry_points.txt").write_text(f"[apexseal.submodels]\nwiper = {package}.wiper:Wiper\n")


def _cli(site, *args: str) -> subprocess.CompletedProcess:
    env = os.environ | {"PYTHONPATH": os.pathsep.join(filter(None, [str(site), os.environ.get("PYTHONPATH")]))}
    return subprocess.run(command(*args), capture_output=True, text=True, env=env, timeout=300)


def test_an_installed_submodel_is_in_the_scene_of_the_command_line(tmp_path):
    site = tmp_path / "site"
    _install(site, PLUGIN)
    default = _cli(site, "scene", "--default", "--out", str(tmp_path))  # default.toml and its pressure table
    assert default.returncode == 0, default.stderr
    scene = tmp_path / "wiper.toml"

    def scene_with(lines: dict[str, str]) -> str:  # the default scene, a line added under each section header
        text = (tmp_path / "default.toml").read_text()
        for section, line in lines.items():
            text = re.sub(rf"^\[{section}\].*$", lambda m, line=line: f"{m.group(0)}\n{line}", text, count=1, flags=re.M)
        return text

    scene.write_text(scene_with({"effects": "wiper = true", "contacts": 'kwp = "3 kN/m"'}))
    run = _cli(site, "scene", "--resolved", str(scene))
    assert run.returncode == 0, run.stderr
    assert "\nwiper = true\n" in run.stdout and '\nkwp = "3000.0 N/m"\n' in run.stdout, run.stdout
    check = _cli(site, "scene", str(scene))
    assert check.returncode == 0 and "submodel wiper from seal-extras 0.2" in check.stdout, check.stderr
    scene.write_text(scene_with({"effects": "wiper = true", "contacts": 'kwp = "-3 kN/m"'}))
    bad = _cli(site, "scene", str(scene))
    assert bad.returncode != 0 and "contacts.kwp" in bad.stderr and "-3" in bad.stderr, bad.stderr
    scene.write_text(scene_with({"contacts": 'kwp = "-3 kN/m"'}))  # the wiper off (its default): kwp read by no law
    off = _cli(site, "scene", str(scene))
    assert off.returncode == 0 and 'contacts.kwp = "-3 kN/m" (not read while effects.wiper is off' in off.stderr, \
        off.stderr


def test_an_installed_submodel_that_is_off_leaves_the_committed_default_current(tmp_path):
    """A package's submodel that is off enters no model: ``generate --check`` finds generated/default current with
    it installed (it reported the committed artefacts stale, and every run derived and generated them again)."""
    site = tmp_path / "site"
    _install(site, PLUGIN, "seal_extras_off")
    check = _cli(site, "generate", "--check")
    assert check.returncode == 0 and "generated/default is current" in check.stdout, check.stdout + check.stderr


def test_an_installed_submodel_that_cannot_load_is_named_with_its_package(tmp_path):
    site = tmp_path / "site"
    _install(site, PLUGIN + "\nraise ImportError('needs a newer sealkit')\n")
    run = _cli(site, "scene", "--resolved")
    assert run.returncode != 0
    assert "seal-extras 0.2" in run.stderr and "wiper = 'seal_extras.wiper:Wiper'" in run.stderr, run.stderr
    assert "needs a newer sealkit" in run.stderr and "Traceback" not in run.stderr, run.stderr


@pytest.fixture
def fresh_registry(monkeypatch, tmp_path):
    """The registry as a new process finds it (restored afterwards for the other tests of this process)."""
    import importlib.metadata

    from apexseal.derive.submodels import registry

    real = importlib.metadata.entry_points
    # the packages these tests install (under a test's tmp_path) alone, not those installed beside apexseal
    monkeypatch.setattr(importlib.metadata, "entry_points", lambda **kw: [
        ep for ep in real(**kw) if ep.dist is not None and str(tmp_path) in str(ep.dist.locate_file(""))])
    saved = dict(registry._registry)
    monkeypatch.setattr(registry, "_loaded", False)
    monkeypatch.setattr(registry, "_broken", None)
    monkeypatch.setattr(registry, "_installed", {})
    registry._registry.clear()
    yield registry
    registry._registry.clear()
    registry._registry.update(saved)


def test_installed_submodels_come_after_the_built_in_ones_and_enter_the_provenance(tmp_path, monkeypatch,
                                                                                   fresh_registry):
    site = tmp_path / "site"
    _install(site, PLUGIN, "seal_extras_in_process")
    monkeypatch.syspath_prepend(str(site))
    from apexseal.runtime.results.summary import versions

    names = [cls.name for cls in fresh_registry.submodels()]
    assert names[-1] == "wiper" and len(names) == len(fresh_registry.BUILTIN) + 1
    assert fresh_registry.extended() and fresh_registry.installed() == {"wiper": "seal-extras-in-process 0.2"}
    # off by default: the default model's vector is the built-in one; switched on, its parameter comes last
    assert "kwp" not in fresh_registry.parameter_names() and "kwp" in fresh_registry.parameter_names(all_inputs=True)
    assert fresh_registry.parameter_names(opts=Options({"wiper": ON}))[-1] == "kwp"
    assert versions()["submodel wiper"] == "seal-extras-in-process 0.2"
    # a run records only what entered its model: the wiper off (its default), its package is not in the record
    assert "submodel wiper" not in versions(Options({}))
    assert versions(Options({"wiper": ON}))["submodel wiper"] == "seal-extras-in-process 0.2"


def test_a_summary_without_the_runs_record_names_only_the_packages_of_its_scenes_model(tmp_path, monkeypatch,
                                                                                       fresh_registry):
    """A result without a ``versions`` record (a run's result before it is written, an older result.json) had its
    summary name every installed package, the one whose submodel was off in its run too: the summary takes its
    scene's model."""
    from types import SimpleNamespace

    from apexseal.derive.assumptions import Assumptions
    from apexseal.derive.effects import Effects
    from apexseal.runtime.results.summary import run_versions

    site = tmp_path / "site"
    _install(site, PLUGIN, "seal_extras_summary")
    monkeypatch.syspath_prepend(str(site))
    assert fresh_registry.installed() == {"wiper": "seal-extras-summary 0.2"}
    off = SimpleNamespace(info={}, scene=SimpleNamespace(effects=Effects(), assumptions=Assumptions()))
    assert "submodel wiper" not in run_versions(off)
    on = SimpleNamespace(info={}, scene=SimpleNamespace(effects=Effects(wiper=True), assumptions=Assumptions()))
    assert run_versions(on)["submodel wiper"] == "seal-extras-summary 0.2"
    recorded = SimpleNamespace(info={"versions": {"apexseal": "x"}}, scene=None)
    assert run_versions(recorded) == {"apexseal": "x"}


def test_an_installed_submodel_that_clashes_names_its_package(tmp_path, monkeypatch, fresh_registry):
    site = tmp_path / "site"
    _install(site, PLUGIN.replace('Parameter("kwp"', 'Parameter("ks"'), "seal_extras_clash")
    monkeypatch.syspath_prepend(str(site))
    for _ in range(2):  # refused on every use, not only the first
        with pytest.raises(fresh_registry.RegistryError, match=r"seal-extras-clash 0\.2.*parameters that exist already: ks"):
            fresh_registry.submodels()
