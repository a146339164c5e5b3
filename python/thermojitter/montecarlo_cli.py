"""``python -m thermojitter.montecarlo_cli ARGS``: the same as ``thermojitter mc ARGS`` (kept for
scripts written before the subcommand; see :mod:`thermojitter.cli.mc`)."""

import sys

from thermojitter.cli.mc import mc_command, read_scenario

__all__ = ["mc_command", "read_scenario"]

if __name__ == "__main__":
    sys.exit(mc_command())
