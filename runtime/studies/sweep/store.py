"""The results of a sweep on disk: one Parquet part-file per finished point, one table at the end.

Layout of the output folder::

    study.json               the study (its hash decides whether a folder can be resumed)
    points/point-000012.parquet   one row per finished point, written atomically as the point finishes
    results.parquet          every finished point, sorted, with units in the column metadata
    results.csv              the same table for spreadsheets
    (``feasible``: a last column when the study states constraints: completed and every constraint met;
    ``periodic``, ``periodic_change`` after the status when its scene asks operation.until_periodic)

Only the process that runs the sweep writes (workers return rows), so a part-file is complete or absent:
a killed worker, Ctrl-C or a crashed machine loses at most the points that were running, and a resumed sweep
recomputes exactly the points without a part-file.
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

    # ------------------------------------------------------------------ opening
    def open(self, study, *, resume: bool = True) -> set[int]:
        """Prepare the folder for ``study``; returns the points already done (empty unless resuming). The folder
        is locked until :meth:`close`: a second sweep into it is refused (two sweeps mixed their rows)."""
        try:
            not_into_a_result(self.folder, "a sweep's points and tables")
        except ResultFolderError as err:
            raise StoreError(str(err)) from None
        self.folder.mkdir(parents=True, exist_ok=True)
        self._lock = try_lock_folder(self.folder)
        if self._lock is None:
            raise StoreError(f"{self.folder} is being written by another sweep running now: wait for it to end, or "
                             "choose another --out folder")
        record = self.folder / "study.json"
        digest = study.content_hash()
        if record.exists() and resume:
            try:
                old = json.loads(record.read_text()).get("hash")
            except (OSError, ValueError):
                old = None
            if old != digest and self.done():
                raise StoreError(f"{self.folder} holds the results of another study (or of this study before it "
                                 "was edited); use --fresh to discard them, or another --out folder")
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

        files = [p for p in self.parts.iterdir() if _PART.match(p.name)] if self.parts.is_dir() else []
        return {int(_PART.match(f.name)[1]) for f in files
                if (~pd.read_parquet(f, columns=["status"])["status"].isin(FINAL)).any()}

    # ------------------------------------------------------------------ writing
    def write(self, row: dict) -> Path:
        """Write one point's row (atomically: a temporary file renamed into place)."""
        path = self.parts / f"point-{int(row['point']):06d}.parquet"
        buf = io.BytesIO()
        pd.DataFrame([row]).to_parquet(buf, index=False)
        atomic_write(path, buf.getvalue(), durable=True)
        return path

    def table(self, study) -> pd.DataFrame:
        """Every finished point, sorted by point, columns in a fixed order (parameters, then quantities)."""
        files = sorted(p for p in self.parts.iterdir() if _PART.match(p.name)) if self.parts.is_dir() else []
        order = [*HEAD, *PERIODIC, *(p.key for p in study.parameters), *study.quantities, *TAIL]
        if not files:  # no point has said whether it became periodic: that column is a finished point's
            return pd.DataFrame(columns=[c for c in order if c not in PERIODIC])
        df = pd.concat([pd.read_parquet(f) for f in files], ignore_index=True)
        df = df.sort_values("point", kind="stable").reset_index(drop=True)
        return df[[c for c in order if c in df.columns]]

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
        atomic_write(self.folder / "results.csv", df.to_csv(index=False))
        df.attrs["units"] = units
        return df


def read_results(folder_or_file: str | Path) -> pd.DataFrame:
    """A sweep's results.parquet as a DataFrame; ``df.attrs["units"]`` maps each column to its unit."""
    import pyarrow.parquet as pq

    path = Path(folder_or_file)
    if path.is_dir():
        path = path / "results.parquet"
    if not path.is_file():
        parts = path.parent / "points"
        found = len([p for p in parts.iterdir() if _PART.match(p.name)]) if parts.is_dir() else 0
        raise FileNotFoundError(f"{path} does not exist" + (
            f": the sweep was stopped before writing it; its {found} finished point(s) are in {parts}/, and running "
            "the same sweep again writes the table (without recomputing them)" if found else ""))
    table = pq.read_table(path)
    df = table.to_pandas()
    df.attrs["units"] = {f.name: (f.metadata or {}).get(b"unit", b"").decode() for f in table.schema}
    return df

