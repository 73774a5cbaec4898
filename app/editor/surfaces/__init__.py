"""Surfaces of the document's atoms drawn with the ribbon (``layer``), built in a process of
their own (``build``)."""
