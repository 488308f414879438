"""Handles: a failed euler gate names the parts whose contact closes a loop, and the build stops refining
when the field itself closes it.

The pincer's claws grow from the body and meet at their tips, so body → claw → claw → body is a loop
and its surface is a torus. The tangled beetle (tests/fixtures/tangled-beetle.json: the beetle example
before its legs were spread along a longer shell) has four handles: on each side the mid leg's knee
overlaps the front leg, and the blend bridges the gap between the rear leg's knee and the mid leg.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pytest

from conftest import REPO, rest_surface, run_cli
from creaturegen.model import layout as col
from creaturegen.model.skeleton import build_skeleton
from creaturegen.motion.compiled import compile_creature
from creaturegen.spec import CharacterSpec, load_spec
from creaturegen.surface.build import build_surface
from creaturegen.surface.handles import (
    Contact,
    _pieces,
    certain_handle_possible,
    cut_genus,
    handle_contacts,
    primitive_gap,
    surface_genus,
    uncut,
)
from creaturegen.surface.mesh import Mesh
from creaturegen.surface.refusal import SurfaceRejectedError

FIXTURES = Path(__file__).parent / "fixtures"
PINCER = FIXTURES / "pincer.json"
TANGLED = FIXTURES / "tangled-beetle.json"


def _torus(n: int = 24, m: int = 12, big: float = 1.0, small: float = 0.3) -> Mesh:
    """A closed quad-grid torus, two triangles per quad, outward winding."""
    u, v = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a, b = 2 * np.pi * u / n, 2 * np.pi * v / m
    ring = big + small * np.cos(b)
    vertices = np.stack([ring * np.cos(a), ring * np.sin(a), small * np.sin(b)], axis=-1).reshape(-1, 3)

    def idx(i: np.ndarray, j: np.ndarray) -> np.ndarray:
        return (i % n) * m + (j % m)

    q00, q10, q01, q11 = idx(u, v), idx(u + 1, v), idx(u, v + 1), idx(u + 1, v + 1)
    faces = np.concatenate([np.stack([q00, q10, q11], -1), np.stack([q00, q11, q01], -1)]).reshape(-1, 3)
    return Mesh(vertices, faces.astype(np.int32))


def test_genus_of_cut_surfaces() -> None:
    torus = _torus()
    assert surface_genus(torus) == 1.0
    centroid = torus.vertices[torus.faces].mean(axis=1)
    angle = np.arctan2(centroid[:, 1], centroid[:, 0])
    # A ring across the tube (an annulus around a non-separating curve) opens the handle.
    across = np.abs(angle) < 0.2
    assert surface_genus(Mesh(torus.vertices, torus.faces[~across])) == 0.0
    # A small disk leaves it: a hole is a boundary, not a lost handle.
    disk = np.linalg.norm(centroid - torus.vertices[0], axis=1) < 0.2
    assert 0 < disk.sum() < across.sum()
    assert surface_genus(Mesh(torus.vertices, torus.faces[~disk])) == 1.0
    # Two rings cut it into two tubes: each a cylinder, still genus 0 in all.
    two = across | (np.abs(np.abs(angle) - np.pi) < 0.2)
    assert surface_genus(Mesh(torus.vertices, torus.faces[~two])) == 0.0


def test_primitive_gap_is_the_segment_distance_less_the_radii() -> None:
    slots = np.zeros((2, col.WIDTH))
    slots[0, col.A], slots[0, col.B], slots[0, col.RA], slots[0, col.RB] = (0, 0, 0), (1, 0, 0), 0.1, 0.2
    slots[1, col.A], slots[1, col.B], slots[1, col.RA], slots[1, col.RB] = (0.5, 1, -1), (0.5, 1, 1), 0.3, 0.3
    # Segments 1 apart at x = 0.5; the round cone counts at its smaller end radius (inside the cone).
    assert primitive_gap(slots, 0, 1) == pytest.approx(1.0 - 0.1 - 0.3)


@cache
def _contacts(path: Path, tier: str) -> tuple[float, tuple[Contact, ...]]:
    s = rest_surface(path, tier)
    mesh, field, rig = s.extraction.mesh, s.field, s.rig
    distances = field.slot_distances(mesh.vertices)
    found = handle_contacts(
        mesh, distances, field.distance, build_skeleton(s.spec, rig), rig.slots, rig.slot_parts
    )
    return surface_genus(mesh), found


def test_the_tangled_beetle_names_its_four_handles() -> None:
    genus, found = _contacts(TANGLED, "repeated")
    # Four at hero; this coarser lattice also closes a near-tangent second touch of one pair (a certain
    # handle is one that any lattice shows; a marginal one may come and go with the spacing).
    assert genus >= 4.0
    culprits = {(c.a, c.b) for c in found if not c.joined}
    assert culprits == {
        ("part.leg-front-left", "part.leg-mid-left"),
        ("part.leg-mid-right", "part.leg-front-right"),
        ("part.leg-mid-right", "part.leg-rear-right"),
        ("part.leg-rear-left", "part.leg-mid-left"),
    }
    overlapping = [c for c in found if not c.joined and c.gap < 0]
    bridged = [c for c in found if not c.joined and c.gap > 0]
    assert len(overlapping) == 2
    assert len(bridged) == 2
    # Both kinds are certain: the field is negative along the whole segment between the primitives.
    assert all(c.certain and c.bridge < 0 for c in found if not c.joined)
    assert "overlap by" in overlapping[0].describe()
    assert "blend bridges" in bridged[0].describe()


def test_a_sphere_body_has_no_handles() -> None:
    genus, found = _contacts(REPO / "examples" / "beetle.json", "repeated")
    assert genus == 0.0
    assert found == ()


def test_the_build_names_the_contacts_and_stops_refining() -> None:
    """Euler is the tangled beetle's only failing mesh gate, and its handles are certain, so a finer
    lattice could only cost time: the build fails after one extraction."""
    spec = load_spec(TANGLED)
    assert isinstance(spec, CharacterSpec)
    said: list[str] = []
    with pytest.raises(SurfaceRejectedError) as caught:
        build_surface(compile_creature(spec), tier="hero", backend="numpy", progress=said.append)
    message = str(caught.value)
    assert "gate euler" in message, message
    assert "genus 4, expected 0" in message, message
    for a, b in (("front-left", "mid-left"), ("mid-right", "front-right"), ("mid-right", "rear-right")):
        assert f"part.leg-{a} touches part.leg-{b} (not joined in the skeleton" in message, message
    assert sum("extracted" in line for line in said) == 1, said
    assert any("a finer lattice cannot open them" in line for line in said), said


def test_the_cli_exits_3_and_writes_nothing(tmp_path: Path) -> None:
    """A valid spec that a build gate refuses exits 3 (2 is for invalid specs and arguments)."""
    out = tmp_path / "out"
    done = run_cli("build", str(PINCER), "-o", str(out), "--picture", "off")
    assert done.returncode == 3, done.stderr
    assert "gate euler" in done.stderr
    assert "part.claw-right touches part.claw-left" in done.stderr
    assert not out.exists() or not any(out.iterdir())


def test_a_joined_pair_touching_again_is_a_culprit() -> None:
    """A child that meets its parent at the joint and again elsewhere (a thigh folded against the belly)
    closes a loop through one joint: its contact strip comes in two pieces, and the message says so."""
    torus = _torus()
    centroid = torus.vertices[torus.faces].mean(axis=1)
    angle = np.arctan2(centroid[:, 1], centroid[:, 0])
    two = (np.abs(angle) < 0.2) | (np.abs(np.abs(angle) - np.pi) < 0.2)
    assert _pieces(torus.faces[two]) == 2
    assert _pieces(torus.faces[np.abs(angle) < 0.2]) == 1
    again = Contact("part.thigh", "part.body", 1.0, True, -0.01, -0.02, places=2)
    assert again.culprit
    assert "part.thigh touches part.body (at their joint and in 1 more place)" in again.describe()
    assert not Contact("part.thigh", "part.body", 1.0, True, -0.01, -0.02).culprit
    apart = Contact("part.leg-a", "part.leg-b", 1.0, False, 0.02, 0.01)
    assert apart.culprit
    assert "give one a k (or kCap) below 0.02 m" in apart.describe()


#: Generated seed 4 (`creaturegen random --seed 4`): at the distant tier its first three lattices close a
#: handle that no pair of unjoined parts makes certain, and the fourth opens it.
UNTIL_FINE = FIXTURES / "genus-until-fine-quadruped.json"


@pytest.mark.parametrize(
    ("path", "tier", "expected"),
    [
        (TANGLED, "repeated", True),
        (UNTIL_FINE, "distant", False),
        (REPO / "examples" / "beetle.json", "repeated", False),
    ],
)
def test_the_quick_certainty_check_agrees_with_the_contacts(path: Path, tier: str, expected: bool) -> None:
    """``certain_handle_possible`` lets the build refine a lattice without its contacts; it must answer
    exactly what the contacts would (a wrong False would refine past a refusal's stop rule, a wrong True
    only costs time)."""
    s = rest_surface(path, tier)
    mesh, field, rig = s.extraction.mesh, s.field, s.rig
    skeleton = build_skeleton(s.spec, rig)
    distances = field.slot_distances(mesh.vertices)
    quick = certain_handle_possible(mesh, distances, field.distance, skeleton, rig.slots, rig.slot_parts)
    _, found = _contacts(path, tier)
    assert quick == any(c.certain for c in found) == expected
    if path == UNTIL_FINE:
        assert surface_genus(mesh) >= 1.0, "the fixture no longer closes a handle at its first lattice"
        assert found


def test_a_cut_genus_from_the_whole_mesh_tables_equals_the_cut_mesh_genus() -> None:
    """``cut_genus`` recounts only what a cut changes; on cuts of every kind (a contact strip, a scatter
    of single faces that leaves pinch vertices, most of the mesh, a ring across the torus) it must equal
    ``surface_genus`` of the cut mesh built anew."""
    s = rest_surface(TANGLED, "repeated")
    rng = np.random.default_rng(7)
    for mesh in (_torus(), s.extraction.mesh):
        base = uncut(mesh)
        centroid = mesh.corners().mean(axis=1)
        size = float(np.ptp(mesh.vertices, axis=0).max())
        cuts = [np.zeros(mesh.face_count, dtype=bool)]
        cuts += [rng.random(mesh.face_count) < p for p in (0.002, 0.05, 0.5, 0.97)]
        for _ in range(6):
            centre = centroid[rng.integers(mesh.face_count)]
            r = rng.uniform(0.02, 0.3) * size
            cuts.append(np.linalg.norm(centroid - centre, axis=1) < r)
            cuts.append(np.abs(centroid[:, 0] - centre[0]) < 0.05 * r)
        values = [cut_genus(base, cut) for cut in cuts]
        assert values == [surface_genus(Mesh(mesh.vertices, mesh.faces[~cut])) for cut in cuts]
        assert len(set(values)) > 1
