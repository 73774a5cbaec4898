"""The Qt editor: the document, undo commands, picking, naming what is under the pointer and
dragging, the scripting API, the Help texts, image export, surfaces built in a process of
their own, the main window and how it is launched."""
