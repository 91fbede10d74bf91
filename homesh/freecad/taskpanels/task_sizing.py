"""The task panel of a Sizing object (layout: Resources/ui/Sizing.ui): MinDelta, MaxDelta and
Eps with their ranges from the parameter table; Predict gives the element count for the values
typed without changing the object; Apply stores them and recomputes it.
"""

import FreeCADGui
from PySide2 import QtWidgets

import homesh

from ..arguments import cad_modes, sizing_arguments
from ..meshing import prediction_summary
from .parameter_widgets import load_form, parameter_widgets


class TaskPanelSizing:
    """MinDelta, MaxDelta, Eps with their ranges; Predict counts the elements; Apply stores the
    values and recomputes the object."""

    def __init__(self, obj):
        self.obj = obj
        self.form = load_form("Sizing.ui")
        self.form.setWindowTitle("HOMesh sizing: %s" % obj.Label)
        self.widgets = parameter_widgets(self.form, obj)
        self.predict_button = self.form.findChild(QtWidgets.QPushButton, "predictButton")
        self.apply_button = self.form.findChild(QtWidgets.QPushButton, "applyButton")
        self.predict_button.clicked.connect(self.predict)
        self.apply_button.clicked.connect(self.apply)
        self.result = self.form.findChild(QtWidgets.QLabel, "result")
        self.result.setText(obj.Status)

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
                                    **cad_modes(shape),  # as the Sizing object's recompute
                                    **dict(sizing_arguments(self.obj), **sizing))
        except (ValueError, homesh.HOMeshError) as e:
            self.result.setText("Cannot predict: %s" % e)
            return None
        self.result.setText(prediction_summary(report))
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
