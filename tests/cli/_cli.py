"""Shared helpers for the CLI tests: run a command in-process and check a refusal."""
from __future__ import annotations

from satmd.cli import main


def run(capsys, *argv):
    """Run ``satmd ARGV`` through `satmd.cli.main`; return (exit code, stdout, stderr)."""
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def refused(capsys, *argv, says=(), alone=True):
    """Assert the command exits 2 with one ``satmd CMD: error: ...`` line naming each of `says`.

    With ``alone`` the error line must be all of stderr; without it, other lines (warnings, progress)
    may stand beside it. Returns the error line.
    """
    rc, out, err = run(capsys, *argv)
    lines = [ln for ln in err.splitlines() if ": error: " in ln]
    assert rc == 2 and len(lines) == 1, (argv, rc, out, err)
    line = lines[0]
    assert line.startswith("satmd "), line
    if alone:
        assert err.strip() == line, err
    for word in says:
        assert word in line, (word, line)
    assert "array(" not in line and "\x1b" not in err
    return line
