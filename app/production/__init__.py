"""The Production page: the statistics of a production line's archive, its charts and the worker that computes them.
"""
