"""``python -m tpee_ompl``: the ``tpee-ompl`` command line (:mod:`tpee_ompl._launch`)."""

import sys

from ._launch import main

sys.exit(main())
