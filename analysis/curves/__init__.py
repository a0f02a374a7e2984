"""Curves imported from other tools: their fit over each channel's own range (fitting) and each line's noise from the curve's local scatter (noise).
"""
