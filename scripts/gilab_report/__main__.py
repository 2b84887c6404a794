"""`python3 -m gilab_report DIR [DIR ...] [--out OUTDIR]`: writes the report (see make.py)."""
import sys

try:
    from .make import main
except ImportError as e:  # a missing Debian package: say which, without a traceback
    print(f"gilab_report: {e}", file=sys.stderr)
    sys.exit(2)

sys.exit(main(sys.argv[1:]))
