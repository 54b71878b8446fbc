"""``python -m navseq`` is the ``navseq`` command."""

import sys

from navseq.cli import main

sys.exit(main())
