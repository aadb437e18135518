"""CSV recordings as a lab's software writes them: its own column names, units in brackets (see `csvrec`)."""
from __future__ import annotations

import re


from ..errors import FormatError
from ._common import numeric_table, parse_quantity_unit
from .recdata import Recording, is_role, ordered, role_of, si_unit, uniform_rate, warn_clipping

TIME_NAMES = ("time_s", "time", "t", "zeit", "temps")
_UNIT = re.compile(r"^(?P<name>.*?)\s*[\[(](?P<unit>[^\])]*)[\])]\s*$")


def split_unit(cell: str) -> tuple[str, str | None]:
    """'Force [N]' -> ('Force', 'N'); 'acc1' -> ('acc1', None)."""
    m = _UNIT.match(cell.strip())
    return (m["name"].strip(), m["unit"].strip()) if m else (cell.strip(), None)


def _time_scale(path, unit, lineno) -> float:
    if unit is None or unit.lower() == "s":
        return 1.0
    if unit.lower() == "ms":
        return 1e-3
    raise FormatError(path, f"time in {unit!r}: give it in s or ms", line=lineno, column=1)


def _si_factor(path, column, role, unit, lineno, j) -> float:
    """The factor to SI of a column's unit for its role (force in N, accelerations in m/s^2)."""
    if unit is None:
        return 1.0
    try:
        q = parse_quantity_unit(unit)
    except ValueError:
        raise FormatError(path, f"column {column!r}: unknown unit {unit!r}", line=lineno, column=j) from None
    want = "force" if role == "force" else 2
    if q is None:
        return 1.0
    if q[0] != want:
        kind = "a force" if role == "force" else "an acceleration"
        raise FormatError(path, f"column {column!r} in {unit!r} is not {kind}", line=lineno, column=j)
    return float(q[1])


def read_lab_csv(path, header, header_line, rows, meta, channel_map=None) -> Recording:
    """A lab's CSV recording (header already split; see the module docstring of `satmd.io.csvrec`)."""
    names = [split_unit(h) for h in header]
    if names[0][0].lower() not in TIME_NAMES:
        raise FormatError(path, f"first column must be time_s (or time, t; in s or ms), got {header[0]!r}",
                          line=header_line, column=1)
    lookup: dict[str, int] = {}
    for j, (name, _) in enumerate(names[1:], start=1):
        lookup.setdefault(name.lower(), j)
        lookup.setdefault(header[j].strip().lower(), j)
    roles: dict[str, int] = {}
    if channel_map:
        for part in str(channel_map).split(","):
            if not part.strip():
                continue
            role, eq, column = part.partition("=")
            if not eq:
                raise FormatError(path, f"map {part.strip()!r}: write force=COLUMN, a1=COLUMN, a2=COLUMN, ...")
            try:
                role = role_of(role)
            except ValueError as exc:
                raise FormatError(path, f"map {part.strip()}: {exc}") from None
            found = lookup.get(column.strip().lower())
            if found is None:
                raise FormatError(path, f"map {part.strip()}: no column {column.strip()!r}; columns: "
                                        f"{', '.join(header[1:])}")
            if role in roles or found in roles.values():
                raise FormatError(path, f"map {part.strip()}: {role} or column {column.strip()!r} given twice")
            roles[role] = found
    else:
        for role in ordered(k for k in lookup if is_role(k)):  # force, acc1, acc2, ...: as the rig's were
            roles[role] = lookup[role]
        if not roles or (roles.keys() == {"force"} and len(header) > 2):
            raise FormatError(path, f"no column named acc1 or acc2 (columns: {', '.join(header[1:])}): say "
                                    f"which is which with a channel map, e.g. force={names[1][0]}"
                                    + (f",a1={names[2][0]}" if len(names) > 2 else ""), line=header_line)
    if len(rows) < 2:
        raise FormatError(path, f"{len(rows)} data row(s): a recording needs at least 2 samples", line=header_line)
    unused = [header[j] for j in range(1, len(header)) if j not in roles.values()]
    if unused:
        from ._common import warn

        warn(path, f"ignored column(s) {', '.join(unused)}")
    values = numeric_table(path, header, rows)
    t = values[:, 0] * _time_scale(path, names[0][1], header_line)
    fs = uniform_rate(path, t, [ln for ln, _ in rows])
    channels = {role: values[:, j] * _si_factor(path, header[j], role, names[j][1], header_line, j + 1)
                for role, j in roles.items()}
    meta.update({"source": str(path), "format": "csv"})
    rec = Recording(fs, channels, {n: si_unit(n) for n in channels}, meta,
                    {n: f"column {j + 1} ({header[j]})" for n, j in roles.items()})
    warn_clipping(path, rec)
    return rec


__all__ = ["TIME_NAMES", "read_lab_csv", "split_unit"]
