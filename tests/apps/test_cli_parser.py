"""The parser of ``prsm-health``: one spelling of defaults in every help, cheap to build, and
the constants it mirrors from heavy modules equal to the library's."""

import argparse
import re
import subprocess
import sys

import pytest

from prsm_health.apps.cli import build_parser, live_options, prognose_options, simulate_options
from prsm_health.apps.cli.options import HelpFormatter, Parser, has_default

#: Default spellings the help used before it had one form: "(default 10e-6)", "(0)", "(1)",
#: "(None: …)", "(None or 0: …)".
OTHER_SPELLINGS = re.compile(r"\(\s*(None\b|default(?!: )|\d+(\.\d+)?\))")


def _commands(parser, path=()):
    """(command path, its parser) for the top level and every subcommand, nested ones too."""
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _commands(sub, (*path, name))


def _helps(parser):
    """(option, its help as printed, unwrapped) of every option and positional shown."""
    formatter = parser._get_formatter()
    for action in parser._actions:
        if action.help is argparse.SUPPRESS or isinstance(action, argparse._SubParsersAction):
            continue
        name = "/".join(action.option_strings) or action.dest
        yield action, name, formatter._expand_help(action)


COMMANDS = list(_commands(build_parser()))


def test_every_command_is_walked():
    names = {" ".join(path) for path, _ in COMMANDS}
    assert {"simulate", "design template", "stiffness gear", "replay", "prognose"} <= names
    assert len(names) > 20


@pytest.mark.parametrize(
    "command", [c for _, c in COMMANDS], ids=[" ".join(p) or "prsm-health" for p, _ in COMMANDS]
)
def test_each_default_is_said_once_in_one_form(command):
    for action, name, text in _helps(command):
        assert not OTHER_SPELLINGS.search(text), f"{name}: {text!r}"
        if has_default(action):
            # exactly one, at the end, and never argparse's placeholder for "not given"
            assert text.count("(default: ") == 1 and text.endswith(")"), f"{name}: {text!r}"
            shown = text[text.index("(default: ") + len("(default: ") : -1]
            assert shown and shown not in ("None", "==SUPPRESS=="), f"{name}: {text!r}"
            assert shown.count("(") == shown.count(")"), f"{name}: not at the end: {text!r}"
        else:  # a flag, a required option, a positional: no default to state
            assert "(default" not in text, f"{name}: {text!r}"


def test_the_check_can_fail():
    # An option with a None default and no default_text, or the old spellings, are caught.
    p = Parser(prog="x", formatter_class=HelpFormatter)
    p.add_argument("--window", type=float, default=None, help="window length [s]")
    p.add_argument("--spread", type=float, default=None, help="uneven wear [-] (0)")
    p.add_argument("--flag", action="store_true", help="a flag")
    texts = {name: text for _, name, text in _helps(p)}
    assert texts["--window"].endswith("(default: None)")
    assert OTHER_SPELLINGS.search(texts["--spread"])
    assert "(default" not in texts["--flag"]


def test_default_text_and_percent_signs():
    p = Parser(prog="x", formatter_class=HelpFormatter)
    p.add_argument("--a", type=float, default=5e-6, help="[s]")
    p.add_argument("--b", default=None, default_text="90 % of the model's", help="share")
    texts = {name: text for _, name, text in _helps(p)}
    assert texts["--a"] == "[s] (default: 5e-06)"
    assert texts["--b"] == "share (default: 90 % of the model's)"


def test_mirrored_constants_are_the_librarys():
    from prsm_health.apps import live
    from prsm_health.prognostics import METHODS
    from prsm_health.simulation.instrumentation import DEFAULT_PROFILE

    assert simulate_options.DEFAULT_PROFILE == DEFAULT_PROFILE
    assert (
        live_options.LIVE_HOST,
        live_options.LIVE_PORT,
        live_options.LIVE_MESSAGE_BUDGET,
    ) == (
        live.DEFAULT_HOST,
        live.DEFAULT_PORT,
        live.MESSAGE_BUDGET,
    )
    assert sorted(prognose_options.PROGNOSIS_METHODS) == sorted(METHODS)


def test_help_loads_no_heavy_library():
    # A fresh interpreter: the help of every command, then what it imported.
    commands = [list(path) for path, _ in COMMANDS]
    code = (
        "import sys\n"
        "from prsm_health.apps.cli import main\n"
        f"for argv in {commands!r}:\n"
        "    try:\n"
        "        main([*argv, '--help'])\n"
        "    except SystemExit:\n"
        "        pass\n"
        "heavy = {'pandas', 'scipy', 'numba', 'sklearn', 'pyarrow', 'matplotlib'}\n"
        "print(sorted(heavy & {m.split('.')[0] for m in sys.modules}), file=sys.stderr)\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.strip().splitlines()[-1] == "[]"
    assert "usage: prsm-health simulate" in proc.stdout


def test_every_handler_exists():
    import importlib

    for path, command in COMMANDS:
        handler = command.get_default("handler")
        if handler is None:  # a group of subcommands (design, stiffness …)
            continue
        module, _, function = handler.partition(":")
        module = importlib.import_module(f"prsm_health.apps.cli.{module}")
        assert callable(getattr(module, function)), (path, handler)


def test_the_formats_doc_names_the_default_step():
    # docs/formats.md once called a 5 µs step "the command line's"; the default is "auto"
    from pathlib import Path

    from prsm_health.simulation.dynamics.model import (
        AUTO_MAX_STEP,
        AUTO_STABLE_FRACTION,
        SimulationOptions,
    )

    default = build_parser().parse_args(["simulate"]).max_step
    assert default == SimulationOptions().max_step
    text = (Path(__file__).resolve().parents[2] / "docs" / "formats.md").read_text()
    text = " ".join(text.split())
    assert not re.search(r"command line's [\d.]+ µs step", text)
    assert f'The default step, `max_step = "{default}"` (the command line\'s `--max-step`' in text
    assert (
        f"takes {AUTO_STABLE_FRACTION:g} of the stable step, at most {AUTO_MAX_STEP * 1e6:g} µs"
        in text
    )
