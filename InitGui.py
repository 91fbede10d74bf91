# HOMesh workbench: GUI registration. Exec'd by FreeCAD at start-up (no __file__ here); the
# compiled core is only loaded when the workbench is activated.
import FreeCADGui


class HOMeshWorkbench(FreeCADGui.Workbench):
    MenuText = "HOMesh"
    ToolTip = "Curved high-order meshes for CFD, with boundary nodes on the CAD"

    def __init__(self):
        # find_spec locates the package without importing it (and the compiled core with it).
        import importlib.util
        import os
        package = os.path.dirname(importlib.util.find_spec("homesh").origin)
        self.__class__.Icon = os.path.join(os.path.dirname(package), "Resources", "icons",
                                           "homesh.svg")

    def Initialize(self):
        import homesh.freecad.commands  # noqa: F401  (registers the commands)
        commands = ["HOMesh_HighOrderMesh", "HOMesh_Sizing", "HOMesh_BoundaryLayer",
                    "HOMesh_MeshRegion", "HOMesh_BoundaryGroup", "HOMesh_CurveFemMesh",
                    "HOMesh_ToFemMesh"]
        self.appendToolbar("HOMesh", commands)
        self.appendMenu("&HOMesh", commands)

    def GetClassName(self):
        return "Gui::PythonWorkbench"


FreeCADGui.addWorkbench(HOMeshWorkbench())
