"""Reading deck annotations: Optional and Annotated wrappers, union variants.

Used to turn pydantic error locations into deck paths
(:mod:`sphdyn.deck.errors`), by the generated reference
(:mod:`sphdyn.deck.docgen`) and by checks that look at the keys of a table.
"""

import types
from typing import Annotated, Any, Union, get_args, get_origin

from pydantic import BaseModel

def strip_optional(annotation: Any) -> Any:
    """Remove ``Annotated`` wrappers and ``Optional`` from an annotation."""
    while True:
        origin = get_origin(annotation)
        if origin is Annotated:
            annotation = get_args(annotation)[0]
        elif origin in (Union, types.UnionType) and type(None) in get_args(
                annotation):
            rest = [a for a in get_args(annotation) if a is not type(None)]
            annotation = rest[0] if len(rest) == 1 else Union[tuple(rest)]
        else:
            return annotation


def variants(annotation: Any) -> dict[str, type[BaseModel]]:
    """Return ``{tag: model}`` of a discriminated union, else ``{}``."""
    annotation = strip_optional(annotation)
    if get_origin(annotation) not in (Union, types.UnionType):
        return {}
    found = {}
    for member in get_args(annotation):
        for key in ("model", "shape"):
            info = getattr(member, "model_fields", {}).get(key)
            if info is not None:
                found[get_args(info.annotation)[0]] = member
    return found


def is_model(annotation: Any) -> bool:
    """Whether ``annotation`` is a pydantic model class."""
    return isinstance(annotation, type) and issubclass(annotation, BaseModel)


def field_annotation(info: Any) -> Any:
    """The annotation of a field with its Annotated metadata put back."""
    if info is None:
        return None
    if info.metadata:
        return Annotated[info.annotation, *info.metadata]
    return info.annotation


def metadata(annotation: Any) -> list:
    """All Annotated metadata found while unwrapping ``annotation``."""
    found = []
    while True:
        origin = get_origin(annotation)
        if origin is Annotated:
            found.extend(annotation.__metadata__)
            annotation = get_args(annotation)[0]
        elif origin in (Union, types.UnionType) and type(None) in get_args(
                annotation):
            annotation = next(a for a in get_args(annotation)
                              if a is not type(None))
        else:
            return found
