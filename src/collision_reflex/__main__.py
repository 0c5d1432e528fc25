"""``python -m collision_reflex`` runs the ``crx`` command."""

import sys

from .cli import main

sys.exit(main())
