"""What every benchmark records about where it ran: interpreter, CPUs, platform and the git state.

Benchmarks compare ratios measured side by side in one run; this record is what makes two JSON files
from different runs comparable at all (same commit? a dirty tree? how many CPUs were usable?).
"""

from __future__ import annotations

import os
import platform
import subprocess
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]


def git_state() -> tuple[str | None, bool | None]:
    """HEAD and whether the working tree differs from it; (None, None) outside a checkout."""
    try:
        commit = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=REPO, capture_output=True, text=True, check=True
        ).stdout.strip()
        dirty = bool(
            subprocess.run(
                ["git", "status", "--porcelain"], cwd=REPO, capture_output=True, text=True, check=True
            ).stdout.strip()
        )
    except (OSError, subprocess.CalledProcessError):
        return None, None
    return commit, dirty


def machine() -> dict[str, Any]:
    """The host fields every benchmark's JSON starts from; each adds its own libraries and devices."""
    commit, dirty = git_state()
    return {
        "python": platform.python_version(),
        "cpu_count": os.cpu_count(),
        "cpus_usable": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count(),
        "platform": platform.platform(),
        "machine": platform.machine(),
        "processor": platform.processor() or None,
        "git_commit": commit,
        "git_dirty": dirty,
    }
