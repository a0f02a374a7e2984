"""JSON that is always valid: never NaN or Infinity (what `linpar ... --json` prints, the JSON exports).

JSON has no NaN and no infinities (Python's json writes them, other readers
refuse them). Every document printed or exported goes through `dumps`: a non-finite
number becomes null, and when it is the "value" of an object (a parameter,
a finding) the object says why in "reason", as a parameter that could not be
measured does. numpy scalars and arrays become plain numbers and lists.
"""
from __future__ import annotations

import json
import math
from typing import Any


def finite(x: Any) -> Any:
    """`x` with every non-finite float replaced by None (and a reason beside a non-finite "value")."""
    if isinstance(x, dict):
        out = {str(k): finite(v) for k, v in x.items()}
        value = x.get("value")
        if _non_finite(value) and "reason" not in x:
            out["reason"] = f"not a finite number ({_plain(value)})"
        return out
    if isinstance(x, (list, tuple)):
        return [finite(v) for v in x]
    if hasattr(x, "tolist") and not isinstance(x, (str, bytes)):       # numpy scalars and arrays
        return finite(x.tolist())
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def _plain(value: Any) -> Any:
    return value.tolist() if hasattr(value, "tolist") else value


def _non_finite(value: Any) -> bool:
    value = _plain(value)
    return isinstance(value, float) and not math.isfinite(value)


def dumps(doc: Any, **kwargs) -> str:
    """json.dumps of finite(doc): valid JSON whatever numbers the document holds."""
    kwargs.setdefault("ensure_ascii", False)
    return json.dumps(finite(doc), allow_nan=False, default=_unknown, **kwargs)


def _unknown(value: Any) -> Any:
    if hasattr(value, "__fspath__"):
        return str(value)
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")
