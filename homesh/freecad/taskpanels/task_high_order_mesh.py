"""The task panel of a HighOrderMesh object (layout: Resources/ui/HighOrderMesh.ui).

Every parameter with its range (from the core's parameter table) and unit; Mesh runs the job on
a worker thread (job.py, made by meshing.py) while a timer shows the stage, the percentage, the
elapsed time and the log; Stop (or Escape) cancels it and leaves the document as it was; a
finished job's parameters and mesh are applied in one undoable transaction, with the summary
(elements, worst scaled Jacobian, invalid count, predicted count) and the quality histogram.
Apply writes the parameters without meshing. Close (or the dialog's Escape) stops a running job
first. No meshing here: the panel holds its values and hands them to meshing.py.
"""

import FreeCAD
import FreeCADGui
from PySide2 import QtCore, QtGui, QtWidgets

import homesh

from .. import meshing
from ..progress_dialog import confirm_large_mesh
from ..properties import value_of
from ..stored_mesh import get_mesh
from .histogram import draw_histogram, histogram_canvas
from .parameter_widgets import load_form, parameter_flags, parameter_widgets


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
        self.form = load_form("HighOrderMesh.ui")
        self.form.setWindowTitle("HOMesh: %s" % obj.Label)
        self.widgets = parameter_widgets(self.form, obj)
        self.flags = parameter_flags(self.form, obj)
        if getattr(obj, "FemMesh", None) is not None:  # curving a FEM mesh: no CAD check
            for flag in self.flags.values():
                flag.setEnabled(False)
                flag.setToolTip("Not used: the mesh curves the FEM mesh %s" % obj.FemMesh.Label)

        find = self.form.findChild
        self.mesh_button = find(QtWidgets.QPushButton, "meshButton")
        self.apply_button = find(QtWidgets.QPushButton, "applyButton")
        self.stop_button = find(QtWidgets.QPushButton, "stopButton")
        self.mesh_button.clicked.connect(self.mesh)
        self.apply_button.clicked.connect(self.apply)
        self.stop_button.clicked.connect(self.cancel)
        self.progress = find(QtWidgets.QProgressBar, "progress")
        self.elapsed_label = find(QtWidgets.QLabel, "elapsed")
        self.stage_label = find(QtWidgets.QLabel, "stage")
        self.summary = find(QtWidgets.QLabel, "summary")
        self.summary.setText(obj.Status if "Status" in obj.PropertiesList else "")
        self.log = find(QtWidgets.QPlainTextEdit, "log")

        # matplotlib's canvas is no Designer widget: it goes into the form's placeholder.
        self.figure, self.canvas = histogram_canvas()
        self.canvas.setVisible(False)  # until there is a mesh
        find(QtWidgets.QWidget, "histogram").layout().addWidget(self.canvas)

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
            job = meshing.job_for(self.obj, values)
            try:
                self.predicted = meshing.check_element_limit(self.obj, job)
            except meshing.LargeMeshError as e:
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
            meshing.apply_result(self.obj, job.result, self.predicted, touch=True,
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
        mesh = get_mesh(obj)
        if mesh is None:
            return
        self.summary.setText(obj.Status)
        palette = self.summary.palette()
        palette.setColor(QtGui.QPalette.WindowText,
                         QtGui.QColor("#b00000" if meshing.not_valid(obj) else "#000000"))
        self.summary.setPalette(palette)
        draw_histogram(self.figure, mesh.quality()["scaled_jacobian"])
        self.canvas.setVisible(True)
        self.canvas.draw()

    def _log(self, line):
        self.log.appendPlainText(line)
