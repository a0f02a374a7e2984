"""The Results page and what it shows: parameters, fit quality, Z / Hx / SPL curves, what a broken measurement still measured."""
