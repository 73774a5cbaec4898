"""The Qt editor. Here: the document and its undo commands, the validation and the map
correlation that follow it, the main window (the composition root: its frame with Qt alone,
then the parts it is furnished with, ``window_parts``), the window busy opening a file and the
molecule sketched meanwhile (``sketch``), what PySide would keep of every module's source
(``source_reads``), its status bar and its one composition per event, the ``rw`` scripting API and
the launch from the command line.
Rooms: ``features`` (the window's features and their menus), ``interaction`` (the mouse in
the view), ``scene`` (the 3D scene, one layer per representation), ``surfaces``, ``docks`` and
``persistence`` (journals and sessions)."""
