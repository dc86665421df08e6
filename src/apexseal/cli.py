"""The ``apexseal`` command: one sub-command per job, each in its own module."""

from __future__ import annotations

import click


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="apexseal")
def main() -> None:
    """Derive, generate and run the apex-seal model of limaçon machines (Phung et al. 2018)."""


def _register() -> None:
    from .commands_bench import bench
    from .commands_calibrate import calibrate
    from .commands_derive import derive
    from .commands_generate import generate
    from .commands_optimise import optimise_preload
    from .commands_scene import scene
    from .commands_simulate import simulate
    from .commands_sweep import sweep

    for command in (simulate, scene, derive, generate, optimise_preload, bench, sweep, calibrate):
        main.add_command(command)


_register()
