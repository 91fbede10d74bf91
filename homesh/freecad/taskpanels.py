"""Task panels (built in code, PySide2) for the HighOrderMesh and Sizing objects.

HighOrderMesh: every parameter with its range (from the core's parameter table) and unit; Mesh
runs the job on a worker thread (job.py) while a timer shows the stage, the percentage, the
elapsed time and the log; Stop (or Escape) cancels it and leaves the document as it was; a
finished job's parameters and mesh are applied in one undoable transaction, with the summary
(elements, worst scaled Jacobian, invalid count, predicted count) and the quality histogram.
Apply writes the parameters without meshing. Close (or the dialog's Escape) stops a running job
first.

Sizing: MinDelta, MaxDelta and Eps; Predict gives the element count without meshing.
"""

import FreeCAD
import FreeCADGui
from PySide2 import QtCore, QtGui, QtWidgets

import homesh

from . import objects
from .job import confirm_large_mesh
from .properties import definition, value_of

_MESH_PARAMETERS = ("Order", "Size", "OptimiserIterations", "OptimiserTimeLimit", "FacetWeight",
                    "LinearTimeLimit", "JobTimeLimit", "RepairRounds", "Threads")
_SIZING_PARAMETERS = ("MinDelta", "MaxDelta", "Eps")
# The CAD check's switches (boolean properties): check boxes under the parameters.
_MESH_FLAGS = (("Heal", "Heal the CAD"), ("SolidsOnly", "Solids only"),
               ("Surface", "Surface mesh (no solid)"), ("AutoMode", "Choose for the shape"))


_LAST = []


def panel_for(obj):
    """The task panel of a HOMesh object (remembered for :func:`last_panel`)."""
    panel = TaskPanelSizing(obj) if objects.is_sizing(obj) else TaskPanelHighOrderMesh(obj)
    _LAST[:] = [panel]
    return panel


def last_panel():
    """The panel :func:`panel_for` made last (FreeCAD's Control.activeDialog() says only
    whether one is shown, not which)."""
    return _LAST[0] if _LAST else None


def _length_unit():
    return " mm"  # FreeCAD's internal length unit, which App::PropertyDistance values are in


def parameter_widget(obj, prop):
    """A spin box for table property ``prop`` of ``obj``: its range, its unit, its doc and range
    as the tooltip, 0 shown as "auto" where 0 means automatic."""
    p = definition(prop)
    value = value_of(obj, prop)
    if p["kind"] == "integer":
        widget = QtWidgets.QSpinBox()
        widget.setRange(int(p["min"]), int(min(p["max"], 2 ** 31 - 1)))
        widget.setValue(int(value))
    else:
        widget = QtWidgets.QDoubleSpinBox()
        # Seconds need no more than a tenth (600.0000 did not fit the panel's field), weights
        # and ratios up to 100 a hundredth ("0.0000" did not fit either); fractions (EPS) 4.
        seconds = p["key"].endswith("_seconds")
        widget.setDecimals(6 if p["kind"] == "length" else 1 if seconds else
                           2 if p["max"] >= 10 else 4)
        low = 0.0 if p["zero_is_automatic"] or p["min_exclusive"] else p["min"]
        high = p["max"] if p["max"] != float("inf") else 1e9
        widget.setRange(low, high)
        widget.setSingleStep(0.1 if p["kind"] == "length" else 0.01)
        if p["kind"] == "length":
            widget.setSuffix(_length_unit())
        widget.setValue(value)
    if p["zero_is_automatic"]:
        # "auto": the panel's narrow field showed "automatic" as "tomatic"; the tooltip says it.
        widget.setSpecialValueText("auto")
    widget.setToolTip("%s.\nAllowed: %s%s." % (p["doc"], p["range"],
                                                ", or 0 for automatic"
                                                if p["zero_is_automatic"] else ""))
    widget.setObjectName(prop)
    widget.setMinimumWidth(60)
    widget.setSizePolicy(QtWidgets.QSizePolicy.Ignored, QtWidgets.QSizePolicy.Fixed)
    return widget


def parameter_box(obj, title, props):
    """A group box with a spin box (parameter_widget) per table property of ``obj`` among
    ``props``, and those widgets by property name."""
    box = QtWidgets.QGroupBox(title)
    form = QtWidgets.QFormLayout(box)
    widgets = {}
    for prop in props:
        if prop in obj.PropertiesList:  # an older document may lack one
            widgets[prop] = parameter_widget(obj, prop)
            form.addRow(_row_label(prop), widgets[prop])
    # Fields take the width that is left; long rows wrap under their label (panels are narrow).
    form.setRowWrapPolicy(QtWidgets.QFormLayout.WrapLongRows)
    form.setFieldGrowthPolicy(QtWidgets.QFormLayout.AllNonFixedFieldsGrow)
    return box, widgets


class TaskPanelHighOrderMesh:
    """``form`` is the panel's widget; ``mesh()``, ``apply()``, ``cancel()`` are its buttons'
    actions (tests call them too). ``progress_values`` records the progress bar's values with
    the stage each was shown in."""

    def __init__(self, obj, confirm_large=None):
        self.obj = obj
        self.job = None
        self.predicted = None
        self.progress_values = []
        self.confirm_large = confirm_large or confirm_large_mesh
        self.form = QtWidgets.QWidget()
        self.form.setWindowTitle("HOMesh: %s" % obj.Label)
        layout = QtWidgets.QVBoxLayout(self.form)

        box, self.widgets = parameter_box(obj, "Parameters", _MESH_PARAMETERS)
        layout.addWidget(box)
        self.flags = {}
        for prop, text in _MESH_FLAGS:
            if prop in obj.PropertiesList:  # an older document may lack one
                flag = QtWidgets.QCheckBox(text)
                flag.setChecked(bool(getattr(obj, prop)))
                flag.setToolTip(obj.getDocumentationOfProperty(prop))
                if getattr(obj, "FemMesh", None) is not None:  # curving a FEM mesh: no CAD check
                    flag.setEnabled(False)
                    flag.setToolTip("Not used: the mesh curves the FEM mesh %s"
                                    % obj.FemMesh.Label)
                box.layout().addRow(flag)
                self.flags[prop] = flag

        buttons = QtWidgets.QGridLayout()
        self.mesh_button = QtWidgets.QPushButton("Mesh")
        self.apply_button = QtWidgets.QPushButton("Apply")
        self.stop_button = QtWidgets.QPushButton("Stop")
        self.stop_button.setEnabled(False)
        self.mesh_button.setToolTip("Mesh with these parameters (on a worker thread)")
        self.apply_button.setToolTip("Store these parameters without meshing")
        self.stop_button.setToolTip("Cancel the running job (Escape); the document is kept "
                                    "as it was")
        self.mesh_button.clicked.connect(self.mesh)
        self.apply_button.clicked.connect(self.apply)
        self.stop_button.clicked.connect(self.cancel)
        for column, b in enumerate((self.mesh_button, self.apply_button, self.stop_button)):
            b.setMinimumWidth(40)
            buttons.addWidget(b, 0, column)
        layout.addLayout(buttons)

        self.progress = QtWidgets.QProgressBar()
        self.progress.setRange(0, 1000)
        self.progress.setFormat("idle")
        self.progress.setTextVisible(True)
        self.elapsed_label = QtWidgets.QLabel("")
        row = QtWidgets.QHBoxLayout()
        row.addWidget(self.progress, 1)
        row.addWidget(self.elapsed_label)
        layout.addLayout(row)
        self.stage_label = QtWidgets.QLabel("")
        self.stage_label.setWordWrap(True)
        layout.addWidget(self.stage_label)

        self.summary = QtWidgets.QLabel(obj.Status if "Status" in obj.PropertiesList else "")
        self.summary.setWordWrap(True)
        layout.addWidget(self.summary)

        self.figure, self.canvas = _histogram_canvas()
        self.canvas.setVisible(False)  # until there is a mesh
        layout.addWidget(self.canvas)

        self.log = QtWidgets.QPlainTextEdit()
        self.log.setReadOnly(True)
        self.log.setLineWrapMode(QtWidgets.QPlainTextEdit.WidgetWidth)
        self.log.setMaximumBlockCount(2000)
        self.log.setMinimumHeight(100)
        layout.addWidget(self.log)

        self.escape = QtWidgets.QShortcut(QtGui.QKeySequence(QtCore.Qt.Key_Escape), self.form)
        self.escape.setContext(QtCore.Qt.WidgetWithChildrenShortcut)
        self.escape.activated.connect(self.cancel)
        # The timer lives and dies with the form: FreeCAD may delete the panel's widgets (its
        # own Escape handling closes the task dialog); a job still running is then cancelled.
        self.timer = QtCore.QTimer(self.form)
        self.timer.setInterval(50)
        self.timer.timeout.connect(self._tick)
        self.form.destroyed.connect(self._abandon)
        self._show_summary()

    # FreeCAD's task dialog protocol -----------------------------------------------------------
    def getStandardButtons(self):
        return int(QtWidgets.QDialogButtonBox.Close)

    def reject(self):
        self.close()
        return True

    def accept(self):
        self.close()
        return True

    def close(self):
        """Stops a running job (waiting for it to end) and leaves edit mode."""
        self.timer.stop()
        self._abandon()
        doc = FreeCADGui.ActiveDocument
        if doc is not None:
            doc.resetEdit()

    def _abandon(self, *_):
        """The form is gone: nothing may touch its widgets; a running job is cancelled and its
        files removed (the document was never changed by it)."""
        job, self.job = self.job, None
        if job is not None:
            job.cancel()
            job.wait(5.0)
            job.discard_files()

    # Actions ------------------------------------------------------------------------------------
    def values(self):
        values = {prop: w.value() for prop, w in self.widgets.items()}
        values.update((prop, flag.isChecked()) for prop, flag in self.flags.items())
        return values

    def apply(self):
        """Writes the panel's parameters to the object (one undoable step; the object is then
        touched: the mesh no longer matches them until it is meshed again)."""
        doc = self.obj.Document
        doc.openTransaction("HOMesh parameters")
        try:
            for prop, value in self.values().items():
                if prop in self.flags:
                    if bool(getattr(self.obj, prop)) != value:
                        setattr(self.obj, prop, value)
                elif abs(value_of(self.obj, prop) - value) > 0:
                    setattr(self.obj, prop, value)
        finally:
            doc.commitTransaction()
        self._log("Parameters applied.")

    def mesh(self):
        """Starts a job with the panel's parameters; returns it (None when it cannot start)."""
        if self.job is not None and self.job.running:
            return self.job
        values = self.values()
        try:
            job = objects.job_for(self.obj, values)
            try:
                self.predicted = objects.check_element_limit(self.obj, job)
            except objects.LargeMeshError as e:
                if not self.confirm_large(str(e)):
                    self._log("Not meshed: %s" % e)
                    return None
                self.predicted = None
        except (ValueError, homesh.HOMeshError) as e:
            self._log("Cannot mesh: %s" % e)
            self.summary.setText("Cannot mesh: %s" % e)
            return None
        self.job = job
        self.progress_values = []
        self.log.clear()
        self._log("Meshing %s: %s" % (self.obj.Part.Label, ", ".join(
            ("%s %s" if isinstance(v, bool) else "%s %g") % (k, v) for k, v in values.items())))
        if self.predicted is not None:
            self._log("About %d linear elements predicted." % self.predicted)
        self.mesh_button.setEnabled(False)
        self.apply_button.setEnabled(False)
        self.stop_button.setEnabled(True)
        job.start()
        self.timer.start()
        return job

    def cancel(self):
        if self.job is not None and self.job.running:
            self.job.cancel()
            self._log("Cancelling ...")

    # Progress -----------------------------------------------------------------------------------
    def _tick(self):
        job = self.job
        if job is None:
            self.timer.stop()
            return
        for line in job.poll():
            self._log(line)
        value = int(1000 * job.fraction)
        if not self.progress_values or self.progress_values[-1] != (job.stage, value):
            self.progress_values.append((job.stage, value))
        self.progress.setValue(value)
        self.progress.setFormat("%s  %%p%%" % (job.stage or "starting"))
        self.stage_label.setText(job.detail)
        self.elapsed_label.setText("%.1f s" % job.elapsed)
        if job.done:
            self.timer.stop()
            self._finish(job)

    def _finish(self, job):
        self.mesh_button.setEnabled(True)
        self.apply_button.setEnabled(True)
        self.stop_button.setEnabled(False)
        if job.error is not None:
            if isinstance(job.error, homesh.CancelledError):
                text = ("Cancelled after %.1f s; the document is unchanged." % job.elapsed)
            else:
                text = "Failed after %.1f s: %s" % (job.elapsed, job.error)
                FreeCAD.Console.PrintError("HOMesh: %s: %s\n" % (self.obj.Label, job.error))
            self.progress.setFormat(text.split(":")[0].split(";")[0])
            self._log(text)
            self.summary.setText(text)
            return
        doc = self.obj.Document
        doc.openTransaction("HOMesh mesh")
        try:
            objects.apply_result(self.obj, job.result, self.predicted, touch=True,
                                 values=job.values, npz_path=job.npz_path)
        finally:
            doc.commitTransaction()
            job.discard_files()
        part = self.obj.Part
        if part is not None and part.ViewObject is not None and self.obj.ViewObject.Visibility:
            part.ViewObject.Visibility = False  # the mesh covers the shape: show the mesh
        self.progress.setValue(1000)
        self.progress.setFormat("done  %p%")
        self._log("Done in %.1f s." % job.elapsed)
        self._show_summary()

    def _show_summary(self):
        obj = self.obj
        mesh = objects.get_mesh(obj)
        if mesh is None:
            return
        self.summary.setText(obj.Status)
        palette = self.summary.palette()
        palette.setColor(QtGui.QPalette.WindowText,
                         QtGui.QColor("#b00000" if objects.not_valid(obj) else "#000000"))
        self.summary.setPalette(palette)
        draw_histogram(self.figure, mesh.quality()["scaled_jacobian"])
        self.canvas.setVisible(True)
        self.canvas.draw()

    def _log(self, line):
        self.log.appendPlainText(line)



_LABELS = {"OptimiserIterations": "Optimiser sweeps", "OptimiserTimeLimit": "Time limit (s)",
           "LinearTimeLimit": "Gmsh time limit (s)", "JobTimeLimit": "Job time limit (s)",
           "RepairRounds": "Repair rounds", "FacetWeight": "Facet weight"}


def _row_label(prop):
    """A short row label (the range is in the field's limits and tooltip: task panels are
    narrow)."""
    return _LABELS.get(prop, prop)


def _histogram_canvas():
    from matplotlib.backends.backend_qt5agg import FigureCanvasQTAgg
    from matplotlib.figure import Figure
    figure = Figure(figsize=(3.2, 1.8), dpi=90)
    canvas = FigureCanvasQTAgg(figure)
    canvas.setMinimumHeight(150)
    return figure, canvas


def draw_histogram(figure, values):
    """Histogram of per-element scaled Jacobians on ``figure``: bars in the view's colours,
    invalid elements (<= 0) in their own bar."""
    import numpy as np
    from ..tessellation import quality_colors
    values = np.asarray(values, dtype=float)
    figure.clear()
    axes = figure.add_subplot(111)
    edges = np.linspace(0.0, 1.0, 21)
    counts, _ = np.histogram(np.clip(values, 1e-12, 1.0), bins=edges)
    centres = 0.5 * (edges[:-1] + edges[1:])
    axes.bar(centres, counts, width=0.05, color=quality_colors(centres), edgecolor="#333333",
             linewidth=0.4)
    invalid = int((values <= 0.0).sum())
    if invalid:
        axes.bar([-0.05], [invalid], width=0.05, color=quality_colors([-1.0]),
                 edgecolor="#333333", linewidth=0.4)
    axes.set_xlim(-0.1 if invalid else 0.0, 1.0)
    axes.set_xlabel("scaled Jacobian", fontsize=7)
    axes.set_title("%d elements, %d invalid" % (len(values), invalid), fontsize=7)
    axes.set_ylabel("elements", fontsize=7)
    axes.tick_params(labelsize=7)
    figure.tight_layout()


class TaskPanelSizing:
    """MinDelta, MaxDelta, Eps with their ranges; Predict counts the elements; Apply stores the
    values and recomputes the object."""

    def __init__(self, obj):
        self.obj = obj
        self.form = QtWidgets.QWidget()
        self.form.setWindowTitle("HOMesh sizing: %s" % obj.Label)
        layout = QtWidgets.QVBoxLayout(self.form)
        box, self.widgets = parameter_box(obj, "Sizing octree", _SIZING_PARAMETERS)
        layout.addWidget(box)
        buttons = QtWidgets.QHBoxLayout()
        self.predict_button = QtWidgets.QPushButton("Predict")
        self.apply_button = QtWidgets.QPushButton("Apply")
        self.predict_button.clicked.connect(self.predict)
        self.apply_button.clicked.connect(self.apply)
        buttons.addWidget(self.predict_button)
        buttons.addWidget(self.apply_button)
        layout.addLayout(buttons)
        self.result = QtWidgets.QLabel(obj.Status)
        self.result.setWordWrap(True)
        layout.addWidget(self.result)

    def getStandardButtons(self):
        return int(QtWidgets.QDialogButtonBox.Close)

    def reject(self):
        FreeCADGui.ActiveDocument.resetEdit()
        return True

    def accept(self):
        return self.reject()

    def values(self):
        return {prop: w.value() for prop, w in self.widgets.items()}

    def predict(self):
        """The element count for the panel's values, without changing the object."""
        values = self.values()
        sizing = {"min_delta": values["MinDelta"] or None,
                  "max_delta": values["MaxDelta"] or None, "eps": values["Eps"]}
        try:
            shape = self.obj.Part.Shape
            report = homesh.predict(shape, name=self.obj.Part.Label,
                                    **objects.cad_modes(shape),  # as the Sizing object's recompute
                                    **dict(objects.sizing_arguments(self.obj), **sizing))
        except (ValueError, homesh.HOMeshError) as e:
            self.result.setText("Cannot predict: %s" % e)
            return None
        self.result.setText(objects.prediction_summary(report))
        return int(report["predicted_elements"])

    def apply(self):
        doc = self.obj.Document
        doc.openTransaction("HOMesh sizing")
        try:
            for prop, value in self.values().items():
                setattr(self.obj, prop, value)
        finally:
            doc.commitTransaction()
        doc.recompute()
        self.result.setText(self.obj.Status)
