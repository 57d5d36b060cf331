"""Running the command line in tests, and what a user mistake must look like."""

from __future__ import annotations

from click.testing import CliRunner

from holoradar.app.cli import main


def run(*args: object, ok: bool = True) -> object:
    """``holoradar ARGS...`` in-process; with ``ok`` it must exit 0."""
    res = CliRunner().invoke(main, [str(a) for a in args])
    if ok:
        assert res.exit_code == 0, res.output
    return res


def one_line_error(res: object, *needles: str) -> None:
    """A user mistake: exit code 2, one line starting 'error:' holding ``needles``, no
    traceback."""
    assert res.exit_code == 2, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("error: ")]
    assert len(errors) == 1, res.output
    assert "Traceback" not in res.output and "Aborted" not in res.output
    for n in needles:
        assert n in errors[0], errors[0]
