"""`python -m satmd` runs the satmd command."""
import sys

from .cli import main

sys.exit(main())
