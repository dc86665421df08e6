"""The chamber gas model with and without the leakage past the seal, side by side (README "Chamber gas").

    python docs/examples/leakage_coupling.py [OUT]

runs the expander-gas scene twice for two revolutions, with ``pressure.source = "chamber"`` (the chambers
exchange gas only through the ports) and ``"chamber+leakage"`` (also through the groove gap and over the lifted
tip, Algorithm 4), and prints the seal's travel and mean friction power over both revolutions, and the leaked
mass and the indicated work of the second one, for each. Both results are saved under OUT (default apexseal-out/leakage).
"""

from __future__ import annotations

import sys
from importlib.resources import files
from pathlib import Path

import apexseal


def compare(out: Path, revolutions: int = 2) -> list[dict]:
    scene = apexseal.load_scene(str(files("apexseal.runtime.scenes") / "expander-gas.toml"))
    rows = []
    for source in ("chamber", "chamber+leakage"):
        result = apexseal.simulate(scene.with_overrides(**{"pressure.source": source}), revolutions=revolutions)
        result.save(out / source.replace("+", "-"))
        s, g = result.summary(), result.summary()["gas"]
        rows.append({"source": source, "status": result.status,
                     "x_um": (s["extremes"]["x"]["min"], s["extremes"]["x"]["max"]),
                     "y_um": (s["extremes"]["y"]["min"], s["extremes"]["y"]["max"]),
                     "friction_W": s["mean_friction_power_W"]["total"],
                     "inducted_g": g["inducted_mass_kg"] * 1e3, "leaked_mg": g["leaked_mass_kg"]["total"] * 1e6,
                     "leaked_fraction": g["leaked_fraction_of_inducted"], "work_J": g["indicated_work_J"]["total"]})
    return rows


def table(rows: list[dict]) -> str:
    lines = ["| pressure.source | x (µm) | y (µm) | friction power (W) | inducted (g) | leaked (mg) | leaked fraction "
             "| indicated work (J) |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['source']} | {r['x_um'][0]:.2f} … {r['x_um'][1]:.2f} | {r['y_um'][0]:.1f} … "
                     f"{r['y_um'][1]:.1f} | {r['friction_W']:.2f} | {r['inducted_g']:.2f} | {r['leaked_mg']:.3f} | "
                     f"{r['leaked_fraction']:.2e} | {r['work_J']:.1f} |")
    return "\n".join(lines)


if __name__ == "__main__":
    print(table(compare(Path(sys.argv[1] if len(sys.argv) > 1 else "apexseal-out/leakage"))))
