"""``python -m pfm_stability`` = the ``pfm-stability`` command."""

import sys

from .cli import main

sys.exit(main())
