"""The documentation site (issue 37): it builds with no warning, it documents every public name, and
every code block of its pages runs and prints what the page shows.

- The build is `make docs-check`'s: Sphinx with warnings as errors, the gallery (examples/plot_*.py)
  not executed, into a temporary folder. Skipped when the docs extra is not installed
  (``pip install -e '.[docs]'``); `make docs` runs the gallery too.
- Code blocks follow the README's rules (`tests/test_readme.py`): ```python blocks run in-process in
  an empty folder, ```bash blocks are `satmd` command lines, ``<!-- readme-test: skip (why) -->``
  marks one that cannot run here and ``<!-- readme-test: output -->`` the output a block must print.
- The README is a landing page: at most 350 lines, and its links into the site lead somewhere.
"""
from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from .test_readme import Block, bash_commands, parse, run_block

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README = ROOT / "README.md"
PAGES = sorted(p for p in DOCS.rglob("*.md")
               if not any(part.startswith(("_", ".")) or part == "auto_examples" for part in p.relative_to(DOCS).parts))
BLOCKS: list[tuple[str, Block]] = [(str(p.relative_to(ROOT)), b) for p in PAGES for b in parse(p.read_text("utf-8"))]
DOCS_EXTRA = ("sphinx", "numpydoc", "sphinx_gallery", "myst_parser", "pydata_sphinx_theme")
MISSING = [m for m in DOCS_EXTRA if importlib.util.find_spec(m) is None]


@pytest.fixture(autouse=True)
def _agg():
    import matplotlib

    matplotlib.use("Agg")


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The site built as CI builds it (no gallery execution, warnings as errors): its HTML folder."""
    if MISSING:
        pytest.skip(f"the docs extra is not installed ({', '.join(MISSING)}): pip install -e '.[docs]'")
    out = tmp_path_factory.mktemp("docs")
    cmd = [sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-j", "1", "-q",
           "-D", "plot_gallery=0", "-d", str(out / "doctrees"), str(DOCS), str(out / "html")]
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=600, env=env, check=False)
    assert proc.returncode == 0, f"the docs build failed (warnings are errors):\n{proc.stderr[-6000:]}"
    return out / "html"


def test_the_site_builds_with_no_warning(site):
    for page in ("index", "getting_started", "guide/index", "api/index", "auto_examples/index", "results"):
        assert (site / f"{page}.html").is_file(), page


def test_the_user_guide_has_its_pages(site):
    for page in ("frf_files", "recordings", "discovery", "adequacy", "nonlinear", "tuning", "inverse", "explain",
                 "fleets", "cli", "formats"):
        assert (site / "guide" / f"{page}.html").is_file(), page


def test_every_public_name_has_an_api_page(site):
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        import api_pages
    finally:
        sys.path.remove(str(DOCS / "_ext"))
    import satmd

    top = {id(getattr(satmd, n)) for n in satmd.__all__}
    missing = []
    for module, names in api_pages.public_modules():
        mod = sys.modules[module]
        for name in names:
            here = site / "api" / "generated" / f"{module}.{name}.html"
            shared = module != "satmd" and id(getattr(mod, name)) in top
            if not here.is_file() and not shared:
                missing.append(f"{module}.{name}")
    assert not missing, f"public names without an API page: {', '.join(missing)}"


def test_the_gallery_holds_every_example(site):
    examples = sorted(p.stem for p in (ROOT / "examples").glob("plot_*.py"))
    assert len(examples) >= 8
    for stem in examples:
        assert (site / "auto_examples" / f"{stem}.html").is_file(), stem


def test_every_block_is_run_or_marked():
    assert any(b.lang == "python" and not b.skip for _, b in BLOCKS)
    for page, b in BLOCKS:
        if b.skip is None and b.lang == "bash":
            for argv in bash_commands(b.code):
                assert argv[0] == "satmd", (f"{page} line {b.line}: `{' '.join(argv)}` is not a satmd command; "
                                            "mark the block `<!-- readme-test: skip (why) -->`")


@pytest.mark.parametrize("page, block", BLOCKS, ids=[f"{p}:{b.id}" for p, b in BLOCKS])
def test_docs_block(page, block, tmp_path, monkeypatch):
    if block.skip:
        pytest.skip(f"{page} line {block.line}: {block.skip}")
    monkeypatch.chdir(tmp_path)
    run_block(block, page)


def test_the_readme_is_a_landing_page():
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 350, f"README.md has {len(text.splitlines())} lines (at most 350)"
    links = re.findall(r"\]\((docs/[^)#\s]+)", text)
    assert links, "the README links into the documentation site"
    broken = [link for link in links if not (ROOT / link).exists()]
    assert not broken, f"README links to missing pages: {', '.join(broken)}"
