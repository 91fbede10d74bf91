# HOMesh workbench: initialisation without GUI (FreeCAD and freecadcmd). FreeCAD puts this Mod
# folder on sys.path, which makes the `homesh` package importable.
import FreeCAD

FreeCAD.addExportType("HOMesh curved mesh (*.msh *.vtu)", "homesh.freecad.exporter")
FreeCAD.addExportType("HOMesh curved mesh for Nektar++ (*.xml)", "homesh.freecad.exporter")
FreeCAD.addExportType("HOMesh curved mesh, CGNS (*.cgns)", "homesh.freecad.exporter")
