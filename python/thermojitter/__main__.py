"""``python -m thermojitter``: the same as the ``thermojitter`` command."""

import sys

from thermojitter.cli import main

sys.exit(main())
