"""Several results side by side: what their scenes differ in, and the designer's numbers of each.

``apexseal compare A B ...`` (and :func:`compare` from Python) answers the question an engineer asks after
changing a design: which keys of the scene changed, and what that did to friction power, displacements, forces,
lift-off and penetrations. The numbers are the named quantities of each run's summary that a sweep collects
(:mod:`.quantities`: the names a study file uses); the scene keys are those of each result's ``scene.toml``,
written in full (:func:`..scenes.resolved.resolved_toml`), so a default value and the same value given explicitly
compare equal. Each number carries its numerical noise (:mod:`.noise`: by a rule from the runs' rtol, or measured by
re-running the first at a tenth of it), and a change within it is marked as such: it is not an effect of what the
runs differ in.
"""

from __future__ import annotations

import hashlib
import math
import re
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from .noise import measured_noise, rerun, rtol_of, rule_noise, same_run_but_rtol, within
from .plausibility import penetrations
from .quantities import ENERGY_QUANTITIES, GAS_QUANTITIES, collect, friction_contacts, quantity_help
from .result import SimulationResult
from .summary import EXTREMES
from .wear import sliding_contacts

#: the scene keys of a result whose scene is not known (saved without its scene.toml)
UNKNOWN = "(no scene.toml)"
#: what :meth:`Comparison.figure` draws against crank angle
FIGURE_QUANTITIES = ("x", "y", "phi", "Pf_total")


@dataclass(eq=False)
class Comparison:
    """``scenes``: a row per scene key whose value differs between the results (a column per result);
    ``numbers``: a row per quantity (its unit in the row's name), a column per result; ``noise``: the same rows
    (without the status) and columns, each number's numerical noise in its unit (NaN: not estimated, a fixed-step
    method's), estimated as ``noise_source`` says; ``noise_run``: the first result re-run at a tighter rtol when
    the noise was measured (``noise_run_kept``: False for one made in memory, which :meth:`save` writes). ``==``
    is identity (the frames' own ``.equals`` compares their content)."""

    labels: list[str]
    scenes: pd.DataFrame
    numbers: pd.DataFrame
    results: list[SimulationResult]
    noise: pd.DataFrame | None = None
    noise_source: str = ""
    noise_run: SimulationResult | None = None
    #: False for a re-run made in memory (``compare(..., noise=True)``): :meth:`save` writes it
    noise_run_kept: bool = True

    def within_noise(self) -> pd.DataFrame:
        """True where a result's number differs from the first's by no more than the two noises together
        (:func:`.noise.within`); the first column, and a number equal to the first's, are False."""
        base = self.labels[0]
        return pd.DataFrame({label: [label != base and self.numbers.loc[q, label] != self.numbers.loc[q, base]
                                     and within(self.numbers.loc[q, label], self.numbers.loc[q, base],
                                                self.noise.loc[q, label], self.noise.loc[q, base])
                                     for q in self.noise.index] for label in self.labels}, index=self.noise.index)

    def figure(self, quantities: Sequence[str] = FIGURE_QUANTITIES, *, pyplot: bool = False):
        """The results' quantities against crank angle, a line per result (:func:`.plots.plot_comparison`)."""
        from .plots import plot_comparison

        return plot_comparison(self.results, quantities, self.labels, pyplot=pyplot)

    def save(self, folder: str | Path) -> list[Path]:
        """Write the numbers (comparison.csv), the scene keys that differ (scene-differences.csv), each number's
        noise (noise.csv, after a comment line saying how it was estimated), the figure (comparison.png) and a
        re-run made in memory for the noise (noise-rerun/) into ``folder``; the paths written."""
        from ...files import atomic_write
        from .figures import save_png

        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        paths = [folder / "comparison.csv", folder / "scene-differences.csv", folder / "noise.csv",
                 folder / "comparison.png"]
        atomic_write(paths[0], self.numbers.to_csv())
        atomic_write(paths[1], self.scenes.to_csv())
        atomic_write(paths[2], f"# numerical noise of each number, {self.noise_source}\n" + self.noise.to_csv())
        save_png(self.figure(), paths[3], 120)
        if self.noise_run is not None and not self.noise_run_kept:
            paths.append(self.noise_run.save(folder / "noise-rerun"))
        return paths

    def text(self) -> str:
        """Both tables for a console, each result's numbers with their change against the first result's."""
        if self.scenes.empty:
            scenes = "the scenes are the same"
        else:
            shown = self.scenes.apply(lambda row: pd.Series(_shortest(list(row)), index=row.index), axis=1)
            scenes = "scene keys that differ:\n" + shown.to_string()
        models = [str(r.info.get("model_hash", "?"))[:12] for r in self.results]
        options = {repr((r.scene.effects, r.scene.assumptions)) if r.scene is not None else "?" for r in self.results}
        if len(set(models)) > 1 and len(options) == 1:  # same effects and choices: the model's sources differ
            scenes += ("\nthe models differ (model hash " + ", ".join(f"{label} {m}" for label, m in
                                                           zip(self.labels, models, strict=True))
                       + "): the derivation, a submodel or the generator changed between the runs")
        scenes += _not_alike(self.labels, self.results)
        numbers = self.numbers.copy().astype(object)
        base = self.numbers.iloc[:, 0]
        marked = self.within_noise().reindex(self.numbers.index, fill_value=False)
        for column in numbers.columns:
            numbers[column] = [_cell(v, b, column != numbers.columns[0]) + ("~" if m else "") for v, b, m in
                               zip(self.numbers[column], base, marked[column], strict=True)]
        numbers.insert(1, "noise", [_noise_cell(self.noise[self.labels[0]].get(q), b) for q, b in base.items()])
        lines = [f"{scenes}\n", _tolerances(self.labels, self.results),
                 f"noise (the first run's, beside it): {self.noise_source}",
                 f"results (change against {self.labels[0]}):\n{numbers.to_string()}"]
        if marked.to_numpy().any():
            lines.append("~: a change within the numerical noise (no larger than the two runs' noises together): not "
                         "an effect of what the runs differ in; a tighter rtol for every run (--rtol, rtol=) resolves it")
        if unresolved := self.unresolved_by_samples():
            lines.append("sampling: the seal's energy balance over the samples does not close for "
                         + ", ".join(f"{label} (misses {abs(j):.3g} J per revolution)" for label, j in unresolved.items())
                         + ": a contact's friction power and wear work of that size or less are not resolved by the "
                         "samples, whatever their noise (the rtol's) says; more samples per revolution "
                         "(solver.samples_per_revolution) resolve them (docs/results.md)")
        return "\n".join(lines)

    def unresolved_by_samples(self) -> dict[str, float]:
        """label -> the energy residual per revolution (J) of each result whose balance over its samples does not
        close (:mod:`.energy`): its contacts' friction powers and wear works of that size are sampling-limited."""
        from .energy import closes

        rows = quantity_row("energy.residual_fraction"), quantity_row("energy.residual")
        if not all(row in self.numbers.index for row in rows):
            return {}
        fraction, residual = (self.numbers.loc[row] for row in rows)
        return {label: float(residual[label]) for label in self.labels
                if math.isfinite(fraction[label]) and not closes(fraction[label])}


def compare(results: Sequence[SimulationResult | str | Path], labels: Sequence[str] | None = None, *,
            noise: bool | SimulationResult | str | Path | None = None) -> Comparison:
    """Results (or result folders) side by side; ``labels`` default to the folders' names, or the scenes'.

    ``noise``: how each number's numerical noise is estimated (:mod:`.noise`). None (the default, no run): from
    each run's rtol by the rule measured on the default scene; True: measured by re-running the first result at a
    tenth of its rtol (:func:`.noise.rerun`, a run as long as the first; kept as ``noise_run``); a result or result
    folder: that re-run, made before (the first's scene at a tighter rtol)."""
    if isinstance(results, str | Path | SimulationResult):  # one result, not a sequence of them (nor of characters)
        raise TypeError(f"results = {results!r}: compare needs a list of at least two results or result folders")
    names = [Path(r) if isinstance(r, (str, Path)) else None for r in results]
    loaded = [r if p is None else SimulationResult.load(p) for r, p in zip(results, names, strict=True)]
    if len(loaded) < 2:
        raise ValueError(f"compare needs at least two results, not {len(loaded)}")
    labels = list(labels) if labels is not None else _labels(loaded, names)
    if len(labels) != len(loaded) or len(set(labels)) != len(labels):
        raise ValueError(f"compare needs one distinct label per result, not {labels}")
    scenes = scene_differences([r.scene for r in loaded], labels)
    numbers = designer_numbers(loaded, labels)
    rerun_result, source = _noise_run(loaded[0], noise)
    return Comparison(labels, scenes, numbers, loaded, *_noise(numbers, loaded, rerun_result, source),
                      noise_run_kept=noise is not True)


def _noise_run(first: SimulationResult, noise) -> tuple[SimulationResult | None, str]:
    """The re-run of ``first`` that ``noise`` asks for (None: the rule), and how it names the estimate."""
    if noise is None or noise is False:
        return None, ("estimated from each run's rtol: the spread that the rtol alone gives on the default scene "
                      "(docs/results.md, \"Numerical noise\"); --noise (noise=True) measures it for these runs")
    if noise is True:
        rerun_result = rerun(first)
    elif isinstance(noise, str | Path | SimulationResult):
        rerun_result = SimulationResult.load(noise) if isinstance(noise, str | Path) else noise
        differing = same_run_but_rtol([scene_keys(first.scene), scene_keys(rerun_result.scene)])
        tight, loose = rtol_of(rerun_result), rtol_of(first)
        if differing or first.scene is None:
            raise ValueError(f"noise = {noise!s:.200}: not a re-run of the first result's scene (differs in "
                             f"{', '.join(differing) or 'scene'}; allowed: the same scene at a tighter solver.rtol)")
        if tight is None or loose is None or not tight < loose:
            raise ValueError(f"noise = {noise!s:.200}: its solver.rtol = {tight} is not tighter than the first "
                             f"result's {loose} (allowed: 0 < rtol < {loose})")
    else:
        raise TypeError(f"noise = {noise!r}: expected None (estimate from the rtol), True (re-run the first result at "
                        "a tenth of its rtol) or a re-run result or its folder")
    return rerun_result, (f"measured: the first run re-run at rtol {rtol_of(rerun_result):g} changed by it (its "
                          "integration error)")


def _noise(numbers: pd.DataFrame, results: list[SimulationResult], rerun_result, source: str):
    """The noise table of ``numbers`` (:mod:`.noise`): by the rule, or the re-run's change scaled to each run's
    rtol; with the source and the re-run."""
    rows = {q: quantity_row(q) for q in compared() if quantity_row(q) in numbers.index}
    names = list(rows)
    columns = {}
    first = {q: numbers.loc[rows[q]].iloc[0] for q in names}
    measured = None if rerun_result is None else measured_noise(first, collect(rerun_result, tuple(names)))
    for label, result in zip(numbers.columns, results, strict=True):
        values = {q: numbers.loc[rows[q], label] for q in names}
        if measured is None:
            columns[label] = rule_noise(values, rtol_of(result))
        else:
            ratio = (rtol_of(result) or math.nan) / rtol_of(results[0])
            columns[label] = {q: measured[q] * ratio for q in names}
    table = pd.DataFrame(columns).reindex(names)
    table.index = pd.Index([rows[q] for q in names], name="quantity")
    return table, source, rerun_result


def scene_differences(scenes, labels: Sequence[str]) -> pd.DataFrame:
    """The scene keys whose values differ between ``scenes`` (a key of any of them; "–" where one lacks it), one
    column per label."""
    keys = [scene_keys(s) for s in scenes]
    differing = sorted({k for ks in keys for k in ks if len({ks.get(k, "–") for ks in keys}) > 1})
    return pd.DataFrame({label: [ks.get(k, "–") for k in differing] for label, ks in zip(labels, keys, strict=True)},
                        index=pd.Index(differing, name="scene key"))


_NUMBER = re.compile(r"^(-?\d[\d.]*(?:[eE][+-]?\d+)?)(\s.*)?$")


def _significant(x: float, digits: int) -> str:
    """``x`` to ``digits`` significant digits, without an exponent from 1e-4 to 1e7 (20000, not 2e+04)."""
    import numpy as np

    if x == 0 or 1e-4 <= abs(x) < 1e7:
        return np.format_float_positional(x, precision=digits, unique=False, fractional=False, trim="-")
    return f"{x:.{digits}g}"


def _shortest(values: list[str]) -> list[str]:
    """A row of scene values as :meth:`Comparison.text` shows them: each number with its unit (as scene.toml writes
    it, to the last digit: -0.436332312998582 rad) to the fewest significant digits, from 4, that keep the row's
    values apart; a value that is not a number (a word, "–" where a result lacks the key), an integer and a number
    that has no more digits stay as written (the table and its CSV keep every value whole)."""
    parsed = [_NUMBER.match(str(v)) for v in values]
    for digits in range(4, 18):
        short = [v if m is None or re.fullmatch(r"-?\d+", m.group(1))
                 else _significant(float(m.group(1)), digits) + (m.group(2) or "")
                 for v, m in zip(values, parsed, strict=True)]
        short = [s if len(s) < len(v) else v for s, v in zip(short, values, strict=True)]
        if len(set(short)) == len(set(values)):
            return short
    return values


def scene_keys(scene) -> dict[str, str]:
    """Every key of ``scene`` as a saved result's scene.toml writes it (dotted name -> value with its unit); a
    pressure table by the sha256 of its rows."""
    if scene is None:
        return {"scene": UNKNOWN}
    from apexseal.derive.submodels.registry import parameters

    from ..scenes.resolved import TABLE_FILE, resolved_toml

    text, files = resolved_toml(scene)
    out = dict(_flatten(tomllib.loads(text)))
    if TABLE_FILE in files:
        out["pressure.file"] = "table sha256 " + hashlib.sha256(files[TABLE_FILE].encode()).hexdigest()[:12]
    for p in parameters(all_inputs=True):  # a key the scene left to be computed (ms from the density, c from its
        value = scene.parameters.get(p.name)  # ratio): its value beside another scene's given one
        if p.key and p.key not in out and value is not None:
            out[p.key] = f"{value:.6g} {p.unit} (derived)"
    return out


def compared() -> tuple[str, ...]:
    """The quantities set side by side (runtime/results/quantities.py, the names a sweep's study file uses)."""
    return ("revolutions", "events.total", *(f"friction_power.{c}" for c in friction_contacts()),
            "liftoff_fraction", "housing_force.mean", "housing_force.max",
            *(f"{s}.{e}" for s in EXTREMES for e in ("min", "max")), "gap.open_fraction", "gap.max",
            *(f"penetration.{c}" for c in penetrations()), "flank.least",
            # the tip's sliding speed and the sliding work (Archard) at each contact (runtime/results/wear.py)
            "wear.housing.speed_mean", "wear.housing.speed_max", "wear.housing.pv_max",
            *(f"wear.{c}.work" for c in sliding_contacts()), "wear.seal_mass",
            # whether the samples resolve the loads' work (runtime/results/energy.py)
            *(f"energy.{name}" for name in ENERGY_QUANTITIES),
            *(f"gas.{name}" for name in GAS_QUANTITIES))  # left out where no run has the gas model


def designer_numbers(results: Sequence[SimulationResult], labels: Sequence[str]) -> pd.DataFrame:
    """A row per quantity of :func:`compared` (named as in a sweep, its unit beside), after the runs' status; a
    quantity no result has (friction at a contact whose effect is off everywhere) is left out."""
    names = compared()
    columns = {label: {"status": r.status, **collect(r, names)} for label, r in zip(labels, results, strict=True)}
    table = pd.DataFrame(columns, index=["status", *names])
    table = table.loc[[q == "status" or table.loc[q].notna().any() for q in table.index]]
    table.index = pd.Index([q if q == "status" else quantity_row(q) for q in table.index], name="quantity")
    return table


def quantity_row(name: str) -> str:
    """A quantity's row in :func:`designer_numbers`: its name with its unit, ``energy.residual (J)``."""
    return f"{name} ({quantity_help()[name][0]})"


def _flatten(table: dict, prefix: str = ""):
    for key, value in table.items():
        if isinstance(value, dict):
            yield from _flatten(value, f"{prefix}{key}.")
        else:
            yield f"{prefix}{key}", str(value)


def _labels(results: list[SimulationResult], paths: list[Path | None]) -> list[str]:
    """The folders' names (their paths where two names coincide), else the scenes' names and hashes; numbered
    where they still coincide (a folder given twice)."""
    from .plots import result_label

    labels = [p.name if p is not None else result_label(r, i) for i, (r, p) in enumerate(zip(results, paths, strict=True))]
    if len(set(labels)) < len(labels):
        labels = [str(p) if p is not None else label for label, p in zip(labels, paths, strict=True)]
    if len(set(labels)) < len(labels):
        labels = [f"{label} ({i + 1})" for i, label in enumerate(labels)]
    return labels


def _cell(value, base, relative: bool) -> str:
    if value is None or isinstance(value, float) and value != value:  # not in this result (NaN)
        return "–"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        text = f"{value:.4g}"
        if relative and isinstance(base, (int, float)) and math.isfinite(base) and base != 0 and value != base:
            text += f" ({100 * (value - base) / abs(base):+.1f} %)"
        return text
    return str(value)


def _noise_cell(noise, base) -> str:
    """A noise for the console: ± its share of the first run's value, or ± itself where that value is 0."""
    if noise is None or isinstance(noise, float) and math.isnan(noise):
        return "–" if noise is None else "not estimated"
    if noise == 0:
        return "0"
    if isinstance(base, (int, float)) and base:
        return f"±{100 * noise / abs(base):.2g} %"
    return f"±{noise:.2g}"


def _not_alike(labels: list[str], results: list[SimulationResult]) -> str:
    """A caveat for runs sampled or run differently: peaks and extremes are taken at the output samples (denser
    sampling finds higher impact peaks, README), and counts and fractions grow or shrink with the revolutions
    computed; "" for runs alike in both."""
    per = [r.info.get("samples_per_revolution") for r in results]
    revolutions = [round(float(r.revolutions), 2) for r in results]
    said = []
    if len(set(per)) > 1:
        said.append("samples per revolution (" + ", ".join(f"{label} {p}" for label, p in zip(labels, per,
                                                                                               strict=True))
                    + "): peaks, extremes and penetrations are the samples' and are not comparable")
    if len(set(revolutions)) > 1:
        said.append("revolutions (" + ", ".join(f"{label} {n:g}" for label, n in zip(labels, revolutions,
                                                                                      strict=True))
                    + "): switch counts are the runs' and the start-up from rest weighs differently in the means")
    return "".join(f"\nnot alike: {s}" for s in said)


def _tolerances(labels: list[str], results: list[SimulationResult]) -> str:
    """The runs' methods and rtol, one line (once when they are all the same)."""
    each = [f"{r.info.get('method', '?')}, rtol {r.info.get('rtol', '?')}" for r in results]
    if len(set(each)) == 1:
        return f"every run: {each[0]}"
    return "runs: " + "; ".join(f"{label} {e}" for label, e in zip(labels, each, strict=True))
