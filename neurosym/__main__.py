"""`python -m neurosym` runs the CLI."""

import sys

from neurosym.cli import main

sys.exit(main())
