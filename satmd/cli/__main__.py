"""`python -m satmd.cli` runs the satmd command."""
import sys

from . import main

sys.exit(main())
