"""Ctrl-C at any moment, imports included: one line ``satmd: interrupted``, exit 130, no traceback (issue 38)."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from satmd.cli import main

ROOT = Path(__file__).resolve().parents[2]


def _satmd(args, cwd):
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    # a runner started in the background (nohup, `&`) hands its children SIGINT ignored, and Python then
    # installs no handler: the child gets SIGINT's default back, as a terminal would give it
    return subprocess.Popen([sys.executable, "-m", "satmd", *args], cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _interrupted(p, delay, presses=1, gap=0.05):
    time.sleep(delay)
    for k in range(presses):
        if k:
            time.sleep(gap)
        if p.poll() is None:
            p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    return p.returncode, out, err


def test_importing_satmd_loads_nothing_heavy():
    """The handler is in place before numpy and scipy load: `import satmd` and the command's module are light."""
    code = ("import sys, satmd, satmd.cli\n"
            "print(sorted(m for m in ('numpy', 'scipy', 'torch', 'satmd.io') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env={**os.environ, "PYTHONPATH": str(ROOT)}).stdout
    assert out.strip() == "[]"


@pytest.mark.parametrize("delay", [0.4, 1.0])
def test_ctrl_c_while_importing_or_working_is_one_line_and_130(tmp_path, delay):
    old = tmp_path / "big.csv"
    old.write_text("old\n")
    p = _satmd(["simulate", "--freq", "1:1000:1000000", "--noise", "0.01", "-o", "big.csv"], tmp_path)
    rc, out, err = _interrupted(p, delay)
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    assert rc == 130 and err.strip() == "satmd: interrupted", (rc, err)
    assert old.read_text() == "old\n" and sorted(q.name for q in tmp_path.iterdir()) == ["big.csv"]


def test_a_double_ctrl_c_is_still_one_line_and_130(tmp_path):
    # a command that is still at work when the presses come (a missing input file was: on a warm machine it
    # could say "no such file" before the first press, a race of the test, not of satmd)
    p = _satmd(["simulate", "--freq", "1:1000:1000000", "--noise", "0.01", "-o", "big.csv"], tmp_path)
    rc, _, err = _interrupted(p, 0.5, presses=3, gap=0.05)
    assert "Traceback" not in err and rc == 130 and err.strip() == "satmd: interrupted", (rc, err)


def test_ctrl_c_during_the_commands_import_in_process(monkeypatch, capsys):
    """A KeyboardInterrupt raised while the commands are imported (numpy, scipy, ...) is caught like any other."""
    import importlib

    real = importlib.import_module

    def interrupted_import(name, *args, **kwargs):
        if name.startswith("satmd.cli.") and not name.endswith("_interrupt"):
            raise KeyboardInterrupt
        return real(name, *args, **kwargs)

    monkeypatch.setattr(importlib, "import_module", interrupted_import)
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        assert main(["info", "x.csv"]) == 130
    finally:
        signal.signal(signal.SIGINT, before)
    assert capsys.readouterr().err == "satmd: interrupted\n"


def test_the_callers_sigint_handler_comes_back(capsys):
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        assert main(["--version"]) == 0
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # a background job's: left alone, and nothing raised
        assert main(["--version"]) == 0
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, before)


def test_ctrl_c_inside_a_weakref_callback_still_ends_the_command(capsys):
    """Python cannot raise from a weakref callback: the press is delivered again, not printed as ignored (fuzz 1575)."""
    import weakref

    from satmd.cli._interrupt import catching_interrupts

    class Thing:
        pass

    def pressed_during_callback(_):
        signal.raise_signal(signal.SIGINT)  # the handler runs here, inside the callback

    reached = []
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with catching_interrupts():
            thing = Thing()
            ref = weakref.ref(thing, pressed_during_callback)
            del thing
            start = time.monotonic()
            while time.monotonic() - start < 5:  # the command's next steps, where the press lands again
                pass
            reached.append(ref)
    finally:
        signal.signal(signal.SIGINT, before)
    err = capsys.readouterr().err
    assert not reached and err == "satmd: interrupted\n", err


def test_ctrl_c_as_the_finished_program_shuts_down_keeps_its_status(tmp_path):
    """A press after the work is done, while Python shuts down, is ignored: not a traceback, not death by SIGINT
    (CPython hands SIGINT back to its default as it shuts down: exit -2 in fuzz 1576, 1646, 1653, 1673)."""
    code = ("import atexit, os, signal, sys, time\n"
            "from satmd.cli import main\n"
            "atexit.register(lambda: (os.kill(os.getpid(), signal.SIGINT), time.sleep(0.2)))\n"
            "sys.argv = ['satmd', '--version']\n"
            "sys.exit(main())\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    p = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True,
                       timeout=60, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert p.returncode == 0 and "Traceback" not in p.stderr and p.stdout.startswith("satmd "), (p.returncode,
                                                                                              p.stderr)
