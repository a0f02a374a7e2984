"""The Large-signal page and its plots.
"""
