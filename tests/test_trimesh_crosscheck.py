"""Hand-written mesh code against trimesh, an independent implementation: the topology gates
(surface/topology.py) and the .glb writer (surface/glb.py).

Why both: the gates must name what is wrong (which edges, which vertex) and run in a fraction of a second
on 1e5 faces, which a library's yes/no answers do not give; trimesh is the well-kept check that our
counting agrees with the standard definitions. Each property is compared on the examples' extracted rest
surfaces and on meshes with one planted defect each, so a disagreement in either direction fails.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt
import pytest
import trimesh

from conftest import CREATURE_EXAMPLES, rest_surface, spec_file
from creaturegen.surface import topology
from creaturegen.surface.glb import write_glb
from creaturegen.surface.mesh import Mesh
from test_surface_asset import make_asset


def _ours(mesh: Mesh) -> dict[str, object]:
    table = topology.edge_table(mesh.faces)
    edges = topology.edge_report(mesh, table)
    comps = topology.components(mesh, table)
    return {
        "watertight": edges.watertight,
        "winding": edges.winding_violations == 0,
        "euler": int(comps.euler.sum()),
        "bodies": comps.count,
        # Bodies split differently where an edge has three faces (by vertices or by manifold face
        # adjacency); χ per body is compared on closed manifold meshes, where the two agree by definition.
        "euler per body": sorted(comps.euler.tolist()) if edges.watertight else None,
    }


def _theirs(mesh: Mesh) -> dict[str, object]:
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False, validate=False)
    parts = tm.split(only_watertight=False, repair=False) if tm.is_watertight else []
    return {
        "watertight": tm.is_watertight,
        "winding": tm.is_winding_consistent,
        "euler": tm.euler_number,
        "bodies": tm.body_count,
        "euler per body": sorted(p.euler_number for p in parts) if tm.is_watertight else None,
    }


def _sphere(subdivisions: int = 2) -> Mesh:
    s = trimesh.creation.icosphere(subdivisions)
    return Mesh(np.asarray(s.vertices, dtype=np.float64), np.asarray(s.faces, dtype=np.int32))


def _joined(a: Mesh, b: Mesh) -> Mesh:
    return Mesh(np.vstack([a.vertices, b.vertices]), np.vstack([a.faces, b.faces + a.vertex_count]))


def _torus() -> Mesh:
    t = trimesh.creation.torus(major_radius=1.0, minor_radius=0.3)
    return Mesh(np.asarray(t.vertices, dtype=np.float64), np.asarray(t.faces, dtype=np.int32))


def _faces(mesh: Mesh, faces: npt.NDArray[np.int32]) -> Mesh:
    return Mesh(mesh.vertices, faces.astype(np.int32))


def _flipped_first() -> Mesh:
    faces = _sphere().faces
    return _faces(_sphere(), np.vstack([faces[:1, ::-1], faces[1:]]))


def _fin() -> Mesh:
    """A third face on one edge of the sphere: a non-manifold edge."""
    s = _sphere()
    a, b, _ = s.faces[0]
    tip = s.vertices[[a, b]].mean(axis=0) * 1.5
    return Mesh(np.vstack([s.vertices, tip]), np.vstack([s.faces, [[b, a, s.vertex_count]]]).astype(np.int32))


PLANTED = {
    "clean sphere": lambda: _sphere(),
    "hole (one face removed)": lambda: _faces(_sphere(), _sphere().faces[1:]),
    "one face flipped": _flipped_first,
    "non-manifold fin": _fin,
    "torus (genus 1)": _torus,
    "two spheres": lambda: _joined(_sphere(), _sphere(1)),
}


@pytest.mark.parametrize("name", list(PLANTED))
def test_planted_meshes_agree_with_trimesh(name: str) -> None:
    mesh = PLANTED[name]()
    assert _ours(mesh) == _theirs(mesh)


def test_planted_defects_are_seen_by_both() -> None:
    """The comparison above could pass with both blind: each planted defect changes what both report."""
    clean = _ours(_sphere())
    assert clean == {"watertight": True, "winding": True, "euler": 2, "bodies": 1, "euler per body": [2]}
    assert not _ours(PLANTED["hole (one face removed)"]())["watertight"]
    assert not _ours(PLANTED["one face flipped"]())["winding"]
    assert not _ours(_fin())["watertight"]
    assert _ours(_torus())["euler"] == 0
    assert _ours(PLANTED["two spheres"]())["bodies"] == 2


@pytest.mark.parametrize("name", CREATURE_EXAMPLES)
def test_extracted_rest_surfaces_agree_with_trimesh(name: str) -> None:
    """Every example's rest surface on the distant tier's first lattice (raw extraction, before the
    build's remedies), where sheets, pinches and handles appear if anywhere."""
    mesh = rest_surface(spec_file(name), "distant").extraction.mesh
    assert _ours(mesh) == _theirs(mesh)


@pytest.mark.parametrize("vertices", [4, 70_000])
def test_trimesh_reads_what_our_glb_writer_wrote(tmp_path: Path, vertices: int) -> None:
    """The hand-written .glb writer (surface/glb.py; why by hand: its docstring) against trimesh's glTF
    reader: the same positions, normals, triangles and every per-vertex attribute, with uint16 and uint32
    indices. trimesh does not serve as the writer: it cannot write the per-slot rest frames (an accessor
    no primitive uses) and would tie the asset's bytes to its version."""
    asset = make_asset(vertices=vertices, slots=5, seed=3)
    path = tmp_path / "surface.glb"
    write_glb(path, asset, name="crosscheck")
    scene = trimesh.load(path, process=False)
    (mesh,) = scene.geometry.values()
    assert np.array_equal(mesh.vertices, asset.positions)
    assert np.array_equal(mesh.faces, asset.indices.reshape(-1, 3))
    attributes = {name: np.asarray(value) for name, value in mesh.vertex_attributes.items()}
    expected = {
        "_SLOTS": asset.slots,
        "_WEIGHTS": asset.weights,
        "_CANDIDATE": asset.candidate.reshape(-1, 1),
        "_RADIAL": asset.radial,
        "_SKIN": asset.skin,
        "_COR": asset.cor_centers,
    }
    assert set(expected) <= set(attributes), sorted(attributes)
    for name, values in expected.items():
        assert np.array_equal(attributes[name], np.asarray(values, dtype=np.float32)), name
    assert np.array_equal(np.asarray(mesh.vertex_normals, dtype=np.float32), asset.normals)
