"""The pinned floating-point kernels (creaturegen/floatenv.py): what makes the golden record, written on an
AMD EPYC, the build of an AVX-512 Intel Xeon too. Each case runs in a child process, because the pin only
acts before numpy loads."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from creaturegen import floatenv

PROBE = """
import json, os, sys
{first}
from creaturegen import floatenv
from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
print(json.dumps({{
    "pinned": floatenv.PINNED,
    "coretype": os.environ.get("OPENBLAS_CORETYPE"),
    "dispatch": [name for name in __cpu_dispatch__ if __cpu_features__[name]],
}}))
"""


def _probe(first: str = "", **env: str) -> dict[str, object]:
    pins = ("OPENBLAS_CORETYPE", "NPY_DISABLE_CPU_FEATURES")
    clean = {k: v for k, v in os.environ.items() if k not in pins}
    done = subprocess.run(
        [sys.executable, "-W", "error::ImportWarning", "-c", PROBE.format(first=first)],
        capture_output=True,
        text=True,
        check=True,
        env={**clean, **env},
    )
    result: dict[str, object] = json.loads(done.stdout)
    return result


def test_importing_creaturegen_first_runs_the_avx2_kernels() -> None:
    found = _probe()
    if not floatenv._has_avx2_fma():
        # Off x86-64 Linux or without AVX2 + FMA nothing is pinned, and that is what PINNED must say.
        assert found["pinned"] is False
        assert found["coretype"] is None
        return
    assert found["pinned"] is True, found
    assert found["coretype"] == "Haswell", found
    dispatch = found["dispatch"]
    assert isinstance(dispatch, list)
    above_avx2 = [name for name in dispatch if "512" in name or name == "X86_V4"]
    assert not above_avx2, f"numpy still dispatches {above_avx2}"


def test_numpy_loaded_first_keeps_its_kernels_and_says_so() -> None:
    found = _probe(first="import numpy")
    assert found["pinned"] is False
    assert found["coretype"] is None


def test_a_kernel_the_user_chose_is_kept() -> None:
    found = _probe(OPENBLAS_CORETYPE="Sandybridge")
    assert found["coretype"] == "Sandybridge"
