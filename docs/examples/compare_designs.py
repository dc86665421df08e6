"""Compare two seal designs: load a scene, override it, run both, plot them together, export, save, reload.

Run it as a script (``python docs/examples/compare_designs.py [output-folder]``) or cell by cell in a notebook;
the test suite executes it (tests/runtime/test_examples.py). ``SETTINGS`` keeps it quick (360 samples per
revolution, quick compiler flags); drop it for the scene's own settings.
"""

import sys
from pathlib import Path

import apexseal

OUT = Path(sys.argv[1] if len(sys.argv) > 1 else "apexseal-out/compare-designs")
SETTINGS = {"samples_per_revolution": 360, "flags": "quick"}

# %% a scene and a variant of it: the paper's case study, and a stiffer, more preloaded spring
base = apexseal.load_scene()  # the embedded default; apexseal.load_scene("my.toml") for a file
stiff = base.with_overrides(**{"spring.ks": "2e4 N/m", "spring.delta_s": "1 mm"})
print(base, stiff, sep="\n")

# %% run both designs
results = {"default spring": apexseal.simulate(base, **SETTINGS),
           "stiff spring": apexseal.simulate(stiff, **SETTINGS)}
for name, r in results.items():
    print(f"{name}: {r!r}")  # status, revolutions, samples, events, friction power

# %% compare them in one figure (a matplotlib Figure: displays in a notebook, savefig in a script)
fig = apexseal.plot_comparison(list(results.values()), ["y", "phi", "F_spring_X", "Pf_total"], labels=list(results))
OUT.mkdir(parents=True, exist_ok=True)
fig.savefig(OUT / "compare.png", dpi=100)

# %% the paper's figures of one result
results["stiff spring"].plot("fig12").savefig(OUT / "stiff-fig12.png", dpi=100)

# %% tables: xarray (with units; netCDF) and pandas
ds = results["stiff spring"].to_xarray()
print(ds["y"].attrs)  # {'long_name': ..., 'units': 'm'}
ds.to_netcdf(OUT / "stiff.nc", engine="scipy")
df = results["stiff spring"].to_pandas()
print(df[["y", "Pf_total"]].describe())
events = results["stiff spring"].event_list()
print(events.head())  # crank angle, time, contact, direction

# %% save each result (with its resolved scene.toml) and load it back
for name, r in results.items():
    folder = r.save(OUT / name.replace(" ", "-"))
    back = apexseal.SimulationResult.load(folder)
    assert back.scene == r.scene  # same content hash: `apexseal simulate <folder>/scene.toml` re-runs it
    print(f"saved {name} to {folder}; scene hash {back.scene.content_hash()[:12]}")
