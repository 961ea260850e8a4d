"""One line per invalid scenario: pydantic's validation errors turned into a
:class:`~dcee.errors.DceeInputError` naming the field the user wrote and what it allows (a misspelt
field gets the closest field of its section)."""

from __future__ import annotations

import difflib
from typing import Any, get_args, get_origin

from pydantic import BaseModel, ValidationError

from dcee.errors import DceeInputError
from dcee.scenarios.schema.common import FIELD_MARK
from dcee.scenarios.schema.truth_models import TRUTH_KINDS


def one_line_error(exc: ValidationError, root: type[BaseModel]) -> DceeInputError:
    """The first relevant error of ``exc`` (raised validating ``root``) as one line."""
    errors = exc.errors()
    # a union (truth.model) reports every branch; the literal branch's complaint is noise
    # when a table was given, so report the error of the branch the input was meant for
    relevant = [e for e in errors if not any(str(p).startswith("literal[") for p in e["loc"])]
    # a misspelt field first: it is why a required one is missing ([agnet] leaves no [agent])
    relevant.sort(key=lambda e: e["type"] != "extra_forbidden")
    err = (relevant or errors)[0]
    # drop pydantic's internal union labels ("tagged-union[...]"), keep the user's field path
    parts = [str(p) for p in err["loc"] if "[" not in str(p)]
    if len(parts) > 2 and parts[:2] == ["truth", "model"] and parts[2] in TRUTH_KINDS:
        del parts[2]  # the union's tag, not a field the user wrote
    loc = ".".join(parts) or "scenario"
    msg = err["msg"].removeprefix("Value error, ")
    if msg.startswith(FIELD_MARK):  # a cross-field check that names its own field
        loc, _, msg = msg.removeprefix(FIELD_MARK).partition(": ")
    if err["type"] == "extra_forbidden":
        msg = _unknown_field(root, parts)
    elif err["type"] == "missing":  # its input is the whole section: say what is missing
        section = ".".join(parts[:-1]) or "the scenario"
        msg = f"required: {section} does not give it (`dcee show paper:1` prints a whole scenario)"
    elif "input" in err and err["type"] != "value_error":
        msg = f"{msg} (got {err['input']!r})"
    return DceeInputError(loc, msg)


def _unknown_field(root: type[BaseModel], parts: list[str]) -> str:
    """The message for a misspelt field at ``parts`` (its dotted path): the closest field of its
    section and the section's fields."""
    fields = _fields_at(root, parts[:-1])
    if not fields:
        return "unknown field"
    close = difflib.get_close_matches(parts[-1], sorted(fields), n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    section = ".".join(parts[:-1]) or "the top level"
    return f"unknown field{hint} (fields of {section}: {', '.join(sorted(fields))})"


def _fields_at(root: type[BaseModel], parents: list[str]) -> set[str]:
    """The field names of the section at a dotted path (a union's members' together; a table
    by name, such as ``prior.q``, is its values' section); empty where it is not a section."""
    models: list[type[BaseModel]] = [root]
    keyed = False  # the previous part named a table by name: this part is one of its keys
    for name in parents:
        if keyed:
            keyed = False
            continue
        nxt: list[type[BaseModel]] = []
        for model in models:
            field = model.model_fields.get(name)
            if field is None:
                continue
            if get_origin(field.annotation) is dict:
                keyed = True
                nxt += [m for a in get_args(field.annotation)[1:] for m in _models_in(a)]
            else:
                nxt += _models_in(field.annotation)
        models = nxt
    return {f for m in models for f in m.model_fields}


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for a in get_args(annotation) if a is not None for m in _models_in(a)]
