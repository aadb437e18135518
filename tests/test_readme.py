"""README honesty: every code block runs and prints what the README shows; result tables match the JSON.

Blocks
------
- ```python blocks run in a fresh namespace, each in its own empty directory, in-process.
- ```bash blocks are `satmd` command lines; each runs in-process through `satmd.cli.main(argv)` and
  must exit 0. A block that is not (``make ...``) or that is too long for the suite (training a net,
  `satmd reproduce`) carries ``<!-- readme-test: skip (why) -->`` on the line before it.
- A ```text block after ``<!-- readme-test: output -->`` is the output of the code block before it: each
  shown line must appear in the output, in that order; a line ``...`` stands for lines left out.
- Other fences (the layout block, ```text without the marker) are prose.

Tables
------
`benchmarks/readme_tables.py --check --sync-only` must pass: every region between ``<!-- results:NAME -->`` markers
is what the script writes from `benchmarks/results/*.json`.
"""
from __future__ import annotations

import contextlib
import json
import io
import re
import shlex
import subprocess
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
SKIP = re.compile(r"<!--\s*readme-test:\s*skip\s*\((?P<why>[^)]+)\)\s*-->")
OUTPUT = re.compile(r"<!--\s*readme-test:\s*output\s*-->")
FENCE = re.compile(r"^```(?P<lang>[\w-]*)\s*$")


@dataclass
class Block:
    lang: str
    line: int  # 1-based line of the opening fence
    code: str
    skip: str | None = None
    expected: list[str] = field(default_factory=list)

    @property
    def id(self):
        return f"{self.lang}-L{self.line}"


def parse(text: str) -> list[Block]:
    lines = text.splitlines()
    blocks: list[Block] = []
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        start = i
        j = i + 1
        while j < len(lines) and lines[j].rstrip() != "```":
            j += 1
        body = "\n".join(lines[start + 1:j]) + "\n"
        k = start - 1
        while k >= 0 and not lines[k].strip():
            k -= 1
        marker = lines[k] if k >= 0 else ""
        lang = m.group("lang")
        if lang == "text" and OUTPUT.search(marker):
            if not blocks:
                raise AssertionError(f"README line {start + 1}: an output block with no code block before it")
            blocks[-1].expected = body.splitlines()
        elif lang in ("python", "bash"):
            s = SKIP.search(marker)
            blocks.append(Block(lang, start + 1, body, s.group("why") if s else None))
        i = j + 1
    return blocks


BLOCKS = parse(README.read_text(encoding="utf-8"))


def check_output(expected: list[str], actual: str, where: str):
    """Every shown line appears in `actual`, in order; '...' lines stand for anything."""
    got = [line.rstrip() for line in actual.splitlines()]
    pos = 0
    for want in expected:
        want = want.rstrip()
        if want == "...":
            continue
        try:
            pos = got.index(want, pos) + 1
        except ValueError:
            tail = "\n".join(got[pos:pos + 40])
            raise AssertionError(f"{where}: the README shows\n  {want!r}\nbut the block printed (from there on):\n"
                                 f"{tail}") from None


def bash_commands(code: str) -> list[list[str]]:
    joined = re.sub(r"\\\n\s*", " ", code)
    cmds = []
    for line in joined.splitlines():
        argv = shlex.split(line, comments=True)
        if argv:
            cmds.append(argv)
    return cmds


@pytest.fixture(autouse=True)
def _agg(monkeypatch):
    import matplotlib

    matplotlib.use("Agg")


def test_readme_has_blocks_and_every_block_is_run_or_marked():
    langs = [b.lang for b in BLOCKS]
    assert "python" in langs and "bash" in langs
    for b in BLOCKS:
        if b.skip is None and b.lang == "bash":
            for argv in bash_commands(b.code):
                assert argv[0] == "satmd", (f"README line {b.line}: `{' '.join(argv)}` is not a satmd command; "
                                            "mark the block `<!-- readme-test: skip (why) -->`")


def run_block(block, origin: str):
    """Run one block (python in-process; bash through the CLI) and check what it prints; ``origin``: its file."""
    out = io.StringIO()
    where = f"{origin} line {block.line}"
    if block.lang == "python":
        from satmd.physics import effects

        before = set(effects._REGISTRY)
        try:
            with contextlib.redirect_stdout(out), warnings.catch_warnings():
                warnings.simplefilter("ignore")  # a block may warn (e.g. a poor fit); the page shows stdout
                exec(compile(block.code, f"{origin}:{block.line}", "exec"), {"__name__": "__readme__"})
        finally:
            for name in set(effects._REGISTRY) - before:  # an example that registers an effect
                effects.unregister(name)
    else:
        from satmd.cli import main

        for argv in bash_commands(block.code):
            err = io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                rc = main(argv[1:])
            assert rc == 0, f"{where}: `{' '.join(argv)}` exited {rc}: {err.getvalue()[-2000:]}"
    if block.expected:
        check_output(block.expected, out.getvalue(), where)


@pytest.mark.parametrize("block", BLOCKS, ids=[b.id for b in BLOCKS])
def test_readme_block(block, tmp_path, monkeypatch):
    if block.skip:
        pytest.skip(f"README line {block.line}: {block.skip}")
    monkeypatch.chdir(tmp_path)
    run_block(block, "README.md")


def test_readme_tables_match_results():
    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "readme_tables.py"), "--check", "--sync-only"],
                          check=False, capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr + proc.stdout


def test_output_matching_is_strict():
    check_output(["a", "...", "c"], "a\nb\nc\n", "self-test")
    with pytest.raises(AssertionError):
        check_output(["c", "a"], "a\nb\nc\n", "self-test")
    with pytest.raises(AssertionError):
        check_output(["a 66.0 Hz"], "a 65.9 Hz\n", "self-test")


def _readme_tables():
    import importlib.util

    spec = importlib.util.spec_from_file_location("readme_tables", ROOT / "benchmarks" / "readme_tables.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_staleness_counts_every_part_and_the_latest_run(tmp_path):
    """A result is as old as its oldest part; a list of runs is as old as its latest; no commit is stale."""
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    first = subprocess.run(["git", "rev-list", "--max-parents=0", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    if head.returncode or first.returncode or not head.stdout.strip():
        pytest.skip("not a git checkout")
    now, root = head.stdout.strip(), first.stdout.split()[0][:7]
    rt = _readme_tables()
    fresh = {"commit": now, "date": "2026-12-02", "platform": "x"}
    old = {"commit": root, "date": "2026-11-01", "platform": "x"}
    docs = {"fresh": {"machine": fresh, "cases": [{"machine": old}]},  # a case's record is not a machine's
            "merged": {"machine": fresh, "runs": [{"machine": fresh}, {"machine": old}]},
            "history": [{"platform": "x"}, {**fresh, "config": {"device": "cpu"}}],  # a run's config: no machine
            "bare": {"machine": {"platform": "x"}}}
    for name, doc in docs.items():
        (tmp_path / f"{name}.json").write_text(json.dumps(doc))
    found = rt.outdated(tmp_path, {name: ["satmd"] for name in docs})
    flagged = {line.split(":", 1)[0] for line in found}
    assert flagged == {"merged", "bare"}, found
    assert any(line.startswith(f"merged: measured at {root}") for line in found)
