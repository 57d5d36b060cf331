"""The ``holoradar`` command line.

Every command takes ``--help``, ``--json`` (a machine-readable summary on
stdout) and ``--quiet``. A user's mistake (a bad argument, an unreadable or
implausible file, an output that would destroy data) is one line on stderr,
``error: ...``, and exit code 2; warnings are one line each; Ctrl-C (SIGINT)
is one line, ``interrupted: ...``, and exit code 130. Outputs are checked
before any work, never replace an input or an existing file unless ``--force``
is given, and are written atomically with the user's umask.
"""

from __future__ import annotations

import sys
import warnings
from typing import Any

import click

from ..._version import __version__

__all__ = ["main"]


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _show_warning(message: Any, category: type[Warning], filename: str, lineno: int,
                  file: Any = None, line: Any = None) -> None:
    click.echo(f"warning: {_one_line(str(message))} ({category.__name__})", err=True)


def _fail(message: str, code: int, args: Any, prefix: str = "error: ") -> None:
    """One line on stderr; with --json also a JSON object on stdout for the caller."""
    click.echo(f"{prefix}{_one_line(message)}", err=True)
    argv = sys.argv[1:] if args is None else list(args)
    if "--json" in argv:
        import json

        said = message if prefix == "error: " else prefix + message  # errors: as before
        click.echo(json.dumps({"error": _one_line(said), "exit_code": code}))
    sys.exit(code)


INTERRUPTED = 130
"""Exit code after Ctrl-C (SIGINT): 128 + the signal's number, as shells report it."""


class _InterruptError(Exception):
    """A KeyboardInterrupt carried past click, which would print a blank line and abort."""


def _interrupted(detail: str, args: Any) -> None:
    """Ctrl-C: one line (what the command leaves, when it knows), exit code 130."""
    if sys.stderr.isatty():
        click.echo("", err=True)  # the terminal echoed ^C: start the line afresh
    _fail(detail or "stopped before the end (outputs are written whole or not at all)",
          INTERRUPTED, args, prefix="interrupted: ")


class HoloradarGroup(click.Group):
    """A click group whose user errors are one line and exit code 2, never a traceback;
    Ctrl-C is one line and exit code 130."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt as exc:
            # A command's KeyboardInterrupt may say what it leaves behind (batch: the
            # frames stored); click would turn it into a bare Abort.
            raise _InterruptError(str(exc)) from None

    def main(self, args: Any = None, prog_name: str | None = None,  # type: ignore[override]
             complete_var: str | None = None, standalone_mode: bool = True,
             **extra: Any) -> Any:
        old = warnings.showwarning
        warnings.showwarning = _show_warning
        try:
            return super().main(args, prog_name, complete_var, standalone_mode=False, **extra)
        except click.exceptions.NoArgsIsHelpError as exc:  # bare "holoradar"
            click.echo(exc.ctx.get_help() if exc.ctx else str(exc))
            sys.exit(0)
        except click.ClickException as exc:
            hint = f" (see {exc.ctx.command_path} --help)" if getattr(exc, "ctx", None) \
                else ""
            _fail(f"{exc.format_message()}{hint}", 2 if exc.exit_code in (1, 2)
                  else exc.exit_code, args)
        except click.exceptions.Exit as exc:
            sys.exit(exc.exit_code)
        except _InterruptError as exc:
            _interrupted(str(exc), args)
        except click.Abort as exc:
            if isinstance(exc.__cause__, KeyboardInterrupt):  # Ctrl-C while parsing
                _interrupted("", args)
            click.echo("error: aborted", err=True)
            sys.exit(1)
        except ValueError as exc:
            _fail(str(exc), 2, args)
        except MemoryError:
            _fail("not enough memory for this job: fewer planes (--z), a smaller "
                  "--upsample or a smaller array", 2, args)
        except (PermissionError, FileNotFoundError, IsADirectoryError,
                NotADirectoryError) as exc:
            _fail(str(exc), 2, args)
        except OSError as exc:  # the system's trouble (a full disk...), not the user's
            _fail(str(exc), 1, args)
        finally:
            warnings.showwarning = old


@click.group(cls=HoloradarGroup, context_settings={"help_option_names": ["-h", "--help"]})
# The version given, not looked up: importlib.metadata adds about 30 ms to the start-up.
@click.version_option(version=__version__, package_name="holoradar")
def main() -> None:
    """holoradar: holographic subsurface radar imaging and simulation.

    Typical use: `holoradar info FILE` to see what a file holds, `holoradar
    image FILE --z 0.3:0.6:0.005 --eps 2.5 --z-surface 0.3 --out img.nc` to
    image it (img.png beside it shows its brightest plane), `holoradar plot
    img.nc --out planes.png --z 0.4 --z 0.45` to look at chosen planes.
    """


def _register() -> None:
    from . import (
        batch,
        calibrate,
        detect,
        focus,
        image,
        info,
        invert,
        misc,
        plot,
        process,
        simulate,
        view,
    )
    from . import report as report_cli

    for module in (misc, simulate, image, invert, process, focus, calibrate, info, plot, batch,
                   detect, report_cli, view):
        for cmd in module.COMMANDS:
            main.add_command(cmd)


_register()
