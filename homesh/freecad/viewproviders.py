"""View providers.

HighOrderMesh: curved elements coloured by a quality measure (scaled Jacobian or distortion),
with the curved element edges on top and a colour legend in the view's corner (Coin3D scene
built from homesh.tessellation). ``Show`` picks what is drawn: the boundary, the elements below
``Threshold`` (whole, so the inside of the mesh can be seen) or only the invalid ones. The tree
icon carries a warning sign while the mesh has elements not proven valid. Selection draws a
bounding box instead of painting the mesh over, so the colours stay readable. Double-clicking
opens the task panel.

Sizing: its size field, the octree's leaves as points coloured by size; its task panel predicts
the element count.
"""

from . import resources
from .arguments import cad_modes, sizing_arguments
from .meshing import not_valid
from .object_types import TYPE_BOUNDARY_GROUP, type_of
from .stored_mesh import get_mesh

DISPLAY_MODES = ["Surface with edges", "Surface", "Wireframe"]
SHOW = ["Boundary", "Elements below threshold", "Invalid elements"]
MEASURES = ["Scaled Jacobian", "Distortion"]
LEGEND_STEPS = 10
# The legend's bar in normalised view coordinates (x0, x1, y0, y1; -1..1 across the view).
LEGEND_BOX = (-0.95, -0.89, -0.8, 0.6)


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


class _EditsWithTaskPanel:
    """Double-click or Edit opens the object's task panel (FreeCAD FEM's convention)."""

    def doubleClicked(self, vobj):
        import FreeCADGui
        FreeCADGui.ActiveDocument.setEdit(vobj.Object.Name)
        return True

    def setEdit(self, vobj, mode=0):
        if mode != 0:
            return None  # transform and the like: FreeCAD's own
        import FreeCADGui
        from .taskpanels import panel_for
        FreeCADGui.Control.showDialog(panel_for(vobj.Object))
        return True

    def unsetEdit(self, vobj, mode=0):
        import FreeCADGui
        FreeCADGui.Control.closeDialog()
        return True


class ViewProviderHighOrderMesh(_Stateless, _EditsWithTaskPanel):
    def __init__(self, vobj):
        vobj.Proxy = self
        self.add_properties(vobj)

    @staticmethod
    def add_properties(vobj):
        have = vobj.PropertiesList
        if "Subdivision" not in have:
            vobj.addProperty("App::PropertyIntegerConstraint", "Subdivision", "Display",
                             "Segments per element edge when drawing curved elements "
                             "(0: twice the order)")
            vobj.Subdivision = (0, 0, 32, 1)
        if "Measure" not in have:
            vobj.addProperty("App::PropertyEnumeration", "Measure", "Display",
                             "Quality measure the colours show: the certified scaled Jacobian "
                             "(min J / max J) or the distortion against the straight element")
            vobj.Measure = MEASURES
        if "Show" not in have:
            vobj.addProperty("App::PropertyEnumeration", "Show", "Display",
                             "What is drawn: the boundary, the whole elements whose measure "
                             "is below Threshold (to see inside), or the invalid elements only")
            vobj.Show = SHOW
        if "Threshold" not in have:
            vobj.addProperty("App::PropertyFloatConstraint", "Threshold", "Display",
                             "With Show 'Elements below threshold': the measure below which an "
                             "element is drawn")
            vobj.Threshold = (0.3, -1.0, 1.0, 0.05)
        if "Legend" not in have:
            vobj.addProperty("App::PropertyBool", "Legend", "Display",
                             "Draw the colour legend of the measure in the view's corner")
            vobj.Legend = True
        if "SelectionStyle" in have:
            vobj.SelectionStyle = "BoundBox"  # selection must not paint over the colours

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

        self.legend_switch = coin.SoSwitch()
        self.legend_text = []
        self.legend_switch.addChild(self._legend(coin))

        modes = []
        for children in ((surface, edges), (surface,), (edges,)):
            group = coin.SoGroup()
            for child in children:
                group.addChild(child)
            group.addChild(self.legend_switch)
            modes.append(group)
        for mode, group in zip(DISPLAY_MODES, modes):
            vobj.addDisplayMode(group, mode)
        self.rebuild()

    def _legend(self, coin):
        """A colour bar with labels, drawn in normalised screen coordinates by its own
        orthographic camera, and left out of the view's bounding box (fit all ignores it)."""
        from ..tessellation import quality_colors
        skip = coin.SoType.fromName("SoSkipBoundingGroup")
        root = skip.createInstance() if not skip.isBad() else coin.SoSeparator()
        if not skip.isBad():
            root.getField("mode").set("EXCLUDE_BBOX")
        inner = coin.SoSeparator()
        root.addChild(inner)
        camera = coin.SoOrthographicCamera()
        camera.viewportMapping = coin.SoCamera.LEAVE_ALONE
        camera.position = (0.0, 0.0, 5.0)
        camera.height = 2.0
        camera.nearDistance = 0.5
        camera.farDistance = 10.0
        light = coin.SoLightModel()
        light.model = coin.SoLightModel.BASE_COLOR
        for node in (camera, light):
            inner.addChild(node)
        # Bar: LEGEND_STEPS bands from 0 (bottom) to 1 (top), plus the invalid colour below; on
        # the left, clear of FreeCAD's navigation cube and axis cross on the right.
        x0, x1, y0, y1 = LEGEND_BOX
        values = [(i + 0.5) / LEGEND_STEPS for i in range(LEGEND_STEPS)]
        colors = [tuple(map(float, c)) for c in quality_colors([-1.0] + values)]
        points, faces = [], []
        bands = [(y0 - 0.15, y0 - 0.05)] + [
            (y0 + i * (y1 - y0) / LEGEND_STEPS, y0 + (i + 1) * (y1 - y0) / LEGEND_STEPS)
            for i in range(LEGEND_STEPS)]
        for k, (lo, hi) in enumerate(bands):
            points += [(x0, lo, 0.0), (x1, lo, 0.0), (x1, hi, 0.0), (x0, hi, 0.0)]
            faces += [4 * k, 4 * k + 1, 4 * k + 2, 4 * k + 3, -1]
        coords = coin.SoCoordinate3()
        coords.point.setValues(0, len(points), points)
        material = coin.SoMaterial()
        material.diffuseColor.setValues(0, len(colors), colors)
        binding = coin.SoMaterialBinding()
        binding.value = coin.SoMaterialBinding.PER_FACE
        bar = coin.SoIndexedFaceSet()
        bar.coordIndex.setValues(0, len(faces), faces)
        for node in (coords, binding, material, bar):
            inner.addChild(node)
        text_color = coin.SoBaseColor()
        text_color.rgb = (0.0, 0.0, 0.0)
        font = coin.SoFont()
        font.size = 13.0
        inner.addChild(text_color)
        inner.addChild(font)
        labels = [(y0 - 0.12, "<= 0 invalid"), (y0, "0"), (0.5 * (y0 + y1), "0.5"), (y1, "1")]
        for y, text in labels:
            sep = coin.SoSeparator()
            move = coin.SoTranslation()
            move.translation = (x1 + 0.01, y - 0.01, 0.0)
            label = coin.SoText2()
            label.string = text
            sep.addChild(move)
            sep.addChild(label)
            inner.addChild(sep)
        title_sep = coin.SoSeparator()
        move = coin.SoTranslation()
        move.translation = (x0 - 0.02, y1 + 0.06, 0.0)
        self.legend_title = coin.SoText2()
        title_sep.addChild(move)
        title_sep.addChild(self.legend_title)
        inner.addChild(title_sep)
        return root

    def rebuild(self):
        """Rebuilds the scene from the object's mesh (after a recompute or a reload) and the
        display properties."""
        from .. import tessellation
        obj = self.Object
        vobj = obj.ViewObject
        mesh = get_mesh(obj)
        self.legend_switch.whichChild = -1
        if mesh is None:
            for field in (self.coords.point, self.faces.coordIndex, self.edge_coords.point,
                          self.lines.coordIndex, self.material.diffuseColor):
                field.setNum(0)
            return
        level = vobj.Subdivision if vobj else 0
        measure = str(vobj.Measure) if vobj else MEASURES[0]
        show = str(vobj.Show) if vobj else SHOW[0]
        if show == SHOW[0]:
            geometry = tessellation.surface_and_edges(mesh, level or None, measure)
        else:
            if show == SHOW[2]:  # invalid or undecided (certified), whatever the measure
                below = mesh.quality()["validity"] <= 0
            else:
                below = tessellation.element_values(mesh, measure) < vobj.Threshold
            geometry = tessellation.element_surfaces(mesh, below.nonzero()[0], level or None,
                                                     measure)
        _set_points(self.coords.point, geometry["points"])
        _set_index(self.faces.coordIndex, geometry["triangles"])
        _set_points(self.material.diffuseColor, geometry["colors"])
        _set_points(self.edge_coords.point, geometry["edge_points"])
        _set_index(self.lines.coordIndex, geometry["edge_polylines"])
        self.legend_title.string = measure
        self.legend_switch.whichChild = -3 if (vobj is None or vobj.Legend) else -1  # all

    def updateData(self, obj, prop):
        if prop in ("MeshData", "InvalidElements", "UndecidedElements"):
            if hasattr(self, "coords") and prop == "MeshData":
                self.rebuild()
            if obj.ViewObject is not None:
                obj.ViewObject.signalChangeIcon()

    def onChanged(self, vobj, prop):
        if prop in ("Subdivision", "Measure", "Show", "Threshold", "Legend") and \
                hasattr(self, "coords"):
            self.rebuild()

    def getDisplayModes(self, vobj):
        return DISPLAY_MODES

    def getDefaultDisplayMode(self):
        return DISPLAY_MODES[0]

    def setDisplayMode(self, mode):
        return mode

    def getIcon(self):
        obj = getattr(self, "Object", None)
        if obj is not None and "InvalidElements" in obj.PropertiesList and not_valid(obj):
            return resources.icon("homesh_mesh_invalid.svg")
        return resources.icon("homesh_mesh.svg")

    def claimChildren(self):
        children = [child for child in (getattr(self.Object, "Part", None),
                                        getattr(self.Object, "Sizing", None),
                                        getattr(self.Object, "BoundaryLayer", None))
                    if child is not None]
        for prop in ("Regions", "Groups"):
            children += list(getattr(self.Object, prop, None) or [])
        return children


class ViewProviderSizing(_Stateless, _EditsWithTaskPanel):
    """A Sizing object draws its size field: a point at the centre of every octree leaf inside
    the shape or on its boundary, coloured by the size there on a log scale from the smallest
    (blue) to the largest (red) (`ShowSizeField`)."""

    def __init__(self, vobj):
        vobj.Proxy = self
        self.add_properties(vobj)

    @staticmethod
    def add_properties(vobj):
        if "ShowSizeField" not in vobj.PropertiesList:
            vobj.addProperty("App::PropertyBool", "ShowSizeField", "Display",
                             "Draw the sizing octree's leaves as points coloured by size "
                             "(blue smallest, red largest, log scale)")
            vobj.ShowSizeField = True

    def attach(self, vobj):
        from pivy import coin
        self.Object = vobj.Object
        self.add_properties(vobj)
        self.coords = coin.SoCoordinate3()
        self.material = coin.SoMaterial()
        binding = coin.SoMaterialBinding()
        binding.value = coin.SoMaterialBinding.PER_VERTEX
        style = coin.SoDrawStyle()
        style.pointSize = 4.0
        light = coin.SoLightModel()
        light.model = coin.SoLightModel.BASE_COLOR
        self.points = coin.SoPointSet()
        group = coin.SoSeparator()
        for node in (light, style, self.coords, binding, self.material, self.points):
            group.addChild(node)
        vobj.addDisplayMode(group, "Size field")
        self.rebuild()

    def rebuild(self):
        """Samples the object's octree again (the parameters changed) and draws it."""
        obj = self.Object
        for field in (self.coords.point, self.material.diffuseColor):
            field.setNum(0)
        vobj = obj.ViewObject
        if vobj is None or not vobj.ShowSizeField or obj.PredictedElements <= 0:
            return
        import homesh
        try:
            shape = obj.Part.Shape
            field = homesh.size_field(shape, name=obj.Part.Label, **cad_modes(shape),
                                      **sizing_arguments(obj))
        except (ValueError, homesh.HOMeshError):
            return  # the object's recompute reports it
        _set_points(self.coords.point, field["centre"])
        _set_points(self.material.diffuseColor, size_colors(field["delta"]))

    def updateData(self, obj, prop):
        if prop == "PredictedElements" and hasattr(self, "coords"):
            self.rebuild()

    def onChanged(self, vobj, prop):
        if prop == "ShowSizeField" and hasattr(self, "coords"):
            self.rebuild()

    def getDisplayModes(self, vobj):
        return ["Size field"]

    def getDefaultDisplayMode(self):
        return "Size field"

    def setDisplayMode(self, mode):
        return mode

    def getIcon(self):
        return resources.icon("homesh_sizing.svg")


def size_colors(delta):
    """RGB per size on a log scale between the smallest (blue) and the largest (red)."""
    import numpy as np
    d = np.log(np.asarray(delta, dtype=float))
    t = (d - d.min()) / (d.max() - d.min()) if d.max() > d.min() else np.zeros_like(d)
    return np.stack([t, 0.2 + 0.6 * (1.0 - np.abs(2.0 * t - 1.0)), 1.0 - t], axis=1)


class ViewProviderIconOnly(_Stateless):
    """Mesh regions and boundary groups draw nothing themselves; their tree icon."""

    def __init__(self, vobj):
        vobj.Proxy = self

    def attach(self, vobj):
        self.Object = vobj.Object

    def getIcon(self):
        kind = type_of(getattr(self, "Object", None))
        return resources.icon("homesh_group.svg" if kind == TYPE_BOUNDARY_GROUP
                              else "homesh_region.svg")


def _set_points(field, array):
    import numpy as np
    values = np.ascontiguousarray(array, dtype=np.float32).reshape(-1, 3)
    field.setNum(0)
    if len(values):
        field.setValues(0, len(values), values)


def _set_index(field, rows):
    import numpy as np
    rows = np.asarray(rows, dtype=np.int32)
    flat = np.hstack([rows, -np.ones((len(rows), 1), dtype=np.int32)]).ravel()
    field.setNum(0)
    if len(flat):
        field.setValues(0, len(flat), np.ascontiguousarray(flat))
