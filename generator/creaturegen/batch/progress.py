"""Progress of a batch: one bar redrawn in place on a terminal, one plain line per finished job elsewhere
(CI logs, pipes), both with the counts so far and an estimate of the time left."""

from __future__ import annotations

import os
import sys
import time
from collections import Counter
from typing import Any, TextIO


def _clock(seconds: float) -> str:
    seconds = max(0, round(seconds))
    return f"{seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


class Progress:
    """Counts of finished jobs by status; ``total`` jobs of which ``skipped`` were already done."""

    def __init__(self, total: int, skipped: int, stream: TextIO | None = None) -> None:
        self.stream = stream or sys.stdout
        self.tty = self.stream.isatty() and not os.environ.get("CI")
        self.total, self.done, self.skipped = total, skipped, skipped
        self.counts: Counter[str] = Counter()
        self.started = time.perf_counter()

    def eta(self) -> float:
        ran = self.done - self.skipped
        if ran <= 0:
            return float("nan")
        return (time.perf_counter() - self.started) / ran * (self.total - self.done)

    def line(self) -> str:
        counts = ", ".join(f"{n} {status}" for status, n in sorted(self.counts.items()))
        eta = self.eta()
        left = "eta --:--:--" if eta != eta else f"eta {_clock(eta)}"
        elapsed = _clock(time.perf_counter() - self.started)
        return f"[{self.done}/{self.total}] {counts or 'running'}; {elapsed} {left}"

    def finished(self, record: dict[str, Any], what: str) -> None:
        """One job ended (``what`` names it and its outcome)."""
        self.done += 1
        self.counts[record["status"]] += 1
        if self.tty:
            width = 24
            filled = round(width * self.done / max(self.total, 1))
            bar = "#" * filled + "-" * (width - filled)
            self.stream.write(f"\r\033[K{bar} {self.line()}  {what}"[:200])
        else:
            self.stream.write(f"{self.line()}: {what}\n")
        self.stream.flush()

    def close(self) -> None:
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()
