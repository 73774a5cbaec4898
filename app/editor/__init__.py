"""The Qt editor: the document, undo commands, picking and dragging, the main window and how
it is launched."""
