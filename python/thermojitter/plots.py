"""Moved to :mod:`thermojitter.reports.plots`. This old path is the same module object (private
names and monkeypatching included), so that code written against it keeps working."""

import sys

from thermojitter.reports import plots as _moved
from thermojitter.reports.plots import *  # noqa: F403  (the names, for type checkers)

sys.modules[__name__] = _moved
