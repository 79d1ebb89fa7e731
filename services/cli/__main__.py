"""``python -m services.cli`` is the ``boltwatch`` command."""

import sys

from services.cli.main import main

sys.exit(main())
