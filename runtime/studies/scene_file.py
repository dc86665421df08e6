"""scene.toml in a study's report folder: the scene the study ran, every value explicit (``--set`` keys included),
with its pressure table beside it, so that the study can be run again and its designs simulated from the folder."""

from __future__ import annotations

from pathlib import Path

from ...files import atomic_write


def write_study_scene(folder: Path, scene, study: str, run_id: str | None, rerun: str,
                      samples: int | None = None, name: str = "scene.toml") -> list[Path]:
    """Write scene.toml (or ``name``; and the pressure table it names) into ``folder``; return their paths. Its first
    lines name the ``study`` ("preload study"), its ``run_id``, the scene and its content hash, and how to run it again
    (``rerun``). ``samples``: the samples per revolution the study ran, written as solver.samples_per_revolution
    where they differ from the scene's (the header says so, with the content hash as written), so that
    ``apexseal simulate scene.toml`` runs the study's sampling."""
    from ..scenes.resolved import stamped_toml

    own, written, notes = scene.solver.samples_per_revolution, scene, ()
    if samples and samples != own:
        written = scene.with_overrides(**{"solver.samples_per_revolution": samples})
        notes = (f"solver.samples_per_revolution = {samples}: the samples the study ran (the scene's {own}); "
                 f"content hash as written {written.content_hash()}",)
    text, extra = stamped_toml(scene, f"{study}{' ' + run_id if run_id else ''}", rerun, notes, written=written)
    paths = []
    for file, content in extra.items():
        atomic_write(Path(folder) / file, content)
        paths.append(Path(folder) / file)
    atomic_write(Path(folder) / name, text)
    return [Path(folder) / name, *paths]
