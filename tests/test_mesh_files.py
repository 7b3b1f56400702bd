"""Issue 30: mb.Mesh reads STL, OBJ and PLY files (written here by trimesh, and a hand-written OBJ of quads
in mm) into the same closed triangle mesh: corners, faces, volume and mass properties of the solid.
Contact with these meshes: tests/test_shape_contact_plane.py (the box on an incline as each file)."""
import numpy as np
import pytest

import mbdsim as mb

A = 0.1
CORNERS = 0.5 * A * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)


def _sorted(v):
    return np.asarray(v)[np.lexsort(np.asarray(v).T)]


@pytest.mark.parametrize("ext", ["stl", "obj", "ply", "ascii.ply"])
def test_mesh_file_reads_the_cube_trimesh_wrote(ext, tmp_path):
    import trimesh
    path = tmp_path / f"cube.{ext}"
    cube = trimesh.creation.box((A, A, A))
    if ext == "ascii.ply":
        cube.export(path, file_type="ply", encoding="ascii")
    else:
        cube.export(path)
    mesh = mb.Mesh(path)
    assert len(mesh.vertices) == 8 and len(mesh.faces) == 12
    assert np.allclose(_sorted(mesh.vertices), _sorted(CORNERS), atol=1e-7)
    mass, c, I = mesh.mass_properties(1000.0)
    m_ref = 1000.0 * A ** 3
    assert mass == pytest.approx(m_ref, rel=1e-6) and np.allclose(c, 0, atol=1e-9)
    assert np.allclose(I, m_ref * A * A / 6 * np.eye(3), rtol=1e-5, atol=1e-12)
    assert repr(mesh) == f"Mesh({path}, 8 vertices, 12 faces)"


def test_obj_of_quads_in_mm_is_triangulated_and_scaled(tmp_path):
    """An OBJ as CAD tools write it: quad faces (1-based indices) in mm; scale=1e-3 gives metres."""
    path = tmp_path / "cube_mm.obj"
    s = 1e3 * A
    verts = [(x, y, z) for x in (0, s) for y in (0, s) for z in (0, s)]
    idx = {v: k + 1 for k, v in enumerate(verts)}
    quads = [[(0, 0, 0), (0, s, 0), (s, s, 0), (s, 0, 0)], [(0, 0, s), (s, 0, s), (s, s, s), (0, s, s)],
             [(0, 0, 0), (s, 0, 0), (s, 0, s), (0, 0, s)], [(0, s, 0), (0, s, s), (s, s, s), (s, s, 0)],
             [(0, 0, 0), (0, 0, s), (0, s, s), (0, s, 0)], [(s, 0, 0), (s, s, 0), (s, s, s), (s, 0, s)]]
    lines = ["o cube"] + [f"v {x:g} {y:g} {z:g}" for x, y, z in verts] + \
        ["f " + " ".join(str(idx[p]) for p in q) for q in quads]
    path.write_text("\n".join(lines) + "\n")
    mesh = mb.Mesh(path, scale=1e-3)
    assert len(mesh.faces) == 12 and mesh.vertices.max() == pytest.approx(A) and mesh.vertices.min() == 0.0
    mass, c, _ = mesh.mass_properties(1000.0)
    assert mass == pytest.approx(1000.0 * A ** 3, rel=1e-9) and np.allclose(c, A / 2)


def test_mesh_file_errors_name_the_file(tmp_path):
    path = tmp_path / "points.ply"
    import trimesh
    trimesh.PointCloud(CORNERS).export(path)
    with pytest.raises(mb.ModelError, match=r"mesh '.*points\.ply'.*no triangle mesh"):
        mb.Mesh(path)
    with pytest.raises(mb.ModelError, match=r"mesh '.*absent\.obj'.*no such file"):
        mb.Mesh(tmp_path / "absent.obj")
