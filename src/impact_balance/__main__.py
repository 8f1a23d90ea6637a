"""``python -m impact_balance`` = the ``impact-balance`` command."""

import sys

from .cli import main

sys.exit(main())
