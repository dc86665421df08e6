"""The ``apexseal`` command: one sub-command per job, each in its own module."""

from __future__ import annotations

import click


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="apexseal")
def main() -> None:
    """Derive, generate and run the apex-seal model of limaçon machines (Phung et al. 2018)."""


def _register() -> None:
    from .commands_derive import derive
    from .commands_simulate import simulate

    main.add_command(simulate)
    main.add_command(derive)
    try:
        from .commands_generate import generate
    except ImportError:  # pragma: no cover - during development only
        pass
    else:
        main.add_command(generate)
    try:
        from .commands_optimise import optimise_preload
    except ImportError:  # pragma: no cover
        pass
    else:
        main.add_command(optimise_preload)
    try:
        from .commands_bench import bench
    except ImportError:  # pragma: no cover
        pass
    else:
        main.add_command(bench)


_register()
