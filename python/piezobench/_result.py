"""Typed results: attribute access, to_dict(), a readable repr."""

import numpy as np


def _plain(value):
    if isinstance(value, Result) or (hasattr(type(value), "to_dict") and not isinstance(value, type)):
        return value.to_dict()
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


class Result:
    """A result of piezobench: its fields are attributes (numbers, strings, numpy arrays, lists
    and nested results). to_dict() gives plain dicts and lists (arrays kept as numpy arrays)."""

    __slots__ = ("_type", "_fields")

    def __init__(self, type_name, fields):
        object.__setattr__(self, "_type", type_name)
        object.__setattr__(self, "_fields", dict(fields))

    def __getattr__(self, name):
        try:
            return self._fields[name]
        except KeyError:
            raise AttributeError(f"{self._type} has no field {name!r}; fields: {', '.join(self._fields)}") from None

    def __setattr__(self, name, value):
        raise AttributeError(f"{self._type} is read-only")

    def __getitem__(self, name):
        return self._fields[name]

    def __contains__(self, name):
        return name in self._fields

    def __dir__(self):
        return list(self._fields) + ["to_dict", "fields"]

    def fields(self):
        """The names of the fields, in order."""
        return list(self._fields)

    def to_dict(self):
        """The fields as a dict (nested results as dicts; arrays stay numpy arrays)."""
        return {k: _plain(v) for k, v in self._fields.items()}

    def __eq__(self, other):
        return isinstance(other, Result) and self._type == other._type and self._fields.keys() == other._fields.keys() \
            and all(np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b
                    for a, b in zip(self._fields.values(), other._fields.values()))

    def __repr__(self):
        return _repr(self._type, self._fields.items())


def _repr(type_name, items):
    parts = []
    for k, v in items:
        if isinstance(v, np.ndarray):
            parts.append(f"{k}=<{v.dtype} array {v.shape}>")
        elif isinstance(v, (list, tuple)) and len(v) > 4:
            parts.append(f"{k}=[{len(v)} items]")
        else:
            r = repr(v)
            parts.append(f"{k}={r if len(r) <= 60 else r[:57] + '...'}")
    return f"{type_name}({', '.join(parts)})"


# Typed results bound as classes (campaign.UnitAnalysis, ident.IffPlantFit, ...): their fields are
# read-only properties, in the order of the C++ struct.
def properties(cls):
    """The names of the read-only properties of a typed result class, in declaration order."""
    names = []
    for klass in reversed(cls.__mro__):
        for name, attr in vars(klass).items():
            if isinstance(attr, property) and not name.startswith("_") and name not in names:
                names.append(name)
    return names


def typed_to_dict(obj):
    """The properties of a typed result as a dict (nested results as dicts; arrays stay numpy arrays)."""
    return {name: _plain(getattr(obj, name)) for name in properties(type(obj))}


def typed_repr(obj):
    return _repr(type(obj).__name__, ((name, getattr(obj, name)) for name in properties(type(obj))))
