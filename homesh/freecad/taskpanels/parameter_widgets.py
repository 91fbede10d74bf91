"""A task panel's form from its .ui file (Resources/ui/), its parameter widgets filled from the
core's parameter table.

The .ui file states the layout only: a spin box or check box named after a table property
(Order, MinDelta, Heal ...) is that parameter, and a label named after it plus "Label" is its
row label. Everything else a widget shows of a parameter comes from the table when the panel
opens: the label (the table's label), the range, the decimals, the unit (mm for a length), the
tooltip (doc and range) and the object's value. Gui only.
"""

import FreeCADGui
from PySide2 import QtWidgets

from .. import resources
from ..properties import definition, range_words, value_of


def load_form(name):
    """The widget tree of Resources/ui/``name`` (FreeCAD's loader, as FEM's task panels)."""
    return FreeCADGui.PySideUic.loadUi(resources.ui(name))


def label_text(p):
    """A row label for table entry ``p``: the table's label (how messages name it),
    capitalised."""
    return p["label"][:1].upper() + p["label"][1:]


def tooltip(p):
    """The table's doc and, for a number, its range in words."""
    if p["kind"] == "boolean":
        return "%s." % p["doc"]
    return "%s.\n%s" % (p["doc"], range_words(p))


def _table_entries(form, widget_class):
    """[(widget, table entry)] of the ``widget_class`` children of ``form`` named after a table
    property, in the form's order."""
    out = []
    for widget in form.findChildren(widget_class):
        try:
            out.append((widget, definition(widget.objectName())))
        except KeyError:
            continue  # a widget of the panel's own (a button's, a label)
    return out


def _configure_spin_box(widget, p):
    """Range, decimals, step, unit and "auto" of a spin box for table entry ``p``."""
    integer = p["kind"] == "integer"
    if integer != isinstance(widget, QtWidgets.QSpinBox):
        raise TypeError("%s: the .ui file makes a %s of %s parameter %s"
                        % (widget.window().objectName(), type(widget).__name__, p["kind"],
                           widget.objectName()))
    if integer:
        low = 0 if p["zero_is_automatic"] else int(p["min"])  # 0: automatic ("auto")
        widget.setRange(low, int(min(p["max"], 2 ** 31 - 1)))
    else:
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
            widget.setSuffix(" mm")  # FreeCAD's internal length unit, App::PropertyDistance's
        # Seconds carry no suffix: " s" pushed "600.0" out of the narrow field; the table's doc,
        # the tooltip, starts with "Seconds".
    if p["zero_is_automatic"]:
        # "auto": the panel's narrow field showed "automatic" as "tomatic"; the tooltip says it.
        widget.setSpecialValueText("auto")


def parameter_widgets(form, obj):
    """Fills the spin boxes of ``form`` named after table properties from the table and
    ``obj``'s values; returns them by property name. A property an older document lacks has its
    row hidden."""
    widgets = {}
    for widget, p in _table_entries(form, QtWidgets.QAbstractSpinBox):
        prop = p["property"]
        label = form.findChild(QtWidgets.QLabel, prop + "Label")
        if prop not in obj.PropertiesList:
            widget.setVisible(False)
            if label is not None:
                label.setVisible(False)
            continue
        _configure_spin_box(widget, p)
        widget.setValue(int(value_of(obj, prop)) if p["kind"] == "integer" else
                        value_of(obj, prop))
        widget.setToolTip(tooltip(p))
        if label is not None:
            label.setText(label_text(p))
            label.setToolTip(tooltip(p))
        widgets[prop] = widget
    return widgets


def parameter_flags(form, obj):
    """Fills the check boxes of ``form`` named after table properties (the CAD check's
    switches) from the table and ``obj``'s values; returns them by property name."""
    flags = {}
    for flag, p in _table_entries(form, QtWidgets.QCheckBox):
        prop = p["property"]
        if prop not in obj.PropertiesList:  # an older document may lack one
            flag.setVisible(False)
            continue
        flag.setText(label_text(p))
        flag.setToolTip(tooltip(p))
        flag.setChecked(bool(getattr(obj, prop)))
        flags[prop] = flag
    return flags
