"""The one adapter between VTK's interactor and the drag controller.

Observers on the interactor's left-button and mouse-move events run before the camera's
interactor style (higher priority). Each event becomes a :class:`~app.editor.interaction.drag.PointerEvent`
(the ray under the pointer, from the renderer's display-to-world transform); when the
handler uses it, the event is aborted so the camera does not also rotate. Mouse events
from Qt and events invoked on the interactor by tests take exactly this path.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pyvista as pv
from pyvista.core.utilities.misc import try_callback

from app.editor.interaction.drag import PointerEvent

PRIORITY = 10.0
"""Above the interactor style's observers (priority 0)."""
EVENTS = {"LeftButtonPressEvent": "press", "MouseMoveEvent": "move", "LeftButtonReleaseEvent": "release"}


class PointerAdapter:
    """Feeds the left-button events of ``plotter`` to ``handler`` as pointer events.

    ``handler`` returns True when it used an event; the interactor style then never sees it.
    Exceptions in the handler become warnings (as in pyvista's own callbacks).
    """

    def __init__(self, plotter: pv.BasePlotter, handler: Callable[[PointerEvent], bool]) -> None:
        self.plotter = plotter
        self.handler = handler
        self._interactor = plotter.iren.interactor
        self._tags = {
            kind: self._interactor.AddObserver(name, self._observer(kind), PRIORITY) for name, kind in EVENTS.items()
        }

    def close(self) -> None:
        """Stop observing the interactor."""
        for tag in self._tags.values():
            self._interactor.RemoveObserver(tag)
        self._tags.clear()

    def event_at(self, kind: str, x: int, y: int, *, shift: bool = False, double: bool = False) -> PointerEvent:
        """The pointer event at display position (x, y) (VTK pixels, origin bottom left)."""
        renderer = self.plotter.renderer
        near, far = _world(renderer, x, y, 0.0), _world(renderer, x, y, 1.0)
        direction = (far - near) / np.linalg.norm(far - near)
        camera = renderer.GetActiveCamera()
        view = np.array(camera.GetDirectionOfProjection())
        height = max(renderer.GetSize()[1], 1)
        if camera.GetParallelProjection():
            return PointerEvent(kind, near, direction, view, 2.0 * camera.GetParallelScale() / height, 0.0, shift, double)
        per_depth = 2.0 * math.tan(math.radians(camera.GetViewAngle()) / 2.0) / height
        eye_distance = float((near - np.array(camera.GetPosition())) @ view)
        return PointerEvent(kind, near, direction, view, per_depth * eye_distance, per_depth * float(direction @ view),
                            shift, double)

    def _observer(self, kind: str) -> Callable[[object, str], None]:
        def observe(interactor: object, _name: str) -> None:
            try_callback(self._dispatch, interactor, kind)

        return observe

    def _dispatch(self, interactor: object, kind: str) -> None:
        x, y = interactor.GetEventPosition()  # type: ignore[attr-defined]
        event = self.event_at(kind, x, y, shift=bool(interactor.GetShiftKey()),  # type: ignore[attr-defined]
                              double=kind == "press" and interactor.GetRepeatCount() > 0)  # type: ignore[attr-defined]
        if self.handler(event):
            interactor.GetCommand(self._tags[kind]).SetAbortFlag(1)  # type: ignore[attr-defined]


def _world(renderer: object, x: float, y: float, z: float) -> np.ndarray:
    renderer.SetDisplayPoint(x, y, z)  # type: ignore[attr-defined]
    renderer.DisplayToWorld()  # type: ignore[attr-defined]
    point = np.array(renderer.GetWorldPoint())  # type: ignore[attr-defined]
    return point[:3] / point[3]
