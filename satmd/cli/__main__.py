"""`python -m satmd.cli` runs the satmd command."""
import sys

try:
    from . import main
except KeyboardInterrupt:  # Ctrl-C before the command could take charge of it: still one line, no traceback
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the process ends now: a second press changes nothing
    sys.stderr.write("satmd: interrupted\n")
    sys.exit(130)

sys.exit(main())
