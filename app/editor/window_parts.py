"""What the editor window is built from beyond Qt: the document, the 3D view and its scene,
the features and the docks' panels (with numpy, scipy, gemmi, VTK and PyVista under them).

:class:`~app.editor.main_window.MainWindow` imports this module only when it is furnished, so
that a window can be shown, with its menus and docks, while these load
(:func:`app.editor.launch.run_open` imports them in a thread meanwhile).
"""

from __future__ import annotations

from app.editor.docks.comparison import ComparisonPanel
from app.editor.docks.console import PythonConsole
from app.editor.docks.map_panel import MapPanel
from app.editor.docks.measurements import MeasurementsPanel
from app.editor.docks.panels import DisplayPanel, RibbonDimensionPanel
from app.editor.docks.ramachandran import RamachandranPanel
from app.editor.docks.sequence import SequenceBar
from app.editor.docks.surfaces import SurfacePanel
from app.editor.docks.validation import ValidationPanel
from app.editor.document import Document
from app.editor.features.clipping import Clipping
from app.editor.features.editing import Editing
from app.editor.features.export import ImageExport
from app.editor.features.files import Files
from app.editor.features.help import Help
from app.editor.features.maps import MapsAndFits
from app.editor.features.measuring import Measuring
from app.editor.features.models import Models
from app.editor.features.navigation import Navigation
from app.editor.features.sessions import Sessions
from app.editor.interaction.drag import DragController
from app.editor.interaction.gestures import Gestures
from app.editor.live_validation import LiveValidation
from app.editor.map_correlation import LiveCorrelation
from app.editor.persistence.journal import Journal
from app.editor.scene.layers.validation_markers import ValidationMarkers
from app.editor.scene.map_mesh import MapMesh
from app.editor.scene.overlay import Comparison, ComparisonView
from app.editor.scene.scene import Scene
from app.editor.scene.view import new_view
from app.editor.scripting import EditorAPI
from app.editor.status_bar import StatusBar
from app.editor.surfaces.layer import SurfaceLayer

__all__ = [
    "Clipping", "Comparison", "ComparisonPanel", "ComparisonView", "DisplayPanel", "Document", "DragController",
    "Editing", "EditorAPI", "Files", "Gestures", "Help", "ImageExport", "Journal", "LiveCorrelation",
    "LiveValidation", "MapMesh", "MapPanel", "MapsAndFits", "MeasurementsPanel", "Measuring", "Models",
    "Navigation", "PythonConsole", "RamachandranPanel", "RibbonDimensionPanel", "Scene", "SequenceBar",
    "Sessions", "StatusBar", "SurfaceLayer", "SurfacePanel", "ValidationMarkers", "ValidationPanel", "new_view",
]
