"""``python -m apexseal.derive.paper_check [docs/paper-check.md]``: the same as ``apexseal derive --check``."""

import sys

from .report import main_check

raise SystemExit(main_check(*sys.argv[1:2]))
