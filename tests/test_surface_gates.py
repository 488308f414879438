"""Mesh-validity gates: a clean marching-cubes sphere passes every gate, and each gate can fail alone.

The exact-predicate tests compare against an independent exact-rational reference (Möller's interval
method computed in fractions.Fraction), not against the implementation's own formulas.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from fractions import Fraction

import numpy as np
import numpy.typing as npt
import pytest
from skimage.measure import marching_cubes

from creaturegen.surface import intersect, topology
from creaturegen.surface.gates import SurfaceGate, mesh_gates, normal_gates, zero_set_to_mesh
from creaturegen.surface.mesh import Mesh

F64 = npt.NDArray[np.float64]
Field = Callable[[F64], F64]

R = 0.37
L = 2 * R


# ------------------------------------------------------------------------------------------ fixtures


def _signed_volume(mesh: Mesh) -> float:
    c = mesh.corners()
    return float(np.einsum("ij,ij->i", c[:, 0], np.cross(c[:, 1], c[:, 2])).sum() / 6.0)


def _extract(sdf: Callable[[F64], F64], n: int, half: float = 0.5) -> Mesh:
    """Marching cubes on a grid, then faces flipped if the signed volume says they face inward."""
    x = np.linspace(-half, half, n)
    grid = np.stack(np.meshgrid(x, x, x, indexing="ij"), axis=-1).reshape(-1, 3)
    values = sdf(grid).reshape(n, n, n)
    verts, faces, _, _ = marching_cubes(values, 0.0, spacing=(x[1] - x[0],) * 3)  # type: ignore[no-untyped-call]
    mesh = Mesh((verts + x[0]).astype(np.float64), faces.astype(np.int32))
    if _signed_volume(mesh) < 0:
        mesh = Mesh(mesh.vertices, np.ascontiguousarray(mesh.faces[:, ::-1]))
    return mesh


def sphere_distance(p: F64, centre: tuple[float, float, float] = (0.0, 0.0, 0.0), r: float = R) -> F64:
    result: F64 = np.linalg.norm(p - np.asarray(centre), axis=1) - r
    return result


def sphere_gradient(p: F64, centre: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> F64:
    q = p - np.asarray(centre)
    result: F64 = q / np.linalg.norm(q, axis=1, keepdims=True)
    return result


def _gates(
    mesh: Mesh, distance: Field = sphere_distance, gradient: Field = sphere_gradient, components: int = 1
) -> dict[str, SurfaceGate]:
    gates = mesh_gates(
        mesh, length_scale=L, distance=distance, gradient=gradient, expected_components=components
    )
    return {g.name: g for g in gates}


def _failed(gates: dict[str, SurfaceGate]) -> set[str]:
    return {name for name, g in gates.items() if not g.passed}


@pytest.fixture(scope="module")
def sphere() -> Mesh:
    return _extract(sphere_distance, 44)


def _with_faces(mesh: Mesh, faces: npt.ArrayLike) -> Mesh:
    return Mesh(mesh.vertices, np.asarray(faces, dtype=np.int32))


# ------------------------------------------------------------------------------------- positive case


def test_clean_sphere_passes_every_gate(sphere: Mesh) -> None:
    assert _signed_volume(sphere) > 0
    gates = _gates(sphere)
    assert not _failed(gates), {n: g.as_dict() for n, g in gates.items() if not g.passed}
    assert set(gates) == {
        "watertight",
        "edgeManifold",
        "vertexManifold",
        "winding",
        "euler",
        "components",
        "degenerate",
        "minAngleP1",
        "selfIntersections",
        "coincidentCoverage",
        "inverted",
        "surfaceToZeroSet",
        "zeroSetToMesh",
        "vertexNormalAngleMax",
        "vertexNormalAngleP99",
        "faceNormalAngleMax",
        "faceNormalAngleP99",
    }
    json.dumps([g.as_dict() for g in gates.values()])
    assert gates["minAngleP1"].direction == "min"


def test_gate_direction_semantics() -> None:
    assert SurfaceGate("a", 1.0, 1.0, "1", "max").passed
    assert not SurfaceGate("a", 1.1, 1.0, "1", "max").passed
    assert SurfaceGate("a", 1.0, 1.0, "1", "min").passed
    assert not SurfaceGate("a", 0.9, 1.0, "1", "min").passed
    assert not SurfaceGate("a", float("nan"), 1.0, "1", "max").passed


def test_topology_of_clean_sphere(sphere: Mesh) -> None:
    report = topology.edge_report(sphere)
    assert report.watertight
    assert report.edge_count * 2 == sphere.face_count * 3
    comps = topology.components(sphere)
    assert comps.count == 1
    assert comps.euler.tolist() == [2]
    assert comps.genus.tolist() == [0.0]
    assert np.all(topology.vertex_fans(sphere) == 1)


# ------------------------------------------------------------------------------------ negative cases


def test_two_interpenetrating_spheres_self_intersect() -> None:
    a = _extract(sphere_distance, 36)
    shift = np.array([0.21, 0.0, 0.0])
    both = Mesh(
        np.concatenate([a.vertices, a.vertices + shift]),
        np.concatenate([a.faces, a.faces + a.vertex_count]).astype(np.int32),
    )
    report = intersect.self_intersections(both)
    assert report.intersecting > 0
    assert report.coincident == 0
    first = report.pairs[0]
    assert (first[0] < a.face_count) != (first[1] < a.face_count)  # one face from each sphere
    gates = _gates(both)
    assert "selfIntersections" in _failed(gates)
    assert "components" in _failed(gates)
    assert "euler" not in _failed(gates)


def test_vertex_pushed_through_opposite_side(sphere: Mesh) -> None:
    v = sphere.vertices.copy()
    tip = int(np.argmax(v[:, 0]))
    v[tip] = np.array([-1.2 * R, 0.0, 0.0])
    gates = _gates(Mesh(v, sphere.faces))
    assert {"selfIntersections", "inverted"} <= _failed(gates)
    assert not {"watertight", "edgeManifold", "vertexManifold", "winding", "euler"} & _failed(gates)


def test_flipped_face_fails_winding_and_inverted(sphere: Mesh) -> None:
    faces = sphere.faces.copy()
    faces[17] = faces[17, ::-1]
    gates = _gates(_with_faces(sphere, faces))
    assert gates["winding"].value == 3
    assert gates["inverted"].value == 1
    # The gate points at the flipped face, so the build can name the part there.
    assert np.allclose(gates["inverted"].where, sphere.vertices[sphere.faces[17]].mean(axis=0))
    assert {"winding", "inverted"} <= _failed(gates)
    assert not {"watertight", "edgeManifold", "vertexManifold", "selfIntersections"} & _failed(gates)


def test_whole_mesh_inside_out_is_consistent_but_inverted(sphere: Mesh) -> None:
    gates = _gates(_with_faces(sphere, sphere.faces[:, ::-1]))
    assert "winding" not in _failed(gates)
    assert gates["inverted"].value == sphere.face_count


def test_duplicated_sheet_fails_duplicate_and_edge_manifold(sphere: Mesh) -> None:
    extra = sphere.faces[:40, ::-1]
    gates = _gates(_with_faces(sphere, np.concatenate([sphere.faces, extra])))
    assert {"coincidentCoverage", "edgeManifold"} <= _failed(gates)
    # It points at one of the duplicated faces (each copy has the same centroid as its original).
    centroids = sphere.vertices[sphere.faces[:40]].mean(axis=1)
    assert np.min(np.linalg.norm(centroids - np.asarray(gates["coincidentCoverage"].where), axis=1)) < 1e-12
    assert topology.duplicate_faces(_with_faces(sphere, np.concatenate([sphere.faces, extra]))).shape == (
        40,
        2,
    )


def _tetrahedron(offset: F64 | None = None) -> tuple[F64, npt.NDArray[np.int32]]:
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int32)
    return (v if offset is None else v + offset), f


def test_coplanar_overlap_is_coincident_not_duplicate() -> None:
    """A closed tetrahedron with a loose sheet lying inside its z = 0 face: coplanar overlap with no
    shared vertex index, so only the exact coplanar test can see it."""
    v, f = _tetrahedron()
    sheet = np.array([[0.1, 0.1, 0.0], [0.6, 0.1, 0.0], [0.1, 0.6, 0.0]])
    mesh = Mesh(np.concatenate([v, sheet]), np.concatenate([f, [[4, 5, 6]]]).astype(np.int32))
    report = intersect.self_intersections(mesh)
    assert report.coincident == report.intersecting == 1
    assert report.coincident_pairs.tolist() == [[0, 4]]
    assert topology.duplicate_faces(mesh).shape[0] == 0

    def dist(p: F64) -> F64:
        return sphere_distance(p, (0.25, 0.25, 0.25), 0.3)

    def grad(p: F64) -> F64:
        return sphere_gradient(p, (0.25, 0.25, 0.25))

    assert "coincidentCoverage" in _failed(_gates(mesh, dist, grad))


def test_tilted_coplanar_half_face_is_coincident() -> None:
    """Same on a tilted face with non-representable coordinates: the sheet is half of face (a, b, c),
    (a', b', m) with m the float midpoint of a and c, which happens to be exact."""
    a, b, c = np.array([0.2, 0.1, 0.9]), np.array([0.9, 0.9, 0.5]), np.array([0.3, 0.0, 0.6])
    m = 0.5 * (a + c)
    assert [Fraction(float(x)) for x in m] == [
        (Fraction(p) + Fraction(q)) / 2 for p, q in zip(a, c, strict=True)
    ]
    apex = (a + b + c) / 3 + 0.4 * np.cross(b - a, c - a)
    verts = np.array([a, b, c, apex, a, b, m])
    faces = np.array([[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0], [4, 5, 6]], dtype=np.int32)
    report = intersect.self_intersections(Mesh(verts, faces))
    assert report.coincident == 1
    assert report.coincident_pairs.tolist() == [[0, 4]]
    assert report.intersecting == 4  # plus the three faces meeting the sheet's copies of a and b


def test_hole_fails_watertight(sphere: Mesh) -> None:
    gates = _gates(_with_faces(sphere, np.delete(sphere.faces, 5, axis=0)))
    assert gates["watertight"].value == 3
    hole = sphere.vertices[sphere.faces[5]]
    where = np.asarray(gates["watertight"].where)
    assert min(np.linalg.norm(where - 0.5 * (hole[i] + hole[(i + 1) % 3])) for i in range(3)) < 1e-12
    assert {"watertight", "euler"} <= _failed(gates)
    assert "edgeManifold" not in _failed(gates)


def test_degenerate_triangle(sphere: Mesh) -> None:
    v = sphere.vertices.copy()
    a, b, c = sphere.faces[100]
    v[c] = 0.5 * (v[a] + v[b])  # collinear to rounding: area ~1e-20, far below 1e-12·L²
    gates = _gates(Mesh(v, sphere.faces))
    assert "degenerate" in _failed(gates)
    assert gates["degenerate"].value >= 1
    repeated = _with_faces(sphere, np.concatenate([sphere.faces, [[0, 0, 1]]]))
    assert topology.degenerate_faces(repeated, 1e-30)[-1]


def _split_near_edge(mesh: Mesh, faces: npt.NDArray[np.int64], t: float) -> Mesh:
    """1-to-3 split of the given faces at a point t of the way from edge (a, b) to c: stays closed and
    manifold, but (a, b, p) becomes a sliver for small t."""
    f = mesh.faces.astype(np.int64)
    c = mesh.corners()[faces]
    mid = 0.5 * (c[:, 0] + c[:, 1])
    p = mid + t * (c[:, 2] - mid)
    ids = mesh.vertex_count + np.arange(faces.size)
    a, b, cc = f[faces, 0], f[faces, 1], f[faces, 2]
    new = np.concatenate([np.stack([a, b, ids], 1), np.stack([b, cc, ids], 1), np.stack([cc, a, ids], 1)])
    keep = np.delete(f, faces, axis=0)
    return Mesh(np.concatenate([mesh.vertices, p]), np.concatenate([keep, new]).astype(np.int32))


def test_slivers_fail_min_angle(sphere: Mesh) -> None:
    rng = np.random.default_rng(3)
    chosen = rng.choice(sphere.face_count, sphere.face_count // 20, replace=False)
    mesh = _split_near_edge(sphere, chosen, 1e-3)
    gates = _gates(mesh)
    assert _failed(gates) == {"minAngleP1"}, {n: gates[n].as_dict() for n in _failed(gates)}
    assert gates["minAngleP1"].value < 0.5


def test_second_component_fails_components_only() -> None:
    a = _extract(sphere_distance, 36)
    shift = np.array([1.0, 0.0, 0.0])
    both = Mesh(
        np.concatenate([a.vertices, a.vertices + shift]),
        np.concatenate([a.faces, a.faces + a.vertex_count]).astype(np.int32),
    )

    def dist(p: F64) -> F64:
        return np.minimum(sphere_distance(p), sphere_distance(p, (1.0, 0.0, 0.0)))

    def grad(p: F64) -> F64:
        first = sphere_distance(p) <= sphere_distance(p, (1.0, 0.0, 0.0))
        return np.where(first[:, None], sphere_gradient(p), sphere_gradient(p, (1.0, 0.0, 0.0)))

    gates = _gates(both, dist, grad)
    assert _failed(gates) == {"components"}
    assert _gates(both, dist, grad, components=2)["components"].passed


def test_pinched_vertex_fails_vertex_manifold() -> None:
    v1, f1 = _tetrahedron()
    v2, f2 = _tetrahedron()
    v2 = -v2[1:]  # mirrored, sharing the apex at the origin
    verts = np.concatenate([v1, v2])
    remap = np.array([0, 4, 5, 6])
    faces = np.concatenate([f1, remap[f2][:, ::-1]]).astype(np.int32)
    mesh = Mesh(verts, faces)
    assert topology.nonmanifold_vertices(mesh).tolist() == [0]
    assert topology.edge_report(mesh).watertight
    assert intersect.self_intersections(mesh).intersecting == 0


def _torus_distance(p: F64, big: float = 0.3, small: float = 0.15) -> F64:
    q = np.hypot(p[:, 0], p[:, 1]) - big
    result: F64 = np.hypot(q, p[:, 2]) - small
    return result


def _torus_gradient(p: F64, big: float = 0.3) -> F64:
    rho = np.hypot(p[:, 0], p[:, 1])
    q = rho - big
    n = np.hypot(q, p[:, 2])
    g = np.stack([q * p[:, 0] / rho, q * p[:, 1] / rho, p[:, 2]], axis=1)
    result: F64 = g / n[:, None]
    return result


def test_torus_fails_euler() -> None:
    """Raw marching cubes on a thin torus has a sliver tail below 1° and area-weighted vertex normals
    near the 5° p99 bound, so only the non-quality gates are pinned here."""
    torus = _extract(_torus_distance, 64)
    gates = _gates(torus, _torus_distance, _torus_gradient)
    quality = {"minAngleP1", *(n for n in gates if "NormalAngle" in n)}
    assert _failed(gates) - quality == {"euler"}, {n: gates[n].as_dict() for n in _failed(gates)}
    assert gates["euler"].value == 1
    comps = topology.components(torus)
    assert comps.euler.tolist() == [0]
    assert comps.genus.tolist() == [1.0]


def test_displaced_mesh_fails_both_distances(sphere: Mesh) -> None:
    gates = _gates(Mesh(sphere.vertices * 1.02, sphere.faces))
    assert {"surfaceToZeroSet", "zeroSetToMesh"} <= _failed(gates)
    assert gates["surfaceToZeroSet"].value == pytest.approx(0.02 * R / L, rel=0.05)


def test_missing_lobe_fails_zero_set_to_mesh_only(sphere: Mesh) -> None:
    """The field has a second blob the mesh lacks: every mesh point is on the zero set, but not every
    zero-set point is near the mesh."""
    blob = (0.3, 0.3, 0.3)  # in a corner of the mesh's box, 0.07 clear of the sphere

    def dist(p: F64) -> F64:
        return np.minimum(sphere_distance(p), sphere_distance(p, blob, 0.08))

    def grad(p: F64) -> F64:
        first = sphere_distance(p) <= sphere_distance(p, blob, 0.08)
        return np.where(first[:, None], sphere_gradient(p), sphere_gradient(p, blob))

    gates = _gates(sphere, dist, grad)
    assert _failed(gates) == {"zeroSetToMesh"}


def test_bumpy_mesh_fails_normal_angles(sphere: Mesh) -> None:
    """Alternate vertices pushed ±0.002·L along the normal: still within the distance tolerance, but
    the facets tilt well past the normal-angle bounds."""
    n = sphere_gradient(sphere.vertices)
    sign = np.where(np.arange(sphere.vertex_count) % 2 == 0, 1.0, -1.0)
    mesh = Mesh(sphere.vertices + (0.002 * L * sign)[:, None] * n, sphere.faces)
    failed = _failed(_gates(mesh))
    assert {"vertexNormalAngleMax", "faceNormalAngleMax"} <= failed
    assert not {"surfaceToZeroSet", "zeroSetToMesh", "inverted"} & failed


def test_a_fused_field_changes_no_gate(sphere: Mesh) -> None:
    """``field`` (distance and gradient in one pass, as BodyField.field) only saves evaluations."""

    def field(p: F64) -> tuple[F64, F64]:
        return sphere_distance(p), sphere_gradient(p)

    plain = mesh_gates(sphere, length_scale=L, distance=sphere_distance, gradient=sphere_gradient)
    fused = mesh_gates(
        sphere, length_scale=L, distance=sphere_distance, gradient=sphere_gradient, field=field
    )
    assert [(g.as_dict(), g.where) for g in fused] == [(g.as_dict(), g.where) for g in plain]


@pytest.mark.parametrize("bumpy", [False, True])
def test_the_normal_gates_alone_equal_a_full_pass(sphere: Mesh, bumpy: bool) -> None:
    """``normal_gates`` lets a remedy be turned down before a full pass (remedies._judged): its four gates
    must be the full pass's, value for value and place for place, failing or not."""

    def field(p: F64) -> tuple[F64, F64]:
        return sphere_distance(p), sphere_gradient(p)

    mesh = sphere
    if bumpy:
        sign = np.where(np.arange(sphere.vertex_count) % 2 == 0, 1.0, -1.0)
        mesh = Mesh(
            sphere.vertices + (0.002 * L * sign)[:, None] * sphere_gradient(sphere.vertices), sphere.faces
        )
    limits = (15.0, 5.0, 30.0, 10.0)
    full = mesh_gates(
        mesh,
        length_scale=L,
        distance=sphere_distance,
        gradient=sphere_gradient,
        field=field,
        vertex_normal_max_deg=limits[0],
        vertex_normal_p99_deg=limits[1],
        face_normal_max_deg=limits[2],
        face_normal_p99_deg=limits[3],
    )
    alone = normal_gates(mesh, length_scale=L, field=field, normal_limits=limits)
    assert [g.name for g in alone] == [
        "vertexNormalAngleMax",
        "vertexNormalAngleP99",
        "faceNormalAngleMax",
        "faceNormalAngleP99",
    ]
    by_name = {g.name: g for g in full}
    assert [(g.as_dict(), g.where) for g in alone] == [
        (by_name[g.name].as_dict(), by_name[g.name].where) for g in alone
    ]
    assert any(not g.passed for g in alone) == bumpy


# ------------------------------------------------------------------------------- exact predicates


def _fr(p: npt.ArrayLike) -> list[Fraction]:
    return [Fraction(float(x)) for x in np.asarray(p)]


def _sub(a: list[Fraction], b: list[Fraction]) -> list[Fraction]:
    return [x - y for x, y in zip(a, b, strict=True)]


def _dot(a: list[Fraction], b: list[Fraction]) -> Fraction:
    return sum((x * y for x, y in zip(a, b, strict=True)), Fraction(0))


def _cross(a: list[Fraction], b: list[Fraction]) -> list[Fraction]:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _section(t: list[list[Fraction]], n: list[Fraction], n0: Fraction) -> list[list[Fraction]] | None:
    """Points of triangle t on the plane n·x = n0: its vertices on it and its edges' crossings."""
    s = [_dot(n, v) - n0 for v in t]
    if all(x > 0 for x in s) or all(x < 0 for x in s):
        return None
    pts = [v for v, x in zip(t, s, strict=True) if x == 0]
    for i in range(3):
        j = (i + 1) % 3
        if s[i] * s[j] < 0:
            k = s[i] / (s[i] - s[j])
            pts.append([a + k * (b - a) for a, b in zip(t[i], t[j], strict=True)])
    return pts


def reference_intersect(t1: F64, t2: F64) -> tuple[bool, bool]:
    """Möller's interval test in exact rationals (coplanar: separating axes). Returns (hit, coplanar)."""
    a = [_fr(v) for v in t1]
    b = [_fr(v) for v in t2]
    n1 = _cross(_sub(a[1], a[0]), _sub(a[2], a[0]))
    n2 = _cross(_sub(b[1], b[0]), _sub(b[2], b[0]))
    s2 = [_dot(n1, _sub(v, a[0])) for v in b]
    if all(x == 0 for x in s2):
        for tri in (a, b):
            for i in range(3):
                axis = _cross(n1, _sub(tri[(i + 1) % 3], tri[i]))
                pa = [_dot(axis, v) for v in a]
                pb = [_dot(axis, v) for v in b]
                if max(pa) < min(pb) or max(pb) < min(pa):
                    return False, True
        return True, True
    sec1 = _section(a, n2, _dot(n2, b[0]))
    sec2 = _section(b, n1, _dot(n1, a[0]))
    if sec1 is None or sec2 is None:
        return False, False
    d = _cross(n1, n2)
    p1 = [_dot(d, p) for p in sec1]
    p2 = [_dot(d, p) for p in sec2]
    return max(min(p1), min(p2)) <= min(max(p1), max(p2)), False


def _collinear(t: F64) -> bool:
    a = [_fr(v) for v in t]
    return all(x == 0 for x in _cross(_sub(a[1], a[0]), _sub(a[2], a[0])))


@pytest.mark.parametrize("scale", [1.0, 0.1, 1.0 / 3.0])
def test_triangle_pairs_match_exact_reference(scale: float) -> None:
    """Small-integer lattices (scaled by non-representable factors) are full of coplanar, touching and
    collinear-edge cases, which is exactly where a float-only test goes wrong."""
    rng = np.random.default_rng(int(scale * 1000))
    t1 = rng.integers(0, 4, size=(1600, 3, 3)).astype(np.float64) * scale
    t2 = rng.integers(0, 4, size=(1600, 3, 3)).astype(np.float64) * scale
    t2[::3, 2, 2] = t2[::3, 2, 2] + 1e-17  # a sprinkle of off-lattice values near the lattice
    keep = np.array([not _collinear(a) and not _collinear(b) for a, b in zip(t1, t2, strict=True)])
    t1, t2 = t1[keep][:1200], t2[keep][:1200]
    verdict = intersect.triangle_pairs(t1, t2)
    expected = [reference_intersect(a, b) for a, b in zip(t1, t2, strict=True)]
    hit = np.array([e[0] for e in expected])
    coplanar = np.array([e[1] for e in expected])
    assert hit.any()
    assert (~hit).any()
    assert (hit & coplanar).any()
    np.testing.assert_array_equal(verdict.hit, hit)
    np.testing.assert_array_equal(verdict.coplanar, coplanar)


def _naive_orient2d(a: F64, b: F64, c: F64) -> int:
    return int(np.sign((a[0] - c[0]) * (b[1] - c[1]) - (a[1] - c[1]) * (b[0] - c[0])))


def test_orient2d_is_exact_where_float_is_wrong() -> None:
    """Shewchuk's classic: points within a few ulps of the line y = x through (12, 12) and (24, 24)."""
    ulp = np.spacing(0.5)
    i, j = np.meshgrid(np.arange(64), np.arange(64), indexing="ij")
    a = np.stack([0.5 + i.reshape(-1) * ulp, 0.5 + j.reshape(-1) * ulp], axis=1)
    b = np.broadcast_to([12.0, 12.0], a.shape).copy()
    c = np.broadcast_to([24.0, 24.0], a.shape).copy()
    signs, exact = intersect.orient2d_filtered(a, b, c)
    truth = []
    for p in a:
        pa, pb, pc = _fr(p), _fr([12.0, 12.0]), _fr([24.0, 24.0])
        det = (pa[0] - pc[0]) * (pb[1] - pc[1]) - (pa[1] - pc[1]) * (pb[0] - pc[0])
        truth.append((det > 0) - (det < 0))
    np.testing.assert_array_equal(signs, truth)
    naive = [_naive_orient2d(p, b[0], c[0]) for p in a]
    assert naive != truth  # the float expression gets some of these wrong
    assert exact > 0


def test_orient3d_is_exact_on_near_coplanar_points() -> None:
    rng = np.random.default_rng(7)
    a, b, c = (np.round(rng.uniform(0, 1, (5000, 3)), 1) for _ in range(3))
    s, t = rng.uniform(0, 1, (2, 5000, 1))
    d = a + s * (b - a) + t * (c - a)  # on the plane up to rounding of the combination
    d = d + rng.integers(-2, 3, d.shape) * np.spacing(d)
    signs, exact = intersect.orient3d_filtered(a, b, c, d)
    truth = []
    for row in zip(a, b, c, d, strict=True):
        fa, fb, fc, fd = (_fr(x) for x in row)
        det = _dot(_sub(fa, fd), _cross(_sub(fb, fd), _sub(fc, fd)))
        truth.append((det > 0) - (det < 0))
    np.testing.assert_array_equal(signs, truth)
    assert exact > 0
    assert 0 in truth


def test_point_contact_decided_exactly() -> None:
    """T2's apex sits exactly on T1's edge at a point with non-representable coordinates (0.25, 0.05,
    0.75 is the float midpoint of (0.2, 0.1, 0.9) and (0.3, 0, 0.6), and happens to be exact), where
    the float orientation is wrong. One ulp toward T2's side separates them; the verdicts follow the
    exact reference in every case."""
    t1 = np.array([[0.2, 0.1, 0.9], [0.9, 0.9, 0.5], [0.3, 0.0, 0.6]])
    m = 0.5 * (t1[0] + t1[2])
    assert [Fraction(float(x)) for x in m] == [
        (Fraction(p) + Fraction(q)) / 2 for p, q in zip(t1[0], t1[2], strict=True)
    ]
    normal = np.cross(t1[1] - t1[0], t1[2] - t1[0])
    # Float says "off the plane" in some evaluation orders; exactly it is on it. Which order a float dot
    # takes depends on the BLAS kernel of the CPU (np.dot said off-plane on the machine this test was
    # written on, on the plane on an AMD EPYC), so the orders are written out in Python floats here.
    v = m - t1[0]
    orders = [sum(float(normal[i]) * float(v[i]) for i in order) for order in ((0, 1, 2), (2, 1, 0))]
    assert any(naive != 0.0 for naive in orders), orders
    up = normal / np.linalg.norm(normal)
    side = np.array([1.0, 0.0, 0.0]) - up * up[0]

    def touching(apex: F64) -> F64:
        return np.array([apex, apex + 0.3 * up + 0.1 * side, apex + 0.3 * up - 0.1 * side])

    k = int(np.argmax(np.abs(normal)))
    nudged_up = m.copy()
    nudged_up[k] = np.nextafter(m[k], np.inf * np.sign(normal[k]))
    nudged_down = m.copy()
    nudged_down[k] = np.nextafter(m[k], -np.inf * np.sign(normal[k]))
    cases = np.stack([touching(m), touching(nudged_up), touching(nudged_down)])
    verdict = intersect.triangle_pairs(np.repeat(t1[None], 3, axis=0), cases)
    expected = [reference_intersect(t1, t2)[0] for t2 in cases]
    assert expected[:2] == [True, False]
    assert verdict.hit.tolist() == expected
    assert verdict.exact_evaluations > 0
    # The same contact as a two-face mesh: the gate counts it.
    mesh = Mesh(np.concatenate([t1, touching(m)]), np.array([[0, 1, 2], [3, 4, 5]], dtype=np.int32))
    assert intersect.self_intersections(mesh).intersecting == 1


# --------------------------------------------------------------------------------- BVH and distances


def _soup(n: int, seed: int) -> Mesh:
    rng = np.random.default_rng(seed)
    centres = rng.uniform(0, 1, (n, 1, 3))
    corners = centres + rng.normal(0, 0.03, (n, 3, 3))
    verts = corners.reshape(-1, 3)
    faces = np.arange(3 * n, dtype=np.int32).reshape(n, 3)
    faces[1::7, 0] = faces[::7, 0][: faces[1::7].shape[0]]  # some shared vertex indices
    return Mesh(verts, faces)


def test_bvh_candidates_equal_brute_force() -> None:
    mesh = _soup(700, 1)
    tree = intersect.triangle_bvh(mesh, leaf_size=4)
    got = set()
    for i, j in intersect.candidate_pairs(tree, mesh.faces):
        got |= {(min(a, b), max(a, b)) for a, b in zip(i.tolist(), j.tolist(), strict=True)}
    c = mesh.corners()
    lo, hi = c.min(axis=1), c.max(axis=1)
    overlap = np.all((lo[:, None] <= hi[None]) & (lo[None] <= hi[:, None]), axis=2)
    shares = np.any(mesh.faces[:, None, :, None] == mesh.faces[None, :, None, :], axis=(2, 3))
    ii, jj = np.nonzero(np.triu(overlap & ~shares, k=1))
    assert got == set(zip(ii.tolist(), jj.tolist(), strict=True))
    assert len(got) > 100


def test_self_intersections_equal_brute_force_narrow_phase() -> None:
    mesh = _soup(400, 2)
    report = intersect.self_intersections(mesh, max_pairs=10_000)
    c = mesh.corners()
    n = mesh.face_count
    ii, jj = np.triu_indices(n, k=1)
    shares = np.any(mesh.faces[ii][:, :, None] == mesh.faces[jj][:, None, :], axis=(1, 2))
    ii, jj = ii[~shares], jj[~shares]
    brute = intersect.triangle_pairs(c[ii], c[jj])
    expected = {(int(a), int(b)) for a, b in zip(ii[brute.hit], jj[brute.hit], strict=True)}
    assert {tuple(p) for p in report.pairs.tolist()} == expected
    assert report.intersecting == len(expected) > 0


def test_distances_to_mesh_equal_brute_force(sphere: Mesh) -> None:
    rng = np.random.default_rng(5)
    points = rng.uniform(-0.5, 0.5, (100, 3))
    corners = sphere.corners()
    got = zero_set_to_mesh(sphere, intersect.triangle_bvh(sphere), points)
    brute = np.array(
        [
            intersect.point_triangle_distance(np.repeat(p[None], sphere.face_count, 0), corners).min()
            for p in points
        ]
    )
    np.testing.assert_allclose(got, brute, rtol=0, atol=1e-15)
    np.testing.assert_allclose(got, np.abs(np.linalg.norm(points, axis=1) - R), atol=0.003)


def test_point_triangle_distance_regions() -> None:
    tri = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]] * 4)
    pts = np.array([[0.2, 0.2, 0.5], [-1.0, -1.0, 0.0], [0.5, -2.0, 0.0], [1.0, 1.0, 0.0]])
    np.testing.assert_allclose(
        intersect.point_triangle_distance(pts, tri), [0.5, np.sqrt(2.0), 2.0, np.sqrt(0.5)], rtol=1e-15
    )
