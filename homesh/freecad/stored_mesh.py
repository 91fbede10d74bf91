"""The curved mesh a HighOrderMesh object holds: cached on its proxy after a recompute, and
stored inside the .FCStd as a compressed array file (property MeshData), so reopening a
document shows and exports the mesh without recomputing it. No Qt; no other module of the
package."""

import os
import shutil
import tempfile


def get_mesh(obj):
    """The :class:`homesh.HighOrderMesh` of a HighOrderMesh object (from the last recompute,
    or read back from the document), or None if it has none or its last recompute failed (the
    view then still shows the last good mesh, as FreeCAD does for failed features)."""
    if not obj.isValid():
        return None
    proxy = getattr(obj, "Proxy", None)
    cached = getattr(proxy, "mesh", None)
    if cached is not None:
        return cached
    path = getattr(obj, "MeshData", "")
    if not path or not os.path.isfile(path):
        return None
    import homesh
    mesh = homesh.load(path)
    if proxy is not None:
        proxy.mesh = mesh
    return mesh


def store_mesh(obj, mesh, npz_path=None):
    """Puts ``mesh`` into the object's MeshData (FreeCAD copies the file into the document)
    and its proxy's cache. ``npz_path``: the mesh already written (by a job's worker thread);
    else it is written here, into a fresh folder (FreeCAD refuses the same path twice)."""
    if npz_path is not None:
        obj.MeshData = npz_path
    else:
        folder = tempfile.mkdtemp(prefix="homesh-")
        try:
            path = os.path.join(folder, "mesh.npz")
            mesh.write(path)
            obj.MeshData = path
        finally:
            shutil.rmtree(folder, ignore_errors=True)
    obj.Proxy.mesh = mesh
