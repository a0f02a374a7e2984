"""Widgets and styles every page uses: plots, grids, placeholders, traffic lights, colours."""
