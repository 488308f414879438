"""One floating-point code path on every x86-64 machine, so that a spec builds to the same bytes on a
laptop, a CI runner and a build farm.

Two libraries pick their kernels by the CPU at load time, and their results differ in the last bits:
OpenBLAS (the sparse LU of the skin weights calls its BLAS; an AVX-512 machine's SkylakeX kernels round
differently from the Haswell kernels an AMD EPYC uses) and numpy's SIMD dispatch (its AVX-512 loops for
sin, cos, exp, … are not the AVX2 ones). A last-bit difference in a harmonic weight moves a vertex across
the seam classification's threshold, so the `.glb` differs, not only a printed figure. Measured on the
hopper: an Intel Xeon with AVX-512 matched the record written on an AMD EPYC only with both pins.

Both libraries read their settings from the environment once, when they load, so ``pin()`` runs from the
package's ``__init__`` before anything imports numpy; a process that imported numpy first keeps its
kernels (``PINNED`` says which happened). A variable the user set is left as it is.
"""

from __future__ import annotations

import os
import platform
import sys
import warnings
from pathlib import Path

#: The OpenBLAS kernel set every AVX2 + FMA machine runs (AMD Zen uses these by itself).
OPENBLAS_KERNELS = "Haswell"
#: numpy's dispatch targets above AVX2, under every name numpy 1.26 to 2.x uses: numpy warns about the
#: ones it does not dispatch (an ImportWarning, silenced while it loads) and ignores them.
NUMPY_ABOVE_AVX2 = (
    "X86_V4 AVX512_ICL AVX512_SPR AVX512F AVX512CD AVX512_KNL AVX512_KNM AVX512_SKX AVX512_CLX AVX512_CNL"
)

#: Whether this process runs the pinned kernels: False where numpy was imported before creaturegen, on a
#: CPU without AVX2 and FMA, or off x86-64 Linux (where the CPU's flags are not read).
PINNED = False


def _has_avx2_fma() -> bool:
    """The CPU flags Linux reports; the Haswell kernels would fault on a CPU without them."""
    if sys.platform != "linux" or platform.machine() not in ("x86_64", "AMD64"):
        return False
    try:
        text = Path("/proc/cpuinfo").read_text(errors="replace")
    except OSError:
        return False
    flags = next((line for line in text.splitlines() if line.startswith("flags")), "").split()
    return "avx2" in flags and "fma" in flags


def pin() -> bool:
    """Set both libraries' kernels (unless the user chose them) and load numpy with them."""
    global PINNED
    if "numpy" in sys.modules or not _has_avx2_fma():
        return PINNED
    os.environ.setdefault("OPENBLAS_CORETYPE", OPENBLAS_KERNELS)
    os.environ.setdefault("NPY_DISABLE_CPU_FEATURES", NUMPY_ABOVE_AVX2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ImportWarning)
        import numpy  # noqa: F401  (loaded now, with the settings above)
    PINNED = True
    return PINNED
