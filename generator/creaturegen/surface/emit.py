"""What of the surface sidecar goes into a package (creature/build.py writes assets/surface.json with it).

The package must be byte-identical for the same spec and version, so what goes in carries no measured
times and no word of which sampling backend ran (the backend cannot change the mesh: surface/sampling.py
settles every sign in float64). Those measurements stay in the cache sidecar and the build's output.
"""

from __future__ import annotations

#: Sidecar entries that vary from run to run on the same input.
VOLATILE = ("timings",)
VOLATILE_SAMPLING = ("backend", "choice", "seconds")
VOLATILE_DEFORMATION = ("seconds",)


def stable_sidecar(sidecar: dict[str, object]) -> dict[str, object]:
    out = {k: v for k, v in sidecar.items() if k not in VOLATILE}
    for key, drop in (("sampling", VOLATILE_SAMPLING), ("deformation", VOLATILE_DEFORMATION)):
        value = out.get(key)
        if isinstance(value, dict):
            out[key] = {k: v for k, v in value.items() if k not in drop}
    return out
