"""`make_designs.py --selftest`: the mass-property integration, the orientation repair, OpenCASCADE's
conventions and the STL writer against closed forms."""

from __future__ import annotations

import math
import pathlib
import tempfile

import gmsh
import numpy as np

from .definitions import DENSITY, MESH_OPTIONS
from .export import read_stl, stl_bytes
from .mass import mesh_mass_properties
from .solid import gmsh_start, occ_prism, occ_properties
from .surface import edge_pairs, orient_outward, pin_axes_clear, signed_volume, surface_triangles, validate_mesh


def box_mesh(lo, hi):
    """Closed, outward-oriented 12-triangle box."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    v = np.array([[lo[0] if i & 1 == 0 else hi[0], lo[1] if i & 2 == 0 else hi[1],
                   lo[2] if i & 4 == 0 else hi[2]] for i in range(8)])
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    t = np.array([tri for a, b, c, e in quads for tri in ((a, b, c), (a, c, e))])
    return v, t


def box_analytic(lo, hi, density):
    size = np.asarray(hi, float) - np.asarray(lo, float)
    vol = np.prod(size)
    m = vol * density * 1e-9
    ixx = m * (size[1] ** 2 + size[2] ** 2) / 12 * 1e-6
    iyy = m * (size[0] ** 2 + size[2] ** 2) / 12 * 1e-6
    izz = m * (size[0] ** 2 + size[1] ** 2) / 12 * 1e-6
    return vol, m, 0.5 * (np.asarray(lo, float) + np.asarray(hi, float)), np.diag([ixx, iyy, izz])


def selftest() -> int:
    failures = []

    def expect(cond, what):
        print(f"  {'ok  ' if cond else 'FAIL'} {what}")
        if not cond:
            failures.append(what)

    # 1. Polyhedral integration against an analytic box, near and far from the origin.
    for lo in ([-10.0, -20.0, -30.0], [1.0e5, -2.0e5, 3.0e5]):
        hi = np.asarray(lo) + [20.0, 40.0, 60.0]
        v, t = box_mesh(lo, hi)
        p = mesh_mass_properties(v, t)
        vol, m, c, inertia = box_analytic(lo, hi, DENSITY)
        expect(abs(p["volume"] / vol - 1) < 1e-12 and abs(p["mass"] / m - 1) < 1e-12,
               f"box at {lo}: volume {p['volume']:.6f} mm^3 (analytic {vol:.6f})")
        expect(np.allclose(p["centroid"], c, rtol=0, atol=1e-9), f"box at {lo}: centroid")
        expect(np.allclose(p["inertia"], inertia, rtol=1e-10, atol=1e-16), f"box at {lo}: inertia tensor")
    # Rotated box: the full tensor (off-diagonal terms) transforms as R I R^T.
    ang = 0.3
    rot = np.array([[math.cos(ang), -math.sin(ang), 0], [math.sin(ang), math.cos(ang), 0], [0, 0, 1]])
    v, t = box_mesh([0, 0, 0], [20, 40, 60])
    p = mesh_mass_properties(v @ rot.T, t)
    _, _, _, inertia = box_analytic([0, 0, 0], [20, 40, 60], DENSITY)
    expect(np.allclose(p["inertia"], rot @ inertia @ rot.T, rtol=1e-10, atol=1e-16),
           "rotated box: off-diagonal inertia terms")

    # 2. Orientation repair: a box with randomly flipped triangles and inverted overall.
    rng = np.random.default_rng(1)
    v, t = box_mesh([0, 0, 0], [1, 2, 3])
    bad = t.copy()
    flip = rng.random(len(t)) < 0.5
    bad[flip] = bad[flip][:, ::-1]
    fixed = orient_outward(bad, v)
    expect(signed_volume(v, fixed) > 0 and not np.any(edge_pairs(fixed)[2]), "orientation repair")
    try:
        validate_mesh(v, bad, "flipped box")
        expect(False, "validation rejects inconsistent winding")
    except ValueError:
        expect(True, "validation rejects inconsistent winding")
    try:
        validate_mesh(v, t[:-1], "open box")
        expect(False, "validation rejects an open mesh")
    except ValueError:
        expect(True, "validation rejects an open mesh")

    # 3. OpenCASCADE conventions: getMatrixOfInertia is about the centre of mass, for unit density.
    gmsh_start()
    gmsh.clear()
    box = gmsh.model.occ.addBox(10, 20, 30, 2, 4, 6)
    gmsh.model.occ.synchronize()
    occ = gmsh.model.occ
    inertia = np.array(occ.getMatrixOfInertia(3, box)).reshape(3, 3)
    expect(abs(occ.getMass(3, box) - 48.0) < 1e-9 and np.allclose(occ.getCenterOfMass(3, box), [11, 22, 33]),
           "OCC box volume and centre of mass")
    expect(np.allclose(inertia, np.diag([48 * (16 + 36) / 12, 48 * (4 + 36) / 12, 48 * (4 + 16) / 12])),
           "OCC getMatrixOfInertia is about the centre of mass (unit density)")

    # 4. STL write/read round trip of a tessellated cylinder, compared with the exact B-rep.
    gmsh.clear()
    cyl = occ.addCylinder(0, 0, -20, 0, 0, 40, 45.0)
    out, _ = occ.cut([(3, cyl)], [(3, occ.addCylinder(0, 0, -40, 0, 0, 80, 25.0))])
    occ.synchronize()
    exact = occ_properties(out[0][1])
    verts, tris = surface_triangles()
    tris = orient_outward(tris, verts)
    validate_mesh(verts, tris, "ring")
    with tempfile.TemporaryDirectory() as tmp:
        path = pathlib.Path(tmp) / "ring.stl"
        path.write_bytes(stl_bytes(verts, tris, "rodstudy selftest ring"))
        v2, t2 = read_stl(path)
        expect(path.stat().st_size == 84 + 50 * len(tris) and not path.read_bytes().startswith(b"solid"),
               "binary STL size and header")
    p = mesh_mass_properties(v2, t2)
    # A ring has no concave/convex cancellation: its section is exact * sin(t)/t for chords of angle
    # t = 2 pi / N (both circles inscribed), so the tessellation loses about t^2/6 of the mass.
    theta = 2 * math.pi / MESH_OPTIONS["Mesh.MeshSizeFromCurvature"]
    rel = p["mass"] / exact["mass"] - 1
    expect(-1.05 * theta**2 / 6 <= rel <= 0,
           f"tessellated ring mass vs exact {rel:+.2e} (inscribed-polygon bound {-theta**2 / 6:+.2e})")
    expect(abs(p["ixx"] / exact["ixx"] - 1) < 1e-3 and abs(p["izz"] / exact["izz"] - 1) < 1e-3,
           "tessellated ring inertia vs exact")
    expect(pin_axes_clear(v2, t2, [(0.0, 0.0)]) == [] and pin_axes_clear(v2, t2, [(35.0, 0.0)]) != [],
           "pin-axis ray test (clear in the bore, hits in the wall)")

    # 5. A polyhedral (faceted, hence exactly tessellated) OCC solid: mesh integration == OCC.
    gmsh.clear()
    body = occ.addBox(-40, -15, -10, 90, 30, 20)
    wedge = occ_prism([(20, -20), (60, -20), (60, 5)], -20, 40)
    notch = occ.addBox(-50, 5, 0, 30, 20, 20)
    out, _ = occ.cut([(3, body)], [(3, wedge), (3, notch)])
    occ.rotate(out, 0, 0, 0, 1, 2, 3, 0.7)
    occ.translate(out, 180, -30, 12)
    occ.synchronize()
    exact = occ_properties(out[0][1])
    verts, tris = surface_triangles()
    tris = orient_outward(tris, verts)
    validate_mesh(verts, tris, "polyhedron")
    p = mesh_mass_properties(verts, tris)
    expect(abs(p["mass"] / exact["mass"] - 1) < 1e-6
           and np.allclose(p["centroid"], exact["centroid"], rtol=0, atol=1e-5)
           and np.allclose(p["inertia"], exact["inertia"], rtol=0, atol=1e-6 * np.abs(exact["inertia"]).max()),
           "rotated polyhedron: mesh integration (float32 vertices) matches OCC's exact tensor")
    print("selftest " + ("passed" if not failures else f"FAILED ({len(failures)})"))
    return 0 if not failures else 1
