"""A result as tables: an xarray Dataset, a pandas DataFrame, the list of contact events.

Units and meanings come from :mod:`.outputs` (the same table as the CSV header and docs/outputs.md).
"""

from __future__ import annotations

import json

import numpy as np

from ...derive.submodels.registry import guards
from .outputs import describe


def columns(result) -> dict[str, np.ndarray]:
    """Every column of the result in CSV order (name -> (n,) array, SI; ``mode`` as strings). The crank angle in
    degrees is rounded to 1e-9 deg, so that a sample at a whole degree is that number (``df.loc[183.0]``: the
    radians' rounding made it 183.00000000000003)."""
    cols: dict[str, np.ndarray] = {"theta_deg": np.round(np.degrees(result.theta), 9), "time_s": result.time}
    cols.update({name: result.state[i] for i, name in enumerate(result.state_names)})
    cols["mode"] = np.asarray(result.modes, dtype=str)
    cols.update({f"closed_{g}": result.closed[i].astype(np.int8) for i, g in enumerate(result.guard_names)})
    cols.update(result.outputs)
    return cols


def to_pandas(result):
    """A DataFrame with one row per sample, indexed by crank angle in degrees; units in ``df.attrs["units"]``."""
    import pandas as pd

    cols = columns(result)
    index = pd.Index(cols.pop("theta_deg"), name="theta_deg")
    df = pd.DataFrame(cols, index=index)
    df.attrs["units"] = {"theta_deg": "deg", **{name: describe(name).unit for name in df.columns}}
    df.attrs["status"] = result.status
    return df


def _attr(v):
    """netCDF attributes hold numbers and strings: anything else as JSON."""
    if isinstance(v, str | int | float) and not isinstance(v, bool):
        return v
    return json.dumps(v, default=str)


def to_xarray(result):
    """An xarray Dataset: dimension ``theta`` (crank angle in rad since the start; coordinates ``time`` in s
    and ``theta_deg``), every state and output with ``units`` and ``long_name`` attributes, the closed flag
    and the running event count of each contact. Write it with ``ds.to_netcdf(path)``. Its arrays are its own
    (copies): changing them (``ds["y"] *= 1e6``) leaves the result as it is."""
    import xarray as xr

    cols = columns(result)
    coords = {"theta": ("theta", result.theta, {"units": "rad", "long_name": "crank angle since the start angle"}),
              "time": ("theta", result.time, {"units": "s", "long_name": describe("time_s").meaning}),
              "theta_deg": ("theta", cols.pop("theta_deg"), {"units": "deg", "long_name": "crank angle"})}
    cols.pop("time_s")
    data = {}
    for name, values in cols.items():
        c = describe(name)
        attrs = {"long_name": c.meaning}
        if c.unit not in ("",):
            attrs["units"] = c.unit
        data[name] = ("theta", values, attrs)
    for i, g in enumerate(result.guard_names):
        data[f"events_{g}"] = ("theta", result.events[i].astype(np.int32),
                               {"long_name": f"running count of switches of contact {g}"})
    attrs = {"status": result.status, "stop": "" if result.stop is None else result.stop.describe(),
             "guard_names": ",".join(result.guard_names)}
    attrs.update({k: _attr(v) for k, v in result.info.items()})
    return xr.Dataset(data, coords=coords, attrs=attrs).copy(deep=True)


def event_list(result):
    """The contact events: one row per switch found between two samples, with its crank angle (deg, since the
    start; located by linear interpolation of the contact's gap when one switch fell in the interval, else the
    interval's midpoint), time (s), contact, direction (the net change, ``closes`` or ``opens``, after an odd number of
    switches between two samples; ``closes+opens`` or ``opens+closes`` after an even number) and the number of
    switches."""
    import pandas as pd

    rows = []
    deg = np.degrees(result.theta)
    gap_of = {g.name: g.output for g in guards()}  # the output column of each guard
    for i, g in enumerate(result.guard_names):
        counts = result.events[i]
        jumps = np.nonzero(np.diff(counts) > 0)[0]
        gap = result.outputs.get(gap_of.get(g, ""))
        for k in jumps:
            n = int(counts[k + 1] - counts[k])
            before, after = bool(result.closed[i, k]), bool(result.closed[i, k + 1])
            if before != after:
                direction = "closes" if after else "opens"
            else:
                direction = "closes+opens" if not before else "opens+closes"
            frac = 0.5
            if n == 1 and gap is not None and gap[k] != gap[k + 1]:
                frac = float(np.clip(gap[k] / (gap[k] - gap[k + 1]), 0.0, 1.0))
            rows.append((deg[k] + frac * (deg[k + 1] - deg[k]),
                         result.time[k] + frac * (result.time[k + 1] - result.time[k]), g, direction, n))
    df = pd.DataFrame(rows, columns=["theta_deg", "time_s", "contact", "direction", "switches"])
    return df.sort_values("theta_deg", kind="stable").reset_index(drop=True)
