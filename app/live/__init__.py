"""A measurement as it runs and what follows it on one driver: live spectra, the level series and the Series page."""
