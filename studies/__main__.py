"""``python -m studies NAME``: run a study from its recipe (studies/runner.py)."""

import sys

from studies.runner import main

sys.exit(main())
