"""Moved to :mod:`thermojitter.reports.distributed`. This old path is the same module object
(private names and monkeypatching included), so that code written against it keeps working."""

import sys

from thermojitter.reports import distributed as _moved
from thermojitter.reports.distributed import *  # noqa: F403  (the names, for type checkers)

sys.modules[__name__] = _moved
