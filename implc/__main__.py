import sys

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C while the modules load, before main() handles it
    print("implc: interrupted", file=sys.stderr)
    raise SystemExit(130) from None

raise SystemExit(main())
