"""The parser's parts every command group uses: the one-line-error parser, the help formatter
that writes every default, the maker of subcommands, the help texts several groups share, and
the argument types (each refuses bad text with a message naming the option).

Nothing here imports more than the standard library and the light ``core`` and ``actuator``
modules: building the parser must stay cheap (``prsm-health --help`` loads neither pandas,
scipy, numba nor scikit-learn).
"""

from __future__ import annotations

import argparse
import math

from prsm_health.actuator.design_files import load_design
from prsm_health.core.errors import PRSMHealthError


class UsageError(Exception):
    """A command line argparse refuses; ``main`` prints it as one ``error: …`` line."""


class Parser(argparse.ArgumentParser):
    """ArgumentParser whose usage errors are one line and exit 2, and whose options may say
    what applies when they are not given (``default_text``)."""

    def error(self, message):  # noqa: D401 - argparse API
        raise UsageError(message)

    def add_argument(self, *args, default_text: str | None = None, **kwargs):
        """:meth:`argparse.ArgumentParser.add_argument`, plus ``default_text``: what the help
        shows as the default, for an option whose ``default`` (None, or an effect that
        depends on other options) does not say it."""
        action = super().add_argument(*args, **kwargs)
        action.default_text = default_text
        return action


class HelpFormatter(argparse.HelpFormatter):
    """Every option's help ends with one ``(default: X)``: its ``default_text``, else its
    default value; flags, required options and positionals have none.

    The one place defaults are written into the help, so they read the same everywhere.
    """

    def _get_help_string(self, action):
        text = action.help or ""
        if text is argparse.SUPPRESS or not has_default(action):
            return text
        shown = getattr(action, "default_text", None)
        if shown is None:
            shown = format_default(action.default)
        # argparse %-formats help strings: a literal % must be doubled
        return f"{text} (default: {shown.replace('%', '%%')})".lstrip()


def has_default(action) -> bool:
    """Whether ``action``'s help states a default: options that take a value and may be left
    out (not flags such as ``--json``, not required options, not positionals)."""
    return bool(action.option_strings) and action.nargs != 0 and not action.required


def format_default(value) -> str:
    """A default for the help: floats in their shortest form (``5e-06``, ``0.02``)."""
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, (list, tuple)):
        return ", ".join(format_default(v) for v in value)
    return str(value)


def command_maker(parser, dest: str):
    """A maker of ``parser``'s subcommands (``simulate``, ``design template`` …), each with
    the same parser class and help formatter."""
    sub = parser.add_subparsers(dest=dest, required=True, parser_class=Parser)

    def make(name: str, text: str):
        return sub.add_parser(name, help=text, description=text, formatter_class=HelpFormatter)

    return make


def add_json(p, what: str = "the result") -> None:
    p.add_argument("--json", action="store_true", help=f"print {what} as JSON instead of a table")


# ----------------------------------------------------------------------------- shared help texts
DESIGN_HELP = "preset name (paper01…paper05) or design TOML file"
PROFILE_HELP = (
    "instrumentation profile: a built-in name (prsm-health instrumentation list) or a TOML file"
)
SHIPPED_MODEL = "the shipped model"
MODEL_WINDOW = "the model's window"


# ----------------------------------------------------------------------------- argument types
def finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


def step(text: str) -> float | str:
    """``--max-step``: seconds, or ``auto``."""
    if text == "auto":
        return text
    try:
        return finite_float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is neither a step in seconds nor 'auto'"
        ) from None


def rate(text: str) -> float | None:
    """A real-time factor, or ``max`` (None: as fast as possible)."""
    if text == "max":
        return None
    value = float(text)
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"{text!r}: use a positive real-time factor or 'max'")
    return value


def port(text: str) -> int:
    value = int(text)
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"{text!r}: use a TCP port 0…65535 (0: any free port)")
    return value


def positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: use an integer >= 1")
    return value


def design(text: str):
    """``--design``: a preset name or a design file, loaded here so errors name the option."""
    try:
        return load_design(text)
    except PRSMHealthError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def removed_option(replacement: str):
    """The type of an option that no longer exists: using it is a one-line error saying what
    replaced it."""

    def reject(text: str):
        raise argparse.ArgumentTypeError(f"this option was removed: {replacement}")

    return reject
