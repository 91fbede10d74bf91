"""Paths of the workbench's resources (icons, task panel layouts), found relative to this
package.

Works both in the source tree and in the staged/installed Mod folder, where Resources/ sits
beside the homesh package. Importing this module does not load the compiled core.
"""

import os

RESOURCES = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "Resources")


def icon(name="homesh.svg"):
    return os.path.join(RESOURCES, "icons", name)


def ui(name):
    """The Qt Designer file of a task panel (Resources/ui/<name>)."""
    return os.path.join(RESOURCES, "ui", name)
