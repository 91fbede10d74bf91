"""View providers. HighOrderMesh: the curved boundary surface coloured by element quality, with
the curved element edges drawn on top (Coin3D scene built from tessellation.surface_and_edges).
Sizing: nothing in the 3D view, only its icon."""

from . import resources

DISPLAY_MODES = ["Surface with edges", "Surface", "Wireframe"]


class _Stateless:
    """View providers keep nothing in the document (FreeCAD 0.20 uses __getstate__, 0.21+
    dumps)."""

    def __getstate__(self):
        return None

    def __setstate__(self, state):
        return None

    def dumps(self):
        return None

    def loads(self, state):
        return None


class ViewProviderHighOrderMesh(_Stateless):
    def __init__(self, vobj):
        vobj.Proxy = self
        self.add_properties(vobj)

    @staticmethod
    def add_properties(vobj):
        if "Subdivision" not in vobj.PropertiesList:
            vobj.addProperty("App::PropertyIntegerConstraint", "Subdivision", "Display",
                             "Segments per element edge when drawing curved elements "
                             "(0: twice the order)")
            vobj.Subdivision = (0, 0, 32, 1)

    def attach(self, vobj):
        from pivy import coin
        self.Object = vobj.Object
        self.add_properties(vobj)
        self.coords = coin.SoCoordinate3()
        self.material = coin.SoMaterial()
        binding = coin.SoMaterialBinding()
        binding.value = coin.SoMaterialBinding.PER_FACE
        hints = coin.SoShapeHints()  # two-sided lighting for open surfaces and reversed faces
        hints.vertexOrdering = coin.SoShapeHints.COUNTERCLOCKWISE
        hints.shapeType = coin.SoShapeHints.UNKNOWN_SHAPE_TYPE
        self.faces = coin.SoIndexedFaceSet()
        offset = coin.SoPolygonOffset()
        surface = coin.SoSeparator()
        for node in (hints, offset, self.coords, binding, self.material, self.faces):
            surface.addChild(node)

        self.edge_coords = coin.SoCoordinate3()
        self.lines = coin.SoIndexedLineSet()
        color = coin.SoBaseColor()
        color.rgb = (0.1, 0.1, 0.15)
        style = coin.SoDrawStyle()
        style.lineWidth = 1.0
        light = coin.SoLightModel()
        light.model = coin.SoLightModel.BASE_COLOR
        edges = coin.SoSeparator()
        for node in (light, color, style, self.edge_coords, self.lines):
            edges.addChild(node)

        modes = []
        for children in ((surface, edges), (surface,), (edges,)):
            group = coin.SoGroup()
            for child in children:
                group.addChild(child)
            modes.append(group)
        for mode, group in zip(DISPLAY_MODES, modes):
            vobj.addDisplayMode(group, mode)
        self.rebuild()

    def rebuild(self):
        """Rebuilds the scene from the object's mesh (after a recompute or a reload)."""
        from .objects import get_mesh
        from ..tessellation import surface_and_edges
        obj = self.Object
        mesh = get_mesh(obj)
        if mesh is None:
            for field in (self.coords.point, self.faces.coordIndex, self.edge_coords.point,
                          self.lines.coordIndex, self.material.diffuseColor):
                field.setNum(0)
            return
        level = obj.ViewObject.Subdivision if obj.ViewObject else 0
        geometry = surface_and_edges(mesh, level or None)
        _set_points(self.coords.point, geometry["points"])
        _set_index(self.faces.coordIndex, geometry["triangles"])
        _set_points(self.material.diffuseColor, geometry["colors"])
        _set_points(self.edge_coords.point, geometry["edge_points"])
        _set_index(self.lines.coordIndex, geometry["edge_polylines"])

    def updateData(self, obj, prop):
        if prop == "MeshData" and hasattr(self, "coords"):
            self.rebuild()

    def onChanged(self, vobj, prop):
        if prop == "Subdivision" and hasattr(self, "coords"):
            self.rebuild()

    def getDisplayModes(self, vobj):
        return DISPLAY_MODES

    def getDefaultDisplayMode(self):
        return DISPLAY_MODES[0]

    def setDisplayMode(self, mode):
        return mode

    def getIcon(self):
        return resources.icon("homesh_mesh.svg")

    def claimChildren(self):
        return [child for child in (getattr(self.Object, "Part", None),
                                    getattr(self.Object, "Sizing", None))
                if child is not None]


class ViewProviderSizing(_Stateless):
    """A Sizing object draws nothing; the view provider gives its tree icon."""

    def __init__(self, vobj):
        vobj.Proxy = self

    def attach(self, vobj):
        self.Object = vobj.Object

    def getIcon(self):
        return resources.icon("homesh_sizing.svg")


def _set_points(field, array):
    values = [tuple(map(float, row)) for row in array]
    field.setNum(0)
    if values:
        field.setValues(0, len(values), values)


def _set_index(field, rows):
    import numpy as np
    rows = np.asarray(rows, dtype=np.int64)
    flat = np.hstack([rows, -np.ones((len(rows), 1), dtype=np.int64)]).ravel().tolist()
    field.setNum(0)
    if flat:
        field.setValues(0, len(flat), flat)

