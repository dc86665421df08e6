"""Generated artefacts: byte-identical regeneration, no machine paths, staleness detection, the CLI check."""

from __future__ import annotations

import getpass
import json
import warnings
from pathlib import Path

import pytest

from apexseal.generated import load
from apexseal.generated.compile import compile_library
from apexseal.generated.generate import generate
from apexseal.generated.load import DEFAULT_DIR, artefact_dir
from apexseal.generated.manifest import StaleArtefactError, StaleArtefactWarning, read_manifest, verify

#: the committed files besides the manifest
COMMITTED = sorted(p.name for p in DEFAULT_DIR.iterdir() if p.is_file())


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory):
    out = tmp_path_factory.mktemp("regen") / "default"
    manifest = generate(out_dir=out, compile=False, echo=None)
    return out, manifest


def test_default_artefacts_are_current():
    verify(DEFAULT_DIR)


def test_regeneration_is_byte_identical(regenerated):
    out, manifest = regenerated
    assert sorted(p.name for p in out.iterdir()) == COMMITTED
    for name in COMMITTED:
        assert (out / name).read_bytes() == (DEFAULT_DIR / name).read_bytes(), name
    assert set(manifest.timings) == {"derive", "lower", "codegen", "render"}


def test_no_machine_paths_or_user_names():
    user = getpass.getuser()
    needles = ["/home/", "/root", "/tmp", "/work", "/Users/", "C:\\", str(Path.home())]
    if len(user) > 3:
        needles.append(user)
    for name in COMMITTED:
        text = (DEFAULT_DIR / name).read_text()
        for needle in needles:
            assert needle not in text, (name, needle)


def test_manifest_records_inputs_outputs_modes(loaded):
    data = read_manifest(DEFAULT_DIR).data
    assert set(data["inputs"]) == {"derive_source", "submodels", "generator_source", "effects", "assumptions",
                                   "templates", "casadi", "sympy"}
    assert [m["label"] for m in data["modes"]] == list(loaded.sx.mode_labels)
    assert not any(name.startswith("mode_") for name in data["functions"])  # only what a run executes
    assert data["names"]["parameters"] == list(loaded.sx.parameter_names)
    assert data["names"]["outputs"] == list(loaded.sx.output_names)
    assert {k: v["n_instructions"] for k, v in data["functions"].items()} == loaded.sx.n_instructions
    assert set(data["files"]) == set(COMMITTED) - {"manifest.json"}


def test_corrupted_c_file_is_detected(artefacts):
    path = artefacts / "casadi_model.c"
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0x01  # one flipped bit
    path.write_bytes(bytes(data))
    with pytest.raises(StaleArtefactError, match="casadi_model.c differs"):
        verify(artefacts)
    with pytest.raises(StaleArtefactError):
        compile_library(artefacts, flags="quick")


def test_missing_file_is_detected(artefacts):
    (artefacts / "apexseal_model.c").unlink()
    with pytest.raises(StaleArtefactError, match="apexseal_model.c is missing"):
        verify(artefacts)


@pytest.mark.parametrize("edit", ["hash", "effects", "derive_source", "files", "garbage"])
def test_corrupted_manifest_is_detected(artefacts, edit):
    path = artefacts / "manifest.json"
    data = json.loads(path.read_text())
    if edit == "hash":
        data["input_hash"] = "0" * 64
    elif edit == "effects":
        data["inputs"]["effects"]["groove_friction"] = False
    elif edit == "derive_source":  # consistent record, but for other derivation sources
        from apexseal.generated.manifest import hash_of

        data["inputs"]["derive_source"] = "1" * 64
        data["input_hash"] = hash_of(data["inputs"])
    elif edit == "files":
        data["files"]["casadi_model.c"] = "2" * 64
    path.write_text(json.dumps(data) if edit != "garbage" else "{ not json")
    with pytest.raises(StaleArtefactError) as info:
        verify(artefacts)
    if edit == "derive_source":
        assert "derive_source" in str(info.value)


def test_stale_default_is_regenerated_into_the_cache(artefacts, monkeypatch):
    (artefacts / "casadi_model.c").write_text("/* stale */\n")
    monkeypatch.setattr(load, "DEFAULT_DIR", artefacts)
    with pytest.warns(StaleArtefactWarning, match="casadi_model.c differs") as warned:
        where = artefact_dir()
    assert f"apexseal generate --out {artefacts} --no-compile`" in str(warned[0].message)  # the folder, outside the cwd
    assert where != artefacts
    verify(where)
    assert (where / "casadi_model.c").read_bytes() == (DEFAULT_DIR / "casadi_model.c").read_bytes()
    stamp = (where / "manifest.json").stat().st_mtime_ns
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert artefact_dir() == where  # the cache copy is current now: used as it is
    assert [str(w.message).startswith(f"stale or modified generated artefacts in {artefacts}") for w in caught] == [True]
    assert (where / "manifest.json").stat().st_mtime_ns == stamp


def test_cli_check(monkeypatch, artefacts):
    from click.testing import CliRunner

    from apexseal.commands_generate import generate as command

    result = CliRunner().invoke(command, ["--check"])
    assert result.exit_code == 0, result.output
    assert "current" in result.output
    (artefacts / "apexseal_model.h").write_text("/* edited */\n")
    monkeypatch.setattr(load, "DEFAULT_DIR", artefacts)
    result = CliRunner().invoke(command, ["--check"])
    assert result.exit_code == 1
    assert "STALE" in result.output


def test_cli_check_names_what_changed_and_the_command_that_refreshes(monkeypatch, artefacts):
    """A law's source edited (here: the record of it) makes --check name the sources that changed and the command
    that refreshes the folder; it said "generated for other effects/assumptions or sources than requested" besides,
    though the effects and assumptions were the requested ones, and gave no command."""
    from click.testing import CliRunner

    from apexseal.commands_generate import generate as command
    from apexseal.generated.manifest import hash_of

    path = artefacts / "manifest.json"
    data = json.loads(path.read_text())
    data["inputs"]["derive_source"] = "1" * 64
    data["input_hash"] = hash_of(data["inputs"])
    path.write_text(json.dumps(data))
    monkeypatch.setattr(load, "DEFAULT_DIR", artefacts)
    result = CliRunner().invoke(command, ["--check"])
    assert result.exit_code == 1
    assert "inputs changed since generation: derive_source" in result.output
    assert "other effects/assumptions" not in result.output
    assert f"refresh them with `apexseal generate --out {artefacts} --no-compile`" in result.output
    data["inputs"]["effects"]["groove_friction"] = False  # options that are not the default's: said so
    data["input_hash"] = hash_of(data["inputs"])
    path.write_text(json.dumps(data))
    assert "generated for other effects/assumptions than requested" in CliRunner().invoke(command, ["--check"]).output


def test_generate_refuses_a_generated_default_that_is_not_the_committed_one(tmp_path, monkeypatch):
    """`--out generated/default` away from the repository's root wrote a stray copy, silently, and left the committed
    artefacts stale."""
    from click.testing import CliRunner

    from apexseal.commands_generate import generate as command

    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(command, ["--out", "generated/default", "--no-compile"])
    assert result.exit_code == 2
    assert f"not the committed default artefacts of the apexseal that runs ({DEFAULT_DIR})" in result.output
    assert not (tmp_path / "generated").exists()


def test_trusted_loader_refuses_c_edited_with_its_manifest_hash(artefacts, monkeypatch):
    """An edit of a C file together with its sha256 in the manifest beside it passes the manifest alone, not the
    loader: the station's index holds the manifest's own sha256 (issue: a loader trusting the manifest beside the
    edited file compiled edited C)."""
    from apexseal.files import sha256_file
    from apexseal.generated.manifest import trust

    trust(artefacts)  # the station wrote this folder
    verify(artefacts, trusted=True)
    path = artefacts / "casadi_model.c"
    path.write_text(path.read_text().replace("casadi_real", "casadi_real ", 1))
    data = json.loads((artefacts / "manifest.json").read_text())
    data["files"]["casadi_model.c"] = sha256_file(path)
    (artefacts / "manifest.json").write_text(json.dumps(data, indent=2) + "\n")
    verify(artefacts)  # consistent with the manifest beside it ...
    with pytest.raises(StaleArtefactError, match="not the one the generator recorded"):
        verify(artefacts, trusted=True)  # ... but not with the station's record
    with pytest.raises(StaleArtefactError):
        compile_library(artefacts, flags="quick")
    monkeypatch.setattr(load, "DEFAULT_DIR", artefacts)
    with pytest.warns(StaleArtefactWarning, match="not the one the generator recorded"):
        assert artefact_dir() != artefacts  # the loader goes to regenerated artefacts, never the edited ones


def test_committed_default_is_in_the_package_index():
    verify(DEFAULT_DIR, trusted=True)


def test_library_refuses_a_foreign_generation_record(loaded):
    from apexseal.generated.load import check_library
    from apexseal.generated.manifest import Manifest

    check_library(loaded.library, loaded.manifest)
    other = Manifest(dict(loaded.manifest.data, input_hash="0" * 64))
    with pytest.raises(StaleArtefactError, match="built from the record"):
        check_library(loaded.library, other)


@pytest.mark.slow  # 30 s: it generates twice (a benchmark table's command; generation itself is tested above)
def test_the_stage_timing_command_reads_every_stage_of_both_generations(capsys):
    """runtime/bench/generate_stages.py (the README's stage table) parses what ``apexseal generate`` prints: if
    that output changed, the table's command would silently time nothing."""
    from apexseal.runtime.bench.generate_stages import main

    times = main(1)
    for flags in ("quick", "optimised"):
        assert set(times[flags]) == {"derive", "lower", "codegen", "render", "compile"}, times
        assert all(len(v) == 1 and v[0] >= 0 for v in times[flags].values())
    assert times["optimised"]["derive"][0] < times["quick"]["derive"][0]  # the derivation came from the cache
    assert "medians of 1, quick: derive" in capsys.readouterr().out


#: modules a generation imports that do not shape what it writes, and why
NOT_SHAPING = {
    "apexseal.generated": "the package",
}


def test_every_module_that_shapes_the_generated_files_is_an_input_of_their_hash(tmp_path):
    """The manifest's input hash covers the generator's and the hybrid DAE's modules by name (GENERATOR_MODULES):
    a module the station imports and the hash leaves out could change the C behind the manifest's back (dropping
    hybrid.py from the list went unnoticed by every other test). A new process generates, and every module of
    generated/ and runtime/ it imported is either in the list or named above."""
    import subprocess
    import sys

    from apexseal.generated.manifest import GENERATOR_MODULES

    code = ("import sys; from pathlib import Path; from apexseal.generated.generate import generate; "
            f"generate(out_dir=Path({str(tmp_path / 'g')!r}), compile=False, echo=None); "
            "print(' '.join(m for m in sys.modules if m.startswith(('apexseal.generated', 'apexseal.runtime'))))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    imported = set(run.stdout.split())
    hashed = {f"apexseal.generated.{m.removesuffix('.py')}" for m in GENERATOR_MODULES}
    assert imported - hashed - set(NOT_SHAPING) == set()
    assert {"apexseal.generated.hybrid", "apexseal.generated.lower"} <= imported
    assert not {m for m in imported if m.startswith("apexseal.runtime")}  # the station needs nothing of the runtime


@pytest.mark.parametrize("args, named", [(["--effects", "groove_friction=off"], "--effects"),
                                          (["--out", "elsewhere", "--assumptions", "damping=always"],
                                           "--out, --assumptions"),
                                          (["--flags", "quick"], "--flags")])
def test_cli_check_refuses_what_it_would_ignore(args, named):
    """--check verifies the committed default artefacts only: a scene's options given with it were ignored
    silently (it said "current" for the default model, whatever the effects asked)."""
    from click.testing import CliRunner

    from apexseal.commands_generate import generate as command

    result = CliRunner().invoke(command, ["--check", *args])
    assert result.exit_code == 2
    assert f"takes no {named}" in result.output


def test_generate_refuses_an_output_folder_it_cannot_make(tmp_path):
    """--out below a file ended in a FileExistsError traceback after the derivation; it is refused first, naming
    the folder and why, as simulate's --out is."""
    from click.testing import CliRunner

    from apexseal.commands_generate import generate as command

    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    result = CliRunner().invoke(command, ["--out", str(blocker / "sub"), "--no-compile"])
    assert result.exit_code == 2 and isinstance(result.exception, SystemExit), result.output
    assert f"cannot create the output folder {blocker / 'sub'}: {blocker} is a file" in result.output
    assert "[apexseal generate] derive" not in result.output


def test_regeneration_with_effects_off_is_byte_identical_across_processes(tmp_path):
    """A model pruned to a scene's effects (friction and the chamber pressure off) regenerates byte for byte in
    another process whose string hashes differ (PYTHONHASHSEED), derivation included (each process derives)."""
    import os
    import subprocess
    import sys

    outs = []
    for seed in ("1", "4242"):
        out = tmp_path / f"seed{seed}"
        subprocess.run([sys.executable, "-m", "apexseal", "generate", "--no-compile", "--out", str(out), "--effects",
                        "housing_friction=off,groove_friction=off,spring_friction=off,chamber_pressure=off"],
                       check=True, capture_output=True, env=os.environ | {"PYTHONHASHSEED": seed,
                                                                           "APEXSEAL_CACHE": str(tmp_path / seed)})
        outs.append(out)
    names = sorted(p.name for p in outs[0].iterdir())
    assert names == sorted(p.name for p in outs[1].iterdir()) and "manifest.json" in names
    for name in names:
        assert (outs[0] / name).read_bytes() == (outs[1] / name).read_bytes(), name
    assert b"tanh" not in (outs[0] / "casadi_model.c").read_bytes()  # the friction laws are not in the C
