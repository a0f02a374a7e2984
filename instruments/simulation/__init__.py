"""Simulated loudspeakers that stream block by block (the virtual rig's drivers).

``BlockDriver`` is the interface; ``LinearBlockDriver`` is the small-signal
model of analysis.model.composed as FIR filters. Other implementations (a nonlinear
time-domain driver) live in their own modules and are imported from there,
not re-exported here, so that importing this package stays cheap.
"""
from instruments.simulation.block_driver import BlockDriver, DriverBlock
from instruments.simulation.linear_driver import LinearBlockDriver

__all__ = ["BlockDriver", "DriverBlock", "LinearBlockDriver"]
