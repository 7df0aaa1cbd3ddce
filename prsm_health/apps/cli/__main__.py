"""``python -m prsm_health.apps.cli``: the ``prsm-health`` command."""

import sys

from . import main

sys.exit(main())
