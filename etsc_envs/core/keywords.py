"""An environment's keyword arguments made visible: its docstring and signature list the fields
of its parameter dataclass, each with its default and the comment the dataclass gives it.

The parameter dataclasses (``<problem>/params.py``) document each field by a string right
after it; :func:`field_docs` reads those strings from the source, and
:func:`document_keywords` appends them to an environment class's docstring and replaces the
``**overrides`` of its ``__init__`` signature by the fields themselves, so that ``help(env)``,
``inspect.signature`` and editors show every keyword.
"""

from __future__ import annotations

import ast
import dataclasses
import inspect
import itertools
import textwrap
from collections.abc import Callable
from typing import Any, TypeVar

EnvClass = TypeVar("EnvClass", bound=type)


def field_docs(params_class: type) -> dict[str, str]:
    """Field name → the string documenting it in ``params_class``'s source (fields without one
    map to ``""``)."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(params_class)))
    definition = tree.body[0]
    if not isinstance(definition, ast.ClassDef):
        raise TypeError(f"params_class must be a class, got {params_class!r}")
    body = definition.body
    docs = {field.name: "" for field in dataclasses.fields(params_class)}
    for statement, following in itertools.pairwise(body):
        if (
            isinstance(statement, ast.AnnAssign)
            and isinstance(statement.target, ast.Name)
            and isinstance(following, ast.Expr)
            and isinstance(following.value, ast.Constant)
            and isinstance(following.value.value, str)
        ):
            docs[statement.target.id] = inspect.cleandoc(following.value.value)
    return docs


def _field_default(field: dataclasses.Field) -> Any:
    if field.default is not dataclasses.MISSING:
        return field.default
    if field.default_factory is not dataclasses.MISSING:
        return field.default_factory()
    return inspect.Parameter.empty


def keywords_section(params_class: type) -> str:
    """The docstring section listing ``params_class``'s fields as keyword arguments."""
    docs = field_docs(params_class)
    lines = [
        f"Keyword arguments (fields of :class:`{params_class.__name__}`; the defaults are the "
        "paper's scenario):",
        "",
    ]
    for field in dataclasses.fields(params_class):
        default = _field_default(field)
        shown = "required" if default is inspect.Parameter.empty else f"default {default!r}"
        lines.append(f"    {field.name} ({shown})")
        for line in docs[field.name].splitlines():
            lines.append(f"        {line}" if line else "")
    return "\n".join(lines)


def document_keywords(params_class: type) -> Callable[[EnvClass], EnvClass]:
    """Class decorator: list ``params_class``'s fields in the class docstring and in the
    signature of its ``__init__`` (in place of its ``**overrides``)."""

    def decorate(env_class: EnvClass) -> EnvClass:
        doc = inspect.cleandoc(env_class.__doc__ or "")
        env_class.__doc__ = f"{doc}\n\n{keywords_section(params_class)}\n"
        init = env_class.__init__
        signature = inspect.signature(init)
        kept = [
            parameter
            for parameter in signature.parameters.values()
            if parameter.kind is not inspect.Parameter.VAR_KEYWORD
        ]
        taken = {parameter.name for parameter in kept}
        fields = [
            inspect.Parameter(
                field.name,
                inspect.Parameter.KEYWORD_ONLY,
                default=_field_default(field),
                annotation=field.type,
            )
            for field in dataclasses.fields(params_class)
            if field.name not in taken
        ]
        # typeshed declares no __signature__ on functions; inspect.signature reads it.
        init.__signature__ = signature.replace(parameters=[*kept, *fields])  # pyright: ignore[reportAttributeAccessIssue]
        return env_class

    return decorate
