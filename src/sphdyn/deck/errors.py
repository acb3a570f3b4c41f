"""From pydantic validation errors to deck problem lines.

:func:`explain` turns a ``ValidationError`` into one line per problem,
``<path>: <what is wrong>. Fix: <what to write>``, prefixed with the dotted
path of the offending key (union tags dropped, list entries ``[i]``) and
labelled with the name of the enclosing table.
"""

import re
from dataclasses import dataclass
from typing import Any, Literal, Optional, get_args, get_origin

from pydantic import BaseModel, ValidationError

from .introspect import field_annotation, is_model, metadata, strip_optional, variants
from .messages import choices, show, suggest
from .scope import get_key
from .values import Quantity, Vector


@dataclass
class Where:
    """An error location resolved against the schema and the raw deck."""

    path: str = ""
    label: str = ""
    owner: Optional[type[BaseModel]] = None
    key: Optional[str] = None
    annotation: Any = None


def locate(loc: tuple, raw: Any, root: type[BaseModel]) -> Where:
    """Resolve a pydantic error location.

    Union tags are dropped from the path, list indexes are written
    ``[i]``, and the name of the enclosing top-level table (if any) becomes
    the label.
    """
    where = Where(annotation=root)
    data = raw
    for item in loc:
        ann = strip_optional(where.annotation)
        if isinstance(item, int):
            where.path += f"[{item}]"
            args = get_args(ann)
            where.annotation = args[0] if args else None
            ok = isinstance(data, (list, tuple)) and 0 <= item < len(data)
            data = data[item] if ok else None
            name = get_key(data, "name") if isinstance(data, dict) else None
            if not where.label and isinstance(name, str):
                where.label = f"{where.path.split('[')[0]} '{name}'"
            continue
        members = variants(ann)
        if item in members:
            where.annotation = members[item]
            continue
        where.path = f"{where.path}.{item}" if where.path else str(item)
        where.owner = ann if is_model(ann) else None
        where.key = item
        info = where.owner.model_fields.get(item) if where.owner else None
        where.annotation = field_annotation(info)
        data = data.get(item) if isinstance(data, dict) else None
    return where


def _param_example(where: Where) -> str:
    """``--param key=value`` a user could write for the key at ``where``
    (``sphdyn material-test``): SI numbers, bare words."""
    key, ann = where.key, where.annotation
    core = strip_optional(ann)
    value = "<value>"
    if get_origin(core) is Literal:
        value = str(get_args(core)[0])
    elif core is bool:
        value = "true"
    for meta in metadata(ann):
        func = getattr(meta, "func", None)
        if isinstance(func, Quantity):
            value = f"{func.dim.si_example:g}"
    return f"--param {key}={value}"


#: ``key = "value"`` or ``key = value`` in a deck-syntax fix
_ASSIGNMENT = re.compile(r"\b([A-Za-z_]\w*) = (?:\"([^\"]*)\"|([\w.+-]+))")


def as_params(fix: str) -> str:
    """A fix written in deck syntax (``eos = "ideal_gas"``) in the syntax of
    ``sphdyn material-test`` (``--param eos=ideal_gas``)."""
    return _ASSIGNMENT.sub(lambda m: f"--param {m[1]}={m[2] if m[2] is not None else m[3]}",
                           fix)


def _example(where: Where) -> str:
    """A TOML snippet a user could write for the key at ``where``."""
    key, ann = where.key, where.annotation
    core = strip_optional(ann)
    if is_model(core):
        return f"a [{where.path}] table"
    if get_origin(core) is tuple and get_args(core):
        element = get_args(core)[0]
        if is_model(strip_optional(element)) or variants(element):
            return f"at least one [[{key}]] table"
    if get_origin(core) is Literal:
        return f"{key} = {choices(get_args(core))}"
    for meta in metadata(ann):
        func = getattr(meta, "func", None)
        if isinstance(func, Quantity):
            return f"{key} = \"{func.dim.example}\""
        if isinstance(func, Vector):
            return f"{key} = [x, y, z]"
    if core is str:
        return f"{key} = \"...\""
    return f"{key} = <value>"


_TYPE_NAMES = {
    "int_type": ("an integer", "give a whole number such as 2"),
    "int_from_float": ("an integer", "give a whole number such as 2"),
    "float_type": ("a number", "give a number such as 0.5"),
    "bool_type": ("true or false", "write true or false (no quotes)"),
    "string_type": ("text", "give text in quotes, e.g. \"steel\""),
    "tuple_type": ("a list", "give a list in brackets, e.g. [1, 2, 3]"),
    "list_type": ("a list", "give a list in brackets, e.g. [1, 2, 3]"),
    "model_type": ("a table", "write it as a table: [section] or { k = v }"),
    "model_attributes_type": ("a table",
                              "write it as a table: [section] or { k = v }"),
    "dict_type": ("a table", "write it as a table: [section] or { k = v }"),
}


def _explain_one(err: dict, where: Where, params: tuple = ()) -> tuple[str, str]:
    """Return ``(what, fix)`` for one pydantic error. With ``params`` (the
    keys a command line may set), fixes are written as ``--param key=value``."""
    if params:
        what, fix = _explain_one(err, where)
        if err["type"] == "missing":
            return what, f"add {_param_example(where)}"
        if err["type"] == "extra_forbidden":
            return what, suggest(str(where.key), list(params),
                                 f"remove it; the parameters: {', '.join(params)}")
        return what, as_params(fix)
    kind, ctx, value = err["type"], err.get("ctx") or {}, err.get("input")
    if kind == "deck":
        return ctx["what"], ctx["fix"]
    if kind == "missing":
        return "a required key is missing", f"add {_example(where)}"
    if kind == "extra_forbidden":
        moved = getattr(where.owner, "moved", {}).get(str(where.key))
        if moved is not None:
            return "the key moved", f"write it as {moved}"
        valid = list(where.owner.model_fields) if where.owner else []
        return "unknown key", suggest(
            str(where.key), valid,
            f"remove or rename it; valid keys here: {', '.join(valid)}")
    if kind == "literal_error":
        options = get_args(strip_optional(where.annotation))
        return (f"{show(value)} is not allowed",
                suggest(str(value), [str(a) for a in options],
                        f"use one of {choices(options)}"))
    if kind in ("union_tag_not_found", "union_tag_invalid"):
        key = ctx.get("discriminator", "").strip("'")
        tags = list(variants(where.annotation))
        allowed = choices(tags)
        if kind == "union_tag_not_found":
            return f"the key '{key}' is missing", f"add {key} = {allowed}"
        tag = str(ctx.get("tag"))
        return (f"{key} = '{tag}' is not known",
                suggest(tag, tags, f"use {key} = {allowed}"))
    if kind == "finite_number":
        return f"{show(value)} is not finite", "give a finite number"
    base_kind = kind.replace("_parsing", "_type")
    if base_kind in _TYPE_NAMES:
        name, fix = _TYPE_NAMES[base_kind]
        return f"{show(value)} is not {name}", fix
    return err["msg"], "see docs/deck-reference.md"


def format_problem(path: str, what: str, fix: str) -> str:
    """Join the parts of one problem line."""
    fix = fix if fix.endswith((".", "?", "!")) else fix + "."
    return f"{path or 'deck'}: {what}. Fix: {fix}"


def explain(exc: ValidationError, raw: Any, root: type[BaseModel],
            params: tuple = ()) -> list[str]:
    """Turn a ``ValidationError`` from validating ``raw`` into problem lines.

    Parameters
    ----------
    exc : ValidationError
        Raised by ``root.model_validate(raw)``.
    raw : Any
        The data that was validated (used to find names for the labels).
    root : type of BaseModel
        The model that was validated.
    params : tuple of str, optional
        The keys a command line sets with ``--param key=value`` (``sphdyn
        material-test``): fixes are then written in that syntax.

    Returns
    -------
    list of str
        ``<path>: <what is wrong>. Fix: <what to write>`` per problem.
    """
    lines = []
    for err in exc.errors(include_url=False):
        where = locate(err["loc"], raw, root)
        what, fix = _explain_one(err, where, params)
        if where.label and where.key != "name":
            what += f" in {where.label}"
        line = format_problem(where.path, what, fix)
        if line not in lines:
            lines.append(line)
    return lines
