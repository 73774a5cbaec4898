"""The dock panels of the editor window: ribbon dimension and display, the sequence bar,
compared structures, surfaces, the map, validation, the Ramachandran plot and the Python
console; and where the docks go, their layout kept between runs (``layout``)."""
