"""The ``prsm-health`` argument parser: the top-level assembly of the command groups.

Each group's commands and options are declared beside its handlers, in ``<group>_options``
(:mod:`.physics_options`, :mod:`.simulate_options`, :mod:`.data_options`,
:mod:`.models_options`, :mod:`.assets_options`, :mod:`.prognose_options`,
:mod:`.serve_options`; ``--live`` in :mod:`.live_options`). Each command names its handler as
``"module:function"`` of this package (``handler``); ``main`` imports that module only when the
command runs, so building the parser — and ``prsm-health --help`` — loads none of pandas,
scipy, numba or scikit-learn. The few library constants the option modules would need from
heavy modules are mirrored there (a test keeps each equal to the library's).

Defaults appear in the help in one form, ``(default: X)``, written by
:class:`~.options.HelpFormatter`; an option whose default is None says what applies instead
with ``default_text``.
"""

from __future__ import annotations

import argparse

from prsm_health.core.version import __version__

from .assets_options import add_asset_commands
from .data_options import add_data_commands
from .models_options import add_model_commands
from .options import HelpFormatter, Parser, command_maker
from .physics_options import add_physics_commands
from .prognose_options import add_prognose_command
from .serve_options import add_serve_command
from .simulate_options import add_simulate_command


def build_parser() -> argparse.ArgumentParser:
    """The parser of every command; ``args.handler`` names the function that runs it."""
    parser = Parser(
        prog="prsm-health",
        description="Planetary roller screw physics, signal generation and diagnostics. "
        "SI units on the command line unless an option says otherwise.",
        formatter_class=HelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"prsm-health {__version__}")
    command = command_maker(parser, "command")
    add_physics_commands(command)
    add_simulate_command(command)
    add_data_commands(command)
    add_model_commands(command)
    add_asset_commands(command)
    add_prognose_command(command)
    add_serve_command(command)
    return parser
