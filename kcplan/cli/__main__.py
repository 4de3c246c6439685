"""``python -m kcplan.cli``: the ``kcplan`` command."""

import sys

from kcplan.cli import main

sys.exit(main())
