"""Progress display for every long step of the package: a tqdm bar in a terminal, plain lines in a log.

When stderr is a terminal, bars redraw in place as tqdm does. When it is not (a log file, a pipe, CI), each
update that is shown becomes a line of its own, at most one every :data:`LOG_INTERVAL` seconds per bar (plus
the first and the last), so a log never gets one long line of carriage-return redraws.
"""

from __future__ import annotations

import re
import sys
import threading
from contextlib import contextmanager

from tqdm import tqdm

LOG_INTERVAL = 10.0
"""Seconds between the lines of one bar when stderr is not a terminal."""
TERMINAL_INTERVAL = 0.5
"""Seconds between the redraws of one bar in a terminal."""


#: Terminal control sequences (tqdm moves the cursor up with ESC [ A to redraw nested bars in place)
_CONTROL = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


class _LineWriter:
    """A file for tqdm that turns every redraw ('\\r' + status) into one line on ``stream``, repeats and
    cursor movements dropped."""

    def __init__(self, stream):
        self.stream = stream
        self.last = ""

    def write(self, text: str) -> None:
        for part in _CONTROL.sub("", text).replace("\n", "\r").split("\r"):
            part = part.strip()
            if part and part != self.last:
                self.stream.write(part + "\n")
                self.last = part

    def flush(self) -> None:
        self.stream.flush()


def interactive() -> bool:
    """True when stderr is a terminal (bars redraw in place)."""
    return bool(getattr(sys.stderr, "isatty", lambda: False)())


def progress_options(enabled: bool = True) -> dict:
    """tqdm keyword arguments for the current stderr: disable, mininterval and, in a log, the line-per-update file."""
    if interactive():
        return {"disable": not enabled, "mininterval": TERMINAL_INTERVAL}
    return {"disable": not enabled, "file": _LineWriter(sys.stderr), "mininterval": LOG_INTERVAL}


def progress_bar(description: str, total: int | None = None, unit: str = "it", enabled: bool = True, **options) -> tqdm:
    """A tqdm bar over ``total`` steps of ``unit`` (no total: a counter) that suits the terminal or the log."""
    return tqdm(desc=description, total=total, unit=unit, **(progress_options(enabled) | options))


@contextmanager
def elapsed(description: str, enabled: bool = True):
    """Show ``description: <elapsed time>`` while the block runs (one long call with no steps to count), and
    ``description: done in <s>`` at its end."""
    bar = progress_bar(description, bar_format="{desc}: {elapsed}", enabled=enabled)
    every = TERMINAL_INTERVAL if interactive() else LOG_INTERVAL
    stop = threading.Event()

    def tick():
        while not stop.wait(every):
            bar.refresh()

    thread = threading.Thread(target=tick, daemon=True)
    thread.start()
    try:
        yield bar
    finally:
        stop.set()
        thread.join()
        bar.bar_format = "{desc}: done in {elapsed}"
        bar.close()
