"""The preload study's report: ``preload.json``, ``preload.md``, ``preload.png`` and ``scene.toml`` (the scene that
ran, every value explicit, with its pressure table when it has one; ``schedule.toml``, the same scene with the
schedule optimum as its ``[spring.schedule]``, where a schedule was solved) in one folder, written as one unit by
:class:`~apexseal.runtime.results.folder.ReportFolder` (:func:`report_folder`).

The figure has four panels: delta_s(theta) of the scene, the constant optimum and the schedule beside the
chamber pressure difference Pa - Pb; the tip's contact force along the periodic revolution with the
minimum force and its smallest value marked; the cycle-mean friction power of each contact for the three
designs.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np

from ....files import atomic_write
from .advice import caveats
from .problem import MM
from .result import squares_text

#: the files a preload report folder may hold (another file makes the command refuse to replace the folder)
REPORT_FILES = frozenset({"preload.json", "preload.md", "preload.png", "scene.toml", "schedule.toml", "pressure.csv"})
#: the report's record: its run id and status ("completed", "interrupted", "failed"), as a result's result.json
RECORD = "preload.json"


def report_folder(out: Path, run_id: str | None = None):
    """The :class:`~apexseal.runtime.results.folder.ReportFolder` of a preload report at ``out`` (refused, a
    ResultFolderError, where ``out`` holds other files)."""
    from ...results.folder import ReportFolder

    return ReportFolder(out, RECORD, REPORT_FILES, "a preload report", run_id)


#: the stage that makes each of a study's results (the command's names for them, as its report says where it stopped)
STAGES = {"constant": "constant optimum", "schedule": "schedule"}


def report_status(results: dict, *, interrupted_by: str = "", stage: str = "", refused: str = "") -> tuple[str, str]:
    """The status of a preload report and why the study ended where it did (``stopped``, the top line of
    preload.md; "" for a study that completed): the one rule of ``apexseal optimise-preload`` and of
    :func:`save_report`, so that a study run from Python reports as the command does. ``results``: the stages'
    results by name (:data:`STAGES`) in their order, a stage that did not run left out; ``interrupted_by`` and
    ``stage``: the signal's sender and the stage it stopped (the command's own signal handling); ``refused``: why
    ``stage`` was refused (a PreloadStudyError of the command's stages). In this order:

    * interrupted (the command's signal, or a result stopped by one, ``interrupted_by``, as
      ``apexseal.optimise_preload`` returns it): ``interrupted``, "interrupted by <sender> during the <stage>";
    * a stage refused: ``failed``, "the <stage> failed: <why>";
    * a result that failed (IPOPT did not reach the optimum, the start was infeasible): ``failed``, "the <stage>
      failed: <its message>" for the first such result;
    * otherwise ``completed``: also where the study warns (:func:`.advice.caveats`: a constant optimum that is not
      robust, a feasible set not monotone in the preload). The study then did what it was asked and its answer is a
      feasible design; the warning (the console's lines, the top of preload.md, ``warnings`` in preload.json) says
      what it is worth and what to do.
    """
    if not interrupted_by:
        key = next((k for k, r in results.items() if r is not None and r.interrupted_by), None)
        if key is not None:
            interrupted_by, stage = results[key].interrupted_by, STAGES[key]
    if interrupted_by:
        return "interrupted", f"interrupted by {interrupted_by} during the {stage}"
    if refused:
        return "failed", f"the {stage} failed: {refused}"
    key = next((k for k, r in results.items() if r is not None and not r.ok), None)
    if key is not None:
        return "failed", f"the {STAGES[key]} failed: {results[key].message.rstrip('.')}"
    return "completed", ""


def save_report(out, constant, schedule=None) -> Path:
    """The report of a preload study run from Python (``apexseal.optimise_preload``), written to the folder ``out``
    as ``apexseal optimise-preload --out`` writes its own: preload.json, preload.md, preload.png and scene.toml (the
    scene the study ran), moved into place as a whole (:func:`report_folder`: a folder holding other files is refused
    with a ResultFolderError, a completed report of another study is not replaced by a failed one). ``constant``: the
    constant optimum (``knots=1``); ``schedule``: a schedule started from it, or None. Its status and top line are
    the command's for the same results (:func:`report_status`): "interrupted" for a result a signal stopped,
    "failed" naming the stage that failed, else "completed". Returns where the report is:
    ``out``, or ``<out>.partial-<id>`` when kept aside (a KeptAsideWarning says why)."""
    import warnings

    from ...results.folder import KeptAsideWarning
    from .problem import PreloadStudyError
    from .result import PreloadResult

    for name, r, many in (("constant", constant, False), ("schedule", schedule, True)):
        if r is None and name == "schedule":
            continue
        if not isinstance(r, PreloadResult):
            raise PreloadStudyError(f"{name}: expected the PreloadResult of apexseal.optimise_preload, "
                                    f"not {type(r).__name__}")
        count = len(r.knots or r.knot_angles_deg)  # the knots asked, where the study found no design
        if count and (count > 1) != many:
            raise PreloadStudyError(f"{name}: a result of {count} knot{'s' * (count > 1)}; the "
                                    f"{'schedule' if many else 'constant optimum'} has "
                                    f"{'more than one' if many else 'one (knots=1)'}")
        if r.scene is None:
            raise PreloadStudyError(f"{name}: this result holds no scene (only a result apexseal.optimise_preload "
                                    "returned in this session does); its report cannot name what it ran")
    scene = constant.scene
    if schedule is not None and schedule.scene.content_hash() != scene.content_hash():
        from ...results.compare import scene_differences

        differ = scene_differences([schedule.scene, scene], ["schedule", "constant"])
        shown = "; ".join(f"{k} = {row['schedule']} against {row['constant']}" for k, row in differ.head(5).iterrows())
        raise PreloadStudyError(f"schedule: a study of another scene ({schedule.scene.name}, content hash "
                                f"{schedule.scene.content_hash()}) than the constant optimum's ({scene.name}, "
                                f"{scene.content_hash()}): {shown}{' …' if len(differ) > 5 else ''}; a schedule "
                                "started from a saved constant optimum (PreloadResult.load) is a study of that "
                                "optimum's scene: optimise_preload(start.scene, ..., start=start)")
    results = {"constant": constant} | ({"schedule": schedule} if schedule is not None else {})  # as the command's
    status, stopped = report_status(results)
    knots = (len(schedule.knots or schedule.knot_angles_deg) or None) if schedule is not None else None
    options = study_options(constant.min_force, constant.max_groove_force, constant.exclude_deg, knots,
                            constant.objective, constant.samples, constant.nodes) \
        | {"written_by": "apexseal.save_preload_report"}
    folder = report_folder(Path(out))
    where = folder.save(lambda into: write_report(
        into, scene, scene.name, results, None, constant.min_force, overrides=scene.overrides,
        stopped=stopped, options=options, run_id=folder.run_id, status=status), status)
    if folder.kept_aside:
        warnings.warn(f"{folder.kept_aside}; this report is in {where}", KeptAsideWarning, stacklevel=2)
    return where


def _shown(overrides: dict) -> str:
    return ", ".join(f"{k}={v if isinstance(v, str) else json.dumps(v)}" for k, v in overrides.items())


def _designs(results: dict) -> list[tuple[str, object, object]]:
    """(label, result, simulation) of the scene's preload, the constant optimum and the schedule, as present."""
    out = []
    first = next((r for r in results.values() if r is not None), None)
    if first is not None and "scene_simulation" in first.__dict__:
        out.append((f"scene ({first.scene_delta_s / MM:.3g} mm)", None, first.__dict__["scene_simulation"]))
    for key, label in (("constant", "constant optimum"), ("schedule", "schedule optimum")):
        r = results.get(key)
        if r is not None and r.ok:
            out.append((label, r, r.__dict__.get("simulation")))
    return out


def markdown(scene_name: str, results: dict, bisection=None, valley=None, overrides: dict | None = None,
             scene_file: bool = False) -> str:
    lines = [f"# Preload study of {scene_name}", ""]
    lines += [f"**Warning: {w}**" + "\n" for w in caveats(results, bisection)]
    if overrides:
        lines += [f"Scene keys replaced (--set): {_shown(overrides)}.", ""]
    if scene_file:
        lines += ["The scene that ran, every value explicit: `scene.toml`.", ""]
        lines += simulate_lines(results)
    for key, r in results.items():
        if r is None:
            continue
        lines += [f"## {key}", "", "```", r.describe(), "```", ""]
    if bisection is not None:
        lines += _bisection(bisection, results.get("constant"))
    if valley:
        from .stiffness import describe

        lines += ["## the design over (delta_s, ks): the same spring force at other stiffnesses", "", "```",
                  describe(valley, results["constant"].deficit_tol), "```", ""]
    saved = saved_friction_power(results)
    if saved is not None:
        c, s = results["constant"], results["schedule"]
        lines += ["## schedule against the best constant preload", "",
                  f"friction power {s.friction_power:.3f} W vs {c.friction_power:.3f} W: saved {saved:.3f} W "
                  f"({100 * saved / c.friction_power:.2f} %)", ""]
    return "\n".join(lines)


def simulate_lines(results: dict) -> list[str]:
    """preload.md's lines on simulating the design with ``apexseal simulate``: the constant optimum is the scene's
    ``spring.delta_s`` (scene.toml keeps the scene's own preload, the study's start); the schedule is the scene's
    ``[spring.schedule]``, written as schedule.toml (:func:`schedule_scene`)."""
    c, s = results.get("constant"), results.get("schedule")
    lines = []
    if c is not None and c.ok and c.delta_s is not None:
        lines += ["Simulate the constant optimum, from this folder: `apexseal simulate scene.toml --set "
                  f'spring.delta_s="{c.delta_s / MM:.6g} mm" -n {c.revolutions} -o ../constant-run` (scene.toml '
                  f"keeps the scene's own preload, {c.scene_delta_s / MM:.6g} mm; the line \"last revolution\" of "
                  f"its summary is the periodic revolution the study reports, {c.friction_power:.3f} W here; a result "
                  "folder outside this one, which a new study replaces whole).", ""]
    if s is not None and s.ok and s.knots and len(s.knots) > 1:
        lines += ["Simulate the schedule, from this folder: `apexseal simulate schedule.toml -o ../schedule-run` "
                  "(scene.toml with the schedule as its `[spring.schedule]`, docs/scenes.md, started at the study's "
                  f"first node, {float(s.knot_angles_deg[0]) % 360.0:.4g} deg, for its {s.revolutions} "
                  "revolutions: the line \"last revolution\" of its summary is the study's re-simulated revolution, "
                  f"{s.friction_power:.3f} W here).", ""]
    return lines


def schedule_scene(scene, result):
    """``scene`` with the schedule ``result`` found as its ``[spring.schedule]`` (the knots sorted by their crank
    angle in 0..360 deg: the schedule is periodic), started where the study re-simulates it, at its first node (the
    first knot) from the scene's initial state, over the study's revolutions (``result.revolutions``): its last
    revolution is the study's re-simulated one computed a second way (docs/preload.md); None where no schedule was
    solved. A scene started at its own angle for its own revolutions (one, by default) reported the start-up from
    rest, with the saving of the schedule lost in it."""
    if scene is None or result is None or not result.ok or not result.knots or len(result.knots) < 2:
        return None
    import warnings

    first = float(result.knot_angles_deg[0]) % 360.0
    knots = sorted(zip((float(a) % 360.0 for a in result.knot_angles_deg), map(float, result.knots), strict=True))
    with warnings.catch_warnings():  # the scene's warnings were given when it was loaded
        warnings.simplefilter("ignore")
        return scene.with_overrides(**{"spring.delta_s": None,
                                       "spring.schedule.angles": [f"{a!r} deg" for a, _ in knots],
                                       "spring.schedule.delta_s": [f"{v!r} m" for _, v in knots],
                                       "operation.start_angle": f"{first!r} deg",
                                       "operation.revolutions": int(result.revolutions)})


def saved_friction_power(results: dict) -> float | None:
    """W, the friction power the schedule saves against the constant optimum (both solved; else None): what the
    command prints, preload.md states and preload.json records (``saved_friction_power_W``)."""
    c, s = results.get("constant"), results.get("schedule")
    return c.friction_power - s.friction_power if c is not None and c.ok and s is not None and s.ok else None


def study_options(min_force, max_groove_force, exclude, knots, objective: str, samples: int, nodes: int) -> dict:
    """The study's options as preload.json records them (``options``), the command's and :func:`save_report`'s
    alike: the minimum force and the groove-force bound (N), the excluded windows (deg), the schedule's knots (None:
    no schedule), the objective, the samples per revolution the study ran and its shooting nodes."""
    return {"min_force_N": min_force, "max_groove_force_N": max_groove_force, "exclude_deg": [list(w) for w in exclude],
            "schedule_knots": knots, "objective": objective, "samples": samples, "nodes": nodes}


def _bisection(b, c) -> list[str]:
    """The bisection's section of preload.md: its bracket; where it did not end, the probes it had simulated."""
    lines = ["## derivative-free check (bisection over full simulations)", ""]
    if b.complete:
        lines += [f"delta_s* in {b.bracket()} ({b.simulations} simulations, {b.wall_time_s:.1f} s, monotone: "
                  f"{b.monotone})", ""]
    else:
        lines += [f"**The bisection did not end.** Its {b.simulations} simulations ({b.wall_time_s:.1f} s) so far put "
                  f"delta_s* {'in ' if b.lower is not None and b.delta_s is not None else ''}{b.bracket()}"
                  f"{'' if b.monotone else ' (not monotone: a probe below the bracket passed)'}; the preloads "
                  "probed:", "",
                  "| delta_s (mm) | passes | force deficit (N^2 rad) | groove-force excess (N^2 rad) | friction power (W) "
                  "| smallest force at the samples (N) |", "|---|---|---|---|---|---|"]
        lines += [f"| {p.delta_s / MM:.4f} | {'yes' if p.passed else 'no'} | {squares_text(p.deficit)} | "
                  f"{squares_text(p.groove_excess)} | "
                  f"{p.friction_power:.3f} | {p.min_measure:.4g} at {p.min_measure_angle:.1f} deg |" for p in b.probes]
        lines += [""]
    if c is not None and not c.ok and b.delta_s is not None:
        lines += [f"IPOPT found no constant optimum (above): this bracket is the study's answer for a constant preload"
                  f"{'' if b.complete else ', as far as the bisection got'}.", ""]
    return lines


def figure(scene, results: dict, min_force: float):
    from ...results.figures import new_figure
    from .problem import smallest_checked

    designs = _designs(results)
    first = next((r for r in results.values() if r is not None), None)
    windows = [tuple(w) for w in first.exclude_deg] if first is not None else []
    fig = new_figure((11, 7.5))
    ax = fig.subplots(2, 2)
    a1, a2, a3, a4 = ax[0, 0], ax[0, 1], ax[1, 0], ax[1, 1]
    for label, _r, sim in designs:
        if sim is None:
            continue
        deg = np.degrees(sim.thetas) % 360.0
        order = np.argsort(deg)
        a1.plot(deg[order], sim.delta_s[order] / MM, label=label)
        a3.plot(deg[order], sim.measure[order], lw=0.8, label=label)
        j = smallest_checked(sim.thetas, sim.measure, windows)
        a3.plot(deg[j], sim.measure[j], "o", ms=5, color=a3.lines[-1].get_color())
    for start, end in windows:  # excluded: no force required there
        for lo, hi in ([(start, end)] if end > start else [(start, 360.0), (0.0, end)]):
            a3.axvspan(lo, hi, color="0.9", zorder=0)
    a1.set(xlabel="crank angle (deg)", ylabel="delta_s (mm)", title="preload delta_s(theta)")
    _legend(a1)
    sim = next((d[2] for d in designs if d[2] is not None), None)
    if sim is not None:
        deg = np.degrees(sim.thetas) % 360.0
        order = np.argsort(deg)
        a2.plot(deg[order], (sim.pressures[0] - sim.pressures[1])[order] / 1e5, color="tab:gray")
    a2.set(xlabel="crank angle (deg)", ylabel="Pa - Pb (bar)", title="chamber pressure difference")
    a3.axhline(min_force, color="k", ls="--", lw=0.8, label=f"min force {min_force:g} N")
    a3.set(xlabel="crank angle (deg)", ylabel="tip contact force (N; < 0: lift-off)",
           title="tip force on the housing (dots: minimum; grey: excluded)")
    lo = min([min_force] + [float(np.min(d[2].measure)) for d in designs if d[2] is not None])
    a3.set_ylim(max(lo, -5 * min_force) - 1, None)
    a3.legend(fontsize=8)
    contacts = None
    width = 0.8 / max(1, len(designs))
    for i, (label, r, _sim) in enumerate(designs):
        powers = r.contact_friction_power if r is not None else next(
            (x.scene_contact_friction_power for x in results.values() if x is not None), {})
        contacts = contacts or list(powers)
        a4.bar(np.arange(len(contacts)) + i * width, [powers.get(k, 0.0) for k in contacts], width, label=label)
    if contacts:
        a4.set_xticks(np.arange(len(contacts)) + 0.4 - width / 2, contacts)
    a4.set(ylabel="cycle-mean friction power (W)", title="friction power per contact")
    _legend(a4)
    return fig


def _legend(ax) -> None:
    """The panel's legend, where it has a labelled design (a study that simulated nothing has none)."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8)


def write_report(folder: Path, scene, scene_name: str, results: dict, bisection=None, min_force: float = 5.0,
                 valley=None, stopped: str = "", *, overrides: dict | None = None, options: dict | None = None,
                 run_id: str | None = None, status: str = "completed", unchanged_from: Path | None = None) -> list:
    """Write preload.json, preload.md, scene.toml (with ``scene``: the scene that ran, every value explicit, and its
    pressure table; and schedule.toml, that scene with the schedule optimum, where one was solved) and preload.png
    into ``folder``; return their paths. ``valley``: the constant optimum's spring
    force at other stiffnesses (runtime/studies/preload/stiffness.py); ``stopped``: why the study ended before its
    last stage (a signal), stated at the top of both reports; ``overrides``: the scene keys replaced on the command
    line (--set), recorded in both; ``options``: the study's own (the command's options), recorded in the JSON;
    ``run_id`` and ``status`` ("completed", "interrupted", "failed"): the report's
    record, as a result's (runtime/results/folder.py); ``unchanged_from``: an earlier report of the same ``results``
    (the bisection's checkpoints: the bisection is not drawn), whose figure and scene files are copied rather than
    drawn and written again (where it has them). Each file is written atomically, the folder is not: write a
    report folder as one unit through :func:`report_folder`."""
    from ...results.figures import save_png

    folder = Path(folder)
    scheduled = schedule_scene(scene, results.get("schedule"))  # the schedule optimum as a scene: schedule.toml
    payload = ({"run_id": run_id} if run_id else {}) | {"status": status, "scene": scene_name,
                                                         "overrides": dict(overrides or {})} \
        | ({"options": dict(options)} if options else {}) \
        | ({"scene_file": "scene.toml"} if scene is not None else {}) | ({"stopped": stopped} if stopped else {}) \
        | ({"schedule_file": "schedule.toml"} if scheduled is not None else {}) \
        | {k: (r.to_dict() if r is not None else None) for k, r in results.items()}
    if bisection is not None:
        payload["bisection"] = bisection.to_dict()
    payload["warnings"] = caveats(results, bisection)
    if valley:
        from dataclasses import asdict

        payload["stiffness_valley"] = [asdict(p) for p in valley]
    if (saved := saved_friction_power(results)) is not None:
        payload["saved_friction_power_W"] = saved
    paths = [folder / "preload.json", folder / "preload.md"]
    atomic_write(paths[0], json.dumps(payload, indent=2, default=str) + "\n")
    atomic_write(paths[1], (f"**{stopped}.**\n\n" if stopped else "")
                 + markdown(scene_name, results, bisection, valley, overrides, scene is not None) + "\n")
    copied = _copy_unchanged(Path(unchanged_from), folder) if unchanged_from is not None else []
    if copied:
        return paths + copied
    if scene is not None:
        samples = next((r.samples for r in results.values() if r is not None and r.samples), None)
        paths += _write_scene(folder, scene, run_id, samples)
        if scheduled is not None:
            paths += _write_scene(folder, scheduled, run_id, samples, "schedule.toml")[:1]
    paths.append(folder / "preload.png")
    save_png(figure(scene, results, min_force), paths[-1], 100)
    return paths


def _copy_unchanged(source: Path, folder: Path) -> list:
    """Copy the figure and the scene files of the report in ``source`` into ``folder`` (a folder being filled, moved
    into place as a whole); [] where ``source`` has no figure."""
    if not (source / "preload.png").is_file():
        return []
    names = [n for n in ("scene.toml", "schedule.toml", "pressure.csv", "preload.png") if (source / n).is_file()]
    for name in names:
        shutil.copyfile(source / name, folder / name)
    return [folder / n for n in names]


def _write_scene(folder: Path, scene, run_id: str | None, samples: int | None = None, name: str = "scene.toml") -> list:
    """scene.toml (and the pressure table it names): the scene the study ran, ``--set`` keys included, with the
    ``samples`` per revolution the study ran (its ``samples`` option) as solver.samples_per_revolution, so that
    ``apexseal simulate scene.toml`` runs the study's grid; or, ``name`` "schedule.toml", that scene with the
    schedule optimum as its preload."""
    from ..scene_file import write_study_scene

    rerun = ("apexseal optimise-preload scene.toml, with the options recorded in preload.json" if name == "scene.toml"
             else "apexseal simulate schedule.toml (the schedule optimum of preload.json; the study re-runs from "
                  "scene.toml)")
    return write_study_scene(folder, scene, "preload study", run_id, rerun, samples, name)
