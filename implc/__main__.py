import sys

from .interrupts import dropped_signals_kept

with dropped_signals_kept():  # main() raises again a Ctrl-C that Python dropped meanwhile
    try:
        from .cli import main
    except KeyboardInterrupt:  # Ctrl-C while the modules load, before main() handles it
        print("implc: interrupted", file=sys.stderr)
        code = 130
    else:
        code = main()
# Under `python -m`, CPython ends the process by SIGINT, whatever the exit code, once a
# KeyboardInterrupt has escaped an exec() or eval() of a string anywhere in the run (its
# _Py_UnhandledKeyboardInterrupt flag): Ctrl-C landing while a dataclass or namedtuple is
# defined in a lazy import, though main() caught it and printed "interrupted"
# (test_fault[compile-SIGINT], about 1 run in 100 under load). Running an empty string
# clears the flag, so the process exits with main()'s code (docs/reference/errors.md "Exit codes").
exec("")
raise SystemExit(code)
