"""``python -m creaturegen.corpus``: see corpus/run.py."""

import sys

from .run import main

sys.exit(main())
