"""Typed file formats: one pydantic model per file a user writes, one way to read it.

Every input file (curve JSON, normal-curve JSON, the UPD model TOML, the elements
TOML, the scene TOML, a ring archive's ``system.json``) is described once by a
:class:`FileModel` subclass: types, ranges, lengths, required and allowed keys. From
that one description follow the checks (:func:`parse`), the messages and the JSON
Schema published in the documentation (``model_json_schema()``).

The models are strict: a boolean is not a number (TOML ``mu = true``), a string is not
a number (``m_d = "0.005"``), numbers are finite, and an unknown key is refused (a typo
never passes silently). :func:`parse` turns pydantic's errors into one line that names
the file and the key's path, ``upd.toml: disk.blades: ...``, raised as ValueError.
"""
from __future__ import annotations

import types
import typing

from pydantic import BaseModel, ConfigDict, ValidationError

#: Longest rendering of a bad value in a message (the rest is cut: messages stay one line).
MAX_SHOWN = 60


class FileModel(BaseModel):
    """Base of every file model: strict types, finite numbers, unknown keys refused."""

    model_config = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False, frozen=True)


def parse(model: type[BaseModel], data, source: str):
    """Validate ``data`` (the parsed file: dict, list...) against ``model``.

    Parameters
    ----------
    model : FileModel subclass
    data : object
        What ``json.loads`` / ``tomllib.loads`` returned.
    source : str
        The file's name, first in every message.

    Returns
    -------
    An instance of ``model``.

    Raises
    ------
    ValueError
        One line: ``source: key.path: what is wrong`` (the first problem, and how
        many more there are).
    """
    try:
        return model.model_validate(data)
    except ValidationError as err:
        raise ValueError(message(model, err, source)) from None
    except (TypeError, ValueError, OverflowError) as err:   # a validator's own arithmetic
        raise ValueError(f"{source}: {str(err).splitlines()[0] if str(err) else type(err).__name__}") from None


def message(model: type[BaseModel], err: ValidationError, source: str) -> str:
    """The one-line message of ``err``: its first error with the key's path."""
    errors = err.errors(include_url=False)
    first = errors[0]
    loc = tuple(first.get("loc", ()))
    cut = next((i for i, part in enumerate(loc) if _is_union_label(part)), None)
    what = describe(model, first)
    if cut is not None:   # a value of several allowed forms (a number or a list...) that fits none
        loc, what = loc[:cut], f"no allowed form fits ({what})"
        errors = [e for e in errors if tuple(e["loc"][:cut]) != loc]
        errors.insert(0, first)
    text = f"{source}: " + (f"{key_path(loc)}: " if loc else "") + what
    if len(errors) > 1:
        text += f" (and {len(errors) - 1} more problem{'s' if len(errors) > 2 else ''})"
    return " ".join(text.split())   # one line whatever the input held


def _is_union_label(part) -> bool:
    """pydantic names the member of a union a value was tried against in the error's
    location ('constrained-float', 'list[...]'); no key of a file model looks like that."""
    return isinstance(part, str) and ("-" in part or "[" in part or part in ("float", "int", "str", "list"))


def key_path(loc) -> str:
    """``("disk", "blades")`` -> ``disk.blades``; list indices as ``[i]``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def describe(model: type[BaseModel], error: dict) -> str:
    """What is wrong, in words a user acts on (pydantic's message, reworded where it helps)."""
    kind, value = error["type"], error.get("input")
    if kind == "missing":
        return "missing (required)"
    if kind == "extra_forbidden":
        known = known_keys(model, error["loc"][:-1])
        return "unknown key" + (f" (known here: {', '.join(known)})" if known else "")
    if kind in ("value_error", "assertion_error"):
        return str(error["ctx"]["error"]) if "ctx" in error else error["msg"]
    if kind == "union_tag_invalid":   # a tagged table (e.g. an element's type) of an unknown kind
        ctx = error.get("ctx", {})
        return f"{ctx.get('discriminator', 'type')}: unknown {ctx.get('tag')!r} (one of {ctx.get('expected_tags')})"
    text = error["msg"]
    text = text.replace("Input should be", "must be").replace("Input", "the value")
    if kind in ("less_than", "less_than_equal", "greater_than", "greater_than_equal"):
        bound = next(iter(error.get("ctx", {}).values()), None)
        if isinstance(bound, (int, float)) and not isinstance(bound, bool):  # 1e100, not its 101 digits
            text = f"must be {kind.replace('_equal', ' or equal to').replace('_', ' ')} {bound:g}"
        why = reason(model, error["loc"])
        if why:
            return f"{text}, got {shown(value)}: {why}"
    if kind == "finite_number":
        text = "must be a finite number"
    if kind == "model_type" or kind == "dict_type":
        text = "must be a table (a JSON object)"
    if kind in ("too_long", "too_short"):
        ctx = error.get("ctx", {})
        bound = ctx.get("max_length") if kind == "too_long" else ctx.get("min_length")
        word = "string of" if isinstance(value, str) else "list of"
        return (f"must be a {word} at {'most' if kind == 'too_long' else 'least'} {bound} "
                f"item{'s' if bound != 1 else ''}, got {ctx.get('actual_length', len(value))}")
    return f"{text}, got {shown(value)}"


def shown(value) -> str:
    """A value as a message shows it: its kind and (cut) representation."""
    kinds = {dict: "a table", list: "a list", str: "a string", bool: "a boolean",
             int: "an integer", float: "a number", type(None): "null"}
    kind = kinds.get(type(value), type(value).__name__)
    if isinstance(value, (dict, list)):
        return f"{kind} of {len(value)}"
    text = repr(value)
    if len(text) > MAX_SHOWN:
        text = text[:MAX_SHOWN] + "..."
    return kind if value is None else f"{kind} {text}"


def reason(model, loc) -> str:
    """The ``why`` of the innermost field on ``loc`` (``Field(json_schema_extra={"why": ...})``:
    why a bound is where it is), or ""."""
    node, why = model, ""
    for part in loc:
        m = _model_of(node)
        if m is not None and isinstance(part, str) and part in m.model_fields:
            extra = m.model_fields[part].json_schema_extra
            why = extra.get("why", why) if isinstance(extra, dict) else why
        node = _step(node, part)
        if node is None:
            break
    return why


def known_keys(model, loc) -> list[str]:
    """Keys allowed at ``loc`` (best effort: [] where the path cannot be followed)."""
    node = model
    for part in loc:
        node = _step(node, part)
        if node is None:
            return []
    node = _model_of(node)
    if node is None:
        return []
    return [f.alias or name for name, f in node.model_fields.items()]


def _step(node, part):
    node = _unwrap(node)
    if isinstance(node, type) and issubclass(node, BaseModel):
        f = node.model_fields.get(part) if isinstance(part, str) else None
        return f.annotation if f is not None else None
    origin = typing.get_origin(node)
    args = typing.get_args(node)
    if origin in (list, tuple) and args and isinstance(part, int):
        return args[0]
    if origin is dict and len(args) == 2 and isinstance(part, str):
        return args[1]
    if origin in (typing.Union, types.UnionType) and isinstance(part, str):   # tagged union: loc holds the tag
        for arg in args:
            m = _model_of(arg)
            if m is not None and _tag_of(m) == part:
                return m
    return None


def _unwrap(node):
    """``Annotated[X, ...]`` -> X; ``X | None`` -> X."""
    while typing.get_origin(node) is typing.Annotated:
        node = typing.get_args(node)[0]
    if typing.get_origin(node) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(node) if a is not type(None)]
        if len(args) == 1:
            return _unwrap(args[0])
    return node


def _model_of(node):
    node = _unwrap(node)
    return node if isinstance(node, type) and issubclass(node, BaseModel) else None


def _tag_of(model) -> str | None:
    f = model.model_fields.get("type")
    if f is None:
        return None
    args = typing.get_args(_unwrap(f.annotation))
    return args[0] if len(args) == 1 and isinstance(args[0], str) else None
