"""Read satmd's docstrings as written: plain-text notation that reStructuredText would misparse.

satmd's docstrings use the notation of its README and papers: ``|A1|`` for a magnitude, shapes
like ``(*batch, n)``, and numbered steps right under the line that introduces them. In
reStructuredText the first is a substitution reference, the second an unclosed emphasis and the
third an indented paragraph, each a build error. This extension (an ``autodoc-process-docstring``
hook that runs after numpydoc) rewrites exactly those three, outside literals, doctests and code
blocks, and nothing else:

1. a ``|`` that is not part of a table is escaped (``\\|``), so ``|A1|`` stays ``|A1|``;
2. a ``*`` that opens emphasis with no closing ``*`` on its line is escaped;
3. a list item (``1.``, ``-``, ``*``) that follows a text line with no blank line gets one.

A docstring's other mistakes (a broken reference, a bad directive, bad indentation) still fail
the build. Data (module constants) are documented by their ``#:`` comment or not at all: the
docstring of their type (``numpy.ndarray``'s, ``list``'s) is dropped.
"""
from __future__ import annotations

import re

_SPAN = re.compile(r"(``.+?``|:[\w:.-]+:`[^`]+`|`[^`]+`_{0,2}|\$[^$]+\$)")
_LIST = re.compile(r"^\s*(\d+[.)]|[-*+•])\s+\S")
_OPEN = set(" \t'\"([{<-/:")
_CLOSE = set(" \t'\")]}>-/:.,;!?\\")


def _stars(text: str) -> str:
    """Escape the '*' runs that open emphasis without a close on the same text."""
    out, i, n = [], 0, len(text)
    while i < n:
        if text[i] != "*":
            out.append(text[i])
            i += 1
            continue
        j = i
        while j < n and text[j] == "*":
            j += 1
        run = text[i:j]
        opens = (i == 0 or text[i - 1] in _OPEN) and j < n and not text[j].isspace()
        if opens:
            closer = re.compile(r"(?<=\S)" + re.escape(run) + r"(?=$|[" + re.escape("".join(_CLOSE)) + r"])")
            if not closer.search(text, j + 1):
                run = "\\*" * len(run)
        out.append(run)
        i = j
    return "".join(out)


def _text(segment: str) -> str:
    return _stars(segment.replace("|", "\\|"))


def _line(line: str) -> str:
    parts = _SPAN.split(line)
    return "".join(p if k % 2 else _text(p) for k, p in enumerate(parts))


def normalise(lines: list[str]) -> list[str]:
    """The docstring's lines with the three rewrites applied (see the module docstring)."""
    out: list[str] = []
    literal_indent = None   # indentation of the paragraph that introduced a literal block
    pending_literal = False
    in_doctest = False
    for line in lines:
        stripped = line.strip()
        indent = len(line) - len(line.lstrip())
        if literal_indent is not None:
            if stripped and indent <= literal_indent:
                literal_indent = None
            else:
                out.append(line)
                continue
        if pending_literal and stripped:
            pending_literal = False
        if stripped.startswith(">>>"):
            in_doctest = True
        if in_doctest:
            if not stripped:
                in_doctest = False
            out.append(line)
            continue
        if stripped.startswith("..") or stripped.startswith("+-") or stripped.startswith("+=") or (
                stripped.startswith("|") and stripped.endswith("|") and stripped.count("|") > 2):
            out.append(line)  # a directive, comment or table line
            if stripped.startswith("..") and "::" in stripped:
                literal_indent = indent  # a directive's body (math, code) is left as written
            continue
        if (_LIST.match(line) and out and out[-1].strip() and not _LIST.match(out[-1])
                and len(out[-1]) - len(out[-1].lstrip()) == indent and out[-1].rstrip().endswith(":")):
            out.append("")
        new = _line(line)
        out.append(new)
        if stripped.endswith("::"):
            literal_indent = indent
    return out


def _type_docstring(app, what, name, obj, options, lines):
    """Runs before numpydoc: a constant's docstring that is only its type's is dropped."""
    import inspect

    if what in ("data", "attribute") and lines and not inspect.isclass(obj) and type(obj).__doc__:
        mine = [t.strip() for t in lines if t.strip()]
        theirs = [t.strip() for t in inspect.cleandoc(type(obj).__doc__).splitlines() if t.strip()]
        if theirs and " ".join(theirs[-4:]) in " ".join(mine):  # after any signature line autodoc puts first
            lines[:] = []


def _process(app, what, name, obj, options, lines):
    lines[:] = normalise(lines)


def setup(app):
    app.setup_extension("numpydoc")
    app.connect("autodoc-process-docstring", _type_docstring, priority=100)
    app.connect("autodoc-process-docstring", _process, priority=900)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
