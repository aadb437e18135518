"""Helpers shared by the file readers: warnings, raw reads, unit labels, channel maps."""
from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import numpy as np

from ..errors import DataWarning, FormatError  # noqa: F401 - DataWarning is io's since before satmd.errors had it
from .atomic import all_or_none, atomic_write  # noqa: F401 - io modules import them from here too

G0 = 9.80665  # standard gravity, for accelerations in g


def warn(path, message: str):
    warnings.warn(f"{path}: {message}", DataWarning, stacklevel=3)


def short_error(exc) -> str:
    """An exception from a third-party reader as a short one-line text (for `FormatError` messages);
    an OSError in words (a damaged archive's seek fails with ``[Errno 22]``), never its errno."""
    if isinstance(exc, OSError) and exc.strerror:
        return f"damaged or truncated ({exc.strerror.lower()})"
    return " ".join(str(exc).split())[:120] or type(exc).__name__


def read_bytes(path, limit: int | None = None) -> bytes:
    """The whole file, refusing missing, unreadable, empty, oversized and non-regular files (one-line FormatError).

    ``limit`` is the largest size read (default `limits.MAX_BINARY_BYTES`); a
    FIFO or a device is refused before it is opened (`limits.check_file`).
    """
    from .limits import MAX_BINARY_BYTES, check_file

    path = Path(path)
    limit = MAX_BINARY_BYTES if limit is None else limit
    check_file(path, limit)
    try:
        with open(path, "rb") as fh:
            raw = fh.read(limit + 1)  # a file that grew since the check is still bounded
    except IsADirectoryError:
        raise FormatError(path, "is a directory, not a file") from None
    except OSError as exc:
        raise FormatError(path, f"cannot read file ({exc.strerror or exc})") from None
    if len(raw) > limit:
        raise FormatError(path, "file grew past the size satmd reads while it was read")
    if not raw.strip():
        raise FormatError(path, "empty file")
    return raw


def writer_for(path, writers: dict, what: str):
    """The writer `writers` holds for `path`'s suffix; a `FormatError` for an unknown suffix or a missing folder."""
    writer = writers.get(path.suffix.lower())
    if writer is None:
        raise FormatError(path, f"cannot write {path.suffix!r} {what} (known: {', '.join(sorted(writers))})")
    if not path.parent.exists():
        raise FormatError(path, f"folder {path.parent} does not exist")
    return writer


def read_text(path) -> str:
    """A text file (UTF-8), bounded by `limits.MAX_TEXT_BYTES`; see `read_bytes` and `decode_text`."""
    from .limits import MAX_TEXT_BYTES

    return decode_text(path, read_bytes(path, MAX_TEXT_BYTES))


def text_lines(text: str) -> list[str]:
    """Lines split at '\\n' only (a '\\r' before it dropped).

    `str.splitlines` also splits at U+2028, U+0085, form feeds and other
    separators, which would shift line numbers and break a comment in two.
    """
    if "\n" not in text and "\r" in text:  # old Mac line ends
        return text.split("\r")
    return [line[:-1] if line.endswith("\r") else line for line in text.split("\n")]


def decode_text(path, raw: bytes) -> str:
    """UTF-8 text (BOM allowed); binary content is refused naming the first bad line."""
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise FormatError(path, "not a text file (invalid UTF-8)", line=line) from None
    if "\x00" in text:
        raise FormatError(path, "not a text file (contains NUL bytes)", line=text[: text.index("\x00")].count("\n") + 1)
    return text


# --- units -------------------------------------------------------------------
# A physical quantity is described by its "power": 0 displacement, 1 velocity,
# 2 acceleration (time derivatives of a length), or "force". Unit labels are
# turned into (quantity, factor to SI).
_LENGTHS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "um": 1e-6, "µm": 1e-6, "μm": 1e-6, "nm": 1e-9,
            "in": 0.0254, "ft": 0.3048}
_FORCES = {"N": 1.0, "kN": 1e3, "mN": 1e-3, "lbf": 4.4482216152605, "lb": 4.4482216152605}
_CHARGES = {"C": 1.0, "mC": 1e-3, "uC": 1e-6, "µC": 1e-6, "nC": 1e-9, "pC": 1e-12}
_LENGTH_RE = re.compile(r"^(?P<len>[a-zµμ]+)(?:/s(?P<pow>2)?)?$")


def _normalise(label: str) -> str:
    s = label.strip().replace(" ", "").replace("²", "2").replace("^", "").replace("**", "")
    s = s.replace("sec", "s")
    if s.startswith("(") and s.endswith(")") and s.count("(") == 1:
        s = s[1:-1]
    return s


def parse_quantity_unit(label: str | None):
    """'m/s^2' -> (2, 1.0), 'g' -> (2, 9.80665), 'mm' -> (0, 1e-3), 'kN' -> ('force', 1e3).

    Returns None for an absent label (None, '', 'NONE') and raises ValueError
    for a label it does not know.
    """
    if label is None or label.strip().upper() in ("", "NONE"):
        return None
    s = _normalise(label)
    if s in _FORCES:
        return "force", _FORCES[s]
    if s in _CHARGES:
        return "charge", _CHARGES[s]
    if s.lower() in ("g", "gn"):
        return 2, G0
    m = _LENGTH_RE.match(s)
    if m and m["len"] in _LENGTHS:
        power = 0 if "/s" not in s else (2 if m["pow"] else 1)
        return power, _LENGTHS[m["len"]]
    raise ValueError(f"unknown unit {label!r}")


def parse_frf_unit(label: str | None):
    """'(m/s^2)/N' or 'g/N' -> (power, factor to SI per newton); None if absent."""
    if label is None or label.strip().upper() in ("", "NONE"):
        return None
    s = _normalise(label)
    num, sep, den = s.rpartition("/")
    if not sep or den not in _FORCES:
        raise ValueError(f"unknown FRF unit {label!r}")
    q = parse_quantity_unit(num)
    if q is None or q[0] == "force":
        raise ValueError(f"unknown FRF unit {label!r}")
    return q[0], q[1] / _FORCES[den]


# --- channel maps ---------------------------------------------------------------
_DIRS = {"x": 1, "y": 2, "z": 3, "rx": 4, "ry": 5, "rz": 6}


def parse_dof(text: str):
    """'12:3', '12:+Z', '12:-x' -> ('dof', 12, 3); '#4' -> ('index', 4, None)."""
    t = text.strip()
    if t.startswith("#"):
        if not t[1:].isdigit() or int(t[1:]) < 1:
            raise ValueError(f"{text!r}: a record number is #1, #2, ...")
        return "index", int(t[1:]), None
    node_text, sep, d = t.partition(":")
    if not sep:
        raise ValueError(f"{text!r}: expected NODE:DIR (e.g. 3:+Z or 3:3) or #RECORD")
    try:
        node = int(node_text)
    except ValueError:
        raise ValueError(f"{text!r}: node {node_text!r} is not an integer") from None
    d = d.strip()
    sign = -1 if d.startswith("-") else 1
    body = d.lstrip("+-").lower()
    if body.isdigit() and 0 <= int(body) <= 6:
        direction = sign * int(body)
    elif body in _DIRS:
        direction = sign * _DIRS[body]
    else:
        raise ValueError(f"{text!r}: direction {d!r} is not 0..6 or ±X/Y/Z/RX/RY/RZ")
    return "dof", node, direction


def parse_channel_map(spec, allowed, aliases=None) -> dict:
    """'a1=1:3,a2=#2' (or a dict) -> {'a1': ('dof', 1, 3), 'a2': ('index', 2, None)}.

    ``allowed`` is the channels a map may name, or a naming rule: a function
    from a key to its channel that raises ValueError for a bad key (a
    recording's roles, `recdata.role_of`: ``a3`` -> ``acc3`` for any N).
    """
    aliases = aliases or {}
    items = spec.items() if isinstance(spec, dict) else (
        part.partition("=")[::2] for part in str(spec).split(",") if part.strip())
    out = {}
    for key, value in items:
        entry = f"{str(key).strip()}={str(value).strip()}"
        if callable(allowed):
            try:
                key = allowed(key)
            except ValueError as exc:
                raise ValueError(f"channel_map {entry}: {exc}") from None
        else:
            key = aliases.get(key.strip(), key.strip())
            if key not in allowed:
                raise ValueError(f"channel_map: unknown channel {key!r} (use {', '.join(allowed)})")
        if not str(value).strip():
            raise ValueError(f"channel_map: {key}= needs NODE:DIR or #RECORD")
        if key in out:
            raise ValueError(f"channel_map {entry}: {key} given twice")
        try:
            out[key] = parse_dof(str(value))
        except ValueError as exc:
            raise ValueError(f"channel_map {key}={str(value).strip()}: {str(exc).split(': ', 1)[-1]}") from None
        same = [k for k, v in out.items() if k != key and _same_source(v, out[key])]
        if same:
            raise ValueError(f"channel_map {entry}: {same[0]} and {key} both name {str(value).strip()} "
                             "(one record or column cannot be two channels)")
    if not out:
        raise ValueError("channel_map is empty")
    return out


def _same_source(a, b) -> bool:
    """Two map entries naming the same record (#N) or the same node and axis."""
    if a[0] != b[0]:
        return False
    return a[1] == b[1] if a[0] == "index" else (a[1], abs(a[2])) == (b[1], abs(b[2]))


def channel_map_of(path, spec, allowed, aliases=None) -> dict:
    """`parse_channel_map` for a reader: a malformed map is a one-line `FormatError` naming the file and the entry."""
    try:
        return parse_channel_map(spec, allowed, aliases)
    except ValueError as exc:
        raise FormatError(path, str(exc)) from None


def split_csv(path, text: str, magic: str):
    """Comment lines, one header row, then data rows of a satmd CSV.

    ``# <magic> vN`` lines check the version (v1 only); ``# key: value``
    comments before the header become metadata (keys may contain ':').
    Returns (header cells, header line number, [(line number, cells)], meta).
    """
    header, header_line, rows, meta = None, None, [], {}
    for lineno, line in enumerate(text_lines(text), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            body = stripped[1:].strip()
            if body.lower().startswith("satmd-frfs"):  # `ChannelFRFs`: a structure's every channel
                raise FormatError(path, "FRFs of every channel of a structure (ChannelFRFs, satmd-frfs v1); this "
                                        "reads a rig's A1 and A2 (satmd-frf v1)", line=lineno)
            if body.lower().startswith(magic):
                if body.split()[1:] != ["v1"]:
                    raise FormatError(path, f"unsupported format version {body!r} (this reader knows {magic} v1)",
                                      line=lineno)
            elif ": " in body and header is None:
                key, _, value = body.partition(": ")
                meta[key.strip()] = value.strip()
            continue
        cells = [c.strip() for c in stripped.split(",")]
        if header is None:
            header, header_line = cells, lineno
        else:
            rows.append((lineno, cells))
    return header, header_line, rows, meta


def numeric_table(path, header, rows) -> np.ndarray:
    """Rows of finite numbers, one per header column; any bad cell names line and column."""
    values = np.empty((len(rows), len(header)))
    for i, (lineno, cells) in enumerate(rows):
        if len(cells) != len(header):
            raise FormatError(path, f"{len(cells)} fields, header has {len(header)}", line=lineno)
        for j, cell in enumerate(cells):
            try:
                x = float(cell)
            except ValueError:
                raise FormatError(path, f"not a number: {cell!r}", line=lineno, column=f"{j + 1} ({header[j]})") from None
            if not math.isfinite(x):
                raise FormatError(path, f"{cell} is not a finite number", line=lineno, column=f"{j + 1} ({header[j]})")
            values[i, j] = x
    return values
