"""JSON values made read-only for a frozen result, and plain again for json.dumps and pickling.

A result's validity (analysis.validity.result) and imported curves' (analysis.validity.imported_curves) keep
what they were given as mapping proxies and tuples, so that a result crossing threads cannot be changed; they
give plain dicts and lists back where JSON is written or a copy is pickled.
"""
from __future__ import annotations

from types import MappingProxyType
from typing import Any, Mapping


def frozen(value: Any) -> Any:
    """A JSON value made read-only: objects as mapping proxies, lists as tuples."""
    if isinstance(value, Mapping):
        return MappingProxyType({str(k): frozen(v) for k, v in value.items()})
    if isinstance(value, (list, tuple)):
        return tuple(frozen(v) for v in value)
    return value


def thawed(value: Any) -> Any:
    """A frozen JSON value as plain dicts and lists again (what json.dumps and analysis.json_finite take)."""
    if isinstance(value, Mapping):
        return {k: thawed(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [thawed(v) for v in value]
    return value


def rebuilt(cls: type, fields: dict) -> Any:
    """`cls(**fields)`: how a frozen result made of these values is unpickled (its __reduce__)."""
    return cls(**fields)
