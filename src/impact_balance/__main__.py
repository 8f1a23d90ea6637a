"""``python -m impact_balance`` = the ``impact-balance`` command."""

import sys

from impact_balance.cli import main

sys.exit(main())
