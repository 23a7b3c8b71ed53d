"""`python -m martello` and the `martello` command (pyproject.toml's entry point): the command
line of martello.cli, with a Ctrl-C while its modules load ending as one line, exit 130, like
a Ctrl-C at any later moment (martello.cli.run_command)."""

import signal
import sys

from . import errors


def main():
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, errors.record_sigint)
    try:
        from .cli import main as command_line
        return command_line()
    except KeyboardInterrupt:     # before the command runs (after, run_command has its own)
        print("martello: interrupted", file=sys.stderr)
        return 130
    finally:                      # every interrupt was handled: the exit code is ours
        errors.forget_handled_interrupts()


if __name__ == "__main__":
    sys.exit(main())
