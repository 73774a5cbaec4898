"""From the mouse to the document: the one adapter of VTK's mouse events (``picking``), plain
pointer events and the drag controller (``drag``), naming what is under the pointer
(``identify``), and where each gesture in the view goes (``gestures``)."""
