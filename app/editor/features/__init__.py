"""The window's features, each with its actions, menu entries and slots, which it puts in the
menus itself (:mod:`~app.editor.features.menus`): structure files, sessions and crash
recovery, editing, navigation and selection, maps and fits (the fits loaded with the first),
image export and help."""
