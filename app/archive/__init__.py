"""The Archive page and its parts: the filter, the table, the overlay of stored curves and the worker that reads the archive.
"""
