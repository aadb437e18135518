"""How much satmd reads and computes at once: one place for every size limit.

Every request whose size comes from the user (a file, ``--fs × --duration``,
a tuning band, Monte Carlo draws, a saved model's settings) is checked here
*before* the memory is taken: a request beyond the limits is refused with the
estimate, never half-run until the machine kills it.

- `check_file` refuses what is not a regular file (a FIFO would block, a
  device never ends) and files larger than a reader takes;
- `check_samples` caps time samples per channel (`MAX_SAMPLES`);
- `check_memory` refuses work whose estimated memory exceeds the budget
  (half the memory the machine has available, at most `MAX_WORK_BYTES`).
"""
from __future__ import annotations

import os
import stat

from ..errors import DataError, FormatError

MAX_SAMPLES = 2 ** 24  # time samples per channel (3 channels of float64: 400 MB)
MAX_TEXT_BYTES = 512 * 2 ** 20  # a text file (CSV, TXT) parsed value by value
MAX_BINARY_BYTES = 2 * 2 ** 30  # a binary file (UFF 58b, WAV, .mat, .npz) read whole
MAX_WORK_BYTES = 8 * 2 ** 30  # no single request computes with more, whatever the machine has
MAX_FREQ_POINTS = 1_000_000  # frequencies computed at once


def size_text(nbytes: float) -> str:
    """'18.9 GB', '512 MB', '12 kB' (decimal units)."""
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if nbytes >= scale:
            return f"{nbytes / scale:.3g} {unit}"
    return f"{int(nbytes)} bytes"


def available_memory() -> int:
    """Bytes of memory available to a new allocation: the machine's MemAvailable (8 GiB when unknown), and no
    more than an address-space limit (``ulimit -v``, `resource.RLIMIT_AS`) leaves this process."""
    free = 8 * 2 ** 30
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    free = int(line.split()[1]) * 1024
                    break
    except (OSError, ValueError, IndexError):
        pass
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
        if soft != resource.RLIM_INFINITY:
            used = 0
            with open("/proc/self/status", encoding="ascii") as fh:
                for line in fh:
                    if line.startswith("VmSize:"):
                        used = int(line.split()[1]) * 1024
                        break
            free = min(free, max(soft - used, 0))
    except (ImportError, OSError, ValueError, IndexError):
        pass
    return free


def memory_budget() -> int:
    """The most memory one request may use: half of what is available, at most `MAX_WORK_BYTES`."""
    return int(min(MAX_WORK_BYTES, available_memory() // 2))


def check_memory(what: str, nbytes: float, hint: str = ""):
    """Refuse (`DataError`) work that needs more than `memory_budget` bytes, saying how much it would need.

    Parameters
    ----------
    what : str
        The request in the user's words, e.g. ``"--fs 1e+06 Hz for --duration 60 s"``.
    nbytes : float
        Estimated memory the work needs, in bytes.
    hint : str, optional
        How to ask for less, appended to the message.
    """
    budget = memory_budget()
    if not nbytes <= budget:  # also refuses NaN
        raise DataError(f"{what}: needs about {size_text(nbytes)} of memory, more than the {size_text(budget)} "
                        f"satmd uses at once{'; ' + hint if hint else ''}")


def check_samples(where, n_samples: float, n_channels: int = 1, *, path=None):
    """Refuse more than `MAX_SAMPLES` samples per channel (and more memory than `check_memory` allows).

    ``where`` names the request (an option, or a file when ``path`` is given:
    the error is then a `FormatError` naming the file).
    """
    need = float(n_samples) * max(1, int(n_channels)) * 8 * 6  # the values and the spectra made from them
    if not float(n_samples) <= MAX_SAMPLES:
        message = (f"{n_samples:.4g} samples per channel: more than the {MAX_SAMPLES} satmd reads at once "
                   f"(about {size_text(need)} of memory); use a shorter record")
        if path is not None:
            raise FormatError(path, message)
        raise DataError(f"{where}: {message}")
    try:
        check_memory(str(where), need, "use a shorter record")
    except DataError as exc:
        if path is not None:
            raise FormatError(path, str(exc).split(": ", 1)[1]) from None
        raise


def check_file(path, max_bytes: int) -> int:
    """The size of a regular file no larger than ``max_bytes``; anything else is a one-line `FormatError`.

    A FIFO, a socket or a device (``/dev/zero``, ``/dev/urandom``) is refused
    without opening it (reading would block or never end).
    """
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise FormatError(path, "no such file") from None
    except OSError as exc:
        raise FormatError(path, f"cannot read file ({exc.strerror or exc})") from None
    if stat.S_ISDIR(st.st_mode):
        raise FormatError(path, "is a directory, not a file")
    if not stat.S_ISREG(st.st_mode):
        kind = ("a FIFO (named pipe)" if stat.S_ISFIFO(st.st_mode) else "a device" if
                stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode) else "a socket" if stat.S_ISSOCK(st.st_mode)
                else "not a regular file")
        raise FormatError(path, f"is {kind}, not a regular file")
    if st.st_size > max_bytes:
        raise FormatError(path, f"file is {size_text(st.st_size)}: more than the {size_text(max_bytes)} satmd reads "
                                f"from one file of this kind")
    return st.st_size


__all__ = ["MAX_BINARY_BYTES", "MAX_FREQ_POINTS", "MAX_SAMPLES", "MAX_TEXT_BYTES", "MAX_WORK_BYTES",
           "available_memory", "check_file", "check_memory", "check_samples", "memory_budget", "size_text"]
