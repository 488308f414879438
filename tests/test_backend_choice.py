"""The sampling backend per lattice (surface/backend_choice.py): numpy while it would finish a lattice's band
before wgpu could start, wgpu timed against it once a lattice is big enough, and the caller's request
honoured. Real backends: numpy and wgpu-py on this machine's adapter (lavapipe in CI)."""

from __future__ import annotations

from conftest import spec_file
from creaturegen.rig import CompiledRig, compile_rig
from creaturegen.spec import CharacterSpec, load_spec
from creaturegen.surface.backend_choice import SamplingBackends


def _rig() -> CompiledRig:
    spec = load_spec(spec_file("reference/hopper.json"))
    assert isinstance(spec, CharacterSpec)
    return compile_rig(spec)


def test_a_small_lattice_samples_with_numpy_without_starting_wgpu() -> None:
    said: list[str] = []
    backends = SamplingBackends(_rig(), "auto", said.append)
    backend, why = backends.for_lattice(200_000)
    assert backend.name == "numpy"
    assert "under wgpu's" in why
    assert backends._gpu is None  # wgpu's start-up was not paid
    assert said == [f"sampling backend numpy ({why})"]


def test_a_lattice_past_the_start_up_times_wgpu_once_and_keeps_the_faster() -> None:
    said: list[str] = []
    backends = SamplingBackends(_rig(), "auto", said.append)
    assert backends.for_lattice(1_000)[0].name == "numpy"
    backend, why = backends.for_lattice(10**10)  # numpy's band would take hours
    assert "wgpu" in why
    assert "ms" in why
    assert backend.name in ("numpy", "wgpu")
    started = backends._gpu
    assert started is not None
    again, why_again = backends.for_lattice(10**10)
    assert backends._gpu is started  # started once
    assert (again.name, why_again) == (backend.name, why)
    # Once wgpu runs, a small lattice takes the faster of the two as well.
    assert backends.for_lattice(1_000)[0].name == backend.name


def test_a_requested_backend_is_used_for_every_lattice() -> None:
    backends = SamplingBackends(_rig(), "numpy", lambda _: None)
    first = backends.for_lattice(10**10)
    assert first[0].name == "numpy"
    assert first[1] == "requested"
    assert backends.for_lattice(1_000)[0] is first[0]
