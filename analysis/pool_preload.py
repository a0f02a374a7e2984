"""Imported once by the process pool's fork server (analysis.parallel), before it forks the workers.

What every worker would otherwise build for itself on its first fit with the air load: the table of
the Struve term (~0.17 s of CPU). The GUI starts a pool for each diagnosis, so its workers are new each
time; built here, the table is paid for once per process and inherited by every worker forked after.
"""
from analysis.effects.mechanical import build_tables

build_tables()
