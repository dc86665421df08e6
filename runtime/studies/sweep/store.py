"""The results of a sweep on disk: one Parquet part-file per finished point, one table at the end.

Layout of the output folder::

    study.json               the study (its hash and name: resumed as it is, carried over from an edit, or refused)
    points/point-000012.parquet   one row per finished point, written atomically as the point finishes
    results.parquet          every finished point, sorted, with units in the column metadata
    results.csv              the same table for spreadsheets, each column's unit in its header (spring.ks [N/m])
    (``feasible``: a last column when the study states constraints: completed and every constraint met;
    ``periodic``, ``periodic_change`` after the status when its scene asks operation.until_periodic)

Only the process that runs the sweep writes (workers return rows), so a part-file is complete or absent:
a killed worker, Ctrl-C or a crashed machine loses at most the points that were running, and a resumed sweep
recomputes exactly the points without a part-file.

A study edited since its folder was written (a value added to a grid, a longer wall-time budget, one more
quantity) keeps the finished points whose scene the edited study has too (:meth:`Store.open`, :func:`carried`):
a point's row depends on its scene (every value and setting, its content hash in the row's ``scene_hash``) and on
the quantities collected, so a row with the same scene and every quantity now asked for is the row the edited study
would compute. The others are computed; the rows of points the edited study no longer has are discarded. A folder
of a study of another name is refused (a mistaken --out would otherwise discard it).
"""

from __future__ import annotations

import io
import json
import os
import re
import shutil
from pathlib import Path

import pandas as pd

from apexseal.files import atomic_write, try_lock_folder
from apexseal.runtime.results.folder import ResultFolderError, not_into_a_result

#: columns every row has, before the parameters and quantities, with their units
HEAD = {"point": "", "scene_hash": "", "status": "", "stop": "", "warnings": ""}
#: with operation.until_periodic (runtime/solving/periodicity.py): whether the point's run became periodic, and its
#: last revolution's change from the one before (summary.json's run.periodic)
PERIODIC = {"periodic": "", "periodic_change": "1"}
TAIL = {"wall_time_s": "s", "run_time_s": "s", "worker": ""}
_PART = re.compile(r"^point-(\d+)\.parquet$")


class StoreError(RuntimeError):
    """An output folder that cannot be used for this study (it holds another one)."""


class Store:
    def __init__(self, folder: str | Path):
        self.folder = Path(folder)
        self.parts = self.folder / "points"
        self.carried: tuple[int, int] | None = None  # rows kept and discarded of the study before an edit (open)

    # ------------------------------------------------------------------ opening
    def open(self, study, *, resume: bool = True, points=None) -> set[int]:
        """Prepare the folder for ``study``; returns the points already done (empty unless resuming). The folder
        is locked until :meth:`close`: a second sweep into it is refused (two sweeps mixed their rows). A folder of
        ``study`` before an edit (same name, another content hash) keeps the rows of ``points`` ((point, scene,
        overrides) of the edited study) that :func:`carried` finds in it, renumbered, and discards the others
        (``self.carried``: (rows kept, rows discarded)); of a study of another name it is refused."""
        try:
            not_into_a_result(self.folder, "a sweep's points and tables")
        except ResultFolderError as err:
            raise StoreError(str(err)) from None
        self.folder.mkdir(parents=True, exist_ok=True)
        self._lock = try_lock_folder(self.folder)
        if self._lock is None:
            raise StoreError(f"{self.folder} is being written by another sweep running now: wait for it to end, or "
                             "choose another --out folder")
        before = self.folder / "points.old"  # killed while an edit's rows were put in place: the old rows are whole
        if before.is_dir() and not self.parts.exists():
            before.rename(self.parts)
        record = self.folder / "study.json"
        digest = study.content_hash()
        if record.exists() and resume:
            try:
                written = json.loads(record.read_text())
            except (OSError, ValueError):
                written = {}
            if written.get("hash") != digest and self.done():
                if written.get("name") != study.name or points is None:
                    raise StoreError(f"{self.folder} holds the results of another study "
                                     f"({written.get('name', 'unnamed')!r}, this one is {study.name!r}); use --fresh "
                                     "to discard them, or another --out folder")
                self._carry_over(study, points)
        if not resume:
            shutil.rmtree(self.parts, ignore_errors=True)
            for name in ("results.parquet", "results.csv"):
                (self.folder / name).unlink(missing_ok=True)
            for figure in self.folder.glob("*.png"):  # the discarded study's figures (sweep_figures writes them here)
                figure.unlink(missing_ok=True)
        self.parts.mkdir(exist_ok=True)
        atomic_write(record, json.dumps({"name": study.name, "hash": digest, "source": study.source,
                                         "study": study.raw, "units": study.units()}, indent=2, default=str) + "\n")
        return self.done()

    def _carry_over(self, study, points) -> None:
        """Replace the part-files of the study before its edit by the rows :func:`carried` keeps for ``points``: the
        new ones written beside the old (points.new/), then put in their place, so that a kill in between leaves the
        old rows or the new, and the earlier study's tables and figures removed (the sweep writes them again)."""
        files = part_files(self.parts)
        rows = carried(pd.concat([pd.read_parquet(f) for f in files], ignore_index=True), study, points)
        staged, old = self.folder / "points.new", self.folder / "points.old"
        for folder in (staged, old):
            shutil.rmtree(folder, ignore_errors=True)
        staged.mkdir()
        for row in rows:
            self.write(row, staged)
        self.parts.rename(old)
        staged.rename(self.parts)
        shutil.rmtree(old, ignore_errors=True)
        for name in ("results.parquet", "results.csv"):
            (self.folder / name).unlink(missing_ok=True)
        for figure in self.folder.glob("*.png"):
            figure.unlink(missing_ok=True)
        self.carried = (len(rows), len(files) - len(rows))

    def close(self) -> None:
        """Let go of the folder (another sweep may resume it from now on)."""
        lock, self._lock = getattr(self, "_lock", None), None
        if lock is not None:
            os.close(lock)

    def done(self) -> set[int]:
        if not self.parts.is_dir():
            return set()
        return {int(m[1]) for p in self.parts.iterdir() if (m := _PART.match(p.name))}

    def not_completed(self) -> set[int]:
        """The points whose rows hold a status that computing them again may change (failed, chattering, an
        error...): not ``completed``, nor ``invalid`` (refused at its start for its scene's values, point.FINAL)."""
        from .point import FINAL

        return {int(_PART.match(f.name)[1]) for f in part_files(self.parts)
                if (~pd.read_parquet(f, columns=["status"])["status"].isin(FINAL)).any()}

    # ------------------------------------------------------------------ writing
    def write(self, row: dict, folder: Path | None = None) -> Path:
        """Write one point's row (atomically: a temporary file renamed into place) into points/ (or ``folder``)."""
        path = (folder or self.parts) / f"point-{int(row['point']):06d}.parquet"
        buf = io.BytesIO()
        pd.DataFrame([row]).to_parquet(buf, index=False)
        atomic_write(path, buf.getvalue(), durable=True)
        return path

    def table(self, study) -> pd.DataFrame:
        """Every finished point, sorted by point, columns in a fixed order (parameters, then quantities)."""
        order = [*HEAD, *PERIODIC, *(p.key for p in study.parameters), *study.quantities, *TAIL]
        files = part_files(self.parts)
        if not files:  # no point has said whether it became periodic: that column is a finished point's
            return pd.DataFrame(columns=[c for c in order if c not in PERIODIC])
        return rows_of(files, order)

    def consolidate(self, study) -> pd.DataFrame:
        """Write results.parquet (units in each column's metadata) and results.csv from the part-files."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        df = self.table(study)
        units = {**HEAD, **(PERIODIC if "periodic" in df else {}), **study.units(), **TAIL}
        if study.constraints:
            df["feasible"] = study.feasible(df)
            units["feasible"] = ""
        table = pa.Table.from_pandas(df, preserve_index=False)
        fields = [f.with_metadata({"unit": units.get(f.name, "")}) for f in table.schema]
        meta = dict(table.schema.metadata or {})
        meta[b"apexseal.sweep"] = json.dumps({"study": study.name, "hash": study.content_hash(), "units": units,
                                             "constraints": [vars(c) for c in study.constraints]}).encode()
        table = table.cast(pa.schema(fields, metadata=meta))
        buf = io.BytesIO()
        pq.write_table(table, buf)
        atomic_write(self.folder / "results.parquet", buf.getvalue())
        # each column's unit in its header cell (spring.ks [N/m]), as trajectory.csv's (a spreadsheet has no metadata)
        named = df.rename(columns={c: f"{c} [{units[c]}]" for c in df.columns if units.get(c, "") not in ("", "1")})
        atomic_write(self.folder / "results.csv", named.to_csv(index=False))
        df.attrs["units"] = units
        return df


def part_files(parts: Path) -> list[Path]:
    """The points' part-files in the folder ``parts`` (points/), by point; none when it is not there."""
    return sorted(p for p in parts.iterdir() if _PART.match(p.name)) if parts.is_dir() else []


def rows_of(files: list[Path], order: list[str]) -> pd.DataFrame:
    """The rows of the part-files ``files`` as one table, sorted by point, with the columns of ``order`` they have,
    in that order."""
    df = pd.concat([pd.read_parquet(f) for f in files], ignore_index=True)
    df = df.sort_values("point", kind="stable").reset_index(drop=True)
    return df[[c for c in order if c in df.columns]]


def carried(old: pd.DataFrame, study, points) -> list[dict]:
    """The rows of ``old`` (the part-files of a study before its edit) that the edited ``study`` keeps: for each of
    its ``points`` ((point, scene, overrides)) whose scene's content hash is a row's ``scene_hash``, that row with the
    point's number and parameter values, if its status is final (completed or invalid: computing it again gives the
    same row; the others are computed) and it holds every quantity ``study`` collects: none when the old rows lack
    one (a quantity added to ``[collect]``), every point is then computed."""
    from .point import FINAL

    if not set(study.quantities) <= set(old.columns):
        return []
    final = old[old["status"].isin(FINAL)].drop_duplicates("scene_hash").set_index("scene_hash")
    keep = [c for c in (*HEAD, *PERIODIC, *study.quantities, *TAIL) if c in final.columns and c != "point"]
    rows = []
    for i, scene, overrides in points:
        digest = scene.content_hash()
        if digest in final.index:
            row = final.loc[digest, keep].to_dict()
            rows.append({"point": int(i), "scene_hash": digest, **overrides, **row})
    return rows


class PartialResultsWarning(UserWarning):
    """A sweep's table read from its finished points' part-files: the sweep is running, was stopped, or was killed
    before it wrote results.parquet (or has finished points since)."""


def read_results(folder_or_file: str | Path) -> pd.DataFrame:
    """A sweep's results.parquet as a DataFrame; ``df.attrs["units"]`` maps each column to its unit.

    A sweep running, stopped or killed before it wrote the table (or one with points finished since it did) is read
    from its points' part-files instead (a table that holds fewer or more points than there are part-files is of
    another moment of the sweep), with a :class:`PartialResultsWarning` saying how many there are: the same columns
    but ``feasible`` (written with the table)."""
    import warnings

    import pyarrow.parquet as pq

    path = Path(folder_or_file)
    if path.is_dir():
        path = path / "results.parquet"
    parts = path.parent / "points"
    files = part_files(parts)
    written = pq.read_metadata(path).num_rows if path.is_file() else None  # the points the table holds
    if files and (written is None or len(files) != written):
        record = path.parent / "study.json"
        if record.is_file():
            units = json.loads(record.read_text()).get("units", {})
            df = rows_of(files, [*HEAD, *PERIODIC, *units, *TAIL])
            df.attrs["units"] = {c: {**HEAD, **PERIODIC, **units, **TAIL}.get(c, "") for c in df.columns}
            state = "not written yet" if written is None else f"of {written} points, not of the {len(files)} now"
            warnings.warn(f"{path} is {state} (the sweep is running, or was stopped before it wrote it): read from the "
                          f"{len(files)} finished point(s) in {parts}/ (no feasible column); running the same sweep "
                          "again computes the others and writes the table", PartialResultsWarning, stacklevel=2)
            return df
    if written is None:
        raise FileNotFoundError(f"{path} does not exist" + (
            f": the sweep was stopped before writing it; its {len(files)} finished point(s) are in {parts}/, and "
            "running the same sweep again writes the table (without recomputing them)" if files else ""))
    table = pq.read_table(path)
    df = table.to_pandas()
    df.attrs["units"] = {f.name: (f.metadata or {}).get(b"unit", b"").decode() for f in table.schema}
    return df
