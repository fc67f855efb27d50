"""``python -m tpee_ompl.cli``: the same as the ``tpee-ompl`` command."""

import sys

from .main import main

sys.exit(main())
