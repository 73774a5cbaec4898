"""The 3D view: the widget that draws one frame per event (``view``, ``widget_view`` and what
both share, ``view_base``), the scene that draws the document layer by layer (``scene``, its
layers in ``layers/``), the compared structures (``overlay``) and the density map
(``map_mesh``), and the numpy geometry behind them (``curves``, ``tube``, ``molecule``)."""
