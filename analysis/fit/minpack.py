"""MINPACK's lmdif as scipy.optimize.leastsq(full_output=True) runs it, without importing scipy.optimize.

Why: importing the scipy.optimize package takes about 0.4 s (it loads scipy.linalg, whose array-API layer
imports every submodule of numpy: f2py, testing, polynomial, ...), two thirds of what `linpar analyze` spends
beyond reading the recording and taking its FFTs. A fit needs two compiled routines of it: MINPACK's
lmdif (scipy.optimize._minpack) and LAPACK's dtrtri (scipy.linalg._flapack) for the covariance. Both are
loaded here from their files, which takes under 10 ms; the steps around them are leastsq's own (scipy 1.16):
one evaluation to learn the residual's length, lmdif, and the covariance from the triangular factor.

scipy is pinned (pyproject.toml). Should its files ever be laid out otherwise, the public leastsq is used
(`load_compiled_routines` returns None) and only the start-up is slower: tests/analysis/fit/test_minpack.py
checks both paths give the same bits.
"""
from __future__ import annotations

import importlib.machinery
import importlib.util
import sys
import threading
from functools import lru_cache
from pathlib import Path
from types import ModuleType
from typing import Callable, NamedTuple

import numpy as np

# leastsq's outcomes that leave a usable solution and covariance.
SUCCESS = (1, 2, 3, 4)


class LeastSquares(NamedTuple):
    """What leastsq(full_output=True) returns that the fits use."""

    best: np.ndarray
    covariance: np.ndarray | None     # None unless the fit succeeded and the factor is invertible
    ier: int


def leastsq(func: Callable[[np.ndarray], np.ndarray], x0, *, xtol: float, ftol: float, gtol: float,
            maxfev: int, epsfcn: float, factor: float) -> LeastSquares:
    """scipy.optimize.leastsq(func, x0, full_output=1, xtol=, ftol=, gtol=, maxfev=, epsfcn=, factor=,
    diag=None), forward differences, in the same steps; exceptions raised by `func` pass through."""
    routines = load_compiled_routines()
    if routines is None:
        from scipy.optimize import leastsq as public_leastsq

        best, covariance, _, _, ier = public_leastsq(func, x0, full_output=1, xtol=xtol, ftol=ftol, gtol=gtol,
                                                     maxfev=maxfev, epsfcn=epsfcn, factor=factor, diag=None)
        return LeastSquares(best, covariance, ier)
    minpack, flapack = routines
    x0 = np.asarray(x0).flatten()
    n = len(x0)
    m = np.atleast_1d(func(x0)).shape[0]      # leastsq's own first evaluation: the residual's length
    if n > m:
        raise TypeError(f"Improper input: func input vector length N={n} must not exceed func output vector "
                        f"length M={m}")
    best, infodict, ier = minpack._lmdif(func, x0, (), 1, ftol, xtol, gtol, maxfev, epsfcn, factor, None)
    return LeastSquares(best, _covariance(flapack, infodict) if ier in SUCCESS else None, int(ier))


def _covariance(flapack: ModuleType, infodict: dict) -> np.ndarray | None:
    """The unscaled covariance of the solution, from MINPACK's QR factor, as leastsq computes it: the inverse
    of R (upper triangular) by LAPACK, its rows put back in the parameters' order, times its transpose."""
    permutation = infodict["ipvt"]       # 0-based in scipy 1.16's compiled lmdif
    n = len(permutation)
    r = np.triu(np.transpose(infodict["fjac"])[:n, :])
    try:
        inverse, info = flapack.dtrtri(r)
    except ValueError:
        return None
    if info != 0:
        return None
    inverse[permutation] = inverse.copy()
    return inverse @ inverse.T


# Fits run in several threads at once (the GUI's background refits): the modules are loaded once.
_LOADING = threading.Lock()


def load_compiled_routines() -> tuple[ModuleType, ModuleType] | None:
    """The compiled lmdif and LAPACK modules (loaded on the first call); None if they cannot be."""
    with _LOADING:
        return _load_compiled_routines()


@lru_cache(maxsize=1)
def _load_compiled_routines() -> tuple[ModuleType, ModuleType] | None:
    """scipy's compiled lmdif and LAPACK modules, loaded from their files; None if they are not where scipy
    1.16 keeps them."""
    spec = importlib.util.find_spec("scipy")          # finds the package without importing it
    if spec is None or not spec.submodule_search_locations:
        return None
    folder = Path(list(spec.submodule_search_locations)[0])
    minpack = _extension(folder / "optimize", "scipy.optimize._minpack")
    flapack = _extension(folder / "linalg", "scipy.linalg._flapack")
    if minpack is None or flapack is None or not hasattr(minpack, "_lmdif") or not hasattr(flapack, "dtrtri"):
        return None
    return minpack, flapack


def _extension(folder: Path, name: str) -> ModuleType | None:
    """The compiled module `name` from `folder`; the one already imported if scipy has loaded it."""
    if name in sys.modules:
        return sys.modules[name]
    stem = name.rpartition(".")[2]
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        file = folder / f"{stem}{suffix}"
        if file.is_file():
            spec = importlib.util.spec_from_file_location(name, file)
            try:
                module = importlib.util.module_from_spec(spec)
                spec.loader.exec_module(module)
            except ImportError:
                return None
            return module
    return None
