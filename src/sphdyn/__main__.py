"""``python -m sphdyn`` is ``sphdyn``."""

import sys

from .cli import main

sys.exit(main())
