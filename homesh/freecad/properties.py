"""Document-object properties made from the core's one parameter table (homesh.parameters()):
each gets its type, group and tooltip (doc and range) from the table, and a value set out of
range, from the property editor, Python or a task panel, is refused: the property goes back to
its last good value and a warning naming the object, the property, the value and the range goes
to the report view (and to the proxy's ``refused`` list, which tests read).

FreeCAD's constraint properties would clamp such a value without a word (Order 20 becoming 10),
so the properties are plain integers, floats and lengths checked here.
"""

import FreeCAD

from ..api import parameters

_PROPERTY_TYPE = {"integer": "App::PropertyInteger", "real": "App::PropertyFloat",
                  "length": "App::PropertyDistance",  # Length would clamp -5 to 0 unsaid
                  "boolean": "App::PropertyBool"}


def _typed(p, value):
    """``value`` as the property of table entry ``p`` holds it."""
    return {"integer": int, "boolean": bool}.get(p["kind"], float)(value)


def definition(prop):
    """The table's entry for a FreeCAD property name (KeyError if it has none)."""
    for p in parameters():
        if p["property"] == prop:
            return p
    raise KeyError(prop)


def add_parameter_property(obj, key, group, doc_extra="", default=None):
    """Adds the property of parameter ``key`` to ``obj`` unless it has it (old documents keep
    theirs), with the table's default unless ``default`` is given."""
    p = [d for d in parameters() if d["key"] == key][0]
    if p["property"] in obj.PropertiesList:
        return
    tip = "%s.%s%s" % (p["doc"], "" if p["kind"] == "boolean" else " " + range_words(p),
                        doc_extra)
    obj.addProperty(_PROPERTY_TYPE[p["kind"]], p["property"], group, tip)
    setattr(obj, p["property"], _typed(p, p["default"] if default is None else default))


def range_words(p):
    """The allowed values of table entry ``p`` in words, for tooltips ("Allowed: <range>[, or 0
    for automatic].")."""
    words = "Allowed: %s" % p["range"]
    if p["zero_is_automatic"]:
        words += ", or 0 for automatic"
    return words + "."


def value_of(obj, prop):
    """A property's value as a plain number (a Quantity's value in the document's units)."""
    value = getattr(obj, prop)
    return float(getattr(value, "Value", value))


def allowed(p, value):
    """Whether ``value`` is allowed for the table entry ``p``: the core's own range check, or
    0 where 0 means automatic."""
    from .. import _core
    if p["zero_is_automatic"] and value == 0:
        return True
    return _core.parameter_in_range(p["key"], float(value))


class ParameterGuard:
    """Mixin for proxies: ``guard(obj, prop)`` from onChanged refuses an out-of-range value of a
    table property. The last good values live on the proxy (not in the document: they are the
    document's own values, read again when it is restored)."""

    def remember(self, obj):
        self._good = {}
        self.refused = []
        for prop in obj.PropertiesList:
            try:
                p = definition(prop)
            except KeyError:
                continue
            value = value_of(obj, prop)
            if allowed(p, value):
                self._good[prop] = value

    def guard(self, obj, prop):
        """Call from onChanged. Returns False when the value was refused (and put back)."""
        good = getattr(self, "_good", None)
        if good is None:
            self.remember(obj)
            good = self._good
        try:
            p = definition(prop)
        except KeyError:
            return True
        if prop not in obj.PropertiesList:
            return True
        value = value_of(obj, prop)
        if allowed(p, value):
            good[prop] = value
            return True
        previous = good.get(prop, p["default"])
        message = ("%s: %s = %g refused: it must be %s%s; kept %g"
                   % (obj.Label, prop, value, p["range"],
                      " (or 0 for automatic)" if p["zero_is_automatic"] else "", previous))
        self.refused.append(message)
        FreeCAD.Console.PrintWarning("HOMesh: %s\n" % message)
        setattr(obj, prop, _typed(p, previous))
        return False
