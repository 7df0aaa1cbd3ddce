"""Command line: ``prsm-health <command>``.

The CLI only parses arguments, calls the library and formats results; SI units on the command
line except where an option name says otherwise (``--pressure-angle DEG``). A user error prints
one line ``error: …`` to stderr and exits with status 2.

Modules: :mod:`.parser` (the parser's top-level assembly; cheap to build), :mod:`.options`
(the parser class, the help formatter that writes each default, argument types), :mod:`.main`
(dispatch and errors), :mod:`.output` (JSON and tables), and per group of commands its options
(``<group>_options``, light, imported to build the parser) and its handlers, imported only
when one of its commands runs: :mod:`.physics` (validate, design,
instrumentation, kinematics, stiffness, friction), :mod:`.simulate`, :mod:`.data` (generate,
import), :mod:`.models` (train, evaluate, diagnose, replay), :mod:`.prognose`, :mod:`.serve`,
:mod:`.live` (the ``--live`` loop of replay and simulate).
"""

from .main import main
from .parser import build_parser

__all__ = ["build_parser", "main"]
