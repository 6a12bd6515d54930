"""CalculiX decks exactly as FreeCAD's FEM workbench writes them, for `rodstudy solve`'s tests.

  FREECAD_DECKS_OUT=DIR [FREECAD_DECKS_GMSH=GMSH] freecadcmd pipeline/freecad_decks.py

Run by FreeCAD's own interpreter (Debian `freecad`, 0.20; `freecadcmd` runs it headless; its
arguments cannot reach the script, hence the environment). Builds a small connecting-rod-like
solid (a 100 x 20 x 10 mm bar with a 12 mm bore through its thickness near one end), meshes it
with gmsh through FreeCAD's `femmesh.gmshtools` (FreeCAD's own mesher settings: first or second
order), sets up the analyses a FreeCAD user sets up on a rod, and writes each deck with FreeCAD's
CalculiX writer (`femtools.ccxtools.FemToolsCcx.write_inp_file`, the writer of the "Write .inp
file" button), unedited:

  static_force_tet10     the end face x = 0 fixed, a force on the far end face (-z);
  static_pressure_tet10  fixed end, pressure on the top face and self-weight;
  static_bore_tet10      the bore held radially and axially in a cylindrical constraint
                         (*TRANSFORM, TYPE=C), the end x = 0 fixed, a force on the far end face;
  static_force_tet4      static_force on a first-order mesh (C3D4);
  buckle_tet10           fixed end, a compressive force on the far end face, 2 buckling factors;
  frequency_tet10        fixed end, the 4 lowest natural frequencies.

Units: FreeCAD writes mm, N, MPa (t/mm^3 for density). FREECAD_DECKS_GMSH names the gmsh
binary when `gmsh` on the PATH is not one (e.g. a wrapper around the project's .venv gmsh).
"""

import os
import shutil
import sys
import tempfile

import FreeCAD
import ObjectsFem
import Part  # noqa: F401  (registers Part::Box, Part::Cylinder, Part::Cut)
from femmesh.gmshtools import GmshTools
from femtools import ccxtools

OUT = os.environ.get("FREECAD_DECKS_OUT", "freecad_decks")
GMSH = os.environ.get("FREECAD_DECKS_GMSH", "")
LENGTH, WIDTH, HEIGHT = 100.0, 20.0, 10.0
BORE_X, BORE_R = 85.0, 6.0
MESH_MAX = 10.0


def solid(doc):
    box = doc.addObject("Part::Box", "Bar")
    box.Length, box.Width, box.Height = LENGTH, WIDTH, HEIGHT
    bore = doc.addObject("Part::Cylinder", "BoreCylinder")
    bore.Radius, bore.Height = BORE_R, HEIGHT
    bore.Placement.Base = FreeCAD.Vector(BORE_X, WIDTH / 2, 0)
    cut = doc.addObject("Part::Cut", "Rod")
    cut.Base, cut.Tool = box, bore
    doc.recompute()
    return cut


def face(shape_obj, test):
    """The name ("FaceN") of the one face whose centre of mass passes `test`."""
    hits = [
        "Face{}".format(i + 1)
        for i, f in enumerate(shape_obj.Shape.Faces)
        if test(f.CenterOfMass, f)
    ]
    if len(hits) != 1:
        raise RuntimeError("expected one face, found {}".format(hits))
    return hits[0]


def analysis_of(name, order, setup):
    doc = FreeCAD.newDocument(name)
    rod = solid(doc)
    analysis = ObjectsFem.makeAnalysis(doc, "Analysis")
    solver = ObjectsFem.makeSolverCalculixCcxTools(doc, "CalculiXccxTools")
    solver.GeometricalNonlinearity = "linear"
    solver.ThermoMechSteadyState = False
    solver.MatrixSolverType = "default"
    solver.IterationsControlParameterTimeUse = False
    solver.SplitInputWriter = False
    analysis.addObject(solver)
    material = ObjectsFem.makeMaterialSolid(doc, "MechanicalMaterial")
    mat = material.Material
    mat["Name"] = "Steel-Generic"
    mat["YoungsModulus"] = "210000 MPa"
    mat["PoissonRatio"] = "0.30"
    mat["Density"] = "7900 kg/m^3"
    material.Material = mat
    analysis.addObject(material)
    fixed = ObjectsFem.makeConstraintFixed(doc, "ConstraintFixed")
    fixed.References = [(rod, face(rod, lambda c, f: abs(c.x) < 1e-9))]
    analysis.addObject(fixed)
    far_end = face(rod, lambda c, f: abs(c.x - LENGTH) < 1e-9)
    setup(doc, analysis, solver, rod, far_end)
    mesh = ObjectsFem.makeMeshGmsh(doc, "FEMMeshGmsh")
    mesh.Part = rod
    mesh.CharacteristicLengthMax = MESH_MAX
    mesh.ElementOrder = order
    mesh.SecondOrderLinear = False
    analysis.addObject(mesh)
    doc.recompute()
    gmsh = GmshTools(mesh, analysis)
    if GMSH:
        gmsh.gmsh_bin = GMSH
    error = gmsh.create_mesh()
    if error:
        raise RuntimeError("gmsh: {}".format(error))
    doc.recompute()
    return doc, analysis, solver


def force(doc, analysis, rod, faces, newtons, direction_edge_test, reversed_):
    con = ObjectsFem.makeConstraintForce(doc, "ConstraintForce")
    con.References = [(rod, f) for f in faces]
    con.Force = newtons
    edges = [
        "Edge{}".format(i + 1)
        for i, e in enumerate(rod.Shape.Edges)
        if direction_edge_test(e)
    ]
    con.Direction = (rod, [edges[0]])
    con.Reversed = reversed_
    analysis.addObject(con)


def along(axis):
    """An edge test: a straight edge along the axis (0, 1, 2)."""

    def test(e):
        if not hasattr(e.Curve, "Direction") or e.Curve.TypeId != "Part::GeomLine":
            return False
        d = e.Curve.Direction
        return abs(abs((d.x, d.y, d.z)[axis]) - 1.0) < 1e-9

    return test


def static_force(doc, analysis, solver, rod, far_end):
    solver.AnalysisType = "static"
    force(doc, analysis, rod, [far_end], 500.0, along(2), True)


def static_pressure(doc, analysis, solver, rod, far_end):
    solver.AnalysisType = "static"
    con = ObjectsFem.makeConstraintPressure(doc, "ConstraintPressure")
    con.References = [(rod, face(rod, lambda c, f: abs(c.z - HEIGHT) < 1e-9))]
    con.Pressure = 2.0  # MPa
    con.Reversed = False
    analysis.addObject(con)
    weight = ObjectsFem.makeConstraintSelfWeight(doc, "ConstraintSelfWeight")
    weight.Gravity_x, weight.Gravity_y, weight.Gravity_z = 0.0, 0.0, -1.0
    analysis.addObject(weight)


def static_bore(doc, analysis, solver, rod, far_end):
    solver.AnalysisType = "static"
    bore = face(rod, lambda c, f: f.Surface.TypeId == "Part::GeomCylinder")
    transform = ObjectsFem.makeConstraintTransform(doc, "ConstraintTransform")
    transform.References = [(rod, bore)]
    transform.TransformType = "Cylindrical"
    analysis.addObject(transform)
    held = ObjectsFem.makeConstraintDisplacement(doc, "ConstraintDisplacement")
    held.References = [(rod, bore)]
    # in the cylinder's axes: radial (x) and axial (z) held, the tangential (y) free
    held.xFree, held.xFix, held.xDisplacement = False, True, 0.0
    held.yFree, held.yFix = True, False
    held.zFree, held.zFix, held.zDisplacement = False, True, 0.0
    analysis.addObject(held)
    force(doc, analysis, rod, [far_end], 500.0, along(1), False)


def buckle(doc, analysis, solver, rod, far_end):
    solver.AnalysisType = "buckling"
    solver.BucklingFactors = 2
    force(doc, analysis, rod, [far_end], 1000.0, along(0), True)


def frequency(doc, analysis, solver, rod, far_end):
    solver.AnalysisType = "frequency"
    solver.EigenmodesCount = 4
    solver.EigenmodeLowLimit = 0.0
    solver.EigenmodeHighLimit = 1000000.0


DECKS = [
    ("static_force_tet10", "2nd", static_force),
    ("static_pressure_tet10", "2nd", static_pressure),
    ("static_bore_tet10", "2nd", static_bore),
    ("static_force_tet4", "1st", static_force),
    ("buckle_tet10", "2nd", buckle),
    ("frequency_tet10", "2nd", frequency),
]


def main():
    os.makedirs(OUT, exist_ok=True)
    for name, order, setup in DECKS:
        doc, analysis, solver = analysis_of(name, order, setup)
        work = tempfile.mkdtemp(prefix="freecad_deck_")
        fea = ccxtools.FemToolsCcx(analysis, solver, test_mode=True)
        fea.update_objects()
        fea.setup_working_dir(work)
        message = fea.check_prerequisites()
        if message:
            raise RuntimeError("{}: {}".format(name, message))
        fea.write_inp_file()
        target = os.path.join(OUT, name + ".inp")
        shutil.copyfile(fea.inp_file_name, target)
        shutil.rmtree(work, ignore_errors=True)
        FreeCAD.closeDocument(doc.Name)
        print("wrote {}".format(target))


main()
sys.stdout.flush()
