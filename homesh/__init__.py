"""HOMesh: curved (high-order) meshes from CAD for high-order CFD.

Usable from FreeCAD's Python console, from ``freecadcmd`` and from plain Python 3.11::

    import homesh
    m = homesh.mesh(shape, order=4, size=0.2)   # a Part.Shape, a CAD file path or BRep text
    m.nodes            # (N, 3) float64
    m.elements         # (E, nodes per element) int64, Gmsh node order
    m.quality()        # per-element scaled Jacobian and summary
    m.write("out.msh") # .msh (Gmsh 4.1), .vtu (VTK), .xml (Nektar++), .npz (arrays)
    homesh.read("mesh.msh")  # a mesh file (.msh 2.2/4.1, Nektar++ .xml, FEM's .unv/.vtk/.vtu)

Every failure raises a subclass of :class:`HOMeshError`; the meshing core never takes the host
process down.
"""

from ._core import (  # noqa: F401  (re-exported)
    CadError,
    CancelledError,
    CancelToken,
    FileError,
    HOMeshError,
    MeshingError,
    ParameterError,
    __version__,
)
from .api import (  # noqa: F401
    BoundaryBlock, HighOrderMesh, curve, load, mesh, parameters, predict, read, size_field)

__all__ = [
    "BoundaryBlock",
    "CadError",
    "CancelToken",
    "CancelledError",
    "FileError",
    "HOMeshError",
    "HighOrderMesh",
    "curve",
    "MeshingError",
    "ParameterError",
    "load",
    "mesh",
    "parameters",
    "predict",
    "read",
    "size_field",
]
