"""Imported once by the process pool's fork server (analysis.parallel), before it forks the workers.

What every worker would otherwise build for itself on its first fit: the table of the air load's Struve term
(~0.17 s of CPU) and MINPACK's compiled routines (analysis.fit.minpack, a few ms). The GUI starts a pool for
each diagnosis, so its workers are new each time; built here, both are paid for once per process and
inherited by every worker forked after.
"""
from analysis.effects.mechanical import build_tables
from analysis.fit.minpack import load_compiled_routines

build_tables()
load_compiled_routines()
